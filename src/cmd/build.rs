//! `scorpion build`: assemble sources and link them in one step, with the
//! objects kept in memory.

use std::path::PathBuf;
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

use crate::cmd::link::{DiskSources, LinkArgs, link_and_write};

/// Assemble ca65-syntax sources and link them into a Scorpion image.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The sources, in link order.
    #[arg(required = true, value_name = "SRC")]
    sources: Vec<PathBuf>,
    /// Search this directory for `.include` and `.incbin` files (repeatable).
    #[arg(short = 'I', long = "include-dir", value_name = "DIR")]
    include_dirs: Vec<PathBuf>,
    /// Define a symbol before the first line of every source: NAME or
    /// NAME=VALUE (repeatable; VALUE as 42, $2A, 0x2A or %101010; default 1).
    #[arg(short = 'D', long = "define", value_name = "NAME[=VALUE]", value_parser = define)]
    defines: Vec<(String, i64)>,
    /// Accept the undocumented NMOS opcodes (as `.setcpu "6502X"`).
    #[arg(long)]
    undocumented: bool,
    /// Stop keeping errors after this many per source (the rest are counted).
    #[arg(long, default_value_t = 50, value_name = "N")]
    max_errors: usize,
    /// Write the sources' listings, one after the other, to this file.
    #[arg(short = 'l', long = "listing", value_name = "LISTING")]
    listing: Option<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
}

/// Parses `NAME` or `NAME=VALUE` as `scorpion asm -D` does.
fn define(text: &str) -> Result<(String, i64), String> {
    let (name, value) = text.split_once('=').unwrap_or((text, "1"));
    let valid = name
        .bytes()
        .next()
        .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
        && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
    if !valid {
        return Err(format!(
            "`{name}` is not a symbol name (letters, digits and `_`)"
        ));
    }
    let value = value.trim();
    let (negative, digits) = value
        .strip_prefix('-')
        .map_or((false, value), |rest| (true, rest));
    let (digits, radix) = if let Some(hex) = digits
        .strip_prefix('$')
        .or_else(|| digits.strip_prefix("0x"))
        .or_else(|| digits.strip_prefix("0X"))
    {
        (hex, 16)
    } else if let Some(binary) = digits.strip_prefix('%') {
        (binary, 2)
    } else {
        (digits, 10)
    };
    let number = i64::from_str_radix(digits, radix)
        .ok()
        .filter(|n| *n <= i64::from(u32::MAX))
        .ok_or_else(|| format!("`{value}` is not a number (write 42, $2A, 0x2A or %101010)"))?;
    Ok((name.to_owned(), if negative { -number } else { number }))
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    #[allow(
        clippy::needless_update,
        reason = "options the assembler adds later keep their defaults"
    )]
    let options = assembler::Options {
        include_dirs: args.include_dirs.clone(),
        defines: args.defines.clone(),
        listing: args.listing.is_some(),
        max_errors: args.max_errors,
        undocumented: args.undocumented,
        // `.include "scorpion.inc"` finds the ROM's names, as in `scorpion asm`.
        builtin_includes: crate::cmd::asm::builtin_includes(),
        ..assembler::Options::default()
    };
    let mut objects = Vec::with_capacity(args.sources.len());
    let mut listings = String::new();
    let mut failures = Vec::new();
    for source in &args.sources {
        match assembler::assemble(&assembler::FsSource, source, &options) {
            Ok(assembly) => {
                crate::cmd::asm::report_warnings(&assembly.warnings);
                for message in &assembly.messages {
                    #[allow(clippy::print_stdout, reason = "`.out` text is the program's output")]
                    {
                        println!("{message}");
                    }
                }
                if let Some(listing) = &assembly.listing {
                    listings.push_str(listing);
                    listings.push('\n');
                }
                objects.push((source.display().to_string(), assembly.object));
            }
            // Every source is assembled, so all their errors show at once.
            Err(error) => failures.push(error),
        }
    }
    if let Some(last) = failures.pop() {
        for error in failures {
            #[allow(clippy::print_stderr, reason = "the CLI reports errors")]
            {
                eprintln!("{:?}", miette::Report::new(error));
            }
        }
        return Err(last.into());
    }
    if let Some(path) = &args.listing {
        std::fs::write(path, &listings)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
    }
    link_and_write(&objects, &args.link, &DiskSources)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_in_every_spelling() {
        assert_eq!(define("DEBUG"), Ok(("DEBUG".into(), 1)));
        assert_eq!(define("X=$2A"), Ok(("X".into(), 42)));
        assert_eq!(define("X=-0x10"), Ok(("X".into(), -16)));
        assert!(define("9X").is_err());
        assert!(define("X=zz").is_err());
    }
}
