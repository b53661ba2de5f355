//! The hand-written byte lexer: one source line at a time into a reused
//! token buffer, identifiers interned as they are read.
//!
//! ca65's lexical rules: `;` comments, `$hex`, `%binary`, decimal and
//! `0FFh` numbers, `'c'` characters, `"strings"` without escapes, `@cheap`
//! locals, `.directives`, `:+`/`:-` unnamed-label references, `::` scope
//! separators; and what ca65's `.feature`s change in them
//! ([`LexFeatures`]).

use crate::diag::Span;
use crate::intern::{Interner, Keyword, NameId};

/// The `.feature`s that change how a line is read.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct LexFeatures {
    /// `@` inside names.
    pub(crate) at_in_identifiers: bool,
    /// `$` inside names.
    pub(crate) dollar_in_identifiers: bool,
    /// `.name` that is no directive is a name.
    pub(crate) leading_dot_in_identifiers: bool,
    /// `_` between digits is ignored.
    pub(crate) underline_in_numbers: bool,
    /// `/* ... */` comments, across lines too.
    pub(crate) c_comments: bool,
    /// `'text'` is a string too.
    pub(crate) loose_string_term: bool,
    /// `'a` without its closing quote is a character.
    pub(crate) missing_char_term: bool,
    /// `\n`, `\t`, `\r`, `\\`, `\"`, `\'`, `\xHH` in strings.
    pub(crate) string_escapes: bool,
    /// `$` alone is the program counter.
    pub(crate) dollar_is_pc: bool,
    /// `[` and `]` are parentheses (indirect addressing).
    pub(crate) bracket_as_indirect: bool,
    /// `\` at the end of a line joins the next one.
    pub(crate) line_continuations: bool,
}

