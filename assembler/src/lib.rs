//! The 6502 assembler: ca65-syntax source to ELF relocatable objects.
//!
//! [`assemble`] reads a main file (and what it includes) through a
//! [`FileSource`], and returns an [`Assembly`]: the object file's bytes,
//! the listing if asked for, warnings and `.out` messages. Problems come
//! back as [`Error::Failed`] carrying every diagnostic of the run (up to
//! [`Options::max_errors`]), each with file, line, column, the marked
//! source and the macro/include backtrace, ready for miette.
//!
//! How it works, in four stages:
//! 1. the front end (`asm`) lexes each line once (`lexer`), expands
//!    macros, `.repeat`s and `.define`s, evaluates conditionals and builds
//!    a `model::Program`: segments cut into chunks of known size, symbols,
//!    expression nodes, fixups;
//! 2. the layout passes (`layout`) place the chunks; with
//!    [`Options::forward_zero_page`] they also settle the operands that
//!    could be zero-page or absolute (symbols defined later) by a widening
//!    fixpoint, where by default such an operand is decided at its line
//!    as ca65 decides it (`addrsize`);
//! 3. resolution turns every fixup into bytes or an `R_MOS_*` relocation,
//!    checks ranges, branches and `.assert`s;
//! 4. `elf` writes the object (docs/ARCHITECTURE.md, "The object format").
//!
//! Constant folding uses `isa::objfmt`'s operators, so the linker computes
//! deferred assertions exactly as the assembler would.

mod addrsize;
mod asm;
mod cursor;
mod diag;
mod directives;
mod elf;
mod expr;
mod features;
mod instr;
mod intern;
mod lexer;
mod listing;
mod macpack;
mod model;
mod output;
mod parse;
mod resolver;
mod source;
pub mod systems;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use diag::{Diagnostic, Location, Severity};
pub use features::{CA65_FEATURES, FeatureError, Features};
pub use source::{FileSource, FsSource, MemorySource};

/// The values a `-D NAME=VALUE` definition may take: ca65's 32-bit
/// magnitudes, either sign. Every front end (the `-D` flag, a project's
/// `defines`) refuses what lies outside rather than truncating it.
pub const DEFINE_VALUES: std::ops::RangeInclusive<i64> = -(u32::MAX as i64)..=u32::MAX as i64;

/// How to assemble.
#[derive(Debug, Clone)]
pub struct Options {
    /// Directories searched by `.include` after the including file's own
    /// directory (`-I`, as ca65's).
    pub include_dirs: Vec<PathBuf>,
    /// Directories searched by `.include` after [`Options::include_dirs`]:
    /// ca65's own path (`CA65_INC`, cc65's `asminc`), from
    /// [`cc65_include_dirs`], where `.include "apple2.inc"` is found
    /// without `-I`.
    pub system_include_dirs: Vec<PathBuf>,
    /// Directories searched by `.incbin` after the working directory and
    /// the including file's directory (ca65's `--bin-include-dir`).
    pub bin_include_dirs: Vec<PathBuf>,
    /// Symbols defined before the first line (`-D NAME=VALUE`).
    pub defines: Vec<(String, i64)>,
    /// Files that `.include` finds by name when no directory has them
    /// (the CLI registers `scorpion.inc` here).
    pub builtin_includes: BTreeMap<String, Vec<u8>>,
    /// Produce a listing.
    pub listing: bool,
    /// List the text of [`Options::builtin_includes`] where `.include`
    /// reads it (the default). Off, the listing shows the `.include` line
    /// and what the including file makes of it, not the included text: a
    /// project's snapshots then change with its own code, not with the
    /// ROM's exported names.
    pub list_builtin_includes: bool,
    /// Errors kept before the rest are only counted.
    pub max_errors: usize,
    /// Accept the undocumented NMOS opcodes from the start (as
    /// `.setcpu "6502X"`).
    pub undocumented: bool,
    /// Most source lines read, expansions included, before assembly stops
    /// with an error: the guard against runaway `.repeat`s and recursive
    /// macros (default 4,000,000, twenty times the 200,000-line benchmark).
    pub max_lines: u64,
    /// `.feature` switches on from the first line (`--feature`).
    pub features: Features,
    /// ca65's target system (`-t`): its symbols and character set.
    pub system: Option<&'static systems::System>,
    /// Zero page for operands whose value is defined further down,
    /// wherever the final value fits (the layout passes settle it). Off
    /// by default: ca65 assembles them as absolute, and so do we (with a
    /// warning where zero page was possible), byte for byte as ca65.
    pub forward_zero_page: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            include_dirs: Vec::new(),
            system_include_dirs: Vec::new(),
            bin_include_dirs: Vec::new(),
            defines: Vec::new(),
            builtin_includes: BTreeMap::new(),
            listing: false,
            list_builtin_includes: true,
            max_errors: 50,
            undocumented: false,
            max_lines: 4_000_000,
            features: Features::default(),
            system: None,
            forward_zero_page: false,
        }
    }
}

