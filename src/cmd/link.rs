//! `scorpion link`: link 6502 ELF objects into a Scorpion image.
//!
//! [`LinkArgs`] are shared with `scorpion build`, which links the objects it
//! assembles without writing them to disk.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use linker::{Format, Image, Linked, SourceProvider, Target};
use miette::Context;

use crate::args;

/// Where the image goes and what the linker needs besides the objects.
#[derive(Debug, clap::Args)]
pub(crate) struct LinkArgs {
    /// The image to write (required but for `scorpion build` in a
    /// project, which writes into `target/scorpion/`).
    #[arg(short, long, value_name = "OUT")]
    pub(crate) output: Option<PathBuf>,
    /// Where things go: flat, scorpion-ext, scorpion-os, scorpion-rom, a
    /// layout file (FILE.toml) or an ld65 configuration (FILE.cfg)
    /// [default: scorpion-ext].
    #[arg(long, value_name = "NAME|FILE.toml|FILE.cfg")]
    pub(crate) target: Option<String>,
    /// First address of the flat target's area; for an ld65
    /// configuration, what `%S` stands for (ld65's `-S`).
    #[arg(long, value_name = "ADDR", value_parser = args::address)]
    pub(crate) start: Option<u16>,
    /// Output format: elf (the linked image the emulator and uploader load),
    /// bin, ihex (Intel HEX), srec (Motorola S-record) or kim (KIM-1 tape)
    /// [default: elf].
    #[arg(long, value_name = "FORMAT", value_parser = parse_format)]
    pub(crate) format: Option<Format>,
    /// Also write a map file (areas, segments, modules, symbols).
    #[arg(long, value_name = "FILE")]
    pub(crate) map: Option<PathBuf>,
    /// Also write a VICE label file.
    #[arg(long, value_name = "FILE")]
    pub(crate) labels: Option<PathBuf>,
    /// Take absolute symbols from a linked ELF image (the ROM, for an
    /// extension); also gives the Scorpion targets their RAM bounds.
    /// Default for scorpion-ext and scorpion-os: the built-in reference ROM.
    #[arg(long = "just-symbols", value_name = "FILE")]
    pub(crate) just_symbols: Vec<PathBuf>,
}

impl LinkArgs {
    /// `--target`, or the default.
    pub(crate) fn target_name(&self) -> &str {
        self.target.as_deref().unwrap_or("scorpion-ext")
    }

    /// `--format`, or the default.
    pub(crate) fn format(&self) -> Format {
        self.format.unwrap_or(Format::Elf)
    }

    /// The flags given that only a build outside a project can honour.
    pub(crate) fn given(&self) -> Vec<&'static str> {
        let mut given = Vec::new();
        for (flag, is) in [
            ("-o", self.output.is_some()),
            ("--target", self.target.is_some()),
            ("--start", self.start.is_some()),
            ("--format", self.format.is_some()),
            ("--map", self.map.is_some()),
            ("--labels", self.labels.is_some()),
            ("--just-symbols", !self.just_symbols.is_empty()),
        ] {
            if is {
                given.push(flag);
            }
        }
        given
    }
}

/// How messages and maps name romlib's ROM image.
const BUILTIN_ROM: &str = "the built-in reference ROM";

fn parse_format(text: &str) -> Result<Format, String> {
    text.parse()
}

/// Link 6502 ELF objects into a Scorpion image.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The objects, in link order.
    #[arg(required = true, value_name = "OBJ")]
    objects: Vec<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
}

/// Source files for diagnostics, read from the disk when asked for.
pub(crate) struct DiskSources;

impl SourceProvider for DiskSources {
    fn source(&self, path: &str) -> Option<String> {
        hostfs::read_text(Path::new(path), hostfs::TEXT).ok()
    }
}

fn read(path: &Path) -> miette::Result<Vec<u8>> {
    hostfs::read(path, hostfs::BINARY).wrap_err_with(|| format!("cannot read {}", path.display()))
}

/// The target `--target` and `--start` name.
fn target(args: &LinkArgs) -> miette::Result<Target> {
    let start = args.start.map(u64::from);
    let name = args.target_name();
    if name.ends_with(".toml") {
        if start.is_some() {
            miette::bail!(
                help = "a layout file gives its areas' addresses itself",
                "--start applies to the flat target, not a layout file"
            );
        }
        let text = hostfs::read_text(Path::new(name), hostfs::TEXT)
            .wrap_err_with(|| format!("cannot read layout {name}"))?;
        return Ok(Target::Custom(linker::Layout::from_toml(name, &text)?));
    }
    if name.ends_with(".cfg") {
        let text = hostfs::read_text(Path::new(name), hostfs::TEXT)
            .wrap_err_with(|| format!("cannot read the ld65 configuration {name}"))?;
        return Ok(Target::Custom(linker::Layout::from_ld65(
            name, &text, start,
        )?));
    }
    Ok(Target::builtin(name, start)?)
}

