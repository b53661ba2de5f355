//! `.scorpion.assert`: assertions the assembler could not decide because
//! they depend on addresses, for the linker to check after placement.
//!
//! Expressions are postfix bytecode over 64-bit signed integers with
//! wrapping arithmetic. [`UnaryOp::apply`] and [`BinaryOp::apply`] are the
//! one definition of every operator, used by the assembler when it folds
//! constants and by the linker when it checks these records, so the two
//! cannot disagree. Comparisons and logical operators give 1 or 0, as ca65's do.
//!
//! Layout (version 1): magic `SCAS`, version, a count, then per assertion:
//! action `u8` (0 error, 1 warning), the file as a length-prefixed string,
//! line `u32`, column `u32`, the message string, an op count, then the ops:
//! `0x01 i64` constant, `0x02 u32` symbol (its `.symtab` index; the value is
//! the symbol's final address or value), `0x10..` unary and `0x20..` binary
//! operators in the order of [`UnaryOp`] and [`BinaryOp`].

use core::fmt;

use super::ASSERT_SECTION;
use super::codec::{FormatError, Reader, Writer};

const MAGIC: &[u8; 4] = b"SCAS";
const VERSION: u8 = 1;

/// What a failed assertion does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AssertAction {
    /// The link fails.
    Error,
    /// The link goes on with a warning.
    Warning,
}

/// A one-operand operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    /// `-x`
    Neg,
    /// `~x`
    BitNot,
    /// `!x` / `.not x`: 1 if x is 0, else 0.
    LogNot,
    /// `<x` / `.lobyte`: bits 0–7.
    LoByte,
    /// `>x` / `.hibyte`: bits 8–15.
    HiByte,
    /// `^x` / `.bankbyte`: bits 16–23.
    BankByte,
}

/// A two-operand operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BinaryOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`, truncating toward zero.
    Div,
    /// `.mod`, with the sign of the dividend (C's `%`).
    Mod,
    /// `&`
    BitAnd,
    /// `|`
    BitOr,
    /// `^`
    BitXor,
    /// `<<` (a negative count shifts right).
    Shl,
    /// `>>`, arithmetic (a negative count shifts left).
    Shr,
    /// `=`
    Eq,
    /// `<>`
    Ne,
    /// `<`
    Lt,
    /// `>`
    Gt,
    /// `<=`
    Le,
    /// `>=`
    Ge,
    /// `&&` / `.and`
    LogAnd,
    /// `||` / `.or`
    LogOr,
    /// `.xor`: 1 if exactly one side is non-zero.
    LogXor,
}

const UNARY: [UnaryOp; 6] = [
    UnaryOp::Neg,
    UnaryOp::BitNot,
    UnaryOp::LogNot,
    UnaryOp::LoByte,
    UnaryOp::HiByte,
    UnaryOp::BankByte,
];

const BINARY: [BinaryOp; 19] = [
    BinaryOp::Add,
    BinaryOp::Sub,
    BinaryOp::Mul,
    BinaryOp::Div,
    BinaryOp::Mod,
    BinaryOp::BitAnd,
    BinaryOp::BitOr,
    BinaryOp::BitXor,
    BinaryOp::Shl,
    BinaryOp::Shr,
    BinaryOp::Eq,
    BinaryOp::Ne,
    BinaryOp::Lt,
    BinaryOp::Gt,
    BinaryOp::Le,
    BinaryOp::Ge,
    BinaryOp::LogAnd,
    BinaryOp::LogOr,
    BinaryOp::LogXor,
];

/// Why an expression has no value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EvalError {
    /// Division or `.mod` by zero.
    DivisionByZero,
    /// A symbol the caller cannot resolve (its `.symtab` index).
    UnresolvedSymbol(u32),
    /// The bytecode does not leave exactly one value.
    Malformed,
}

impl fmt::Display for EvalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalError::DivisionByZero => f.write_str("division by zero"),
            EvalError::UnresolvedSymbol(index) => write!(f, "symbol #{index} has no value"),
            EvalError::Malformed => f.write_str("malformed expression bytecode"),
        }
    }
}

impl std::error::Error for EvalError {}

fn truth(value: bool) -> i64 {
    i64::from(value)
}

fn shift_left(value: i64, count: i64) -> i64 {
    match count {
        i64::MIN..0 => shift_right(value, count.saturating_neg()),
        0..64 => value.wrapping_shl(count as u32),
        _ => 0,
    }
}

fn shift_right(value: i64, count: i64) -> i64 {
    match count {
        i64::MIN..0 => shift_left(value, count.saturating_neg()),
        0..64 => value >> count,
        _ => {
            if value < 0 {
                -1
            } else {
                0
            }
        }
    }
}

