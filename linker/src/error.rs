//! The linker's one error type: every way a link, a layout or an image can
//! be wrong, each with a stable code and, where the user can act, help.
//!
//! A link collects its problems and fails once with [`Error::Failed`], which
//! carries every error as a related diagnostic, so a user sees all undefined
//! symbols and range errors of a program in one run. Problems that point at
//! source carry the source text and a span when the caller's
//! [`SourceProvider`](crate::SourceProvider) can supply the file.

use std::sync::Arc;

use miette::{NamedSource, SourceSpan};

/// Source text and the span of the line a diagnostic is about.
pub(crate) type Snippet = (Option<Arc<NamedSource<String>>>, Option<SourceSpan>);

/// Everything that can go wrong in the linker.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// The link found problems; each is a related diagnostic.
    #[error("link failed with {count} error{}", if *count == 1 { "" } else { "s" })]
    #[diagnostic(code(linker::failed))]
    Failed {
        /// How many errors.
        count: usize,
        /// The errors in a stable order, then any warnings.
        #[related]
        errors: Vec<Error>,
    },

    /// An input is not a readable ELF file.
    #[error("{file}: not a readable ELF file: {reason}")]
    #[diagnostic(
        code(linker::not_elf),
        help("the linker reads ELF32 relocatable objects from `scorpion asm` or llvm-mos")
    )]
    NotElf {
        /// The input's name.
        file: String,
        /// What the ELF parser said.
        reason: String,
    },

    /// An input is ELF, but not a 6502 file the linker can use.
    #[error("{file}: {reason}")]
    #[diagnostic(
        code(linker::wrong_kind),
        help("link ELF32 little-endian `EM_MOS` (6502) relocatable objects")
    )]
    WrongKind {
        /// The input's name.
        file: String,
        /// What is wrong (class, byte order, machine or file type).
        reason: String,
    },

    /// An object was built for a CPU the Scorpion's NMOS 6502 cannot run.
    #[error("{file}: built for {cpus} (e_flags {flags:#x}); the Scorpion has an NMOS 6502")]
    #[diagnostic(
        code(linker::wrong_cpu),
        help("assemble for the 6502 (ca65 `--cpu 6502` or `6502X`, llvm-mos `-mcpu=mos6502`)")
    )]
    WrongCpu {
        /// The input's name.
        file: String,
        /// The offending `e_flags`.
        flags: u32,
        /// The CPUs those flags name.
        cpus: String,
    },

    /// An object uses a relocation the linker does not apply.
    #[error(
        "{file}: section {section} uses relocation type {r_type} ({name}), which the linker does not support"
    )]
    #[diagnostic(
        code(linker::unsupported_relocation),
        help(
            "supported: R_MOS_NONE, IMM8, ADDR8, ADDR16, ADDR16_LO, ADDR16_HI, PCREL_8, ADDR24, ADDR24_BANK, FK_DATA_4, FK_DATA_8"
        )
    )]
    UnsupportedRelocation {
        /// The input's name.
        file: String,
        /// The section the relocation patches.
        section: String,
        /// The raw `r_type`.
        r_type: u32,
        /// Its `R_MOS_*` name, or "unknown".
        name: String,
    },

    /// An object is inconsistent (a bad index, a relocation outside its
    /// section, a malformed metadata section...).
    #[error("{file}: malformed object: {reason}")]
    #[diagnostic(code(linker::malformed_object))]
    MalformedObject {
        /// The input's name.
        file: String,
        /// What is inconsistent.
        reason: String,
    },

    /// A layout file is not valid TOML or does not match the schema.
    #[error("{path}: {message}")]
    #[diagnostic(
        code(linker::layout_syntax),
        help("see the layout reference in the linker's documentation (`linker::layout`)")
    )]
    LayoutSyntax {
        /// The layout file.
        path: String,
        /// What the TOML parser said.
        message: String,
        /// The layout text.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// Where in it.
        #[label("here")]
        span: Option<SourceSpan>,
    },

    /// A value an ld65 configuration computes while linking (an area's
    /// start or size, a symbol) cannot be had.
    #[error("{path}: {message}")]
    #[diagnostic(code(linker::layout_value), help("{help}"))]
    LayoutValue {
        /// The configuration file.
        path: String,
        /// What went wrong.
        message: String,
        /// What to check.
        help: String,
        /// The configuration's text.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The expression.
        #[label("here")]
        span: Option<SourceSpan>,
    },

    /// A layout parses but makes no sense.
    #[error("{path}: {reason}")]
    #[diagnostic(code(linker::layout_invalid))]
    LayoutInvalid {
        /// The layout file or built-in layout name.
        path: String,
        /// What is wrong.
        reason: String,
    },

    /// `--target` names no built-in layout.
    #[error("unknown target `{name}`")]
    #[diagnostic(
        code(linker::unknown_target),
        help(
            "built-in targets: flat, scorpion-ext, scorpion-os, scorpion-rom; or give a layout file ending in .toml"
        )
    )]
    UnknownTarget {
        /// What the user asked for.
        name: String,
    },

    /// The `flat` layout needs a start address, and only it takes one.
    #[error("{reason}")]
    #[diagnostic(code(linker::start_address), help("{help}"))]
    StartAddress {
        /// What is wrong.
        reason: String,
        /// What to do.
        help: String,
    },

    /// A Scorpion layout needs the ROM's symbols and has none.
    #[error("target {target} needs the ROM's symbols {missing}")]
    #[diagnostic(code(linker::rom_symbols), help("{help}"))]
    MissingRomSymbols {
        /// The layout.
        target: String,
        /// The symbols it could not find.
        missing: String,
        /// Where they come from.
        help: String,
    },

    /// An input section has no segment in the layout.
    #[error("{file}: section {section} has no place in layout {layout}")]
    #[diagnostic(code(linker::unplaced_section), help("{help}"))]
    UnplacedSection {
        /// The input's name.
        file: String,
        /// The section (segment) name.
        section: String,
        /// The layout's name.
        layout: String,
        /// What the layout does place.
        help: String,
    },

    /// Segments do not fit in their memory area.
    #[error("{segment} overflows {area} by {amount} byte{}: {contributors}", if *amount == 1 { "" } else { "s" })]
    #[diagnostic(
        code(linker::overflow),
        help("make the program smaller, or move a segment to another area in a custom layout")
    )]
    Overflow {
        /// The segment that crosses the end.
        segment: String,
        /// The memory area.
        area: String,
        /// How many bytes too many.
        amount: u64,
        /// The largest inputs in the area, largest first.
        contributors: String,
    },

    /// A segment with a fixed start address would overlap what precedes it.
    #[error(
        "segment {segment} must start at ${start:04X}, but {area} is already used up to ${reached:04X} by {by}"
    )]
    #[diagnostic(
        code(linker::fixed_start_overlap),
        help("the segments before it are {overlap} byte(s) too big")
    )]
    FixedStartOverlap {
        /// The segment with the fixed start.
        segment: String,
        /// Its start address.
        start: u64,
        /// The area.
        area: String,
        /// The first free address before it.
        reached: u64,
        /// The segment that reaches past the start.
        by: String,
        /// `reached - start`.
        overlap: u64,
    },

    /// A zero-page segment ended up outside page zero.
    #[error(
        "zero-page segment {segment} occupies ${start:04X}-${end:04X}, outside page zero ($00-$FF)"
    )]
    #[diagnostic(
        code(linker::zeropage_placement),
        help("place zero-page segments in an area within $0000-$00FF")
    )]
    ZeroPagePlacement {
        /// The segment.
        segment: String,
        /// Its first address.
        start: u64,
        /// Its last address.
        end: u64,
    },

    /// A segment with bytes is loaded into an area that is not written out.
    #[error("segment {segment} holds bytes, but its load area {area} is not part of the image")]
    #[diagnostic(
        code(linker::not_loaded),
        help("load it into an area with `output = true`, or make it `kind = \"bss\"`")
    )]
    NotLoaded {
        /// The segment.
        segment: String,
        /// The area.
        area: String,
    },

    /// A symbol is referenced and defined nowhere.
    #[error("undefined symbol `{name}`, referenced at {places}")]
    #[diagnostic(code(linker::undefined_symbol), help("{help}"))]
    Undefined {
        /// The symbol.
        name: String,
        /// Every referencing place.
        places: String,
        /// What to check.
        help: String,
        /// The first referencing source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The first reference.
        #[label("referenced here")]
        span: Option<SourceSpan>,
    },

    /// A symbol is defined twice.
    #[error("symbol `{name}` is defined twice: at {first} and at {second}")]
    #[diagnostic(
        code(linker::duplicate_symbol),
        help("rename one of them, or make one local by not exporting it")
    )]
    Duplicate {
        /// The symbol.
        name: String,
        /// The first definition.
        first: String,
        /// The second definition.
        second: String,
        /// The second definition's source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The second definition.
        #[label("defined again here")]
        span: Option<SourceSpan>,
    },

    /// A branch cannot reach its target.
    #[error(
        "branch to {target} at {at} is out of range: the target is {distance:+} bytes away, a branch reaches -128 to +127"
    )]
    #[diagnostic(
        code(linker::branch_range),
        help(
            "branch over a JMP instead (`bcc :+` / `jmp target` / `:`), or move the target closer"
        )
    )]
    BranchRange {
        /// The target's name and address.
        target: String,
        /// The branch's location.
        at: String,
        /// Target minus the address after the branch.
        distance: i64,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The branch.
        #[label("this branch")]
        span: Option<SourceSpan>,
    },

    /// A zero-page operand resolved above `$FF`.
    #[error(
        "zero-page operand {target} at {at} resolves to ${value:04X}, outside page zero ($00-$FF)"
    )]
    #[diagnostic(
        code(linker::zeropage_range),
        help(
            "define the symbol in a zero-page segment (`.zeropage`, `.exportzp`), or use absolute addressing (`a:`)"
        )
    )]
    ZeroPageRange {
        /// The target's name.
        target: String,
        /// The operand's location.
        at: String,
        /// The resolved value.
        value: i64,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The operand.
        #[label("needs a zero-page address")]
        span: Option<SourceSpan>,
    },

    /// A relocated value does not fit its field.
    #[error("{kind} value {target} at {at} is {value} (${value:X}), which does not fit {range}")]
    #[diagnostic(code(linker::value_range))]
    ValueRange {
        /// The relocation type's name.
        kind: &'static str,
        /// The target's name.
        target: String,
        /// The value.
        value: i64,
        /// The allowed range.
        range: &'static str,
        /// The field's location.
        at: String,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The field.
        #[label("here")]
        span: Option<SourceSpan>,
    },

    /// A deferred `.assert` failed.
    #[error("assertion failed at {at}: {message}")]
    #[diagnostic(code(linker::assert_failed))]
    AssertFailed {
        /// The assertion's message.
        message: String,
        /// Where the `.assert` is.
        at: String,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The `.assert`.
        #[label("this assertion")]
        span: Option<SourceSpan>,
    },

    /// A deferred `.assert` with the warning action failed.
    #[error("assertion failed at {at}: {message}")]
    #[diagnostic(code(linker::assert_warning), severity(Warning))]
    AssertWarning {
        /// The assertion's message.
        message: String,
        /// Where the `.assert` is.
        at: String,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The `.assert`.
        #[label("this assertion")]
        span: Option<SourceSpan>,
    },

    /// A deferred `.assert` cannot be evaluated.
    #[error("assertion at {at} cannot be evaluated: {reason}")]
    #[diagnostic(code(linker::assert_invalid))]
    AssertInvalid {
        /// Where the `.assert` is.
        at: String,
        /// Why.
        reason: String,
    },

    /// A field computed from an expression (`.scorpion.exprs`) has no
    /// value.
    #[error("the expression at {at} cannot be evaluated: {reason}")]
    #[diagnostic(code(linker::expression_invalid))]
    ExpressionInvalid {
        /// Where the field is.
        at: String,
        /// Why.
        reason: String,
        /// The source file.
        #[source_code]
        src: Option<Arc<NamedSource<String>>>,
        /// The field.
        #[label("here")]
        span: Option<SourceSpan>,
    },

    /// A segment's start is not a multiple of its inputs' alignment (the
    /// `flat` layout does not align segments, as ld65 does not).
    #[error(
        "segment {segment} starts at ${start:04X}, which is not a multiple of its alignment {align}"
    )]
    #[diagnostic(
        code(linker::misaligned_segment),
        severity(Warning),
        help(
            "`.align` inside it will not hold: give the segment `align = {align}` in a layout file (the flat target places segments back to back, as ld65 does)"
        )
    )]
    MisalignedSegment {
        /// The segment.
        segment: String,
        /// Its start.
        start: u64,
        /// The alignment its inputs ask for.
        align: u64,
    },

    /// A segment the layout requires has no input.
    #[error("layout {layout}: segment {segment} is not optional, but no object has it")]
    #[diagnostic(
        code(linker::empty_segment),
        severity(Warning),
        help("mark it `optional = true` in the layout if that is expected")
    )]
    EmptySegment {
        /// The layout.
        layout: String,
        /// The segment.
        segment: String,
    },

    /// The exported hook symbols are inconsistent.
    #[error("{reason}")]
    #[diagnostic(
        code(linker::hook),
        help(
            "export the handler as __scorpion_hook_unknown / __scorpion_hook_loop and its chain slot as __scorpion_chain_unknown / __scorpion_chain_loop, both inside the image (scorpion.inc's macros do this)"
        )
    )]
    Hook {
        /// What is wrong.
        reason: String,
    },

    /// The image does not fit an output format.
    #[error("cannot write {format}: {reason}")]
    #[diagnostic(code(linker::format))]
    Format {
        /// The format.
        format: String,
        /// Why.
        reason: String,
    },

    /// A linked image cannot be read.
    #[error("{file}: not a usable linked image: {reason}")]
    #[diagnostic(
        code(linker::bad_image),
        help("link the program with `scorpion link` (ELF output, the default)")
    )]
    BadImage {
        /// The image's name.
        file: String,
        /// What is wrong.
        reason: String,
    },
}

impl Error {
    /// Whether this diagnostic is a warning rather than an error.
    #[must_use]
    pub fn is_warning(&self) -> bool {
        matches!(
            self,
            Error::AssertWarning { .. }
                | Error::MisalignedSegment { .. }
                | Error::EmptySegment { .. }
        )
    }
}
