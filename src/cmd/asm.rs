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
    #[command(flatten)]
    assembler: AsmOptions,
}

/// The assembler's options, shared by `scorpion asm` and `scorpion build`.
#[derive(Debug, clap::Args)]
pub(crate) struct AsmOptions {
    /// Search this directory for `.include` files, after the including
    /// file's own (repeatable).
    #[arg(short = 'I', long = "include-dir", value_name = "DIR")]
    include_dirs: Vec<PathBuf>,
    /// Search this directory for `.incbin` files, after the working
    /// directory and the including file's (repeatable; ca65's order).
    #[arg(long = "bin-include-dir", value_name = "DIR")]
    bin_include_dirs: Vec<PathBuf>,
    /// Define a symbol before the first line of each source: NAME or
    /// NAME=VALUE (repeatable; VALUE as 42, $2A, 0x2A or %101010; default 1).
    #[arg(short = 'D', long = "define", value_name = "NAME[=VALUE]", value_parser = crate::args::define)]
    defines: Vec<(String, i64)>,
    /// Accept the undocumented NMOS opcodes (as `.setcpu "6502X"`).
    #[arg(long)]
    undocumented: bool,
    /// Stop keeping errors of a source after this many (the rest are counted).
    #[arg(long, default_value_t = 50, value_name = "N")]
    max_errors: usize,
    /// Switch a ca65 feature on from the first line, as `.feature NAME`
    /// does (repeatable).
    #[arg(long = "feature", value_name = "NAME", value_parser = crate::args::feature)]
    features: Vec<String>,
    /// ca65's target system (`ca65 -t c64`): defines its symbols
    /// (`__C64__`, `__CBM__`) and translates strings and characters to its
    /// character set (PETSCII, ATASCII).
    #[arg(short = 't', long = "system", value_name = "SYSTEM", value_parser = crate::args::system)]
    system: Option<&'static assembler::systems::System>,
    /// Zero page for operands whose symbol is defined further down,
    /// wherever its final value fits (ca65, and so the default, assembles
    /// them as absolute and warns).
    #[arg(long)]
    forward_zero_page: bool,
}

impl AsmOptions {
    /// The library's options; `.include "scorpion.inc"` finds the ROM's
    /// names with no path.
    pub(crate) fn options(&self, listing: bool) -> assembler::Options {
        assembler::Options {
            include_dirs: self.include_dirs.clone(),
            // As ca65: `.include "apple2.inc"` with no `-I`.
            system_include_dirs: assembler::cc65_include_dirs(),
            bin_include_dirs: self.bin_include_dirs.clone(),
            defines: self.defines.clone(),
            listing,
            max_errors: self.max_errors,
            undocumented: self.undocumented,
            builtin_includes: scorpion_project::runner::builtin_includes(),
            features: {
                let mut features = assembler::Features::default();
                for name in &self.features {
                    // Checked by the argument's parser.
                    let _ = features.set(name, true);
                }
                features
            },
            system: self.system,
            forward_zero_page: self.forward_zero_page,
            ..assembler::Options::default()
        }
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let options = args.assembler.options(args.listing.is_some());
    let assembly = assembler::assemble(&assembler::FsSource, &args.source, &options)?;
    report(&assembly);
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

/// Prints an assembly's warnings as miette reports on stderr and its
/// `.out` text on stdout.
pub(crate) fn report(assembly: &assembler::Assembly) {
    for warning in &assembly.warnings {
        // "Warning: " as miette heads a related warning: the problem
        // matcher reads a warning's severity there.
        crate::cmd::say_err(&format!(
            "Warning: {:?}\n",
            miette::Report::new(warning.clone())
        ));
    }
    for message in &assembly.messages {
        // `.out` text is the program's output.
        crate::cmd::say_out(&format!("{message}\n"));
    }
}
