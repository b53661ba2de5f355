//! `.scorpion.exprs`: bytes the linker computes from an expression that no
//! ELF relocation can express (`.byte (__VLIR0_LAST__ - __VLIR0_START__ - 1)
//! / 254`, `<~__DATA_SIZE__`, `ext1 - ext2`), as ld65 finishes ca65's
//! expressions. The expression is the same postfix bytecode as
//! `.scorpion.assert`'s ([`Expr`]), so the assembler folding constants and
//! the linker finishing a field use one definition of every operator.
//!
//! Layout (version 1): magic `SCEX`, version, a count, then per field:
//! `section: u32` (ELF section header index), `offset: u32`, the kind `u8`
//! (the order of [`FieldKind`]), an op count and the ops as in
//! `.scorpion.assert`.

use super::Expr;
use super::assert::{decode_ops, encode_ops};
use super::codec::{FormatError, Reader, Writer};
use super::{EXPRS_SECTION, VALUES_SECTION};

const MAGIC: &[u8; 4] = b"SCEX";
const VERSION: u8 = 1;

/// How a field stores its value, and which values it takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FieldKind {
    /// One byte, 0 to 255 (`.byte`, an immediate or zero-page operand).
    Byte,
    /// Two bytes, low first, 0 to $FFFF (`.word`, an absolute operand).
    Word,
    /// Two bytes, high first, 0 to $FFFF (`.dbyt`).
    WordBigEndian,
    /// Three bytes, low first, 0 to $FFFFFF (`.faraddr`).
    Far,
    /// Four bytes, low first, 0 to $FFFFFFFF (`.dword`).
    Dword,
}

const KINDS: [FieldKind; 5] = [
    FieldKind::Byte,
    FieldKind::Word,
    FieldKind::WordBigEndian,
    FieldKind::Dword,
    FieldKind::Far,
];

impl FieldKind {
    /// Its size in bytes.
    #[must_use]
    pub fn size(self) -> usize {
        match self {
            FieldKind::Byte => 1,
            FieldKind::Word | FieldKind::WordBigEndian => 2,
            FieldKind::Far => 3,
            FieldKind::Dword => 4,
        }
    }

    /// The values it holds, inclusive: what ld65's range check accepts.
    #[must_use]
    pub fn range(self) -> (i64, i64) {
        match self {
            FieldKind::Byte => (0, 0xFF),
            FieldKind::Word | FieldKind::WordBigEndian => (0, 0xFFFF),
            FieldKind::Far => (0, 0xFF_FFFF),
            FieldKind::Dword => (0, i64::from(u32::MAX)),
        }
    }

    /// `value`'s bytes in this field, or `None` when out of [`Self::range`].
    #[must_use]
    pub fn encode(self, value: i64) -> Option<Vec<u8>> {
        let (low, high) = self.range();
        if value < low || value > high {
            return None;
        }
        let bytes = (value as u32).to_le_bytes();
        Some(match self {
            FieldKind::WordBigEndian => vec![bytes[1], bytes[0]],
            _ => bytes[..self.size()].to_vec(),
        })
    }
}

/// A field of a section whose value the linker computes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExprField {
    /// ELF section header index of the section holding it.
    pub section: u32,
    /// Its first byte's offset in the section.
    pub offset: u32,
    /// How it stores the value.
    pub kind: FieldKind,
    /// The value.
    pub expr: Expr,
}

