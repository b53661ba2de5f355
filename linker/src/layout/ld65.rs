//! ld65 configurations as layouts (`--target FILE.cfg`): `MEMORY`,
//! `SEGMENTS`, `SYMBOLS`, `FEATURES` (`CONDES`, `STARTADDRESS`), `FILES`
//! and `FORMATS`, read as ld65 2.19 reads them, so a ca65 project links
//! with its own configuration. Errors name the file, line and column.
//!
//! What ld65 evaluates late stays late: an area's `start` and `size` may
//! name symbols (`__HEADER_LAST__`, `__HIMEM__ - __MAIN_START__`, `%S`),
//! kept as [`Expr`]s and evaluated when placement reaches the area.

use std::ops::Range;
use std::sync::Arc;

use miette::{NamedSource, SourceSpan};

use super::expr::{Expr, Op};
use super::{
    Area, CondesKind, CondesTable, Layout, LayoutSymbol, OutputFormat, Segment, SegmentKind,
    SymbolKind,
};
use crate::error::Error;

/// ld65's start address when neither `-S`/`--start` nor `STARTADDRESS`
/// gives one.
const DEFAULT_START_ADDRESS: u64 = 0x200;

/// The name `%S` takes in layout expressions.
pub(crate) const START_ADDRESS_SYMBOL: &str = "%S";

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Number(i64),
    Str(String),
    /// `%O`: the output file's name.
    OutputName,
    /// `%S`: the start address.
    StartAddress,
    Punct(char),
}

#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    span: Range<usize>,
}

struct Reader<'a> {
    path: &'a str,
    text: &'a str,
    tokens: Vec<Token>,
    pos: usize,
}

type R<T> = Result<T, Error>;

/// Where a segment's name, `load` and `run` are in the file.
type SegmentSpans = (Range<usize>, Range<usize>, Option<Range<usize>>);

fn syntax(path: &str, text: &str, message: String, span: Range<usize>) -> Error {
    Error::LayoutSyntax {
        path: path.to_owned(),
        message,
        src: Some(Arc::new(NamedSource::new(path, text.to_owned()))),
        span: Some(SourceSpan::from(span)),
    }
}

fn lex(path: &str, text: &str) -> R<Vec<Token>> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        let tok = match c {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            _ if c.is_ascii_whitespace() => {
                i += 1;
                continue;
            }
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
                    i += 1;
                }
                if bytes.get(i) != Some(&b'"') {
                    return Err(syntax(
                        path,
                        text,
                        "this string is not closed on its line".into(),
                        start..i,
                    ));
                }
                i += 1;
                Tok::Str(text[start + 1..i - 1].to_owned())
            }
            b'%' if matches!(bytes.get(i + 1), Some(b'O' | b'S')) => {
                i += 2;
                if bytes[start + 1] == b'O' {
                    Tok::OutputName
                } else {
                    Tok::StartAddress
                }
            }
            b'$' | b'%' | b'0'..=b'9' => {
                let radix = match c {
                    b'$' => 16,
                    b'%' => 2,
                    _ => 10,
                };
                if radix != 10 {
                    i += 1;
                }
                let digits = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let value = i64::from_str_radix(&text[digits..i], radix)
                    .ok()
                    .filter(|_| i > digits)
                    .ok_or_else(|| {
                        syntax(
                            path,
                            text,
                            format!("`{}` is not a number", &text[start..i]),
                            start..i.max(start + 1),
                        )
                    })?;
                Tok::Number(value)
            }
            _ if c.is_ascii_alphabetic() || c == b'_' => {
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                Tok::Ident(text[start..i].to_owned())
            }
            b'{' | b'}' | b':' | b';' | b',' | b'=' | b'+' | b'-' | b'*' | b'/' | b'(' | b')' => {
                i += 1;
                Tok::Punct(c as char)
            }
            _ => {
                let len = text[start..].chars().next().map_or(1, char::len_utf8);
                return Err(syntax(
                    path,
                    text,
                    format!(
                        "unexpected `{}` in an ld65 configuration",
                        &text[start..start + len]
                    ),
                    start..start + len,
                ));
            }
        };
        tokens.push(Token {
            tok,
            span: start..i,
        });
    }
    Ok(tokens)
}

