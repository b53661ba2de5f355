//! The output model: what the resolver hands the object writer and the
//! listing (sections with bytes and relocations, symbols, deferred
//! assertions), and how a constant is stored in a field.

use isa::objfmt::{BinaryOp, ExprOp, FillRun, SrcMapEntry, UnaryOp};

use crate::model::FixKind;

/// What a relocation or a deferred assertion refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Target {
    /// The section symbol of an output section (index in [`Output::sections`]).
    Section(usize),
    /// An output symbol (index in [`Output::symbols`]).
    Symbol(usize),
    /// No symbol (`S = 0`).
    Absolute,
}

#[derive(Debug, Clone)]
pub(crate) struct OutReloc {
    pub(crate) offset: u32,
    pub(crate) r_type: u32,
    pub(crate) target: Target,
    pub(crate) addend: i64,
}

#[derive(Debug, Clone)]
pub(crate) struct OutSection {
    pub(crate) name: String,
    pub(crate) zp: bool,
    pub(crate) nobits: bool,
    pub(crate) data: Vec<u8>,
    pub(crate) size: u32,
    pub(crate) align: u32,
    pub(crate) relocs: Vec<OutReloc>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OutSymKind {
    Abs(i64),
    Sec(usize, u32),
    Undef { zp: bool },
}

#[derive(Debug, Clone)]
pub(crate) struct OutSym {
    pub(crate) name: String,
    pub(crate) kind: OutSymKind,
    pub(crate) global: bool,
    /// (file, line, column) of the definition.
    pub(crate) place: Option<(u32, u32, u32)>,
    /// Where the outermost macro expansion that defined it was written
    /// (file, line, column), if a macro defined it.
    pub(crate) expanded_at: Option<(u32, u32, u32)>,
}

/// One bytecode step of a deferred assertion, before symbol numbering.
#[derive(Debug, Clone, Copy)]
pub(crate) enum AssertOp {
    Const(i64),
    Target(Target),
    Unary(UnaryOp),
    Binary(BinaryOp),
}

#[derive(Debug, Clone)]
pub(crate) struct OutAssert {
    pub(crate) error: bool,
    pub(crate) file: u32,
    pub(crate) line: u32,
    pub(crate) column: u32,
    pub(crate) message: String,
    pub(crate) ops: Vec<AssertOp>,
}

/// A field the linker computes from `ops` (`.scorpion.exprs`).
#[derive(Debug, Clone)]
pub(crate) struct OutField {
    /// Index in [`Output::sections`].
    pub(crate) section: usize,
    pub(crate) offset: u32,
    pub(crate) kind: FixKind,
    pub(crate) ops: Vec<AssertOp>,
}

/// Everything the object writer needs.
#[derive(Debug, Default)]
pub(crate) struct Output {
    pub(crate) sections: Vec<OutSection>,
    pub(crate) symbols: Vec<OutSym>,
    /// Where every item came from; `section` is the index in
    /// [`Output::sections`] until the object writer numbers the sections.
    pub(crate) items: Vec<SrcMapEntry>,
    /// For the items a macro made: the outermost macro call, keyed as in
    /// [`Output::items`].
    pub(crate) calls: Vec<SrcMapEntry>,
    pub(crate) asserts: Vec<OutAssert>,
    /// Fields the linker computes.
    pub(crate) fields: Vec<OutField>,
    /// Routines for the linker's tables: (output symbol, type, priority).
    pub(crate) condes: Vec<(usize, u8, u8)>,
    /// Exported symbols the linker computes: (output symbol, bytecode).
    pub(crate) values: Vec<(usize, Vec<AssertOp>)>,
    /// The same before compiling: (output symbol, symbol).
    pub(crate) pending_values: Vec<(usize, crate::model::SymId)>,
    /// Output section of each segment (`None` when the segment is empty).
    pub(crate) seg_section: Vec<Option<usize>>,
    /// Reserved bytes the linker fills; `section` as in [`Output::items`].
    pub(crate) fills: Vec<FillRun>,
}

/// The bytes of a constant stored as `kind`, or what and which range.
pub(crate) fn const_bytes(
    kind: FixKind,
    value: i64,
) -> Result<[u8; 4], (&'static str, (i64, i64))> {
    let what = match kind {
        FixKind::Imm8 => "immediate value",
        FixKind::Byte => "byte value",
        FixKind::Zp => "zero-page address",
        FixKind::Abs => "address",
        FixKind::Word | FixKind::Dbyt => "word value",
        FixKind::Far => "far address",
        FixKind::Dword => "dword value",
        FixKind::Branch => "branch distance",
    };
    // The linker checks the fields it computes against the same ranges.
    let range = kind
        .field()
        .map_or((-128, 127), isa::objfmt::FieldKind::range);
    if value < range.0 || value > range.1 {
        return Err((what, range));
    }
    let v = value as u32;
    Ok(match kind {
        FixKind::Dbyt => [(v >> 8) as u8, v as u8, 0, 0],
        _ => v.to_le_bytes(),
    })
}

/// Converts assertion ops into `isa::objfmt` bytecode, given symbol indices.
pub(crate) fn assert_ops(
    ops: &[AssertOp],
    target_index: impl Fn(Target) -> Option<u32>,
) -> Option<Vec<ExprOp>> {
    ops.iter()
        .map(|op| {
            Some(match *op {
                AssertOp::Const(v) => ExprOp::Const(v),
                AssertOp::Target(Target::Absolute) => ExprOp::Const(0),
                AssertOp::Target(target) => ExprOp::Symbol(target_index(target)?),
                AssertOp::Unary(op) => ExprOp::Unary(op),
                AssertOp::Binary(op) => ExprOp::Binary(op),
            })
        })
        .collect()
}