/// ca65's `<<` on constants it folds: cc65's `shl_l`, the count taken as
/// C's `unsigned` (its low 32 bits), counts past 63 shifting everything out.
fn ca65_shift_left(value: i64, count: i64) -> i64 {
    match count as u32 {
        count @ 0..64 => value.wrapping_shl(count),
        _ => 0,
    }
}

/// ca65's `>>` on constants it folds: cc65's `shr_l`, a *logical* shift (a
/// negative number's sign bits are not copied in), the count taken as C's
/// `unsigned`. ld65 computes what reaches it with C's arithmetic `>>`
/// instead, which [`BinaryOp::apply`] follows.
fn ca65_shift_right(value: i64, count: i64) -> i64 {
    match count as u32 {
        count @ 0..64 => ((value as u64) >> count) as i64,
        _ => 0,
    }
}

impl UnaryOp {
    /// Applies the operator.
    #[must_use]
    pub fn apply(self, value: i64) -> i64 {
        match self {
            UnaryOp::Neg => value.wrapping_neg(),
            UnaryOp::BitNot => !value,
            UnaryOp::LogNot => truth(value == 0),
            UnaryOp::LoByte => value & 0xFF,
            UnaryOp::HiByte => (value >> 8) & 0xFF,
            UnaryOp::BankByte => (value >> 16) & 0xFF,
        }
    }
}

impl BinaryOp {
    /// Applies the operator.
    ///
    /// # Errors
    /// [`EvalError::DivisionByZero`] for `/` or `.mod` by zero.
    pub fn apply(self, left: i64, right: i64) -> Result<i64, EvalError> {
        Ok(match self {
            BinaryOp::Add => left.wrapping_add(right),
            BinaryOp::Sub => left.wrapping_sub(right),
            BinaryOp::Mul => left.wrapping_mul(right),
            BinaryOp::Div => {
                if right == 0 {
                    return Err(EvalError::DivisionByZero);
                }
                left.wrapping_div(right)
            }
            BinaryOp::Mod => {
                if right == 0 {
                    return Err(EvalError::DivisionByZero);
                }
                left.wrapping_rem(right)
            }
            BinaryOp::BitAnd => left & right,
            BinaryOp::BitOr => left | right,
            BinaryOp::BitXor => left ^ right,
            BinaryOp::Shl => shift_left(left, right),
            BinaryOp::Shr => shift_right(left, right),
            BinaryOp::Eq => truth(left == right),
            BinaryOp::Ne => truth(left != right),
            BinaryOp::Lt => truth(left < right),
            BinaryOp::Gt => truth(left > right),
            BinaryOp::Le => truth(left <= right),
            BinaryOp::Ge => truth(left >= right),
            BinaryOp::LogAnd => truth(left != 0 && right != 0),
            BinaryOp::LogOr => truth(left != 0 || right != 0),
            BinaryOp::LogXor => truth((left != 0) != (right != 0)),
        })
    }

    /// Applies the operator as ca65 does when it folds constants while
    /// assembling: as [`BinaryOp::apply`] (ld65's arithmetic, for what
    /// the linker finishes) but for the shifts, which ca65 makes logical
    /// with an unsigned 32-bit count (`(-16 >> 60) & $FF` is `$0F` in ca65
    /// and `$FF` in ld65).
    ///
    /// # Errors
    /// [`EvalError::DivisionByZero`] for `/` or `.mod` by zero.
    pub fn apply_ca65(self, left: i64, right: i64) -> Result<i64, EvalError> {
        match self {
            BinaryOp::Shl => Ok(ca65_shift_left(left, right)),
            BinaryOp::Shr => Ok(ca65_shift_right(left, right)),
            _ => self.apply(left, right),
        }
    }
}

/// One step of an expression's postfix bytecode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExprOp {
    /// Push a constant.
    Const(i64),
    /// Push a symbol's value (`.symtab` index).
    Symbol(u32),
    /// Pop one value, push the result.
    Unary(UnaryOp),
    /// Pop right then left, push the result.
    Binary(BinaryOp),
}

/// An expression as postfix bytecode.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct Expr {
    /// The steps, in evaluation order.
    pub ops: Vec<ExprOp>,
}

