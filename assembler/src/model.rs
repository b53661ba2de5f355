//! What the front end builds and the layout passes resolve: segments cut
//! into chunks, symbols, scopes, expression nodes, fixups.
//!
//! A *chunk* is a run of bytes whose size is known when it is read. A chunk
//! ends where an item's size is not yet known (an instruction whose
//! operand may turn out zero-page or absolute, an `.align` at an unknown
//! position) and at each `.org`/`.reloc`. Labels are (chunk, offset), so a
//! layout pass only has to place chunks, not every line.

use isa::objfmt::{BinaryOp, UnaryOp};

use crate::diag::{CtxId, Span};
use crate::intern::NameId;

pub(crate) type SymId = u32;
pub(crate) type ChunkId = u32;
pub(crate) type SegId = u32;
pub(crate) type NodeId = u32;
pub(crate) type ScopeId = u32;
pub(crate) type LocId = u32;
pub(crate) type VarId = u32;

/// The root scope.
pub(crate) const GLOBAL_SCOPE: ScopeId = 0;

/// An expression node; children come before parents in the arena.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Node {
    Const(i64),
    Sym(SymId),
    /// A position (`*`, or a label position captured directly).
    Pos {
        chunk: ChunkId,
        off: u32,
    },
    Unary(UnaryOp, NodeId),
    Binary(BinaryOp, NodeId, NodeId),
    /// `.sizeof` of a scope whose end is not known yet.
    ScopeSize(ScopeId),
}

/// How a symbol is defined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SymDef {
    Undefined,
    Label {
        chunk: ChunkId,
        off: u32,
    },
    Const(i64),
    Expr(NodeId),
    Import {
        zp: bool,
    },
    /// A reference inside a scope resolved, at the end, to an outer symbol.
    Alias(SymId),
    /// A `.set` variable: references take the current value's node.
    Var(NodeId),
}

/// Which namespace a symbol lives in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SymKind {
    /// Scoped, written to the object.
    Normal,
    /// `@local`: not written.
    Cheap,
    /// `:`: not written.
    Unnamed,
}

#[derive(Debug, Clone)]
pub(crate) struct Sym {
    pub(crate) name: NameId,
    pub(crate) scope: ScopeId,
    pub(crate) kind: SymKind,
    pub(crate) def: SymDef,
    /// `.export`/`.exportzp`/`.global` seen (with the zero-page flag).
    pub(crate) export: Option<bool>,
    /// `.global`/`.globalzp`: import when not defined.
    pub(crate) global: bool,
    pub(crate) def_loc: Option<LocId>,
    pub(crate) ref_loc: Option<LocId>,
    pub(crate) export_loc: Option<LocId>,
    /// Evaluation caches of a symbol defined by an expression, boxed:
    /// most symbols are labels, and a small `Sym` keeps the symbol table
    /// of a large program in cache.
    pub(crate) memo: Option<Box<Memo>>,
    pub(crate) busy: bool,
    /// Where it was defined (file, line, column), for the source map.
    pub(crate) def_file: u32,
    pub(crate) def_line: u32,
    pub(crate) def_column: u32,
    /// The expansion context of the definition, for the place in the
    /// user's file that expanded a macro defining it.
    pub(crate) def_ctx: u32,
}

impl Sym {
    pub(crate) fn new(name: NameId, scope: ScopeId, kind: SymKind) -> Sym {
        Sym {
            name,
            scope,
            kind,
            def: SymDef::Undefined,
            export: None,
            global: false,
            def_loc: None,
            ref_loc: None,
            export_loc: None,
            memo: None,
            busy: false,
            def_file: 0,
            def_line: 0,
            def_column: 0,
            def_ctx: 0,
        }
    }

    pub(crate) fn is_defined(&self) -> bool {
        !matches!(self.def, SymDef::Undefined)
    }
}

/// The evaluation caches of a symbol defined by an expression.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Memo {
    /// Cached front-end value, once it can no longer change.
    pub(crate) front: Option<crate::expr::Value>,
    /// (layout pass stamp, result) after layout; (definitions count,
    /// result) before.
    pub(crate) result: Option<(u32, Result<crate::expr::Value, crate::expr::EvalErr>)>,
}

/// What kind of scope.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ScopeKind {
    Global,
    Scope,
    Proc,
    Struct,
    Union,
    Enum,
}

#[derive(Debug, Clone)]
pub(crate) struct Scope {
    pub(crate) name: NameId,
    pub(crate) parent: ScopeId,
    pub(crate) kind: ScopeKind,
    /// Where the scope's code starts and ends (for `.sizeof`).
    pub(crate) start: Option<(ChunkId, u32)>,
    pub(crate) end: Option<(ChunkId, u32)>,
    /// A struct's, union's or enum's size.
    pub(crate) size: Option<i64>,
}