impl ExprField {
    /// Serialises fields as a section's contents.
    #[must_use]
    pub fn encode_all(fields: &[ExprField]) -> Vec<u8> {
        let mut out = Writer::header(MAGIC, VERSION);
        out.len32(fields.len());
        for field in fields {
            out.u32(field.section);
            out.u32(field.offset);
            out.u8(KINDS.iter().position(|k| *k == field.kind).unwrap_or(0) as u8);
            encode_ops(&mut out, &field.expr);
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not version-1 expression fields.
    pub fn decode_all(bytes: &[u8]) -> Result<Vec<ExprField>, FormatError> {
        let mut input = Reader::new(EXPRS_SECTION, bytes);
        input.header(MAGIC, VERSION)?;
        let count = input.count(10)?;
        let mut fields = Vec::with_capacity(count);
        for _ in 0..count {
            let section = input.u32()?;
            let offset = input.u32()?;
            let tag = input.u8()?;
            let kind = *KINDS
                .get(usize::from(tag))
                .ok_or_else(|| input.error(format!("unknown field kind {tag}")))?;
            let expr = decode_ops(&mut input)?;
            fields.push(ExprField {
                section,
                offset,
                kind,
                expr,
            });
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last field"));
        }
        Ok(fields)
    }
}

/// A symbol whose value the linker computes (`alias = imported + 1`,
/// exported): in the symbol table it is an absolute 0; its value is the
/// expression's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExprSymbol {
    /// The symbol's `.symtab` index.
    pub symbol: u32,
    /// Its value.
    pub expr: Expr,
}

const SYMBOLS_MAGIC: &[u8; 4] = b"SCSV";

impl ExprSymbol {
    /// Serialises symbols as a section's contents (`.scorpion.values`:
    /// magic `SCSV`, version 1, a count, then per symbol its index `u32`
    /// and the expression as in `.scorpion.assert`).
    #[must_use]
    pub fn encode_all(symbols: &[ExprSymbol]) -> Vec<u8> {
        let mut out = Writer::header(SYMBOLS_MAGIC, VERSION);
        out.len32(symbols.len());
        for symbol in symbols {
            out.u32(symbol.symbol);
            encode_ops(&mut out, &symbol.expr);
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not version-1 symbol values.
    pub fn decode_all(bytes: &[u8]) -> Result<Vec<ExprSymbol>, FormatError> {
        let mut input = Reader::new(VALUES_SECTION, bytes);
        input.header(SYMBOLS_MAGIC, VERSION)?;
        let count = input.count(8)?;
        let mut symbols = Vec::with_capacity(count);
        for _ in 0..count {
            let symbol = input.u32()?;
            let expr = decode_ops(&mut input)?;
            symbols.push(ExprSymbol { symbol, expr });
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last symbol"));
        }
        Ok(symbols)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objfmt::{BinaryOp, ExprOp};

    #[test]
    fn fields_round_trip_and_bad_bytes_are_errors() {
        let fields = vec![
            ExprField {
                section: 2,
                offset: 7,
                kind: FieldKind::Byte,
                expr: Expr {
                    ops: vec![
                        ExprOp::Symbol(3),
                        ExprOp::Symbol(4),
                        ExprOp::Binary(BinaryOp::Sub),
                        ExprOp::Const(254),
                        ExprOp::Binary(BinaryOp::Div),
                    ],
                },
            },
            ExprField {
                section: 3,
                offset: 0,
                kind: FieldKind::WordBigEndian,
                expr: Expr {
                    ops: vec![ExprOp::Const(0x1234)],
                },
            },
        ];
        let bytes = ExprField::encode_all(&fields);
        assert_eq!(ExprField::decode_all(&bytes), Ok(fields));
        for cut in 0..bytes.len() {
            assert!(
                ExprField::decode_all(&bytes[..cut]).is_err(),
                "cut at {cut}"
            );
        }
        let mut bad_kind = bytes.clone();
        bad_kind[4 + 1 + 4 + 8] = 9;
        assert!(ExprField::decode_all(&bad_kind).is_err());
    }

    #[test]
    fn symbol_values_round_trip() {
        let symbols = vec![ExprSymbol {
            symbol: 4,
            expr: Expr {
                ops: vec![
                    ExprOp::Symbol(2),
                    ExprOp::Const(1),
                    ExprOp::Binary(BinaryOp::Add),
                ],
            },
        }];
        let bytes = ExprSymbol::encode_all(&symbols);
        assert_eq!(ExprSymbol::decode_all(&bytes), Ok(symbols));
        for cut in 0..bytes.len() {
            assert!(ExprSymbol::decode_all(&bytes[..cut]).is_err());
        }
    }

    #[test]
    fn kinds_store_values_as_ld65_and_refuse_the_rest() {
        assert_eq!(FieldKind::Byte.encode(255), Some(vec![0xFF]));
        assert_eq!(FieldKind::Byte.encode(-1), None, "ld65: range error");
        assert_eq!(FieldKind::Byte.encode(256), None);
        assert_eq!(FieldKind::Word.encode(0x1234), Some(vec![0x34, 0x12]));
        assert_eq!(
            FieldKind::WordBigEndian.encode(0x1234),
            Some(vec![0x12, 0x34])
        );
        assert_eq!(FieldKind::Word.encode(0x1_0000), None);
        assert_eq!(FieldKind::Dword.encode(0x0102_0304), Some(vec![4, 3, 2, 1]));
    }
}
