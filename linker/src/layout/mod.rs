//! Where segments go: memory areas, segments, and the built-in targets.
//!
//! A layout is ld65's `MEMORY`/`SEGMENTS` model with fewer traps. Memory
//! **areas** are address ranges; **segments** (the objects' sections,
//! by name) are placed into areas in the order the layout lists them.
//!
//! # Built-in targets
//!
//! | target | areas | segments |
//! |---|---|---|
//! | `flat` | `ZP` $0000-$00FF (not written), `MAIN` from `--start` to $FFFF | `ZEROPAGE` in `ZP`; `CODE`, `RODATA`, `DATA`, `BSS` in `MAIN`, in that order |
//! | `scorpion-ext` | `ZP` = `USER_ZP_START`..=`USER_ZP_END`, `RAM` = `USER_RAM_START`..=`USER_RAM_END` | `ZEROPAGE` in `ZP`; `CODE`, `RODATA`, `DATA`, `BSS` in `RAM` |
//! | `scorpion-os` | `ZP` (user zero page), `KIM` = $1000-$BFFF (KIM-bus expansion RAM), `URAM` (user RAM, not written) | `ZEROPAGE` in `ZP`; `CODE`, `RODATA`, `DATA` in `KIM`; `BSS` in `URAM` |
//! | `scorpion-rom` | `ZP` = $0000..`USER_ZP_START`, `RAM` = $0200..`USER_RAM_START` (the ROM's own, not written), `ROM` = $F000-$FFFF filled with $FF | `ZEROPAGE` in `ZP`; `CODE`, `RODATA` in `ROM`; `DATA` loaded in `ROM`, run in `RAM` (with `__DATA_LOAD__`/`__DATA_RUN__`/`__DATA_SIZE__` for the start-up copy); `BSS` in `RAM`; optional `JUMPTABLE` at $FF00; `VECTORS` at $FFFA |
//!
//! Each built-in segment also takes the sections llvm-mos names for the same
//! purpose (`CODE`: `.text`, `.text.*`; `RODATA`: `.rodata*`; `DATA`:
//! `.data*`; `BSS`: `.bss*`, `.noinit*`; `ZEROPAGE`: `.zp*`, `.zeropage*`),
//! so other producers' objects link without a layout file.
//!
//! `flat` is exactly what ld65 produces with
//!
//! ```text
//! MEMORY {
//!     ZP:   start = $0000, size = $0100, type = rw, file = "";
//!     MAIN: start = ADDR,  size = $10000 - ADDR,    file = %O;
//! }
//! SEGMENTS {
//!     ZEROPAGE: load = ZP,   type = zp,  optional = yes;
//!     CODE:     load = MAIN, type = ro,  optional = yes;
//!     RODATA:   load = MAIN, type = ro,  optional = yes;
//!     DATA:     load = MAIN, type = rw,  optional = yes;
//!     BSS:      load = MAIN, type = bss, optional = yes;
//! }
//! ```
//!
//! including ld65's habit of not aligning segment starts (each object's
//! part of a segment is aligned within the segment; a misaligned segment
//! start is a warning, as ld65's "isn't aligned properly").
//!
//! The three Scorpion targets take their RAM bounds from the ROM's exported
//! symbols (inclusive ends), never from constants in the linker: give the
//! ROM's linked ELF with `--just-symbols`. `scorpion-rom` links the ROM
//! itself and reads `USER_ZP_START` and `USER_RAM_START` from the ROM's own
//! absolute exports. The KIM-bus range is the board's memory map
//! (docs/ARCHITECTURE.md), not a ROM property.
//!
//! # Layout files (`--target FILE.toml`)
//!
//! ```toml
//! name = "rom with RAM data"      # optional, for messages and the map
//!
//! [[area]]
//! name = "ZP"
//! start = "$80"                   # integers, "$hex", "0xhex" or "%binary"
//! size = "$80"                    # or: end = "$FF" (inclusive)
//! output = false                  # not part of the image (zero page, BSS)
//!
//! [[area]]
//! name = "ROM"
//! start = "$F000"
//! size = "$1000"                  # may exceed 64 KiB, e.g. "$1000000"
//! fill = true                     # write the whole area, gaps included
//! fill-value = "$FF"              # for gaps, alignment, `fill` and reserved bytes
//! define = true                   # __ROM_START__, __ROM_SIZE__, __ROM_LAST__
//!
//! [[segment]]
//! name = "CODE"
//! load = "ROM"
//! kind = "ro"                     # ro (default), rw, bss, zp
//!
//! [[segment]]
//! name = "DATA"
//! load = "ROM"                    # where its bytes are stored
//! run = "RAM"                     # where it runs (symbols get these addresses)
//! kind = "rw"
//! define = true                   # __DATA_LOAD__, __DATA_RUN__, __DATA_SIZE__
//! align = 2                       # run address alignment; align-load for the load address
//! optional = true                 # no warning when no object has it
//! sections = ["DATA", ".data*"]   # input sections it takes (default: its name; `*` ends a prefix)
//!
//! [[segment]]
//! name = "VECTORS"
//! load = "ROM"
//! start = "$FFFA"                 # a fixed address
//! ```
//!
//! Segments are placed into each area in the order the file lists them.
//! Without `align`, a segment starts at the largest alignment its inputs
//! ask for (ld65 would only warn). `__NAME_LOAD__`, `__NAME_RUN__` and
//! `__NAME_SIZE__` are the segment's load address, run address and size,
//! as ld65's `define = yes` makes them.

