//! `scorpion disasm`: disassemble a raw binary.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

use crate::args;

/// Disassemble a raw binary file.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The raw binary to disassemble.
    file: PathBuf,
    /// Address of the file's first byte.
    #[arg(long, value_parser = args::address, default_value = "0")]
    base: u16,
    /// Address to start disassembling at (default: the base).
    #[arg(long, value_parser = args::address)]
    start: Option<u16>,
    /// Number of bytes to disassemble (default: to the end of the file).
    #[arg(long, value_parser = args::length)]
    length: Option<u32>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let bytes = std::fs::read(&args.file)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {}", args.file.display()))?;
    let start = args.start.unwrap_or(args.base);
    let offset = usize::from(start.wrapping_sub(args.base));
    if start < args.base || offset > bytes.len() {
        miette::bail!(
            "--start ${start:04X} is outside {} (${:04X}-${:04X})",
            args.file.display(),
            args.base,
            usize::from(args.base) + bytes.len().saturating_sub(1)
        );
    }
    let rest = &bytes[offset..];
    let length = args
        .length
        .map_or(rest.len(), |length| (length as usize).min(rest.len()));
    let mut out = std::io::stdout().lock();
    for line in isa::Disassembler::new(&rest[..length], start) {
        writeln!(out, "{line}").into_diagnostic()?;
    }
    Ok(ExitCode::SUCCESS)
}
