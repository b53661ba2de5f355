//! What the source says to its reader: `.assert` (checked now or by the
//! linker), `.out`, `.warning`, `.error` and `.fatal`.

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag;
use crate::intern::Dir;
use crate::lexer::Tok;
use crate::model::AssertRec;

impl Asm<'_> {
    pub(super) fn assert(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let start = c.pos();
        let expr = self.expression(c)?;
        let span = self.join(c.span_of(start), c.last_span());
        self.comma(c)?;
        let Some(action) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err(
                "asm::syntax",
                span,
                "expected `error`, `warning`, `lderror` or `ldwarning`",
            ));
        };
        c.advance();
        let word = self.names.name(action.name()).to_ascii_lowercase();
        let (error, link_only) = match word.as_str() {
            "error" => (true, false),
            "warning" | "warn" => (false, false),
            "lderror" => (true, true),
            "ldwarning" | "ldwarn" => (false, true),
            _ => {
                return Err(self.err(
                    "asm::syntax",
                    action.span,
                    "expected `error`, `warning`, `lderror` or `ldwarning`",
                ));
            }
        };
        let mut message = String::from("assertion failed");
        if c.eat(Tok::Comma) {
            let Some(text) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected the message in quotes"));
            };
            message = String::from_utf8_lossy(&self.string_bytes(&text)).into_owned();
            c.advance();
        }
        self.expect_end(c)?;
        let loc = self.loc(span);
        let column = self.column_of(head.span);
        self.keep_nodes = true;
        self.prog.asserts.push(AssertRec {
            expr,
            error,
            link_only,
            message,
            loc,
            line: self.input.line.line,
            column,
        });
        Ok(())
    }

    pub(super) fn message(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let Some(text) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected a message in quotes"));
        };
        c.advance();
        self.expect_end(c)?;
        let message = String::from_utf8_lossy(&self.string_bytes(&text)).into_owned();
        let span = self.join(head.span, text.span);
        match dir {
            Dir::Out => self.messages.push(message),
            Dir::Warning => {
                self.report(diag::warning("asm::user-warning", span, message));
            }
            Dir::Fatal => {
                self.err("asm::user-error", span, message);
                self.stop = true;
            }
            _ => {
                self.err("asm::user-error", span, message);
            }
        }
        Ok(())
    }
}