/// The directories ca65 searches for `.include` after its `-I` ones, in
/// its order: each of `CA65_INC` (a path list), `$CC65_HOME/asminc`, then
/// the places cc65's packages install `asminc` (`/usr/share/cc65/asminc`,
/// `/usr/local/share/cc65/asminc`); only those that exist.
#[must_use]
pub fn cc65_include_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = Vec::new();
    if let Some(list) = std::env::var_os("CA65_INC") {
        dirs.extend(std::env::split_paths(&list));
    }
    if let Some(home) = std::env::var_os("CC65_HOME") {
        dirs.push(PathBuf::from(home).join("asminc"));
    }
    dirs.push(PathBuf::from("/usr/share/cc65/asminc"));
    dirs.push(PathBuf::from("/usr/local/share/cc65/asminc"));
    let mut seen = Vec::new();
    dirs.retain(|dir| {
        let keep = dir.is_dir() && !seen.contains(dir);
        seen.push(dir.clone());
        keep
    });
    dirs
}

/// A successful assembly.
#[derive(Debug, Clone)]
pub struct Assembly {
    /// The ELF relocatable object.
    pub object: Vec<u8>,
    /// The listing, if [`Options::listing`] was set.
    pub listing: Option<String>,
    /// Warnings (the object is still good).
    pub warnings: Vec<Diagnostic>,
    /// Text from `.out` directives, in order.
    pub messages: Vec<String>,
}

/// Why there is no object.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// The main source file cannot be read.
    #[error("cannot read `{path}`")]
    #[diagnostic(code(asm::read), help("check that the file exists and is readable"))]
    Read {
        /// The path as given.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The source has errors; every diagnostic of the run is attached.
    #[error("{errors} error{} in `{path}`", if *errors == 1 { "" } else { "s" })]
    #[diagnostic(code(asm::failed))]
    Failed {
        /// The main file.
        path: PathBuf,
        /// How many errors there were (more than are attached if capped).
        errors: usize,
        /// Errors and warnings, in the order found.
        #[related]
        diagnostics: Vec<Diagnostic>,
    },
    /// The object writer failed (not expected for any input).
    #[error("cannot encode the ELF object: {0}")]
    #[diagnostic(code(asm::object))]
    Object(String),
}

impl Error {
    /// The diagnostics of a failed assembly (empty for other errors).
    #[must_use]
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            Error::Failed { diagnostics, .. } => diagnostics,
            _ => &[],
        }
    }
}