impl Expr {
    /// Evaluates the expression, asking `symbol` for each symbol's value.
    ///
    /// # Errors
    /// [`EvalError`] for division by zero, a symbol `symbol` cannot resolve,
    /// or bytecode that does not leave exactly one value.
    pub fn evaluate(&self, mut symbol: impl FnMut(u32) -> Option<i64>) -> Result<i64, EvalError> {
        let mut stack: Vec<i64> = Vec::with_capacity(8);
        for op in &self.ops {
            match *op {
                ExprOp::Const(value) => stack.push(value),
                ExprOp::Symbol(index) => {
                    stack.push(symbol(index).ok_or(EvalError::UnresolvedSymbol(index))?);
                }
                ExprOp::Unary(unary) => {
                    let value = stack.pop().ok_or(EvalError::Malformed)?;
                    stack.push(unary.apply(value));
                }
                ExprOp::Binary(binary) => {
                    let right = stack.pop().ok_or(EvalError::Malformed)?;
                    let left = stack.pop().ok_or(EvalError::Malformed)?;
                    stack.push(binary.apply(left, right)?);
                }
            }
        }
        match stack.as_slice() {
            [value] => Ok(*value),
            _ => Err(EvalError::Malformed),
        }
    }

    /// The `.symtab` indices the expression reads.
    pub fn symbols(&self) -> impl Iterator<Item = u32> + '_ {
        self.ops.iter().filter_map(|op| match op {
            ExprOp::Symbol(index) => Some(*index),
            _ => None,
        })
    }
}

/// Writes an expression: its op count, then the ops.
pub(super) fn encode_ops(out: &mut Writer, expr: &Expr) {
    out.len32(expr.ops.len());
    for op in &expr.ops {
        match *op {
            ExprOp::Const(value) => {
                out.u8(0x01);
                out.i64(value);
            }
            ExprOp::Symbol(index) => {
                out.u8(0x02);
                out.u32(index);
            }
            ExprOp::Unary(unary) => {
                let code = UNARY.iter().position(|u| *u == unary).unwrap_or(0);
                out.u8(0x10 + code as u8);
            }
            ExprOp::Binary(binary) => {
                let code = BINARY.iter().position(|b| *b == binary).unwrap_or(0);
                out.u8(0x20 + code as u8);
            }
        }
    }
}

/// Reads what [`encode_ops`] wrote.
pub(super) fn decode_ops(input: &mut Reader<'_>) -> Result<Expr, FormatError> {
    let op_count = input.count(1)?;
    let mut ops = Vec::with_capacity(op_count);
    for _ in 0..op_count {
        let tag = input.u8()?;
        ops.push(match tag {
            0x01 => ExprOp::Const(input.i64()?),
            0x02 => ExprOp::Symbol(input.u32()?),
            0x10..=0x1F => ExprOp::Unary(
                *UNARY
                    .get(usize::from(tag - 0x10))
                    .ok_or_else(|| input.error(format!("unknown operator {tag:#04x}")))?,
            ),
            0x20..=0x3F => ExprOp::Binary(
                *BINARY
                    .get(usize::from(tag - 0x20))
                    .ok_or_else(|| input.error(format!("unknown operator {tag:#04x}")))?,
            ),
            _ => return Err(input.error(format!("unknown operator {tag:#04x}"))),
        });
    }
    Ok(Expr { ops })
}

/// One deferred `.assert`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Assertion {
    /// Error or warning when the expression is zero.
    pub action: AssertAction,
    /// Source file of the `.assert`.
    pub file: String,
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1.
    pub column: u32,
    /// The user's message.
    pub message: String,
    /// The condition: the assertion holds when it is non-zero.
    pub expr: Expr,
}

