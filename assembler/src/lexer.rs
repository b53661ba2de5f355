//! The hand-written byte lexer: one source line at a time into a reused
//! token buffer, identifiers interned as they are read.
//!
//! ca65's lexical rules: `;` comments, `$hex`, `%binary`, decimal and
//! `0FFh` numbers, `'c'` characters, `"strings"` without escapes, `@cheap`
//! locals, `.directives`, `:+`/`:-` unnamed-label references, `::` scope
//! separators.

use crate::diag::Span;
use crate::intern::{Interner, NameId};

/// Token kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Tok {
    /// An identifier; `value` is its [`NameId`].
    Ident,
    /// A cheap local `@name`; `value` is the [`NameId`] of `@name`.
    Local,
    /// A directive `.name`; `value` is the [`NameId`] of `.name`.
    Directive,
    /// A number; `value` is the number.
    Number,
    /// A character constant; `value` is its code (before `.charmap`).
    Char,
    /// A string; its text is the span without the quotes.
    Str,
    Plus,
    Minus,
    Star,
    Slash,
    Amp,
    Pipe,
    Caret,
    Tilde,
    Bang,
    Lt,
    Gt,
    Le,
    Ge,
    Ne,
    Eq,
    Shl,
    Shr,
    AndAnd,
    OrOr,
    LParen,
    RParen,
    LBracket,
    RBracket,
    LBrace,
    RBrace,
    Comma,
    Colon,
    ColonColon,
    /// `:=`
    Assign,
    Hash,
    /// `:+` / `:-`...; `value` is the signed count as `i64` bits.
    Unnamed,
    /// A macro parameter inside a stored macro body; `value` is its index.
    Param,
}

/// One token.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Token {
    pub(crate) kind: Tok,
    pub(crate) span: Span,
    pub(crate) value: u64,
}

impl Token {
    pub(crate) fn name(&self) -> NameId {
        self.value as NameId
    }
}

/// Where a line is in its file.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LineInfo {
    pub(crate) file: u32,
    /// Line number from 1.
    pub(crate) line: u32,
    /// Offset of the first byte of the line.
    pub(crate) start: u32,
    /// Offset after the last byte (before `\r\n` / `\n`).
    pub(crate) end: u32,
    /// The line is ASCII, so columns are byte offsets.
    pub(crate) ascii: bool,
}

/// A lexing problem: where and what.
pub(crate) type LexError = (Span, String);

/// Reads one file line by line.
#[derive(Debug, Clone)]
pub(crate) struct Lexer {
    file: u32,
    pos: usize,
    line: u32,
}

/// Bytes that continue an identifier: a table, as the lexer asks for
/// every byte of every name.
const IDENT: [bool; 256] = {
    let mut table = [false; 256];
    let mut b = 0;
    while b < 256 {
        let c = b as u8;
        table[b] = c.is_ascii_alphanumeric() || c == b'_';
        b += 1;
    }
    table
};

fn is_ident_start(byte: u8) -> bool {
    byte.is_ascii_alphabetic() || byte == b'_'
}

fn is_ident_char(byte: u8) -> bool {
    IDENT[usize::from(byte)]
}

impl Lexer {
    pub(crate) fn new(file: u32) -> Lexer {
        Lexer {
            file,
            pos: 0,
            line: 0,
        }
    }

    fn span(&self, start: usize, end: usize) -> Span {
        Span {
            file: self.file,
            start: start as u32,
            end: end as u32,
        }
    }