/// Assembles `path`, reading it and its includes through `source`.
///
/// # Errors
/// [`Error::Read`] when the main file cannot be read, [`Error::Failed`]
/// with every diagnostic when the source has errors.
pub fn assemble(
    source: &dyn FileSource,
    path: &Path,
    options: &Options,
) -> Result<Assembly, Error> {
    let bytes = source.read(path).map_err(|error| Error::Read {
        path: path.to_path_buf(),
        source: error,
    })?;
    let mut asm = asm::Asm::new(source, options);
    if options.listing {
        asm.listing = Some(listing::ListingBuilder::new());
    }
    let system_defines: Vec<(String, i64)> = options
        .system
        .iter()
        .flat_map(|s| s.defines.iter().map(|name| ((*name).to_owned(), 1)))
        .filter(|(name, _)| !options.defines.iter().any(|(own, _)| own == name))
        .collect();
    define_symbols(&mut asm, &system_defines);
    define_symbols(&mut asm, &options.defines);
    let name = path.display().to_string();
    asm.main_name = path
        .file_name()
        .map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned());
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    asm.push_file(name, bytes, dir, 0);
    asm.run();
    // After a missing include the rest of the source was not read:
    // checking what was would only report what the include defines.
    let out = (!asm.fatal).then(|| {
        asm.finish_front();
        asm.layout();
        asm.resolve()
    });
    // In source order: by where each came from in the main file (the
    // outermost include or macro call), then by its own place.
    let ctx = &asm.ctx;
    asm.rep.diags.sort_by_key(|raw| {
        let mut outer = raw.span;
        let mut id = raw.ctx;
        let mut guard = 0;
        while id != 0 && guard < 256 {
            let Some(node) = ctx.get(id as usize) else {
                break;
            };
            outer = node.span;
            id = node.parent;
            guard += 1;
        }
        (outer.file, outer.start, raw.span.file, raw.span.start)
    });
    let mut diagnostics: Vec<Diagnostic> = asm
        .rep
        .diags
        .iter()
        .map(|raw| Diagnostic::render(&asm.files, &asm.ctx, raw))
        .collect();
    if asm.rep.dropped > 0 {
        let stopped = if asm.rep.stopped {
            "; assembly stopped early because of the number of errors"
        } else {
            ""
        };
        diagnostics.push(Diagnostic::plain(
            Severity::Error,
            "asm::too-many-errors",
            format!(
                "{} more diagnostic{} not shown{stopped}",
                asm.rep.dropped,
                if asm.rep.dropped == 1 { "" } else { "s" }
            ),
        ));
    }
    let mut out = match out {
        Some(out) if !asm.rep.has_errors() => out,
        _ => {
            return Err(Error::Failed {
                path: path.to_path_buf(),
                errors: asm.rep.errors,
                diagnostics,
            });
        }
    };
    let mut e_flags = isa::elf::EF_MOS_ARCH_6502;
    if asm.used_undoc {
        e_flags |= isa::elf::EF_MOS_ARCH_6502X;
    }
    let object = elf::write_object(&mut out, &asm.files, &asm.main_name, e_flags)
        .map_err(|error| Error::Object(error.to_string()))?;
    let listing = asm
        .listing
        .as_ref()
        .map(|listing| listing.render(&asm.main_name, &asm.files, &asm.prog, &out));
    Ok(Assembly {
        object,
        listing,
        warnings: diagnostics,
        messages: std::mem::take(&mut asm.messages),
    })
}

/// Assembles source text held in memory (no includes beyond `options`'
/// built-in files).
///
/// # Errors
/// As [`assemble`].
pub fn assemble_str(name: &str, text: &str, options: &Options) -> Result<Assembly, Error> {
    let source = MemorySource::new().with(name, text.as_bytes());
    assemble(&source, Path::new(name), options)
}

/// `-D NAME=VALUE` symbols, defined in a pseudo-file so that diagnostics
/// can point at them.
fn define_symbols(asm: &mut asm::Asm<'_>, defines: &[(String, i64)]) {
    if defines.is_empty() {
        return;
    }
    let mut text = String::new();
    let mut spans = Vec::new();
    for (name, value) in defines {
        let start = text.len() as u32;
        text.push_str(name);
        spans.push((name.clone(), *value, start, text.len() as u32));
        text.push_str(&format!("={value}\n"));
    }
    let file = asm
        .files
        .add("<command line>".to_string(), Arc::new(text.into_bytes()));
    for (line, (name, value, start, end)) in spans.into_iter().enumerate() {
        asm.input.line = lexer::LineInfo {
            file,
            line: line as u32 + 1,
            start,
            end,
            ascii: name.is_ascii(),
        };
        let span = diag::Span { file, start, end };
        let valid = !name.is_empty()
            && name
                .bytes()
                .next()
                .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
            && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
        if !valid {
            asm.err(
                "asm::define",
                span,
                format!("`{name}` is not a symbol name (letters, digits and `_`)"),
            );
            continue;
        }
        let id = asm.names.intern(&name);
        let sym = asm.sym_in(model::GLOBAL_SCOPE, id);
        let _ = asm.define(sym, model::SymDef::Const(value), span);
    }
}