/// Links named objects with `args` and writes everything asked for.
pub(crate) fn link_and_write(
    objects: &[(String, Vec<u8>)],
    args: &LinkArgs,
    sources: &dyn SourceProvider,
) -> miette::Result<ExitCode> {
    let Some(output) = &args.output else {
        miette::bail!(
            help = "name the image to write: `-o ext.elf`",
            "no output file (-o OUT)"
        );
    };
    let target = target(args)?;
    let mut symbol_images = Vec::with_capacity(args.just_symbols.len());
    for path in &args.just_symbols {
        let name = path.display().to_string();
        let image = Image::parse(&name, &read(path)?)?;
        symbol_images.push((name, image));
    }
    // Code for the robot links against the ROM it will run with: the
    // reference ROM unless the user names their own.
    if symbol_images.is_empty() && matches!(target, Target::ScorpionExt | Target::ScorpionOs) {
        let name = BUILTIN_ROM.to_owned();
        let image = Image::parse(&name, romlib::ROM_ELF)?;
        symbol_images.push((name, image));
    }
    let mut linked =
        scorpion_project::runner::link_objects(objects, &target, &symbol_images, sources)?;
    report_warnings(&mut linked);
    let bytes = linked.write(args.format())?;
    // Every output is checked before any is written: a missing directory
    // for the map must not leave a new image beside the old map.
    check_outputs(args)?;
    for file in &linked.other_files {
        hostfs::check_writable(file.path(&output.display().to_string()))?;
    }
    write(output, &bytes)?;
    let mut others = Vec::new();
    for file in &linked.other_files {
        let path = PathBuf::from(file.path(&output.display().to_string()));
        let bytes = file.bytes();
        write(&path, &bytes)?;
        others.push(format!("{} ({} bytes)", path.display(), bytes.len()));
    }
    if let Some(path) = &args.map {
        write(path, linked.map().as_bytes())?;
    }
    if let Some(path) = &args.labels {
        write(path, linked.vice_labels().as_bytes())?;
    }
    summary(&linked, args, output, &others);
    Ok(ExitCode::SUCCESS)
}

/// Refuses outputs that cannot be written (a missing directory, a FIFO, a
/// device), before anything is written.
pub(crate) fn check_outputs(args: &LinkArgs) -> miette::Result<()> {
    for path in args.output.iter().chain(&args.map).chain(&args.labels) {
        hostfs::check_writable(path)?;
    }
    Ok(())
}

/// Writes an output as every command does (whole or not at all, and the
/// same words when it cannot).
fn write(path: &Path, bytes: &[u8]) -> miette::Result<()> {
    Ok(hostfs::write(path, bytes)?)
}

fn report_warnings(linked: &mut Linked) {
    for warning in std::mem::take(&mut linked.warnings) {
        // "Warning: " as miette heads a related warning: the problem
        // matcher reads a warning's severity there.
        crate::cmd::say_err(&format!("Warning: {:?}\n", miette::Report::new(warning)));
    }
}

fn summary(linked: &Linked, args: &LinkArgs, output: &Path, others: &[String]) {
    let image = &linked.image;
    let ranges: Vec<String> = image
        .areas
        .iter()
        .map(|area| format!("${:04X}-${:04X}", area.load, area.end().saturating_sub(1)))
        .collect();
    let bytes: usize = image.areas.iter().map(|area| area.bytes.len()).sum();
    crate::cmd::say_out(&format!(
        "{} ({}, target {}): {} byte{} at {}, entry ${:04X}\n",
        output.display(),
        args.format(),
        linked.layout.name,
        bytes,
        if bytes == 1 { "" } else { "s" },
        if ranges.is_empty() {
            "no address".to_owned()
        } else {
            ranges.join(", ")
        },
        image.entry
    ));
    if !others.is_empty() {
        crate::cmd::say_out(&format!("also wrote {}\n", others.join(", ")));
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let mut objects = Vec::with_capacity(args.objects.len());
    for path in &args.objects {
        objects.push((path.display().to_string(), read(path)?));
    }
    link_and_write(&objects, &args.link, &DiskSources)
}