impl Reader<'_> {
    fn error(&self, message: impl Into<String>, span: Range<usize>) -> Error {
        syntax(self.path, self.text, message.into(), span)
    }

    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    /// The span of the next token, or the end of the file.
    fn here(&self) -> Range<usize> {
        self.peek()
            .map_or(self.text.len()..self.text.len(), |t| t.span.clone())
    }

    fn next(&mut self, what: &str) -> R<Token> {
        let token = self.peek().cloned().ok_or_else(|| {
            self.error(
                format!("expected {what}, found the end of the file"),
                self.here(),
            )
        })?;
        self.pos += 1;
        Ok(token)
    }

    fn is(&self, c: char) -> bool {
        matches!(self.peek(), Some(Token { tok: Tok::Punct(p), .. }) if *p == c)
    }

    fn expect(&mut self, c: char) -> R<Range<usize>> {
        if self.is(c) {
            return Ok(self.next("")?.span);
        }
        let found = self.describe();
        Err(self.error(format!("expected `{c}`, found {found}"), self.here()))
    }

    fn describe(&self) -> String {
        match self.peek().map(|t| &t.tok) {
            None => "the end of the file".into(),
            Some(Tok::Ident(name)) => format!("`{name}`"),
            Some(Tok::Number(value)) => format!("the number {value}"),
            Some(Tok::Str(text)) => format!("the string \"{text}\""),
            Some(Tok::OutputName) => "`%O`".into(),
            Some(Tok::StartAddress) => "`%S`".into(),
            Some(Tok::Punct(c)) => format!("`{c}`"),
        }
    }

    fn ident(&mut self, what: &str) -> R<(String, Range<usize>)> {
        match self.peek().cloned() {
            Some(Token {
                tok: Tok::Ident(name),
                span,
            }) => {
                self.pos += 1;
                Ok((name, span))
            }
            _ => {
                let found = self.describe();
                Err(self.error(format!("expected {what}, found {found}"), self.here()))
            }
        }
    }

    fn expr(&mut self) -> R<Expr> {
        let mut left = self.term()?;
        while self.is('+') || self.is('-') {
            let op = if self.is('+') { Op::Add } else { Op::Sub };
            self.pos += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.term()?));
        }
        Ok(left)
    }

    fn term(&mut self) -> R<Expr> {
        let mut left = self.factor()?;
        while self.is('*') || self.is('/') {
            let op = if self.is('*') { Op::Mul } else { Op::Div };
            self.pos += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.factor()?));
        }
        Ok(left)
    }

    fn factor(&mut self) -> R<Expr> {
        let found = self.describe();
        let token = self.next("an expression")?;
        Ok(match token.tok {
            Tok::Number(value) => Expr::Number(value),
            Tok::Ident(name) => Expr::Symbol(name, token.span),
            Tok::StartAddress => Expr::Symbol(START_ADDRESS_SYMBOL.into(), token.span),
            Tok::Punct('-') => Expr::Neg(Box::new(self.factor()?)),
            Tok::Punct('+') => self.factor()?,
            Tok::Punct('(') => {
                let inner = self.expr()?;
                self.expect(')')?;
                inner
            }
            _ => {
                return Err(self.error(
                    format!("expected a number, a symbol or `%S`, found {found}"),
                    token.span,
                ));
            }
        })
    }

    /// `yes`/`no` (ld65 also takes `true`/`false`).
    fn boolean(&mut self) -> R<bool> {
        let (word, span) = self.ident("`yes` or `no`")?;
        match word.to_ascii_lowercase().as_str() {
            "yes" | "true" => Ok(true),
            "no" | "false" => Ok(false),
            _ => Err(self.error(format!("expected `yes` or `no`, found `{word}`"), span)),
        }
    }

    /// A constant expression that fits `max`.
    fn constant(&mut self, what: &str, max: u64) -> R<u64> {
        let start = self.here().start;
        let expr = self.expr()?;
        let span = start..self.tokens[self.pos - 1].span.end;
        let value = expr.constant().ok_or_else(|| {
            self.error(
                format!("{what} must be a number here, not an expression of symbols"),
                span.clone(),
            )
        })?;
        u64::try_from(value)
            .ok()
            .filter(|value| *value <= max)
            .ok_or_else(|| {
                self.error(
                    format!("{what} {value:#X} is out of range (0 to {max:#X})"),
                    span,
                )
            })
    }

    /// `name: attr = value, attr = value ...;` items until `}`; `attrs`
    /// reads one attribute's value.
    fn items(&mut self, mut item: impl FnMut(&mut Self, Token) -> R<()>) -> R<()> {
        self.expect('{')?;
        while !self.is('}') {
            let name = self.next("a name or `}`")?;
            self.expect(':')?;
            item(self, name)?;
        }
        self.expect('}')?;
        Ok(())
    }

    /// The attributes of one item up to its `;`: `(name, span)` handed to
    /// `attr`, which reads the value after `=`. Commas between them are
    /// optional, as ld65's.
    fn attributes(
        &mut self,
        mut attr: impl FnMut(&mut Self, &str, Range<usize>) -> R<()>,
    ) -> R<()> {
        let mut seen: Vec<String> = Vec::new();
        loop {
            if self.is(';') {
                self.pos += 1;
                return Ok(());
            }
            let (name, span) = self.ident("an attribute name or `;`")?;
            let lower = name.to_ascii_lowercase();
            // The Atari format may name an init routine for several areas.
            if seen.contains(&lower) && lower != "initad" {
                return Err(self.error(format!("`{name}` is given twice"), span));
            }
            seen.push(lower.clone());
            self.expect('=')?;
            attr(self, &lower, span)?;
            if self.is(',') {
                self.pos += 1;
            }
        }
    }
}