/// A segment, written as one ELF section.
#[derive(Debug, Clone)]
pub(crate) struct Segment {
    pub(crate) name: String,
    pub(crate) zp: bool,
    /// Fixed bytes of all chunks, in order.
    pub(crate) data: Vec<u8>,
    pub(crate) chunks: Vec<ChunkId>,
    /// Something other than `.res` was written (else `SHT_NOBITS`).
    pub(crate) has_data: bool,
    /// Anything at all was written or defined here.
    pub(crate) used: bool,
    /// Largest `.align`.
    pub(crate) align: u32,
    /// The chunk being filled.
    pub(crate) cur: ChunkId,
    /// Final size after layout.
    pub(crate) size: u32,
}

/// A variable-size item that ends a chunk.
#[derive(Debug, Clone, Copy)]
pub(crate) enum VarKind {
    /// An instruction whose operand may be zero-page or absolute.
    Instr {
        narrow: u8,
        wide: u8,
        expr: NodeId,
        /// Widened (never narrowed again).
        is_wide: bool,
    },
    /// `.align` at a position unknown when read; without a fill value the
    /// padding is reserved (the linker's fill value).
    Align { align: u32, fill: Option<u8> },
    /// `.res n` whose `n` depends on a position not known when read
    /// (`.res $1E00 - *` after instructions whose size the layout passes
    /// decide): its size follows the placement.
    Res { count: NodeId, fill: Option<u8> },
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct VarItem {
    pub(crate) kind: VarKind,
    pub(crate) loc: LocId,
    /// Current size in bytes.
    pub(crate) size: u32,
}

#[derive(Debug, Clone)]
pub(crate) struct Chunk {
    pub(crate) seg: SegId,
    /// Absolute (`.org`) mode: labels are constants.
    pub(crate) org: bool,
    /// The `.org` value if this chunk starts with one.
    pub(crate) org_base: Option<i64>,
    /// Absolute mode carried over from another segment's chunk (ca65's
    /// `.org` is global unless `.feature org_per_seg`): this chunk starts
    /// where that one ends.
    pub(crate) org_after: Option<ChunkId>,
    /// `.org expr` whose value depends on a position not known when read
    /// (`.org VTOC + 256`): evaluated as placement goes, into `org_base`.
    pub(crate) org_expr: Option<NodeId>,
    /// Where the chunk's fixed bytes start in the segment's data.
    pub(crate) data_start: u32,
    /// Fixed bytes.
    pub(crate) len: u32,
    /// The variable item that ends the chunk.
    pub(crate) var: Option<VarId>,
    /// Segment offset of the start, when known in the front end.
    pub(crate) known_start: Option<u32>,
    /// Absolute address of the start, when known in the front end.
    pub(crate) known_abs: Option<i64>,
    /// Segment offset after layout.
    pub(crate) start: u32,
    /// Absolute address after layout (org mode).
    pub(crate) abs: i64,
}

/// How a fixup's value is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FixKind {
    /// Immediate operand: 8 bits, 0..=255.
    Imm8,
    /// `.byte`: 8 bits, 0..=255.
    Byte,
    /// Zero-page operand: 0..=255, `R_MOS_ADDR8`.
    Zp,
    /// Absolute operand: 0..=$FFFF, `R_MOS_ADDR16`.
    Abs,
    /// `.word` / `.addr`: 0..=$FFFF.
    Word,
    /// `.dbyt`: big-endian 16 bits.
    Dbyt,
    /// `.dword`: 32 bits, constants only.
    Dword,
    /// `.faraddr`: 24 bits, 0..=$FFFFFF, `R_MOS_ADDR24`.
    Far,
    /// Branch displacement.
    Branch,
}

impl FixKind {
    /// How a field of this kind is stored, as the linker stores it too
    /// (`.scorpion.exprs`); `None` for a branch, whose value is a
    /// distance.
    pub(crate) fn field(self) -> Option<isa::objfmt::FieldKind> {
        use isa::objfmt::FieldKind;
        Some(match self {
            FixKind::Imm8 | FixKind::Byte | FixKind::Zp => FieldKind::Byte,
            FixKind::Abs | FixKind::Word => FieldKind::Word,
            FixKind::Dbyt => FieldKind::WordBigEndian,
            FixKind::Far => FieldKind::Far,
            FixKind::Dword => FieldKind::Dword,
            FixKind::Branch => return None,
        })
    }

