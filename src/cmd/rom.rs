//! `scorpion rom read`: a robot's whole ROM, read over its line and
//! verified, as a ROM profile (a linked ELF) that a project's `[robot]
//! rom` (its `build`, `test`, `upload`, `sim`), `link --just-symbols` and
//! `scorpion sim --rom` use.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use crate::cmd::ports;

/// What `scorpion rom` does.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// Read the robot's whole ROM (`$F000`-`$FFFF`, every span read until
    /// two answers agree) into a ROM profile: the bytes read, with the
    /// names (services, hooks, RAM) of a base profile.
    Read(ReadArgs),
}

/// `scorpion rom read`.
#[derive(Debug, clap::Args)]
struct ReadArgs {
    #[command(flatten)]
    line: ports::Line,
    /// Where to write the profile (an ELF image).
    #[arg(short, long)]
    output: PathBuf,
    /// The profile whose names the new one keeps (the jump table's are
    /// fixed; RAM names come from the ROM's documentation); by default the
    /// built-in reference ROM's.
    #[arg(long, value_name = "ROM.elf")]
    base: Option<PathBuf>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    match &args.command {
        Command::Read(read) => run_read(read),
    }
}

/// A base profile is a ROM's image: bytes in the ROM (`$F000`-`$FFFF`)
/// and the services of its jump table. An extension's image has neither,
/// and the profile made from it would name nothing.
fn refuse_non_rom(name: &str, image: &linker::Image) -> miette::Result<()> {
    let start = u32::from(platform::map::ROM_START);
    let in_rom = image.areas.iter().any(|area| area.end() > u64::from(start));
    let services = uploader::SERVICES
        .iter()
        .filter(|service| image.symbol(service).is_some())
        .count();
    if in_rom && services > 0 {
        return Ok(());
    }
    let loads: Vec<String> = image
        .areas
        .iter()
        .map(|area| format!("${:04X}-${:04X}", area.load, area.end().saturating_sub(1)))
        .collect();
    let what = if in_rom {
        "names none of the jump table's services".to_owned()
    } else if loads.is_empty() {
        "loads nothing".to_owned()
    } else {
        format!(
            "loads {}, and a ROM loads at ${start:04X}-$FFFF",
            loads.join(", ")
        )
    };
    Err(miette::miette!(
        help = "give a ROM profile (the ROM's linked ELF, or one `scorpion rom read` wrote), or leave --base out for the reference ROM's names",
        "--base {name} is not a ROM profile: it {what}"
    ))
}

fn run_read(args: &ReadArgs) -> miette::Result<ExitCode> {
    let (base_name, base) = match &args.base {
        Some(path) => {
            let name = path.display().to_string();
            let bytes = hostfs::read(path, hostfs::BINARY)?;
            let image = linker::Image::parse(&name, &bytes)?;
            refuse_non_rom(&name, &image)?;
            (name, image)
        }
        None => (
            "the built-in reference ROM".to_owned(),
            linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF)?,
        ),
    };
    hostfs::check_writable(&args.output)?;
    let (mut client, _) = ports::probed_for_rom(&args.line)?;
    let start = platform::map::ROM_START;
    let bytes = client.read_memory(start, platform::map::ROM_SIZE)?;
    let (image, differences) = uploader::rom_profile_image(&base, start, &bytes);
    let out = linker::output::write_elf(&image)?;
    hostfs::write(&args.output, &out)?;
    let mut text = format!(
        "read the robot's ROM (${start:04X}-$FFFF, {} bytes, verified) into {}",
        bytes.len(),
        args.output.display()
    );
    if differences == 0 {
        let _ = write!(text, "\n  it is {base_name}, byte for byte");
    } else {
        let _ = write!(
            text,
            "\n  {differences} {} from {base_name}, whose names it keeps",
            if differences == 1 {
                "byte differs"
            } else {
                "bytes differ"
            }
        );
    }
    crate::cmd::say_out(&format!("{text}\n"));
    Ok(ExitCode::SUCCESS)
}