/// A string token's `value`: its text has escapes to decode.
pub(crate) const STRING_ESCAPED: u64 = 1;

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
    /// The switches in force for the next line.
    pub(crate) features: LexFeatures,
    /// Inside a `/* */` comment that began on an earlier line (where).
    in_comment: bool,
    comment_start: usize,
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
            features: LexFeatures::default(),
            in_comment: false,
            comment_start: 0,
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
        let f = self.features;
        let ident_char = |b: u8| {
            is_ident_char(b)
                || (f.at_in_identifiers && b == b'@')
                || (f.dollar_in_identifiers && b == b'$')
        };
        let line_start = self.pos;
        let mut line_end = memchr_newline(text, self.pos);
        let mut end = line_end;
        if end > line_start && text[end - 1] == b'\r' {
            end -= 1;
        }
        self.pos = line_end + 1;
        let mut i = line_start;
        loop {
            if self.in_comment {
                match find(text, i, end, b"*/") {
                    Some(close) => {
                        self.in_comment = false;
                        i = close + 2;
                    }
                    None => i = end,
                }
            }
            let mut continued = false;
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
                    b'/' if f.c_comments && text.get(i + 1) == Some(&b'*') && i + 1 < end => {
                        match find(text, i + 2, end, b"*/") {
                            Some(close) => i = close + 2,
                            None => {
                                self.in_comment = true;
                                self.comment_start = i;
                                i = end;
                            }
                        }
                        continue;
                    }
                    b'\\'
                        if f.line_continuations
                            && text[i + 1..end].iter().all(|b| matches!(b, b' ' | b'\t')) =>
                    {
                        continued = true;
                        break;
                    }
                    b'[' if f.bracket_as_indirect => simple(Tok::LParen, 1),
                    b']' if f.bracket_as_indirect => simple(Tok::RParen, 1),
                    b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                        let mut j = i + 1;
                        while j < end && ident_char(text[j]) {
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
                        let starts =
                            |b: u8| is_ident_start(b) || (byte == b'@' && b.is_ascii_digit());
                        if j < end && starts(text[j]) {
                            while j < end && ident_char(text[j]) {
                                j += 1;
                            }
                            let id = names.intern_bytes(&text[i..j]);
                            // `.feature leading_dot_in_identifiers`: a dotted
                            // name that is no directive is a name.
                            let dotted_name = byte == b'.'
                                && f.leading_dot_in_identifiers
                                && !matches!(names.keyword(id), Keyword::Directive(_));
                            out.push(Token {
                                kind: if byte == b'@' {
                                    Tok::Local
                                } else if dotted_name {
                                    Tok::Ident
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
                        match number(&digits_of(&text[i..j], f.underline_in_numbers)) {
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
                    b'$' if f.dollar_is_pc
                        && !text[i + 1..end].first().is_some_and(u8::is_ascii_hexdigit) =>
                    {
                        simple(Tok::Star, 1)
                    }
                    b'$' | b'%' => {
                        let radix = if byte == b'$' { 16 } else { 2 };
                        let mut j = i + 1;
                        while j < end && is_ident_char(text[j]) {
                            j += 1;
                        }
                        let digits = digits_of(&text[i + 1..j], f.underline_in_numbers);
                        match digits_value(&digits, radix) {
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
                        let close = closing_quote(text, i + 1, end, b'"', f.string_escapes);
                        match close {
                            Some(close) => {
                                let j = close + 1;
                                let escaped =
                                    f.string_escapes && text[i + 1..close].contains(&b'\\');
                                out.push(Token {
                                    kind: Tok::Str,
                                    span: self.span(i, j),
                                    value: if escaped { STRING_ESCAPED } else { 0 },
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
                    // `.feature loose_string_term`: 'text' is a string.
                    b'\''
                        if f.loose_string_term
                            && char_constant(&text[i + 1..end]).is_none()
                            && closing_quote(text, i + 1, end, b'\'', f.string_escapes)
                                .is_some() =>
                    {
                        let close =
                            closing_quote(text, i + 1, end, b'\'', f.string_escapes).unwrap_or(end);
                        let escaped = f.string_escapes && text[i + 1..close].contains(&b'\\');
                        out.push(Token {
                            kind: Tok::Str,
                            span: self.span(i, close + 1),
                            value: if escaped { STRING_ESCAPED } else { 0 },
                        });
                        i = close + 1;
                        continue;
                    }
                    // `.feature missing_char_term`: 'a with no closing quote.
                    b'\''
                        if f.missing_char_term
                            && char_constant(&text[i + 1..end]).is_none()
                            && text.get(i + 1).is_some_and(|b| b.is_ascii() && *b != b'\'')
                            && i + 1 < end =>
                    {
                        out.push(Token {
                            kind: Tok::Char,
                            span: self.span(i, i + 2),
                            value: u64::from(text[i + 1]),
                        });
                        i += 2;
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
            // A `/*` comment still open at the end of the file.
            if self.in_comment && self.pos >= text.len() {
                self.in_comment = false;
                let start = self.comment_start;
                errors.push((
                    self.span(start, (start + 2).min(text.len())),
                    "this `/*` comment has no `*/` before the end of the file".to_string(),
                ));
            }
            // `\` at the end: the next physical line goes on this one.
            if !continued || self.pos >= text.len() {
                break;
            }
            self.line += 1;
            i = self.pos;
            line_end = memchr_newline(text, self.pos);
            end = line_end;
            if end > i && text[end - 1] == b'\r' {
                end -= 1;
            }
            self.pos = line_end + 1;
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

/// Where `needle` starts in `text[from..to]`, if it does.
fn find(text: &[u8], from: usize, to: usize, needle: &[u8]) -> Option<usize> {
    text.get(from..to)?
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|at| from + at)
}

/// The closing `quote` of a string or character whose text starts at
/// `from`, skipping `\`-escaped characters when `escapes`.
fn closing_quote(text: &[u8], from: usize, to: usize, quote: u8, escapes: bool) -> Option<usize> {
    let mut i = from;
    while i < to {
        match text[i] {
            b'\\' if escapes => i += 2,
            b if b == quote => return Some(i),
            _ => i += 1,
        }
    }
    None
}

/// A number's digits, without the `_`s that `.feature
/// underline_in_numbers` allows between them.
fn digits_of(digits: &[u8], underline: bool) -> std::borrow::Cow<'_, [u8]> {
    if underline && digits.contains(&b'_') {
        std::borrow::Cow::Owned(digits.iter().copied().filter(|b| *b != b'_').collect())
    } else {
        std::borrow::Cow::Borrowed(digits)
    }
}

/// A string's bytes with its escapes decoded (`.feature string_escapes`):
/// `\n` `\r` `\t` `\\` `\"` `\'` and `\xHH`; another escaped character stands
/// for itself.
pub(crate) fn unescape(raw: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(raw.len());
    let mut i = 0;
    while i < raw.len() {
        if raw[i] != b'\\' || i + 1 >= raw.len() {
            out.push(raw[i]);
            i += 1;
            continue;
        }
        let next = raw[i + 1];
        i += 2;
        match next {
            b'n' => out.push(b'\n'),
            b'r' => out.push(b'\r'),
            b't' => out.push(b'\t'),
            b'x' => {
                let hex: Vec<u8> = raw[i..]
                    .iter()
                    .take(2)
                    .take_while(|b| b.is_ascii_hexdigit())
                    .copied()
                    .collect();
                let value = std::str::from_utf8(&hex)
                    .ok()
                    .and_then(|h| u8::from_str_radix(h, 16).ok());
                match value {
                    Some(value) => {
                        out.push(value);
                        i += hex.len();
                    }
                    None => out.push(b'x'),
                }
            }
            other => out.push(other),
        }
    }
    out
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