impl Assertion {
    /// Serialises a list of assertions as a section's contents.
    #[must_use]
    pub fn encode_all(assertions: &[Assertion]) -> Vec<u8> {
        let mut out = Writer::header(MAGIC, VERSION);
        out.len32(assertions.len());
        for assertion in assertions {
            out.u8(match assertion.action {
                AssertAction::Error => 0,
                AssertAction::Warning => 1,
            });
            out.string(&assertion.file);
            out.u32(assertion.line);
            out.u32(assertion.column);
            out.string(&assertion.message);
            encode_ops(&mut out, &assertion.expr);
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not a version-1 assertion section.
    pub fn decode_all(bytes: &[u8]) -> Result<Vec<Assertion>, FormatError> {
        let mut input = Reader::new(ASSERT_SECTION, bytes);
        input.header(MAGIC, VERSION)?;
        let count = input.count(22)?;
        let mut assertions = Vec::with_capacity(count);
        for _ in 0..count {
            let action = match input.u8()? {
                0 => AssertAction::Error,
                1 => AssertAction::Warning,
                other => return Err(input.error(format!("unknown assertion action {other}"))),
            };
            let file = input.string()?;
            let line = input.u32()?;
            let column = input.u32()?;
            let message = input.string()?;
            let expr = decode_ops(&mut input)?;
            assertions.push(Assertion {
                action,
                file,
                line,
                column,
                message,
                expr,
            });
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last assertion"));
        }
        Ok(assertions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<Assertion> {
        // (end - start) < $100, with `end` = symbol 3 and `start` = symbol 4.
        let expr = Expr {
            ops: vec![
                ExprOp::Symbol(3),
                ExprOp::Symbol(4),
                ExprOp::Binary(BinaryOp::Sub),
                ExprOp::Const(0x100),
                ExprOp::Binary(BinaryOp::Lt),
            ],
        };
        vec![Assertion {
            action: AssertAction::Error,
            file: "ext.s".into(),
            line: 12,
            column: 9,
            message: "table crosses a page".into(),
            expr,
        }]
    }

    #[test]
    fn round_trip_and_evaluate() {
        let decoded = Assertion::decode_all(&Assertion::encode_all(&sample())).unwrap();
        assert_eq!(decoded, sample());
        let value = |start: i64, end: i64| {
            decoded[0]
                .expr
                .evaluate(|index| match index {
                    3 => Some(end),
                    4 => Some(start),
                    _ => None,
                })
                .unwrap()
        };
        assert_eq!(value(0x1000, 0x10FF), 1);
        assert_eq!(value(0x1000, 0x1100), 0);
        assert_eq!(
            decoded[0].expr.evaluate(|_| None),
            Err(EvalError::UnresolvedSymbol(3))
        );
    }

    #[test]
    fn every_operator_round_trips() {
        let mut ops = vec![ExprOp::Const(-5), ExprOp::Symbol(u32::MAX)];
        ops.extend(UNARY.iter().map(|u| ExprOp::Unary(*u)));
        ops.extend(BINARY.iter().map(|b| ExprOp::Binary(*b)));
        let mut assertion = sample().remove(0);
        assertion.expr = Expr { ops };
        let bytes = Assertion::encode_all(std::slice::from_ref(&assertion));
        assert_eq!(Assertion::decode_all(&bytes).unwrap(), vec![assertion]);
    }

    #[test]
    fn operators_follow_ca65() {
        assert_eq!(BinaryOp::Div.apply(-7, 2), Ok(-3));
        assert_eq!(BinaryOp::Mod.apply(-7, 2), Ok(-1));
        assert_eq!(BinaryOp::Div.apply(1, 0), Err(EvalError::DivisionByZero));
        assert_eq!(BinaryOp::Shl.apply(1, 4), Ok(16));
        assert_eq!(BinaryOp::Shl.apply(16, -4), Ok(1));
        assert_eq!(BinaryOp::Shr.apply(-16, 2), Ok(-4));
        assert_eq!(BinaryOp::Shr.apply(-16, 200), Ok(-1));
        // ca65 2.19's folding, as it assembled `.byte <(...)` of each.
        assert_eq!(BinaryOp::Shr.apply_ca65(-16, 60), Ok(0x0F));
        assert_eq!(BinaryOp::Shr.apply_ca65(-16, 64), Ok(0));
        assert_eq!(
            BinaryOp::Shr.apply_ca65(-256, 4).map(|v| v & 0xFF),
            Ok(0xF0)
        );
        assert_eq!(
            BinaryOp::Shr
                .apply_ca65(-1, (1 << 32) + 4)
                .map(|v| v & 0xFF),
            Ok(0xFF)
        );
        assert_eq!(BinaryOp::Shl.apply_ca65(1, (1 << 32) + 1), Ok(2));
        assert_eq!(BinaryOp::Shl.apply_ca65(-16, -4), Ok(0));
        assert_eq!(BinaryOp::Shr.apply_ca65(16, -2), Ok(0));
        assert_eq!(BinaryOp::Shr.apply_ca65(1 << 63, 56), Ok(0x80));
        assert_eq!(BinaryOp::LogXor.apply(3, 0), Ok(1));
        assert_eq!(BinaryOp::LogXor.apply(3, 4), Ok(0));
        assert_eq!(UnaryOp::HiByte.apply(0x12345), 0x23);
        assert_eq!(UnaryOp::BankByte.apply(0x12345), 0x01);
        assert_eq!(UnaryOp::LogNot.apply(0), 1);
    }

    #[test]
    fn malformed_bytecode_is_an_error_not_a_panic() {
        let expr = Expr {
            ops: vec![ExprOp::Binary(BinaryOp::Add)],
        };
        assert_eq!(expr.evaluate(|_| Some(0)), Err(EvalError::Malformed));
        let bytes = Assertion::encode_all(&sample());
        for len in 0..bytes.len() {
            assert!(
                Assertion::decode_all(&bytes[..len]).is_err(),
                "length {len}"
            );
        }
        let mut bad = bytes.clone();
        let last = bad.len() - 1;
        bad[last] = 0x7F;
        assert!(Assertion::decode_all(&bad).is_err());
    }
}