#[derive(Default)]
struct AreaAttrs {
    start: Option<Expr>,
    size: Option<Expr>,
    file: Option<Option<String>>,
    define: bool,
    fill: bool,
    fill_value: Option<u8>,
}

/// Reads an ld65 configuration; `start` is `--start` (ld65's `-S`), which
/// `%S` takes before `STARTADDRESS`'s default.
pub(super) fn parse(path: &str, text: &str, start: Option<u64>) -> R<Layout> {
    let mut r = Reader {
        path,
        text,
        tokens: lex(path, text)?,
        pos: 0,
    };
    let mut layout = Layout {
        name: path.to_owned(),
        areas: Vec::new(),
        segments: Vec::new(),
        ld65_alignment: true,
        config: super::Config {
            source: Some(Arc::from(text)),
            ld65: true,
            ..super::Config::default()
        },
    };
    let mut start_default = None;
    let mut area_spans: Vec<Range<usize>> = Vec::new();
    let mut segment_spans: Vec<SegmentSpans> = Vec::new();
    while r.peek().is_some() {
        let (section, span) = r.ident("MEMORY, SEGMENTS, SYMBOLS, FEATURES, FILES or FORMATS")?;
        match section.to_ascii_uppercase().as_str() {
            "MEMORY" => r.items(|r, name| {
                let Tok::Ident(name_text) = name.tok else {
                    return Err(r.error("expected a memory area's name", name.span));
                };
                if layout.areas.iter().any(|a| a.name == name_text) {
                    return Err(r.error(format!("memory area {name_text} is defined twice"), name.span));
                }
                let mut attrs = AreaAttrs::default();
                r.attributes(|r, attr, span| {
                    match attr {
                        "start" => attrs.start = Some(r.expr()?),
                        "size" => attrs.size = Some(r.expr()?),
                        "type" => {
                            let (kind, span) = r.ident("`ro` or `rw`")?;
                            if !matches!(kind.as_str(), "ro" | "rw") {
                                return Err(r.error(format!("a memory area's type is `ro` or `rw`, not `{kind}`"), span));
                            }
                        }
                        "file" => {
                            let found = r.describe();
                            let token = r.next("a file name")?;
                            attrs.file = Some(match token.tok {
                                Tok::OutputName => Some("%O".into()),
                                Tok::Str(name) if name.is_empty() => None,
                                Tok::Str(name) => Some(name),
                                _ => return Err(r.error(format!("expected a file name in quotes or %O, found {found}"), token.span)),
                            });
                        }
                        "define" => attrs.define = r.boolean()?,
                        "fill" => attrs.fill = r.boolean()?,
                        "fillval" => attrs.fill_value = Some(r.constant("fillval", 0xFF)? as u8),
                        "bank" => {
                            r.expr()?;
                        }
                        _ => return Err(r.error(format!("`{attr}` is not an attribute of a memory area (start, size, type, file, define, fill, fillval, bank)"), span)),
                    }
                    Ok(())
                })?;
                let Some(start) = attrs.start else {
                    return Err(r.error(format!("memory area {name_text} has no `start`"), name.span));
                };
                let Some(size) = attrs.size else {
                    return Err(r.error(format!("memory area {name_text} has no `size`"), name.span));
                };
                let file = attrs.file.unwrap_or_else(|| Some("%O".into()));
                let (start_value, size_value) = (start.constant(), size.constant());
                let deferred = start_value.is_none() || size_value.is_none();
                layout.areas.push(Area {
                    name: name_text,
                    start: start_value.and_then(|v| u64::try_from(v).ok()).unwrap_or(0),
                    size: size_value.and_then(|v| u64::try_from(v).ok()).unwrap_or(1),
                    fill: attrs.fill,
                    fill_value: attrs.fill_value.unwrap_or(0),
                    output: file.is_some(),
                    define: attrs.define,
                    file: file.filter(|f| f != "%O"),
                    exprs: deferred.then_some((start, size)),
                });
                area_spans.push(name.span);
                Ok(())
            })?,
            "SEGMENTS" => r.items(|r, name| {
                let Tok::Ident(name_text) = name.tok else {
                    return Err(r.error("expected a segment's name", name.span));
                };
                if layout.segments.iter().any(|s| s.name == name_text) {
                    return Err(r.error(format!("segment {name_text} is defined twice"), name.span));
                }
                let mut segment = Segment::new(&name_text, "", SegmentKind::ReadOnly);
                segment.optional = false;
                let mut load_span = None;
                let mut run_span = None;
                let mut kind = None;
                r.attributes(|r, attr, span| {
                    match attr {
                        "load" => {
                            let (area, span) = r.ident("a memory area")?;
                            segment.load = area;
                            load_span = Some(span);
                        }
                        "run" => {
                            let (area, span) = r.ident("a memory area")?;
                            segment.run = Some(area);
                            run_span = Some(span);
                        }
                        "type" => {
                            let (word, span) = r.ident("ro, rw, bss or zp")?;
                            kind = Some(match word.as_str() {
                                "ro" => SegmentKind::ReadOnly,
                                "rw" => SegmentKind::ReadWrite,
                                "bss" => SegmentKind::Bss,
                                "zp" => SegmentKind::ZeroPage,
                                "overwrite" => return Err(r.error("`type = overwrite` segments are not supported: this linker never lets one segment write over another", span)),
                                _ => return Err(r.error(format!("a segment's type is ro, rw, bss or zp, not `{word}`"), span)),
                            });
                        }
                        "align" => segment.align = Some(alignment(r, "align")?),
                        "align_load" => segment.align_load = Some(alignment(r, "align_load")?),
                        "start" => segment.start = Some(r.constant("start", 0xFFFF_FFFF)?),
                        "offset" => segment.offset = Some(r.constant("offset", 0xFFFF_FFFF)?),
                        "optional" => segment.optional = r.boolean()?,
                        "define" => segment.define = r.boolean()?,
                        "fillval" => {
                            r.constant("fillval", 0xFF)?;
                        }
                        _ => return Err(r.error(format!("`{attr}` is not an attribute of a segment (load, run, type, align, align_load, start, offset, optional, define, fillval)"), span)),
                    }
                    Ok(())
                })?;
                if load_span.is_none() {
                    return Err(r.error(format!("segment {name_text} has no `load`"), name.span));
                }
                // ld65's default type.
                segment.kind = kind.unwrap_or(SegmentKind::ReadOnly);
                segment_spans.push((name.span, load_span.unwrap_or_default(), run_span));
                layout.segments.push(segment);
                Ok(())
            })?,
            "SYMBOLS" => r.items(|r, name| {
                let Tok::Ident(name_text) = name.tok else {
                    return Err(r.error("expected a symbol's name", name.span));
                };
                let mut kind = SymbolKind::Export;
                let mut value = None;
                r.attributes(|r, attr, span| {
                    match attr {
                        "type" => {
                            let (word, span) = r.ident("export, import or weak")?;
                            kind = match word.as_str() {
                                "export" => SymbolKind::Export,
                                "import" => SymbolKind::Import,
                                "weak" => SymbolKind::Weak,
                                _ => return Err(r.error(format!("a symbol's type is export, import or weak, not `{word}`"), span)),
                            };
                        }
                        "value" => value = Some(r.expr()?),
                        // Checked, not kept: a value's size does not change
                        // where the linker puts anything.
                        "addrsize" => {
                            let (word, span) = r.ident("an address size")?;
                            if !matches!(word.as_str(), "zp" | "zeropage" | "direct" | "abs" | "absolute" | "near") {
                                return Err(r.error(format!("`{word}` is not an address size of the 6502 (zp or abs)"), span));
                            }
                        }
                        _ => return Err(r.error(format!("`{attr}` is not an attribute of a symbol (type, value, addrsize)"), span)),
                    }
                    Ok(())
                })?;
                match (kind, &value) {
                    (SymbolKind::Import, Some(_)) => {
                        return Err(r.error(format!("{name_text} is imported and cannot have a value"), name.span));
                    }
                    (SymbolKind::Export | SymbolKind::Weak, None) => {
                        return Err(r.error(format!("{name_text} needs a `value`"), name.span));
                    }
                    _ => {}
                }
                layout.config.symbols.push(LayoutSymbol {
                    name: name_text,
                    kind,
                    value,
                    span: name.span,
                });
                Ok(())
            })?,
            "FEATURES" => r.items(|r, name| {
                let Tok::Ident(feature) = name.tok else {
                    return Err(r.error("expected a feature's name", name.span));
                };
                match feature.to_ascii_uppercase().as_str() {
                    "CONDES" => {
                        let mut kind = None;
                        let (mut label, mut count, mut segment, mut import) = (None, None, None, None);
                        let mut increasing = true;
                        r.attributes(|r, attr, span| {
                            match attr {
                                "type" => {
                                    kind = Some(if let Some(Token { tok: Tok::Number(n), span }) = r.peek().cloned() {
                                        r.pos += 1;
                                        let n = u8::try_from(n).ok().filter(|n| *n <= 6).ok_or_else(|| r.error("a table type is 0 to 6", span))?;
                                        CondesKind::from_number(n)
                                    } else {
                                        let (word, span) = r.ident("constructor, destructor or interruptor")?;
                                        match word.as_str() {
                                            "constructor" => CondesKind::Constructor,
                                            "destructor" => CondesKind::Destructor,
                                            "interruptor" => CondesKind::Interruptor,
                                            _ => return Err(r.error(format!("a table's type is constructor, destructor, interruptor or a number, not `{word}`"), span)),
                                        }
                                    });
                                }
                                "label" => label = Some(r.ident("a symbol")?.0),
                                "count" => count = Some(r.ident("a symbol")?.0),
                                "segment" => segment = Some(r.ident("a segment")?),
                                "import" => import = Some(r.ident("a symbol")?.0),
                                "order" => {
                                    let (word, span) = r.ident("increasing or decreasing")?;
                                    increasing = match word.as_str() {
                                        "increasing" => true,
                                        "decreasing" => false,
                                        _ => return Err(r.error(format!("order is increasing or decreasing, not `{word}`"), span)),
                                    };
                                }
                                _ => return Err(r.error(format!("`{attr}` is not an attribute of CONDES (type, label, count, segment, order, import)"), span)),
                            }
                            Ok(())
                        })?;
                        let missing = |what: &str| r.error(format!("CONDES needs `{what}`"), name.span.clone());
                        let (segment, segment_span) = segment.ok_or_else(|| missing("segment"))?;
                        layout.config.tables.push(CondesTable {
                            kind: kind.ok_or_else(|| missing("type"))?,
                            label: label.ok_or_else(|| missing("label"))?,
                            count,
                            segment,
                            segment_span,
                            increasing,
                            import,
                        });
                    }
                    "STARTADDRESS" => r.attributes(|r, attr, span| {
                        if attr != "default" {
                            return Err(r.error(format!("`{attr}` is not an attribute of STARTADDRESS (default)"), span));
                        }
                        start_default = Some(r.constant("default", 0xFFFF_FFFF)?);
                        Ok(())
                    })?,
                    _ => return Err(r.error(format!("`{feature}` is not a feature of ld65 2.19 (CONDES, STARTADDRESS)"), name.span)),
                }
                Ok(())
            })?,
            "FILES" => r.items(|r, name| {
                let file = match name.tok {
                    Tok::OutputName => "%O".to_owned(),
                    Tok::Str(file) => file,
                    _ => return Err(r.error("expected a file name in quotes or %O", name.span)),
                };
                r.attributes(|r, attr, span| {
                    if attr != "format" {
                        return Err(r.error(format!("`{attr}` is not an attribute of a file (format)"), span));
                    }
                    let (word, span) = r.ident("a format")?;
                    let format = match word.as_str() {
                        "bin" | "binary" => OutputFormat::Bin,
                        "atari" => OutputFormat::Atari,
                        "o65" => {
                            return Err(r.error(
                                "the o65 format is not supported: this linker writes absolute images (format = bin or atari); link for a fixed address instead",
                                span,
                            ));
                        }
                        _ => return Err(r.error(format!("`{word}` is not an output format of ld65 2.19 (bin, o65, atari)"), span)),
                    };
                    layout.config.formats.push((file.clone(), format, span));
                    Ok(())
                })
            })?,
            "FORMATS" => r.items(|r, name| {
                let format = match &name.tok {
                    Tok::Ident(format) => format.clone(),
                    _ => return Err(r.error("expected a format's name", name.span)),
                };
                r.attributes(|r, attr, span| {
                    match (format.as_str(), attr) {
                        // The Atari executable's run and init addresses:
                        // `runad = symbol`, `initad = AREA: symbol`.
                        ("atari", "runad") => {
                            let (symbol, span) = r.ident("a symbol")?;
                            layout.config.atari.runad = Some((symbol, span));
                        }
                        ("atari", "initad") => {
                            let (area, _) = r.ident("a memory area")?;
                            r.expect(':')?;
                            let (symbol, span) = r.ident("a symbol")?;
                            layout.config.atari.initad.push((area, symbol, span));
                        }
                        ("atari", _) => {
                            return Err(r.error(format!("`{attr}` is not an option of the atari format (runad, initad)"), span));
                        }
                        // o65's options: read for their syntax; FILES
                        // refuses the format.
                        _ => {
                            let found = r.describe();
                            match r.next("a value")?.tok {
                                Tok::Ident(_) | Tok::Number(_) | Tok::Str(_) => {}
                                _ => return Err(r.error(format!("expected a value, found {found}"), r.tokens[r.pos - 1].span.clone())),
                            }
                        }
                    }
                    Ok(())
                })
            })?,
            _ => {
                return Err(r.error(
                    format!("`{section}` is not a section of an ld65 configuration (MEMORY, SEGMENTS, SYMBOLS, FEATURES, FILES, FORMATS)"),
                    span,
                ));
            }
        }
    }
    // References, with the place that makes them.
    for (segment, (name_span, load_span, run_span)) in layout.segments.iter().zip(&segment_spans) {
        for (area, span) in [
            (segment.load.as_str(), Some(load_span)),
            (segment.run_area(), run_span.as_ref()),
        ] {
            if !layout.areas.iter().any(|a| a.name == *area) {
                let span = span.unwrap_or(name_span).clone();
                return Err(r.error(
                    format!(
                        "segment {} names memory area {area}, which MEMORY does not define (areas: {})",
                        segment.name,
                        layout.areas.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", ")
                    ),
                    span,
                ));
            }
        }
    }
    for (area, span) in layout.areas.iter().zip(&area_spans) {
        if area.exprs.is_none() && area.size == 0 {
            return Err(r.error(
                format!("memory area {} has size 0", area.name),
                span.clone(),
            ));
        }
    }
    layout.config.start_address = start.or(start_default).unwrap_or(DEFAULT_START_ADDRESS);
    layout.validate()?;
    Ok(layout)
}

/// An alignment: ld65 takes any from 1 (GEOS's VLIR records align to 254).
fn alignment(r: &mut Reader<'_>, what: &str) -> R<u64> {
    let span = r.here();
    let value = r.constant(what, 1 << 24)?;
    if value == 0 {
        return Err(r.error(format!("{what} must be at least 1"), span));
    }
    Ok(value)
}