//!
//! # ld65 configurations (`--target FILE.cfg`)
//!
//! [`Layout::from_ld65`] reads ld65 2.19's configuration language, so a
//! ca65 project links with its own file: `MEMORY` (`start`, `size`,
//! `file` (`%O`, `""` or another name), `fill`, `fillval`, `define`,
//! `type`, `bank`), `SEGMENTS` (`load`, `run`, `type` (`ro` by default),
//! `align` (any value, as GEOS's 254), `align_load`, `start`, `offset`,
//! `optional`, `define`), `SYMBOLS` (`export`, `weak`, `import`),
//! `FEATURES` (`CONDES` tables the linker fills from the objects'
//! `.constructor` and kin, `STARTADDRESS`), `FILES` (`bin`, `atari`) and
//! `FORMATS` (`atari: runad, initad`). An area's start and size may name
//! symbols (`start = __HEADER_LAST__`, `size = __HIMEM__ - __MAIN_START__`,
//! `%S`); they are [`Expr`]s evaluated when placement reaches the area, as
//! ld65 evaluates them. As ld65: segment starts are not aligned, bytes
//! loaded where no file goes are dropped, and a BSS segment inside a
//! written area takes no room in the binary file
//! ([`crate::Linked::write`]). o65 output and `type = overwrite` are
//! refused by name.

mod builtin;
mod expr;
mod file;
mod ld65;

use std::ops::Range;
use std::sync::Arc;

pub use builtin::{BUILTIN_TARGETS, RomSymbols};
pub use expr::{EvalError, Expr, Op};
pub(crate) use ld65::START_ADDRESS_SYMBOL;

use crate::error::Error;

/// The largest area `fill = true` may write whole: a typo in a size must not
/// make the linker allocate gigabytes.
pub const MAX_FILLED_AREA: u64 = 1 << 24;

/// A memory area.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Area {
    /// Name, for segments and messages.
    pub name: String,
    /// First address.
    pub start: u64,
    /// Size in bytes (may exceed 64 KiB).
    pub size: u64,
    /// Write the whole area to the image, gaps filled.
    pub fill: bool,
    /// The byte for gaps, alignment padding, `fill`, and the reserved bytes
    /// of the sections loaded here (`.res` and `.align` without a value,
    /// listed in `.scorpion.fill`), as ld65's `fillval`.
    pub fill_value: u8,
    /// Whether the area's bytes are part of the image.
    pub output: bool,
    /// Define `__NAME_START__`, `__NAME_SIZE__`, `__NAME_LAST__`.
    pub define: bool,
    /// The output file its bytes go to when not the main one (ld65's
    /// `file = "%O.1"`; `%O` is the main output's name).
    pub file: Option<String>,
    /// `start` and `size` as an ld65 configuration writes them when they
    /// name symbols: evaluated when placement reaches the area (earlier
    /// areas' and segments' symbols known), replacing `start` and `size`.
    pub exprs: Option<(Expr, Expr)>,
}

impl Area {
    /// One past the last address.
    #[must_use]
    pub fn end(&self) -> u64 {
        self.start + self.size
    }
}

