//! The resolver, after the front end: end-of-input checks, the layout fixpoint that
//! settles zero-page versus absolute operands, and final resolution of
//! every fixup into bytes or relocations.
//!
//! The fixpoint starts every undecided operand at zero page and only ever
//! widens: a pass places the chunks, re-evaluates the undecided operands
//! with the placed addresses, widens those that no longer fit, and stops
//! when a pass widens nothing. Each operand widens at most once, so the
//! loop ends.
//!
//! Stages, each a file: [`checks`] (end of input), [`fixpoint`] (the
//! layout), [`fields`] (every fixup into bytes or a relocation, the
//! symbols, fills, branch and assertion checks), into an
//! [`Output`](crate::output::Output).

mod checks;
mod fields;
mod fixpoint;

use crate::asm::Asm;
use crate::diag::{self, RawDiag, Span};
use crate::model::{FixKind, LocId};

fn show(value: i64) -> String {
    if (0..10).contains(&value) {
        value.to_string()
    } else if value < 0 {
        format!("{value}")
    } else {
        format!("{value} (${value:X})")
    }
}

/// A range error naming the value and the allowed range.
pub(crate) fn range_diag(span: Span, what: &str, value: i64, range: (i64, i64)) -> RawDiag {
    let bounds = if range.0 >= 0 && range.1 >= 16 {
        format!("{} to {} (${:X})", range.0, range.1, range.1)
    } else {
        format!("{} to {}", range.0, range.1)
    };
    diag::error(
        "asm::range",
        span,
        format!("{what} {} is outside {bounds}", show(value)),
    )
    .label(format!("this is {}", show(value)))
}

/// A range error for a value stored as `kind`, with advice where the
/// usual mistake is clear.
pub(crate) fn field_range_diag(
    span: Span,
    kind: FixKind,
    value: i64,
    what: &str,
    range: (i64, i64),
) -> RawDiag {
    let diag = range_diag(span, what, value, range);
    match kind {
        FixKind::Imm8 | FixKind::Byte if value > 0xFF => diag.help(
            "to take one byte of a 16-bit value, write `<value` (low byte) or `>value` (high byte)",
        ),
        _ => diag,
    }
}

/// A branch that does not reach.
pub(crate) fn branch_diag(span: Span, distance: i64) -> RawDiag {
    diag::error(
        "asm::branch-range",
        span,
        format!("branch target is {distance:+} bytes away; a branch reaches -128 to +127"),
    )
    .label(format!("{distance:+} bytes from the next instruction"))
    .help("branch the other way over a `jmp` to the target")
}

impl Asm<'_> {
    pub(crate) fn report_at(&mut self, loc: LocId, mut diag: RawDiag) {
        if let Some(l) = self.prog.locs.get(loc as usize) {
            diag.ctx = l.ctx;
        }
        self.rep.push(diag);
    }

    pub(crate) fn loc_span(&self, loc: LocId) -> Span {
        self.prog
            .locs
            .get(loc as usize)
            .map(|l| l.span)
            .unwrap_or_default()
    }
}
