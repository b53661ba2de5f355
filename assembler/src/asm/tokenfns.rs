//! ca65's token functions, which make tokens rather than values and so are
//! expanded in the line before it is read: `.left`, `.mid`, `.right` (parts
//! of a token list), `.concat`, `.string`, `.sprintf` (strings) and
//! `.ident` (a name from a string). The innermost call goes first, so they
//! nest (`.ident(.concat("lab", "el"))`). Strings they make live in a small
//! generated source, so diagnostics can still quote them.

use std::sync::Arc;

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag::Span;
use crate::intern::{Dir, Keyword};
use crate::lexer::{Lexer, Tok, Token};

/// Most token-function calls expanded in one line: the guard against a
/// runaway expansion.
const MAX_CALLS: usize = 256;

/// The widest `.sprintf` field (a string is at most a line).
const MAX_WIDTH: usize = 1024;

impl Asm<'_> {
    /// The token function `tok` names, if any.
    fn token_function(&self, tok: &Token) -> Option<Dir> {
        if tok.kind != Tok::Directive {
            return None;
        }
        match self.names.keyword(tok.name()) {
            Keyword::Directive(
                dir @ (Dir::Left
                | Dir::Mid
                | Dir::Right
                | Dir::Concat
                | Dir::String
                | Dir::Ident
                | Dir::Sprintf),
            ) => Some(dir),
            _ => None,
        }
    }

    /// Whether the current line calls a token function.
    pub(crate) fn has_token_functions(&self) -> bool {
        let toks = &self.input.toks;
        toks.windows(2)
            .any(|w| w[1].kind == Tok::LParen && self.token_function(&w[0]).is_some())
    }

    /// Expands every token function in the current line, innermost first.
    pub(crate) fn expand_token_functions(&mut self) -> PResult<()> {
        for _ in 0..MAX_CALLS {
            let toks = &self.input.toks;
            // The last call whose `(` follows it is one without calls in
            // its arguments.
            let Some(at) = (0..toks.len().saturating_sub(1)).rev().find(|&i| {
                toks[i + 1].kind == Tok::LParen && self.token_function(&toks[i]).is_some()
            }) else {
                return Ok(());
            };
            let dir = self.token_function(&toks[at]).unwrap_or(Dir::Left);
            let head = toks[at];
            let lists = match dir {
                Dir::Left | Dir::Right => Some(1),
                Dir::Mid => Some(2),
                _ => None,
            };
            let (args, end) = self.call_arguments(at + 1, lists)?;
            let replacement = self.call(dir, head.span, &args)?;
            self.input.toks.splice(at..end, replacement);
        }
        let span = self.input.toks.first().map(|t| t.span).unwrap_or_default();
        Err(self.err(
            "asm::too-deep",
            span,
            format!("more than {MAX_CALLS} token-function calls in one line"),
        ))
    }

    /// The arguments of the call whose `(` is at `open` (split at commas
    /// outside parentheses and braces), and the index after its `)`. The
    /// argument after `list_after` commas is a token list, read as ca65
    /// reads one: a braced list up to the first `}`, or the tokens up to
    /// the first `)`, parentheses not counted (`.left(1, (a))` is `(`).
    fn call_arguments(
        &mut self,
        open: usize,
        list_after: Option<usize>,
    ) -> PResult<(Vec<Vec<Token>>, usize)> {
        let toks = &self.input.toks;
        let mut args = vec![Vec::new()];
        let mut depth = 0usize;
        let mut i = open + 1;
        while let Some(&tok) = toks.get(i) {
            let at_list = depth == 0
                && Some(args.len() - 1) == list_after
                && args.last().is_some_and(Vec::is_empty);
            if at_list {
                let (list, next) = raw_list(toks, i, Tok::RParen);
                if toks.get(next).map(|t| t.kind) == Some(Tok::RParen) {
                    if let Some(last) = args.last_mut() {
                        *last = list;
                    }
                    return Ok((args, next + 1));
                }
                // Something other than `)` after a braced list: read on
                // as other arguments (an arity error follows).
            }
            match tok.kind {
                Tok::LParen | Tok::LBrace => depth += 1,
                Tok::RParen if depth == 0 => return Ok((args, i + 1)),
                Tok::RParen | Tok::RBrace => depth = depth.saturating_sub(1),
                Tok::Comma if depth == 0 => {
                    args.push(Vec::new());
                    i += 1;
                    continue;
                }
                _ => {}
            }
            if let Some(last) = args.last_mut() {
                last.push(tok);
            }
            i += 1;
        }
        let span = toks[open].span;
        Err(self.err("asm::syntax", span, "this `(` has no `)`"))
    }

    /// One call's tokens.
    fn call(&mut self, dir: Dir, span: Span, args: &[Vec<Token>]) -> PResult<Vec<Token>> {
        let want = |n: usize| -> Option<&'static str> {
            (args.len() != n).then_some(match n {
                1 => "one argument",
                2 => "two arguments",
                _ => "three arguments",
            })
        };
        let name = dir_name(dir);
        let arity = match dir {
            Dir::Left | Dir::Right => want(2),
            Dir::Mid => want(3),
            Dir::String | Dir::Ident => want(1),
            _ => None,
        };
        if let Some(expected) = arity {
            return Err(self.err(
                "asm::syntax",
                span,
                format!("`.{name}` takes {expected}, not {}", args.len()),
            ));
        }
        Ok(match dir {
            Dir::Left => {
                let count = self.count_arg(&args[0], span)?;
                let list = braced(&args[1]);
                list[..count.min(list.len())].to_vec()
            }
            Dir::Right => {
                let count = self.count_arg(&args[0], span)?;
                let list = braced(&args[1]);
                list[list.len() - count.min(list.len())..].to_vec()
            }
            Dir::Mid => {
                let start = self.count_arg(&args[0], span)?;
                let count = self.count_arg(&args[1], span)?;
                let list = braced(&args[2]);
                let start = start.min(list.len());
                list[start..(start + count).min(list.len())].to_vec()
            }
            Dir::Concat => {
                let mut text = Vec::new();
                for arg in args {
                    text.extend(self.string_arg(arg, name, span)?);
                }
                vec![self.generated_string(&text, span)]
            }
            // A name's text, or a constant's value in decimal, as ca65's.
            Dir::String => {
                let text = match braced(&args[0]) {
                    [tok] if tok.kind == Tok::Ident || tok.kind == Tok::Local => {
                        self.names.name(tok.name()).as_bytes().to_vec()
                    }
                    list => {
                        let list = list.to_vec();
                        self.constant_of(&list, span, "a name or a constant")?
                            .to_string()
                            .into_bytes()
                    }
                };
                vec![self.generated_string(&text, span)]
            }
            Dir::Ident => {
                let text = self.string_arg(&args[0], name, span)?;
                let valid = text
                    .first()
                    .is_some_and(|b| b.is_ascii_alphabetic() || *b == b'_' || *b == b'@')
                    && text[1..]
                        .iter()
                        .all(|b| b.is_ascii_alphanumeric() || *b == b'_');
                if !valid {
                    return Err(self.err(
                        "asm::syntax",
                        span,
                        format!(
                            "`.ident` needs a string that is a name, not \"{}\"",
                            String::from_utf8_lossy(&text)
                        ),
                    ));
                }
                let id = self.names.intern_bytes(&text);
                let kind = if text[0] == b'@' {
                    Tok::Local
                } else {
                    Tok::Ident
                };
                vec![Token {
                    kind,
                    span,
                    value: u64::from(id),
                }]
            }
            _ => {
                let text = self.sprintf(args, span)?;
                vec![self.generated_string(&text, span)]
            }
        })
    }

    /// A count or position argument: a constant from 0.
    fn count_arg(&mut self, arg: &[Token], span: Span) -> PResult<usize> {
        let value = self.constant_of(arg, span, "a token count")?;
        usize::try_from(value).map_err(|_| {
            self.err(
                "asm::range",
                span,
                format!("a token count cannot be negative ({value})"),
            )
        })
    }

    /// The constant value of the tokens `arg`.
    fn constant_of(&mut self, arg: &[Token], span: Span, what: &str) -> PResult<i64> {
        if arg.is_empty() {
            return Err(self.err("asm::syntax", span, format!("expected {what}")));
        }
        let mut c = self.cursor(arg);
        let value = self.const_expr(&mut c, what)?;
        if !c.is_end() {
            let at = c.span();
            return Err(self.err(
                "asm::syntax",
                at,
                format!("expected `,` or `)` after {what}"),
            ));
        }
        Ok(value)
    }

    /// The bytes of a string argument (one string token).
    fn string_arg(&mut self, arg: &[Token], name: &str, span: Span) -> PResult<Vec<u8>> {
        match braced(arg) {
            [tok] if tok.kind == Tok::Str => Ok(self.string_bytes(tok)),
            _ => Err(self.err(
                "asm::syntax",
                arg.first().map_or(span, |t| t.span),
                format!("`.{name}` takes strings here"),
            )),
        }
    }

    /// `.sprintf(format, args...)`: `%d` `%i` `%u` `%x` `%X` `%o`
    /// (numbers, with `-`, `0` and a width), `%s` (a string), `%c` (a
    /// character code) and `%%`.
    fn sprintf(&mut self, args: &[Vec<Token>], span: Span) -> PResult<Vec<u8>> {
        let Some(format) = args.first() else {
            return Err(self.err("asm::syntax", span, "`.sprintf` needs a format string"));
        };
        let format = self.string_arg(format, "sprintf", span)?;
        let mut out = Vec::new();
        let mut next = 1;
        let mut i = 0;
        while i < format.len() {
            let byte = format[i];
            i += 1;
            if byte != b'%' {
                out.push(byte);
                continue;
            }
            let mut left = false;
            let mut zero = false;
            while let Some(flag @ (b'-' | b'0')) = format.get(i).copied() {
                left |= flag == b'-';
                zero |= flag == b'0';
                i += 1;
            }
            let mut width = 0usize;
            while let Some(digit) = format.get(i).filter(|b| b.is_ascii_digit()) {
                width = width
                    .saturating_mul(10)
                    .saturating_add(usize::from(digit - b'0'));
                i += 1;
            }
            if width > MAX_WIDTH {
                return Err(self.err(
                    "asm::range",
                    span,
                    format!("a `.sprintf` width of {width} is more than {MAX_WIDTH}"),
                ));
            }
            let Some(&conversion) = format.get(i) else {
                return Err(self.err(
                    "asm::syntax",
                    span,
                    "the format ends inside a `%` conversion",
                ));
            };
            i += 1;
            if conversion == b'%' {
                out.push(b'%');
                continue;
            }
            let Some(arg) = args.get(next) else {
                return Err(self.err(
                    "asm::syntax",
                    span,
                    format!("the format wants more than {} argument(s)", args.len() - 1),
                ));
            };
            next += 1;
            let text: Vec<u8> = match conversion {
                b's' => self.string_arg(arg, "sprintf", span)?,
                b'c' => {
                    let value = self.constant_of(arg, span, "a character code")?;
                    vec![value as u8]
                }
                b'd' | b'i' | b'u' | b'x' | b'X' | b'o' => {
                    let value = self.constant_of(arg, span, "a number")?;
                    match conversion {
                        b'x' => format!("{value:x}"),
                        b'X' => format!("{value:X}"),
                        b'o' => format!("{value:o}"),
                        _ => value.to_string(),
                    }
                    .into_bytes()
                }
                other => {
                    return Err(self.err(
                        "asm::syntax",
                        span,
                        format!(
                            "`%{}` is not a conversion `.sprintf` knows (d i u x X o s c %)",
                            other as char
                        ),
                    ));
                }
            };
            let pad = width.saturating_sub(text.len());
            let numeric = !matches!(conversion, b's' | b'c');
            if left {
                out.extend(&text);
                out.extend(std::iter::repeat_n(b' ', pad));
            } else if zero && numeric {
                let (sign, digits) = match text.first() {
                    Some(b'-') => (&text[..1], &text[1..]),
                    _ => (&text[..0], &text[..]),
                };
                out.extend(sign);
                out.extend(std::iter::repeat_n(b'0', pad));
                out.extend(digits);
            } else {
                out.extend(std::iter::repeat_n(b' ', pad));
                out.extend(&text);
            }
        }
        if next < args.len() {
            return Err(self.err(
                "asm::syntax",
                span,
                format!(
                    "the format uses {} argument(s) of {}",
                    next - 1,
                    args.len() - 1
                ),
            ));
        }
        Ok(out)
    }

    /// A string token with `text`, lexed from a generated source (one per
    /// distinct text) so that it reads like any other.
    fn generated_string(&mut self, text: &[u8], at: Span) -> Token {
        let mut quoted = Vec::with_capacity(text.len() + 2);
        quoted.push(b'"');
        quoted.extend(text.iter().map(|b| if *b == b'"' { b'\'' } else { *b }));
        quoted.push(b'"');
        let file = match self.input.generated.get(&quoted) {
            Some(file) => *file,
            None => {
                let file = self
                    .files
                    .add("<token function>".to_owned(), Arc::new(quoted.clone()));
                self.input.generated.insert(quoted.clone(), file);
                file
            }
        };
        let mut tokens = Vec::new();
        let mut errors = Vec::new();
        Lexer::new(file).next_line(&quoted, &mut self.names, &mut tokens, &mut errors);
        match tokens.as_slice() {
            [tok] if tok.kind == Tok::Str => *tok,
            _ => Token {
                kind: Tok::Str,
                span: at,
                value: 0,
            },
        }
    }

    /// `.tcount(list)`: how many tokens (braces around the list not
    /// counted).
    pub(crate) fn tcount(&mut self, c: &mut Cursor<'_>) -> PResult<i64> {
        let arg = self.one_list(c)?;
        Ok(braced(&arg).len() as i64)
    }

    /// `.match(a, b)` (`exact` false: token kinds) and `.xmatch(a, b)`
    /// (kinds and values).
    pub(crate) fn token_match(&mut self, c: &mut Cursor<'_>, exact: bool) -> PResult<bool> {
        self.expect(c, Tok::LParen, "`(`")?;
        let first = self.list_until(c, Tok::Comma)?;
        self.expect(c, Tok::Comma, "`,`")?;
        let second = self.list_until(c, Tok::RParen)?;
        self.expect(c, Tok::RParen, "`)`")?;
        let (a, b) = (braced(&first), braced(&second));
        // ca65 scans the register names as tokens of their own.
        let register = |tok: &Token| {
            (tok.kind == Tok::Ident)
                .then(|| self.names.name(tok.name()).to_ascii_lowercase())
                .filter(|name| matches!(name.as_str(), "a" | "x" | "y"))
        };
        Ok(a.len() == b.len()
            && a.iter().zip(b).all(|(x, y)| {
                let same_kind = x.kind == y.kind
                    && register(x) == register(y)
                    && (x.kind != Tok::Directive || x.value == y.value);
                let same_value = match x.kind {
                    Tok::Str => self.string_bytes(x) == self.string_bytes(y),
                    _ => x.value == y.value,
                };
                same_kind && (!exact || same_value)
            }))
    }

    /// `( list )` for `.tcount`.
    fn one_list(&mut self, c: &mut Cursor<'_>) -> PResult<Vec<Token>> {
        self.expect(c, Tok::LParen, "`(`")?;
        let list = self.list_until(c, Tok::RParen)?;
        self.expect(c, Tok::RParen, "`)`")?;
        Ok(list)
    }

    /// A token list as ca65 reads one ([`raw_list`]), the cursor left on
    /// what follows it.
    fn list_until(&mut self, c: &mut Cursor<'_>, stop: Tok) -> PResult<Vec<Token>> {
        let toks = c.tokens();
        let (list, next) = raw_list(toks, c.pos(), stop);
        c.advance_by(next.saturating_sub(c.pos()));
        Ok(list)
    }
}

