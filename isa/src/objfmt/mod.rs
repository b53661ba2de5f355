//! Our own metadata sections in 6502 ELF files, beside llvm-mos's numbering.
//!
//! ELF has no place for seven things our tools pass along, so they travel in
//! non-allocated `SHT_PROGBITS` sections that other tools ignore:
//!
//! | section | written by | read by | holds |
//! |---|---|---|---|
//! | [`SRCMAP_SECTION`] | assembler | linker | where each instruction, data item and symbol came from (file:line:col) |
//! | [`ASSERT_SECTION`] | assembler | linker | `.assert`s that depend on addresses, as expression bytecode |
//! | [`EXPRS_SECTION`] | assembler | linker | bytes computed from expressions no relocation can express, as bytecode |
//! | [`VALUES_SECTION`] | assembler | linker | exported symbols whose value is an expression of others (`alias = imported + 1`) |
//! | [`CONDES_SECTION`] | assembler | linker | routines for the linker's tables (`.constructor`, `.destructor`, `.interruptor`) |
//! | [`FILL_SECTION`] | assembler | linker | reserved bytes (`.res`, `.align` without a fill value) that take the load area's fill value |
//! | [`HOOKS_SECTION`] | linker | uploader, `scorpion sim` | which ROM hooks an image takes over, and where its fallthrough lives |
//!
//! [`RelObject`] is the one writer of relocatable objects (the assembler's
//! and, through [`ObjectBuilder`], the tests').
//!
//! Every section starts with a four-byte magic and a version byte; all
//! integers are little-endian. Decoders return [`FormatError`] for any
//! malformed input and never panic: the linker reads other producers'
//! objects too.

mod assert;
mod builder;
mod codec;
mod condes;
mod fields;
mod fill;
mod hooks;
mod srcmap;
mod write;

pub use assert::{AssertAction, Assertion, BinaryOp, EvalError, Expr, ExprOp, UnaryOp};
pub use builder::{ObjectBuilder, SectionId, SymbolDef, SymbolId};
pub use codec::FormatError;
pub use condes::{CondesEntry, MAX_CONDES_TYPE};
pub use fields::{ExprField, ExprSymbol, FieldKind};
pub use fill::FillRun;
pub use hooks::{
    CHAIN_LOOP_SYMBOL, CHAIN_UNKNOWN_SYMBOL, HOOK_LOOP_SYMBOL, HOOK_UNKNOWN_SYMBOL, HookKind,
    HookRecord, Hooks,
};
pub use srcmap::{SourceLoc, SrcMap, SrcMapEntry, SymbolLoc, user_place};
pub use write::{
    Binding, Definition, Numbering, ObjReloc, ObjSection, ObjSymbol, RelObject, RelocTarget,
};

/// Source locations of section bytes and symbols (assembler to linker).
pub const SRCMAP_SECTION: &str = ".scorpion.srcmap";
/// Deferred assertions (assembler to linker).
pub const ASSERT_SECTION: &str = ".scorpion.assert";
/// Fields the linker computes from expressions (assembler to linker).
pub const EXPRS_SECTION: &str = ".scorpion.exprs";
/// Symbols whose value the linker computes (assembler to linker).
pub const VALUES_SECTION: &str = ".scorpion.values";
/// Routines for the linker's tables (assembler to linker).
pub const CONDES_SECTION: &str = ".scorpion.condes";
/// Reserved byte ranges that take the load area's fill value (assembler to
/// linker).
pub const FILL_SECTION: &str = ".scorpion.fill";
/// Hook records of a linked image (linker to uploader and simulator).
pub const HOOKS_SECTION: &str = ".scorpion.hooks";
/// Where a linked image's bytes came from (linker to debugger): a
/// [`SrcMap`] in the same encoding whose entries' `section` is 0 and whose
/// `offset` is the run address; each entry covers the bytes up to the next.
pub const LINES_SECTION: &str = ".scorpion.lines";