/// What a segment holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SegmentKind {
    /// Code and constants.
    ReadOnly,
    /// Initialised data.
    ReadWrite,
    /// Reserved space: never written to the image.
    Bss,
    /// Zero-page variables: reserved space that must lie in $00-$FF.
    ZeroPage,
}

/// A segment: which input sections, where they load and where they run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Segment {
    /// Name (`CODE`).
    pub name: String,
    /// The area its bytes are stored in.
    pub load: String,
    /// The area it runs in (its symbols' addresses), if not `load`.
    pub run: Option<String>,
    /// What it holds.
    pub kind: SegmentKind,
    /// Run-address alignment; `None` takes the inputs' largest.
    pub align: Option<u64>,
    /// Load-address alignment, when load and run differ.
    pub align_load: Option<u64>,
    /// A fixed start address.
    pub start: Option<u64>,
    /// A fixed start relative to its run area's start (ld65's `offset`).
    pub offset: Option<u64>,
    /// No warning when no input has it.
    pub optional: bool,
    /// Define `__NAME_LOAD__`, `__NAME_RUN__`, `__NAME_SIZE__`.
    pub define: bool,
    /// Input section names it takes; a trailing `*` matches a prefix.
    pub sections: Vec<String>,
}

impl Segment {
    /// A segment with defaults: read-only, runs where it loads, takes the
    /// sections of its own name.
    #[must_use]
    pub fn new(name: &str, load: &str, kind: SegmentKind) -> Segment {
        Segment {
            name: name.to_owned(),
            load: load.to_owned(),
            run: None,
            kind,
            align: None,
            align_load: None,
            start: None,
            offset: None,
            optional: true,
            define: false,
            sections: vec![name.to_owned()],
        }
    }

    /// The area it runs in.
    #[must_use]
    pub fn run_area(&self) -> &str {
        self.run.as_deref().unwrap_or(&self.load)
    }

    /// Whether it takes input section `name`.
    #[must_use]
    pub fn takes(&self, name: &str) -> bool {
        self.sections
            .iter()
            .any(|pattern| match pattern.strip_suffix('*') {
                Some(prefix) => name.starts_with(prefix),
                None => pattern == name,
            })
    }
}

/// A complete, checked layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Its name (`flat`, `scorpion-ext`, a file path).
    pub name: String,
    /// Memory areas, in output order.
    pub areas: Vec<Area>,
    /// Segments, in placement order.
    pub segments: Vec<Segment>,
    /// ld65 compatibility: segment starts are not aligned automatically.
    pub ld65_alignment: bool,
    /// What only an ld65 configuration gives: symbols, tables, the start
    /// address, output formats.
    pub config: Config,
}

/// The parts of an ld65 configuration beyond areas and segments.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Config {
    /// `SYMBOLS`, in order.
    pub symbols: Vec<LayoutSymbol>,
    /// `FEATURES { CONDES: ... }`: the constructor, destructor and
    /// interruptor tables the linker builds.
    pub tables: Vec<CondesTable>,
    /// `%S`: `--start`, else `STARTADDRESS`'s default, else $200.
    pub start_address: u64,
    /// `FILES`: output formats by file (`%O` for the main one), with the
    /// place of the format's name.
    pub formats: Vec<(String, OutputFormat, Range<usize>)>,
    /// The configuration's text, for errors found while linking.
    pub source: Option<Arc<str>>,
    /// `FORMATS { atari: ... }`.
    pub atari: AtariOptions,
    /// Read from an ld65 configuration: bytes loaded in an area that goes
    /// to no file are dropped, as ld65 drops them, instead of an error.
    pub ld65: bool,
}

/// The Atari executable format's options (ld65's `FORMATS { atari: ...}`):
/// symbols whose addresses go to the DOS's run and init vectors.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AtariOptions {
    /// `runad = symbol`: written to RUNAD ($02E0) after the last block.
    pub runad: Option<(String, Range<usize>)>,
    /// `initad = AREA: symbol`: written to INITAD ($02E2) after that
    /// area's block.
    pub initad: Vec<(String, String, Range<usize>)>,
}