/// A token list from `toks[at..]` as ca65 reads one (`GetTokListTerm`):
/// `{...}` up to the first `}` (braces kept, for [`braced`] to drop), or
/// the tokens up to the first `stop`, with no nesting of parentheses. The
/// list and the index after it.
fn raw_list(toks: &[Token], at: usize, stop: Tok) -> (Vec<Token>, usize) {
    let term = if toks.get(at).map(|t| t.kind) == Some(Tok::LBrace) {
        Tok::RBrace
    } else {
        stop
    };
    let mut i = at + usize::from(term == Tok::RBrace);
    while let Some(tok) = toks.get(i) {
        if tok.kind == term {
            break;
        }
        i += 1;
    }
    if term == Tok::RBrace {
        let end = (i + 1).min(toks.len());
        return (toks[at..end].to_vec(), end);
    }
    (toks[at..i].to_vec(), i)
}

/// A token-list argument without the braces that may enclose it.
fn braced(arg: &[Token]) -> &[Token] {
    match arg {
        [first, inner @ .., last] if first.kind == Tok::LBrace && last.kind == Tok::RBrace => inner,
        _ => arg,
    }
}

/// The directive's name for messages.
fn dir_name(dir: Dir) -> &'static str {
    match dir {
        Dir::Left => "left",
        Dir::Mid => "mid",
        Dir::Right => "right",
        Dir::Concat => "concat",
        Dir::String => "string",
        Dir::Ident => "ident",
        _ => "sprintf",
    }
}