    pub(crate) fn len(self) -> u32 {
        match self {
            FixKind::Imm8 | FixKind::Byte | FixKind::Zp | FixKind::Branch => 1,
            FixKind::Abs | FixKind::Word | FixKind::Dbyt => 2,
            FixKind::Far => 3,
            FixKind::Dword => 4,
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Fixup {
    pub(crate) chunk: ChunkId,
    pub(crate) off: u32,
    pub(crate) kind: FixKind,
    pub(crate) expr: NodeId,
    pub(crate) loc: LocId,
}

/// A source location recorded for later diagnostics.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Loc {
    pub(crate) span: Span,
    pub(crate) ctx: CtxId,
}

/// One instruction or data item, for the source map and branch checks.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Item {
    pub(crate) chunk: ChunkId,
    pub(crate) off: u32,
    pub(crate) file: u32,
    pub(crate) line: u32,
    pub(crate) column: u32,
    /// Instruction length, 0 for data.
    pub(crate) instr_len: u8,
    /// The context it was assembled in (a macro's expansion, an include).
    pub(crate) ctx: CtxId,
}

/// A `.assert` checked after layout.
#[derive(Debug, Clone)]
pub(crate) struct AssertRec {
    pub(crate) expr: NodeId,
    pub(crate) error: bool,
    /// Checked by the linker only (`ldwarning`/`lderror`).
    pub(crate) link_only: bool,
    pub(crate) message: String,
    pub(crate) loc: LocId,
    pub(crate) line: u32,
    pub(crate) column: u32,
}

/// Everything the front end produced, resolved by the layout passes.
#[derive(Debug, Default)]
pub(crate) struct Program {
    pub(crate) nodes: Vec<Node>,
    pub(crate) syms: Vec<Sym>,
    pub(crate) scopes: Vec<Scope>,
    pub(crate) segs: Vec<Segment>,
    pub(crate) chunks: Vec<Chunk>,
    pub(crate) vars: Vec<VarItem>,
    pub(crate) fixups: Vec<Fixup>,
    pub(crate) locs: Vec<Loc>,
    pub(crate) items: Vec<Item>,
    pub(crate) asserts: Vec<AssertRec>,
    /// `.org`s whose address waited for placement: (chunk, where).
    pub(crate) deferred_orgs: Vec<(ChunkId, LocId)>,
    /// `.constructor` and its kin: (symbol, table type, priority).
    pub(crate) condes: Vec<(SymId, u8, u8)>,
    /// Reserved bytes in chunks' fixed data (chunk, offset, length):
    /// `.res` and `.align` without a fill value, which the linker fills.
    pub(crate) fills: Vec<(ChunkId, u32, u32)>,
    /// Branch operands (chunk, offset of the operand byte, location), for
    /// the check that a branch does not land inside an instruction.
    pub(crate) branches: Vec<(ChunkId, u32, LocId)>,
    /// Layout pass counter, for symbol memos.
    pub(crate) stamp: u32,
    /// True once every chunk is placed (final evaluation).
    pub(crate) placed: bool,
    /// Budget of evaluation steps left, against pathological expressions.
    pub(crate) budget: u32,
    /// Symbol definitions so far (front-end memo validity).
    pub(crate) defs: u32,
    /// Names used inside a scope that does not define them (yet), with
    /// the outer symbol of that name visible where they were used. As in
    /// ca65 the use belongs to the scope's own symbol, which may still be
    /// defined further down; the outer one only lends its address size,
    /// and its value where a constant is needed at once
    /// ([`Program::outer_fallback`]).
    pub(crate) outer: rustc_hash::FxHashMap<SymId, OuterUse>,
    /// Evaluating where a value is needed at once (`.if`, `.res`): an
    /// undefined name of a scope takes the value of its outer namesake,
    /// and the use is remembered ([`OuterUse::used`]) so that a later
    /// definition in the scope is refused instead of silently disagreeing.
    pub(crate) outer_fallback: bool,
    /// The names that took an outer value in the last fallback evaluation.
    pub(crate) outer_hits: Vec<SymId>,
    /// Operands assembled as absolute because their value was not known
    /// yet (ca65's choice), to warn at where zero page was possible.
    pub(crate) absolute_guesses: Vec<crate::addrsize::AbsoluteGuess>,
}

/// A scope's name that stood for an outer symbol when it was used.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OuterUse {
    /// The outer symbol of the same name, where the name was first used.
    pub(crate) outer: SymId,
    /// Where the outer symbol's value was taken for a constant.
    pub(crate) used: Option<LocId>,
}

impl Program {
    pub(crate) fn node(&mut self, node: Node) -> NodeId {
        self.nodes.push(node);
        (self.nodes.len() - 1) as NodeId
    }

    pub(crate) fn loc(&mut self, span: Span, ctx: CtxId) -> LocId {
        self.locs.push(Loc { span, ctx });
        (self.locs.len() - 1) as LocId
    }
}