    /// Lexes the next line into `out` (cleared first). Returns `None` at the
    /// end of the file. Problems go to `errors`; the bad characters are
    /// skipped.
    pub(crate) fn next_line(
        &mut self,
        text: &[u8],
        names: &mut Interner,
        out: &mut Vec<Token>,
        errors: &mut Vec<LexError>,
    ) -> Option<LineInfo> {
        out.clear();
        if self.pos >= text.len() {
            return None;
        }
        self.line += 1;
        let line_start = self.pos;
        let line_end = memchr_newline(text, self.pos);
        let mut end = line_end;
        if end > line_start && text[end - 1] == b'\r' {
            end -= 1;
        }
        self.pos = line_end + 1;
        let mut i = line_start;
        while i < end {
            let byte = text[i];
            let start = i;
            let simple = |kind: Tok, len: usize| (kind, len);
            let (kind, len) = match byte {
                b' ' | b'\t' | b'\x0C' => {
                    i += 1;
                    while i < end && matches!(text[i], b' ' | b'\t') {
                        i += 1;
                    }
                    continue;
                }
                b';' => break,
                b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                    let mut j = i + 1;
                    while j < end && is_ident_char(text[j]) {
                        j += 1;
                    }
                    let id = names.intern_bytes(&text[i..j]);
                    out.push(Token {
                        kind: Tok::Ident,
                        span: self.span(i, j),
                        value: u64::from(id),
                    });
                    i = j;
                    continue;
                }
                b'@' | b'.' => {
                    let mut j = i + 1;
                    // A cheap local may start with a digit (`@1:`), as in
                    // ca65; a directive may not.
                    let starts = |b: u8| is_ident_start(b) || (byte == b'@' && b.is_ascii_digit());
                    if j < end && starts(text[j]) {
                        while j < end && is_ident_char(text[j]) {
                            j += 1;
                        }
                        let id = names.intern_bytes(&text[i..j]);
                        out.push(Token {
                            kind: if byte == b'@' {
                                Tok::Local
                            } else {
                                Tok::Directive
                            },
                            span: self.span(i, j),
                            value: u64::from(id),
                        });
                    } else {
                        let what = if byte == b'@' {
                            "`@` must start a cheap local label name (`@loop`)"
                        } else {
                            "`.` must start a directive name (`.byte`)"
                        };
                        errors.push((self.span(i, j), what.to_string()));
                    }
                    i = j;
                    continue;
                }
                b'0'..=b'9' => {
                    let mut j = i + 1;
                    while j < end && is_ident_char(text[j]) {
                        j += 1;
                    }
                    match number(&text[i..j]) {
                        Ok(value) => out.push(Token {
                            kind: Tok::Number,
                            span: self.span(i, j),
                            value,
                        }),
                        Err(message) => errors.push((self.span(i, j), message)),
                    }
                    i = j;
                    continue;
                }
                b'$' | b'%' => {
                    let radix = if byte == b'$' { 16 } else { 2 };
                    let mut j = i + 1;
                    while j < end && is_ident_char(text[j]) {
                        j += 1;
                    }
                    let digits = &text[i + 1..j];
                    match digits_value(digits, radix) {
                        Ok(value) => out.push(Token {
                            kind: Tok::Number,
                            span: self.span(i, j),
                            value,
                        }),
                        Err(message) => errors.push((self.span(i, j.max(i + 1)), message)),
                    }
                    i = j.max(i + 1);
                    continue;
                }
                b'"' => {
                    let close = text[i + 1..end].iter().position(|b| *b == b'"');
                    match close {
                        Some(len) => {
                            let j = i + 1 + len + 1;
                            out.push(Token {
                                kind: Tok::Str,
                                span: self.span(i, j),
                                value: 0,
                            });
                            i = j;
                        }
                        None => {
                            errors.push((
                                self.span(i, end),
                                "this string has no closing `\"` on its line".to_string(),
                            ));
                            i = end;
                        }
                    }
                    continue;
                }
                b'\'' => {
                    match char_constant(&text[i + 1..end]) {
                        Some((value, len)) => {
                            let j = i + 1 + len + 1;
                            out.push(Token {
                                kind: Tok::Char,
                                span: self.span(i, j),
                                value: u64::from(value),
                            });
                            i = j;
                        }
                        None => {
                            // Skip to the closing quote, if any, so one bad
                            // constant is one error.
                            let j = text[i + 1..end]
                                .iter()
                                .position(|b| *b == b'\'')
                                .map_or((i + 2).min(end), |len| i + 1 + len + 1);
                            errors.push((
                                self.span(i, j),
                                "a character constant is one character between quotes (`'a'`)"
                                    .to_string(),
                            ));
                            i = j;
                        }
                    }
                    continue;
                }
                b'+' => simple(Tok::Plus, 1),
                b'-' => simple(Tok::Minus, 1),
                b'*' => simple(Tok::Star, 1),
                b'/' => simple(Tok::Slash, 1),
                b'~' => simple(Tok::Tilde, 1),
                b'^' => simple(Tok::Caret, 1),
                b'!' => simple(Tok::Bang, 1),
                b'#' => simple(Tok::Hash, 1),
                b',' => simple(Tok::Comma, 1),
                b'(' => simple(Tok::LParen, 1),
                b')' => simple(Tok::RParen, 1),
                b'[' => simple(Tok::LBracket, 1),
                b']' => simple(Tok::RBracket, 1),
                b'{' => simple(Tok::LBrace, 1),
                b'}' => simple(Tok::RBrace, 1),
                b'=' => simple(Tok::Eq, 1),
                b'&' => {
                    if text.get(i + 1) == Some(&b'&') && i + 1 < end {
                        (Tok::AndAnd, 2)
                    } else {
                        (Tok::Amp, 1)
                    }
                }
                b'|' => {
                    if i + 1 < end && text[i + 1] == b'|' {
                        (Tok::OrOr, 2)
                    } else {
                        (Tok::Pipe, 1)
                    }
                }
                b'<' => match text.get(i + 1).filter(|_| i + 1 < end) {
                    Some(b'>') => (Tok::Ne, 2),
                    Some(b'=') => (Tok::Le, 2),
                    Some(b'<') => (Tok::Shl, 2),
                    _ => (Tok::Lt, 1),
                },
                b'>' => match text.get(i + 1).filter(|_| i + 1 < end) {
                    Some(b'=') => (Tok::Ge, 2),
                    Some(b'>') => (Tok::Shr, 2),
                    _ => (Tok::Gt, 1),
                },
                b':' => match text.get(i + 1).filter(|_| i + 1 < end) {
                    Some(b':') => (Tok::ColonColon, 2),
                    Some(b'=') => (Tok::Assign, 2),
                    Some(sign @ (b'+' | b'-')) => {
                        let mut j = i + 1;
                        while j < end && text[j] == *sign {
                            j += 1;
                        }
                        let count = (j - i - 1) as i64;
                        let value = if *sign == b'+' { count } else { -count };
                        out.push(Token {
                            kind: Tok::Unnamed,
                            span: self.span(i, j),
                            value: value as u64,
                        });
                        i = j;
                        continue;
                    }
                    _ => (Tok::Colon, 1),
                },
                _ => {
                    // Skip a whole UTF-8 character so the span is readable.
                    let mut j = i + 1;
                    while j < end && (text[j] & 0xC0) == 0x80 {
                        j += 1;
                    }
                    let shown = String::from_utf8_lossy(&text[i..j]).into_owned();
                    errors.push((
                        self.span(i, j),
                        format!("unexpected character `{}`", shown.escape_debug()),
                    ));
                    i = j;
                    continue;
                }
            };
            out.push(Token {
                kind,
                span: self.span(start, start + len),
                value: 0,
            });
            i = start + len;
        }
        Some(LineInfo {
            file: self.file,
            line: self.line,
            start: line_start as u32,
            end: end as u32,
            ascii: text[line_start..end].is_ascii(),
        })
    }
}