/// How a layout symbol is defined (ld65's `SYMBOLS` `type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SymbolKind {
    /// Defined with its value.
    Export,
    /// Defined with its value unless an object defines it.
    Weak,
    /// Must be defined by an object (the link fails otherwise).
    Import,
}

/// A symbol of the layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LayoutSymbol {
    /// Its name.
    pub name: String,
    /// How it is defined.
    pub kind: SymbolKind,
    /// Its value (none for an import).
    pub value: Option<Expr>,
    /// Where the layout names it.
    pub span: Range<usize>,
}

/// Which routines a table lists (ca65's `.constructor`, `.destructor`,
/// `.interruptor`, or `.condes name, N`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CondesKind {
    /// Type 0.
    Constructor,
    /// Type 1.
    Destructor,
    /// Type 2.
    Interruptor,
    /// Types 3 to 6, which ca65 reserves for the user.
    User(u8),
}

impl CondesKind {
    /// The kind of ca65's type number `n` (0 to 6).
    #[must_use]
    pub fn from_number(n: u8) -> CondesKind {
        match n {
            0 => CondesKind::Constructor,
            1 => CondesKind::Destructor,
            2 => CondesKind::Interruptor,
            n => CondesKind::User(n),
        }
    }

    /// ca65's type number.
    #[must_use]
    pub fn number(self) -> u8 {
        match self {
            CondesKind::Constructor => 0,
            CondesKind::Destructor => 1,
            CondesKind::Interruptor => 2,
            CondesKind::User(n) => n,
        }
    }
}

/// A table of routine addresses the linker builds (ld65's `CONDES`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CondesTable {
    /// Which routines.
    pub kind: CondesKind,
    /// The symbol for the table's address.
    pub label: String,
    /// The symbol for the number of entries, if wanted.
    pub count: Option<String>,
    /// The segment the table is appended to.
    pub segment: String,
    /// Where the configuration names that segment.
    pub segment_span: Range<usize>,
    /// Entries by increasing priority (ld65's default) or decreasing.
    pub increasing: bool,
    /// A symbol imported when the table is not empty (`__CALLIRQ__`).
    pub import: Option<String>,
}

/// An ld65 output format (`FILES { %O: format = ...; }`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// The areas' bytes, one after the other.
    Bin,
    /// Atari DOS executables: `$FFFF`, then per area its first and last
    /// address and its bytes; RUNAD and INITAD blocks from
    /// [`AtariOptions`].
    Atari,
}

