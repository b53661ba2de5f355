//! Layout expressions: what an ld65 configuration may write for an area's
//! start and size or a symbol's value (`__HIMEM__ - __MAIN_START__`,
//! `%S - 2`), evaluated when placement reaches them, as ld65 does.

use std::collections::HashMap;
use std::ops::Range;

/// A binary operator of a layout expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/` (integer division; by zero is an error)
    Div,
}

/// An expression over numbers and symbols.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Expr {
    /// A number.
    Number(i64),
    /// A symbol: the layout's `SYMBOLS`, an object's absolute export, or a
    /// `define = yes` symbol of an area or segment placed before; with its
    /// place in the layout file.
    Symbol(String, Range<usize>),
    /// `-x`
    Neg(Box<Expr>),
    /// `a op b`
    Binary(Op, Box<Expr>, Box<Expr>),
}

/// Why an expression has no value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EvalError {
    /// A symbol nothing defines (yet), with its place.
    Undefined(String, Range<usize>),
    /// Division by zero.
    DivisionByZero,
}

impl Expr {
    /// The value, with `symbols` for the names it uses.
    ///
    /// # Errors
    /// [`EvalError`] for an unknown name or a division by zero.
    pub fn eval(&self, symbols: &HashMap<String, i64>) -> Result<i64, EvalError> {
        Ok(match self {
            Expr::Number(value) => *value,
            Expr::Symbol(name, span) => *symbols
                .get(name)
                .ok_or_else(|| EvalError::Undefined(name.clone(), span.clone()))?,
            Expr::Neg(inner) => inner.eval(symbols)?.wrapping_neg(),
            Expr::Binary(op, left, right) => {
                let (a, b) = (left.eval(symbols)?, right.eval(symbols)?);
                match op {
                    Op::Add => a.wrapping_add(b),
                    Op::Sub => a.wrapping_sub(b),
                    Op::Mul => a.wrapping_mul(b),
                    Op::Div => a.checked_div(b).ok_or(EvalError::DivisionByZero)?,
                }
            }
        })
    }

    /// The value when it uses no symbol.
    #[must_use]
    pub fn constant(&self) -> Option<i64> {
        self.eval(&HashMap::new()).ok()
    }

    /// The place of its first symbol in the layout file, if any.
    #[must_use]
    pub fn span(&self) -> Option<Range<usize>> {
        match self {
            Expr::Number(_) => None,
            Expr::Symbol(_, span) => Some(span.clone()),
            Expr::Neg(inner) => inner.span(),
            Expr::Binary(_, left, right) => left.span().or_else(|| right.span()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sym(name: &str) -> Box<Expr> {
        Box::new(Expr::Symbol(name.into(), 0..name.len()))
    }

    #[test]
    fn evaluates_with_symbols_and_reports_the_missing_one() {
        let expr = Expr::Binary(Op::Sub, sym("__HIMEM__"), sym("__MAIN_START__"));
        let mut symbols = HashMap::from([("__HIMEM__".to_owned(), 0xD000)]);
        assert_eq!(
            expr.eval(&symbols),
            Err(EvalError::Undefined("__MAIN_START__".into(), 0..14))
        );
        symbols.insert("__MAIN_START__".into(), 0x080D);
        assert_eq!(expr.eval(&symbols), Ok(0xD000 - 0x080D));
        let div = Expr::Binary(
            Op::Div,
            Box::new(Expr::Number(4)),
            Box::new(Expr::Number(0)),
        );
        assert_eq!(div.eval(&symbols), Err(EvalError::DivisionByZero));
        assert_eq!(Expr::Neg(Box::new(Expr::Number(2))).constant(), Some(-2));
    }
}