fn memchr_newline(text: &[u8], from: usize) -> usize {
    text[from..]
        .iter()
        .position(|b| *b == b'\n')
        .map_or(text.len(), |p| from + p)
}

fn digits_value(digits: &[u8], radix: u32) -> Result<u64, String> {
    let what = if radix == 16 { "hexadecimal" } else { "binary" };
    if digits.is_empty() {
        return Err(format!("a {what} number needs at least one digit"));
    }
    let mut value: u64 = 0;
    for &digit in digits {
        let Some(d) = (digit as char).to_digit(radix) else {
            return Err(format!(
                "`{}` is not a {what} digit",
                (digit as char).escape_debug()
            ));
        };
        value = value * u64::from(radix) + u64::from(d);
        if value > u64::from(u32::MAX) {
            return Err("this number does not fit in 32 bits".to_string());
        }
    }
    Ok(value)
}

fn number(text: &[u8]) -> Result<u64, String> {
    if let [digits @ .., b'h' | b'H'] = text
        && digits.iter().all(u8::is_ascii_hexdigit)
    {
        return digits_value(digits, 16);
    }
    let mut value: u64 = 0;
    for &digit in text {
        if !digit.is_ascii_digit() {
            return Err(format!(
                "`{}` is not a number (write $1F or 1Fh for hexadecimal)",
                String::from_utf8_lossy(text)
            ));
        }
        value = value * 10 + u64::from(digit - b'0');
        if value > u64::from(u32::MAX) {
            return Err("this number does not fit in 32 bits".to_string());
        }
    }
    Ok(value)
}