impl Layout {
    /// Checks names and references; every layout passes through here.
    ///
    /// # Errors
    /// [`Error::LayoutInvalid`] for duplicate names, unknown areas, empty
    /// areas, alignments that are not powers of two.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |reason: String| Error::LayoutInvalid {
            path: self.name.clone(),
            reason,
        };
        for (index, area) in self.areas.iter().enumerate() {
            if self.areas[..index].iter().any(|a| a.name == area.name) {
                return Err(invalid(format!("area {} is defined twice", area.name)));
            }
            if area.size == 0 && area.exprs.is_none() {
                return Err(invalid(format!("area {} has size 0", area.name)));
            }
            if area.end() > 1 << 32 {
                return Err(invalid(format!("area {} ends past $FFFFFFFF", area.name)));
            }
            if area.fill && area.size > MAX_FILLED_AREA {
                return Err(invalid(format!(
                    "area {} is filled (fill = true) but is {} bytes; filled areas are written whole, so at most {MAX_FILLED_AREA} bytes (16 MiB)",
                    area.name, area.size
                )));
            }
        }
        for (index, segment) in self.segments.iter().enumerate() {
            if self.segments[..index]
                .iter()
                .any(|s| s.name == segment.name)
            {
                return Err(invalid(format!(
                    "segment {} is defined twice",
                    segment.name
                )));
            }
            for area in [segment.load.as_str(), segment.run_area()] {
                if !self.areas.iter().any(|a| a.name == area) {
                    return Err(invalid(format!(
                        "segment {} names area {area}, which the layout does not define (areas: {})",
                        segment.name,
                        self.areas
                            .iter()
                            .map(|a| a.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
            }
            for align in [segment.align, segment.align_load].into_iter().flatten() {
                // ld65 takes any alignment (GEOS's VLIR records use 254).
                if align == 0 {
                    return Err(invalid(format!("segment {} has alignment 0", segment.name)));
                }
            }
        }
        Ok(())
    }

    /// Parses a layout file.
    ///
    /// # Errors
    /// [`Error::LayoutSyntax`] (with the span) for TOML and schema errors,
    /// [`Error::LayoutInvalid`] for inconsistent layouts.
    pub fn from_toml(path: &str, text: &str) -> Result<Layout, Error> {
        file::parse(path, text)
    }

    /// An error about the value at `span` of this layout's file.
    pub(crate) fn value_error(
        &self,
        message: String,
        help: &str,
        span: Option<Range<usize>>,
    ) -> Error {
        Error::LayoutValue {
            path: self.name.clone(),
            message,
            help: help.to_owned(),
            src: self
                .config
                .source
                .as_ref()
                .map(|text| Arc::new(miette::NamedSource::new(&self.name, text.to_string()))),
            span: span.map(|span| miette::SourceSpan::from(span.start..span.end)),
        }
    }

    /// Reads an ld65 configuration (`FILE.cfg`); `start` is `--start`,
    /// what `%S` stands for (ld65's `-S`).
    ///
    /// # Errors
    /// [`Error::LayoutSyntax`] at the place in the file for anything ld65
    /// 2.19 would not read or this linker does not support.
    pub fn from_ld65(path: &str, text: &str, start: Option<u64>) -> Result<Layout, Error> {
        ld65::parse(path, text, start)
    }
}

/// What `--target` names: a built-in layout, or one read from a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// One area from `start` to $FFFF, like ld65's simplest config.
    Flat {
        /// The first address.
        start: u64,
    },
    /// An extension in the user RAM the ROM leaves free.
    ScorpionExt,
    /// An operating system in KIM-bus expansion RAM.
    ScorpionOs,
    /// The 4 KiB ROM at $F000.
    ScorpionRom,
    /// A layout from a file.
    Custom(Layout),
}

impl Target {
    /// A built-in target by name; `start` is for `flat` only.
    ///
    /// # Errors
    /// [`Error::UnknownTarget`], or [`Error::StartAddress`] when `flat`
    /// lacks `--start` or another target is given one.
    pub fn builtin(name: &str, start: Option<u64>) -> Result<Target, Error> {
        let target = match name {
            "flat" => {
                let start = start.ok_or_else(|| Error::StartAddress {
                    reason: "the flat target needs a start address".into(),
                    help: "give it with --start ADDR (e.g. --start $1000)".into(),
                })?;
                if start > 0xFFFF {
                    return Err(Error::StartAddress {
                        reason: format!("start address ${start:X} is above $FFFF"),
                        help: "the flat area runs from --start to $FFFF".into(),
                    });
                }
                return Ok(Target::Flat { start });
            }
            "scorpion-ext" => Target::ScorpionExt,
            "scorpion-os" => Target::ScorpionOs,
            "scorpion-rom" => Target::ScorpionRom,
            _ => {
                return Err(Error::UnknownTarget {
                    name: name.to_owned(),
                });
            }
        };
        if start.is_some() {
            return Err(Error::StartAddress {
                reason: format!("--start applies to the flat target, not {name}"),
                help: format!("{name} places code where the ROM leaves room; drop --start"),
            });
        }
        Ok(target)
    }

    /// The target's name.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Target::Flat { .. } => "flat",
            Target::ScorpionExt => "scorpion-ext",
            Target::ScorpionOs => "scorpion-os",
            Target::ScorpionRom => "scorpion-rom",
            Target::Custom(layout) => &layout.name,
        }
    }

    /// The concrete layout, taking the Scorpion targets' bounds from the
    /// ROM's symbols.
    ///
    /// # Errors
    /// [`Error::MissingRomSymbols`] when a Scorpion target lacks them,
    /// [`Error::LayoutInvalid`] when they make no sense.
    pub fn resolve(&self, rom: &RomSymbols) -> Result<Layout, Error> {
        let layout = match self {
            Target::Flat { start } => builtin::flat(*start),
            Target::ScorpionExt => builtin::scorpion_ext(rom)?,
            Target::ScorpionOs => builtin::scorpion_os(rom)?,
            Target::ScorpionRom => builtin::scorpion_rom(rom)?,
            Target::Custom(layout) => layout.clone(),
        };
        layout.validate()?;
        Ok(layout)
    }
}
