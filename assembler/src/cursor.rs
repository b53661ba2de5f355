//! A statement's tokens and the place of the next one to read: what the
//! parser, the instruction encoder and the directives pass each other
//! instead of a slice and an index.

use crate::diag::Span;
use crate::lexer::{Tok, Token};

/// A read position in one statement's tokens.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cursor<'t> {
    toks: &'t [Token],
    pos: usize,
    /// Where the line ends: the place of a missing token on an empty line.
    end: Span,
}

impl<'t> Cursor<'t> {
    /// A cursor at the first of `toks`, on a line that ends at `end`.
    pub(crate) fn new(toks: &'t [Token], end: Span) -> Cursor<'t> {
        Cursor { toks, pos: 0, end }
    }

    /// The same tokens, read from `pos`.
    #[must_use]
    pub(crate) fn at(self, pos: usize) -> Cursor<'t> {
        Cursor { pos, ..self }
    }

    /// The index of the next token.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    /// All of the statement's tokens.
    pub(crate) fn tokens(&self) -> &'t [Token] {
        self.toks
    }

    /// The tokens not read yet.
    pub(crate) fn rest(&self) -> &'t [Token] {
        self.toks.get(self.pos..).unwrap_or_default()
    }

    /// Whether every token was read.
    pub(crate) fn is_end(&self) -> bool {
        self.pos >= self.toks.len()
    }

    /// The next token.
    pub(crate) fn peek(&self) -> Option<&'t Token> {
        self.toks.get(self.pos)
    }

    /// The token `ahead` places after the next one.
    pub(crate) fn peek_at(&self, ahead: usize) -> Option<&'t Token> {
        self.toks.get(self.pos + ahead)
    }

    /// The next token's kind.
    pub(crate) fn peek_kind(&self) -> Option<Tok> {
        self.peek().map(|tok| tok.kind)
    }

    /// The kind of the token `ahead` places after the next one.
    pub(crate) fn peek_kind_at(&self, ahead: usize) -> Option<Tok> {
        self.peek_at(ahead).map(|tok| tok.kind)
    }

    /// The next token, when the caller knows there is one (a statement's
    /// head, a token just peeked).
    pub(crate) fn current(&self) -> Token {
        self.toks[self.pos]
    }

    /// Reads the next token.
    pub(crate) fn next_token(&mut self) -> Option<Token> {
        let tok = self.peek().copied();
        if tok.is_some() {
            self.pos += 1;
        }
        tok
    }

    /// Steps over the next token.
    pub(crate) fn advance(&mut self) {
        self.pos += 1;
    }

    /// Steps over `count` tokens.
    pub(crate) fn advance_by(&mut self, count: usize) {
        self.pos += count;
    }

    /// Steps over the next token if it is a `kind`.
    pub(crate) fn eat(&mut self, kind: Tok) -> bool {
        let found = self.peek_kind() == Some(kind);
        if found {
            self.pos += 1;
        }
        found
    }

    /// The span of token `index`, or a zero-width span just after the last
    /// token (where something is missing), or the line's end.
    pub(crate) fn span_of(&self, index: usize) -> Span {
        if let Some(tok) = self.toks.get(index) {
            return tok.span;
        }
        match self.toks.last() {
            Some(last) => Span {
                file: last.span.file,
                start: last.span.end,
                end: last.span.end,
            },
            None => self.end,
        }
    }

    /// The span of the next token, or where it is missing.
    pub(crate) fn span(&self) -> Span {
        self.span_of(self.pos)
    }

    /// The span of the token read last.
    pub(crate) fn last_span(&self) -> Span {
        self.span_of(self.pos.saturating_sub(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tok(kind: Tok, start: u32) -> Token {
        Token {
            kind,
            span: Span {
                file: 0,
                start,
                end: start + 1,
            },
            value: 0,
        }
    }

    #[test]
    fn reads_peeks_and_places_missing_tokens() {
        let toks = [tok(Tok::Ident, 0), tok(Tok::Comma, 2), tok(Tok::Number, 4)];
        let end = Span {
            file: 0,
            start: 9,
            end: 9,
        };
        let mut c = Cursor::new(&toks, end);
        assert_eq!(c.peek_kind(), Some(Tok::Ident));
        assert_eq!(c.peek_kind_at(1), Some(Tok::Comma));
        assert!(!c.eat(Tok::Comma));
        assert_eq!(c.next_token().map(|t| t.kind), Some(Tok::Ident));
        assert!(c.eat(Tok::Comma));
        assert_eq!(c.last_span().start, 2);
        c.advance();
        assert!(c.is_end());
        assert!(c.next_token().is_none());
        // A missing token is placed just after the last one.
        assert_eq!((c.span().start, c.span().end), (5, 5));
        assert_eq!(Cursor::new(&[], end).span(), end);
        assert_eq!(c.at(1).rest().len(), 2);
    }
}