/// The value and byte length of the character after an opening quote,
/// if a closing quote follows it.
fn char_constant(rest: &[u8]) -> Option<(u32, usize)> {
    let first = *rest.first()?;
    let len = match first {
        0x00..=0x7F => 1,
        0xC0..=0xDF => 2,
        0xE0..=0xEF => 3,
        0xF0..=0xF7 => 4,
        _ => 1,
    };
    if rest.get(len) != Some(&b'\'') {
        return None;
    }
    let value = if len == 1 {
        u32::from(first)
    } else {
        std::str::from_utf8(&rest[..len]).ok()?.chars().next()? as u32
    };
    Some((value, len))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(text: &str) -> (Vec<Tok>, Vec<u64>, Vec<String>) {
        let mut names = Interner::new();
        let mut lexer = Lexer::new(0);
        let mut out = Vec::new();
        let mut errors = Vec::new();
        lexer.next_line(text.as_bytes(), &mut names, &mut out, &mut errors);
        (
            out.iter().map(|t| t.kind).collect(),
            out.iter().map(|t| t.value).collect(),
            errors.into_iter().map(|e| e.1).collect(),
        )
    }

    #[test]
    fn numbers_in_every_base() {
        let (kinds, values, errors) = lex("$1F %101 42 0FFh 1fH");
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(kinds, vec![Tok::Number; 5]);
        assert_eq!(values, vec![0x1F, 5, 42, 0xFF, 0x1F]);
        let (_, _, errors) = lex("$ %2 12x $100000000");
        assert_eq!(errors.len(), 4, "{errors:?}");
    }

    #[test]
    fn operators_and_unnamed_references() {
        let (kinds, values, _) = lex("a<>b <= >= << >> && || := :: :++ :- : ; comment");
        assert_eq!(
            kinds,
            vec![
                Tok::Ident,
                Tok::Ne,
                Tok::Ident,
                Tok::Le,
                Tok::Ge,
                Tok::Shl,
                Tok::Shr,
                Tok::AndAnd,
                Tok::OrOr,
                Tok::Assign,
                Tok::ColonColon,
                Tok::Unnamed,
                Tok::Unnamed,
                Tok::Colon
            ]
        );
        assert_eq!(values[11] as i64, 2);
        assert_eq!(values[12] as i64, -1);
    }

    #[test]
    fn strings_chars_and_errors() {
        let (kinds, values, errors) = lex("\"hi;there\" 'a' '' \"open");
        assert_eq!(kinds, vec![Tok::Str, Tok::Char]);
        assert_eq!(values[1], u64::from(b'a'));
        assert_eq!(errors.len(), 2, "{errors:?}");
    }

    #[test]
    fn lines_and_crlf() {
        let mut names = Interner::new();
        let mut lexer = Lexer::new(0);
        let mut out = Vec::new();
        let mut errors = Vec::new();
        let text = b"nop\r\n\nlda #1";
        let first = lexer
            .next_line(text, &mut names, &mut out, &mut errors)
            .unwrap();
        assert_eq!((first.line, first.start, first.end), (1, 0, 3));
        let second = lexer
            .next_line(text, &mut names, &mut out, &mut errors)
            .unwrap();
        assert_eq!((second.line, out.len()), (2, 0));
        let third = lexer
            .next_line(text, &mut names, &mut out, &mut errors)
            .unwrap();
        assert_eq!((third.line, out.len()), (3, 3));
        assert!(
            lexer
                .next_line(text, &mut names, &mut out, &mut errors)
                .is_none()
        );
    }
}
