//! `scorpion asm`: assemble one ca65-syntax source file into an ELF object.

use std::path::PathBuf;
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

/// Assemble a ca65-syntax source file into an ELF relocatable object.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The source file.
    source: PathBuf,
    /// The object file to write (default: the source with `.o`).
    #[arg(short = 'o', long = "output", value_name = "OBJ")]
    output: Option<PathBuf>,
    /// Write a listing (address, bytes, source per line) to this file.
    #[arg(short = 'l', long = "listing", value_name = "LISTING")]
    listing: Option<PathBuf>,
    /// Search this directory for `.include` and `.incbin` files (repeatable).
    #[arg(short = 'I', long = "include-dir", value_name = "DIR")]
    include_dirs: Vec<PathBuf>,
    /// Define a symbol before the first line: NAME or NAME=VALUE (repeatable;
    /// VALUE as 42, $2A, 0x2A or %101010; default 1).
    #[arg(short = 'D', long = "define", value_name = "NAME[=VALUE]", value_parser = define)]
    defines: Vec<(String, i64)>,
    /// Accept the undocumented NMOS opcodes (as `.setcpu "6502X"`).
    #[arg(long)]
    undocumented: bool,
    /// Stop keeping errors after this many (the rest are counted).
    #[arg(long, default_value_t = 50, value_name = "N")]
    max_errors: usize,
}

/// Parses `NAME` or `NAME=VALUE`.
fn define(text: &str) -> Result<(String, i64), String> {
    let (name, value) = match text.split_once('=') {
        Some((name, value)) => (name, Some(value)),
        None => (text, None),
    };
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
    let Some(value) = value else {
        return Ok((name.to_string(), 1));
    };
    let value = value.trim();
    let (negative, digits) = match value.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, value),
    };
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
    Ok((name.to_string(), if negative { -number } else { number }))
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let options = assembler::Options {
        include_dirs: args.include_dirs.clone(),
        defines: args.defines.clone(),
        listing: args.listing.is_some(),
        max_errors: args.max_errors,
        undocumented: args.undocumented,
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&assembler::FsSource, &args.source, &options)?;
    report_warnings(&assembly.warnings);
    for message in &assembly.messages {
        #[allow(clippy::print_stdout, reason = "`.out` text is the program's output")]
        {
            println!("{message}");
        }
    }
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| args.source.with_extension("o"));
    std::fs::write(&output, &assembly.object)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", output.display()))?;
    if let (Some(path), Some(listing)) = (&args.listing, &assembly.listing) {
        std::fs::write(path, listing)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Prints warnings as miette reports on stderr.
pub(crate) fn report_warnings(warnings: &[assembler::Diagnostic]) {
    for warning in warnings {
        #[allow(clippy::print_stderr, reason = "the CLI reports warnings")]
        {
            eprintln!("{:?}", miette::Report::new(warning.clone()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_in_every_spelling() {
        assert_eq!(define("DEBUG"), Ok(("DEBUG".into(), 1)));
        assert_eq!(define("X=$2A"), Ok(("X".into(), 42)));
        assert_eq!(define("X=0x2a"), Ok(("X".into(), 42)));
        assert_eq!(define("X=%101"), Ok(("X".into(), 5)));
        assert_eq!(define("X=-3"), Ok(("X".into(), -3)));
        assert!(define("1X=2").is_err());
        assert!(define("X=zz").is_err());
    }
}
