//! `scorpion read`: dump robot memory with `/7R` questions.

use std::path::PathBuf;
use std::process::ExitCode;

use miette::IntoDiagnostic;

use crate::args;
use crate::cmd::ports;

/// Read robot memory with `/7Raaaa##` questions (each span read until two
/// answers agree) and print it as hex, or write it raw to a file.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    #[command(flatten)]
    line: ports::Line,
    /// The first address: `0x0400`, `$0400` or `1024`.
    #[arg(value_parser = args::address)]
    address: u16,
    /// How many bytes.
    #[arg(value_parser = args::length)]
    length: u32,
    /// Write the bytes to this file instead of printing them.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    if u32::from(args.address) + args.length > 0x1_0000 {
        miette::bail!(
            "reading {} bytes at ${:04X} runs past $FFFF",
            args.length,
            args.address
        );
    }
    // A FIFO or a device is refused before the line is used, not blocked
    // on after the read.
    if let Some(path) = &args.output {
        hostfs::check_writable(path)?;
    }
    let (mut client, _) = ports::probed(&args.line)?;
    // A counter the robot's program keeps is read as it was at one
    // moment, and said (hostile16 F4), not refused as a failed read.
    let uploader::LiveRead { bytes, changing } =
        client.read_live(args.address, args.length as usize)?;
    if !changing.is_empty() {
        // On stderr: stdout is the dump, which scripts read.
        crate::cmd::say_err(&format!(
            "note: the robot wrote {} while it was read, as it runs: one moment's value\n",
            uploader::addresses_text(&changing)
        ));
    }
    match &args.output {
        Some(path) => hostfs::write(path, &bytes)?,
        None => {
            let mut out = std::io::stdout().lock();
            debugger::monitor::write_dump(&mut out, args.address, &bytes).into_diagnostic()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
