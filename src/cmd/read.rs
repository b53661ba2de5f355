//! `scorpion read`: dump robot memory with `/7R` questions.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

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
    let (mut client, _) = ports::probed(&args.line)?;
    let bytes = client.read_memory(args.address, args.length as usize)?;
    match &args.output {
        Some(path) => std::fs::write(path, &bytes)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?,
        None => {
            let mut out = std::io::stdout().lock();
            write_dump(&mut out, args.address, &bytes).into_diagnostic()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Sixteen bytes a line: address, hex, and the printable characters.
pub(crate) fn write_dump(out: &mut impl Write, address: u16, bytes: &[u8]) -> std::io::Result<()> {
    for (row, chunk) in bytes.chunks(16).enumerate() {
        let at = usize::from(address) + row * 16;
        write!(out, "{at:04X}:")?;
        for byte in chunk {
            write!(out, " {byte:02X}")?;
        }
        let pad = 3 * (16 - chunk.len());
        let text: String = chunk
            .iter()
            .map(|&b| {
                if (0x20..0x7F).contains(&b) {
                    char::from(b)
                } else {
                    '.'
                }
            })
            .collect();
        writeln!(out, "{:pad$}  {text}", "")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn dump_layout() {
        let mut out = Vec::new();
        super::write_dump(&mut out, 0x0400, b"HELLO, SCORPION!\x4C\x00").expect("in memory");
        assert_eq!(
            String::from_utf8(out).expect("ASCII"),
            "0400: 48 45 4C 4C 4F 2C 20 53 43 4F 52 50 49 4F 4E 21  HELLO, SCORPION!\n\
             0410: 4C 00                                            L.\n"
        );
    }
}
