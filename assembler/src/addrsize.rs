//! ca65's address size for an operand whose value is not known yet (a
//! symbol defined further down): ca65 reads a source once, so it decides
//! zero page or absolute from what it knows at that line, and so do we
//! by default. Where the final value would have fit zero page we warn,
//! as ca65 does ("Didn't use zeropage addressing"), with the place and
//! how to get zero page. [`Options::forward_zero_page`](crate::Options)
//! keeps the layout passes' choice instead (zero page wherever the final
//! value fits).

use isa::objfmt::UnaryOp;

use crate::asm::Asm;
use crate::diag;
use crate::expr::{EvalErr, Value};
use crate::model::{LocId, Node, NodeId, SymDef, SymId};

/// Most nodes and symbols looked at for one guess: the guard against
/// long chains of definitions.
const MAX_STEPS: u32 = 256;

/// An operand assembled as absolute because its value was not known,
/// checked after layout for a value that fits zero page.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AbsoluteGuess {
    /// The operand's expression.
    pub(crate) expr: NodeId,
    /// The operand, for the warning.
    pub(crate) loc: LocId,
}

impl Asm<'_> {
    /// Whether ca65 would take `expr`, whose value is not known yet, as
    /// zero page: a byte operator (`<`, `>`, `^`), a literal or known
    /// value below $100, a symbol declared zero page (`.globalzp`), a
    /// name of a scope whose outer namesake is zero page; all of them on
    /// both sides of an operator. Anything else (a plain name defined
    /// later) is absolute.
    pub(crate) fn guess_zero_page(&mut self, expr: NodeId) -> bool {
        let mut steps = MAX_STEPS;
        self.guess_node(expr, &mut steps)
    }

    fn guess_node(&mut self, node: NodeId, steps: &mut u32) -> bool {
        if *steps == 0 {
            return false;
        }
        *steps -= 1;
        match self.prog.eval(node) {
            Ok(value) => return self.value_fit(value).unwrap_or(false),
            Err(EvalErr::NotYet(_)) => {}
            Err(_) => return false,
        }
        let Some(&n) = self.prog.nodes.get(node as usize) else {
            return false;
        };
        match n {
            Node::Const(value) => (0..=0xFF).contains(&value),
            Node::Sym(sym) => self.guess_sym(sym, steps),
            Node::Unary(UnaryOp::LoByte | UnaryOp::HiByte | UnaryOp::BankByte, _) => true,
            Node::Unary(_, inner) => self.guess_node(inner, steps),
            Node::Binary(_, left, right) => {
                self.guess_node(left, steps) && self.guess_node(right, steps)
            }
            Node::Pos { .. } | Node::ScopeSize(_) => false,
        }
    }

    fn guess_sym(&mut self, sym: SymId, steps: &mut u32) -> bool {
        let Some(s) = self.prog.syms.get(sym as usize) else {
            return false;
        };
        match s.def {
            SymDef::Undefined => {
                if s.global && s.export == Some(true) {
                    return true;
                }
                // ca65 lends a scope's name the address size of the
                // nearest outer symbol of that name, only its own: one
                // not defined yet lends nothing (absolute), even where a
                // symbol further out would have been zero page.
                match self.prog.outer.get(&sym).map(|o| o.outer) {
                    Some(outer) if *steps > 0 => {
                        *steps -= 1;
                        let o = &self.prog.syms[outer as usize];
                        if o.def == SymDef::Undefined {
                            o.global && o.export == Some(true)
                        } else {
                            self.guess_sym(outer, steps)
                        }
                    }
                    _ => false,
                }
            }
            SymDef::Expr(node) | SymDef::Var(node) => self.guess_node(node, steps),
            SymDef::Alias(other) => self.guess_sym(other, steps),
            SymDef::Import { zp } => zp,
            SymDef::Const(value) => (0..=0xFF).contains(&value),
            SymDef::Label { chunk, off } => {
                let value = self.prog.position(chunk, i64::from(off));
                self.value_fit(value).unwrap_or(false)
            }
        }
    }

    /// After layout: warns at each operand assembled as absolute for want
    /// of its value whose value turned out to fit zero page.
    pub(crate) fn check_absolute_guesses(&mut self) {
        let guesses = std::mem::take(&mut self.prog.absolute_guesses);
        for guess in &guesses {
            let fits = match self.prog.eval(guess.expr) {
                Ok(value @ Value::Const(_)) | Ok(value @ Value::Addr { .. }) => {
                    self.value_fit(value).unwrap_or(false)
                }
                _ => false,
            };
            if !fits {
                continue;
            }
            let span = self.loc_span(guess.loc);
            self.report_at(
                guess.loc,
                diag::warning(
                    "asm::zp-forward",
                    span,
                    "assembled as absolute, as ca65 does: the value is defined further down, and it fits zero page",
                )
                .label("defined after this use")
                .help("define it before this line (or `.globalzp` it, or write `z:`) for zero-page addressing; `--forward-zero-page` chooses zero page wherever the final value fits, which ca65 does not"),
            );
        }
        self.prog.absolute_guesses = guesses;
    }
}
