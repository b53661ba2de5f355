//! Text that expands: `.macro` (with `.local` and `.exitmacro`),
//! `.repeat`, `.define` and `.undefine`. The expansion itself is the
//! expander's (`asm::expand`); these record what to expand.

use crate::asm::{Asm, Frame, PResult, Reported};
use crate::cursor::Cursor;
use crate::diag::CtxKind;
use crate::intern::{Dir, NameId};
use crate::lexer::Tok;

/// Largest `.repeat` count.
const MAX_REPEAT: i64 = 1 << 20;

impl Asm<'_> {
    pub(super) fn define_macro(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let Some(name) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            // Still skip the body so it is not assembled.
            let _ = self.collect_body(Dir::Macro, Dir::Endmacro, &[], head.span);
            return Err(self.err("asm::syntax", span, "expected the macro's name"));
        };
        c.advance();
        let reserved = self.reserved_name(&name, true);
        let param_tokens = c.rest();
        let mut params: Vec<NameId> = Vec::new();
        let mut bad = None;
        for tok in param_tokens {
            match tok.kind {
                Tok::Ident if !params.contains(&tok.name()) => params.push(tok.name()),
                Tok::Comma => {}
                _ => {
                    bad.get_or_insert(tok.span);
                }
            }
        }
        let body = self.collect_body(Dir::Macro, Dir::Endmacro, &params, head.span);
        reserved?;
        for param in param_tokens.iter().filter(|tok| tok.kind == Tok::Ident) {
            self.reserved_name(param, false)?;
        }
        if let Some(span) = bad {
            return Err(self.err(
                "asm::syntax",
                span,
                "macro parameters are names separated by commas",
            ));
        }
        let Some(body) = body else {
            return Err(Reported);
        };
        if let Some(info) = self.names.info.get(name.value as usize)
            && info.macro_id.is_some()
        {
            let text = self.names.name(name.name()).to_string();
            return Err(self.err(
                "asm::duplicate",
                name.span,
                format!("macro `{text}` is already defined"),
            ));
        }
        let id = self.input.macros.len() as u32;
        self.input.macros.push(crate::asm::Macro {
            name: name.name(),
            params,
            body: std::rc::Rc::new(body),
        });
        if let Some(info) = self.names.info_mut(name.name()) {
            info.macro_id = Some(id);
        }
        Ok(())
    }

    pub(super) fn local(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let Some(index) = self
            .input
            .frames
            .iter()
            .rposition(|frame| matches!(frame, Frame::Macro { .. }))
        else {
            return Err(self.err(
                "asm::syntax",
                head.span,
                "`.local` is only allowed inside a macro",
            ));
        };
        let mut names = Vec::new();
        while let Some(tok) = c.next_token() {
            match tok.kind {
                // `.local @j`: a cheap local of each expansion's own, as
                // in ca65 (still bound to the region of the last label).
                Tok::Ident | Tok::Local => names.push(tok.name()),
                Tok::Comma => {}
                _ => return Err(self.err("asm::syntax", tok.span, "expected a name")),
            }
        }
        let serial = self.ctx.len();
        let renamed: Vec<(NameId, NameId)> = names
            .iter()
            .map(|name| {
                let text = format!("{}.{serial}", self.names.name(*name));
                (*name, self.names.intern(&text))
            })
            .collect();
        if let Some(Frame::Macro { locals, .. }) = self.input.frames.get_mut(index) {
            locals.extend(renamed);
        }
        Ok(())
    }

    pub(super) fn exit_macro(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        self.expect_end(c)?;
        let Some(index) = self
            .input
            .frames
            .iter()
            .rposition(|frame| matches!(frame, Frame::Macro { .. }))
        else {
            return Err(self.err("asm::syntax", head.span, "`.exitmacro` outside a macro"));
        };
        let conds = match &self.input.frames[index] {
            Frame::Macro { conds, .. } => *conds,
            _ => self.input.conds.len(),
        };
        self.input.frames.truncate(index);
        self.input.conds.truncate(conds);
        Ok(())
    }

    pub(super) fn repeat(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let count_span = c.span();
        let count = self.const_expr(c, "`.repeat`");
        let mut var = None;
        if count.is_ok() && c.eat(Tok::Comma) {
            match c.peek().filter(|t| t.kind == Tok::Ident) {
                Some(tok) => var = Some(tok.name()),
                None => {
                    let span = c.span();
                    self.err("asm::syntax", span, "expected the name of the counter");
                }
            }
            c.advance();
        }
        let end_ok = count.is_ok() && self.expect_end(c).is_ok();
        let body = self.collect_body(Dir::Repeat, Dir::Endrepeat, &[], head.span);
        let count = count?;
        if !end_ok {
            return Err(Reported);
        }
        let Some(body) = body else {
            return Err(Reported);
        };
        if !(0..=MAX_REPEAT).contains(&count) {
            return Err(self.report(crate::resolver::range_diag(
                count_span,
                "`.repeat` count",
                count,
                (0, MAX_REPEAT),
            )));
        }
        if count == 0 || body.lines.is_empty() {
            return Ok(());
        }
        self.frame_room(head.span)?;
        let ctx = self.new_ctx(CtxKind::Repeat, head.span);
        self.input.frames.push(Frame::Repeat {
            body: std::rc::Rc::new(body),
            line: 0,
            iter: 0,
            count: count as u32,
            var,
            ctx,
            conds: self.input.conds.len(),
        });
        Ok(())
    }

    pub(super) fn define_text(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let Some(name) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected the name to define"));
        };
        c.advance();
        self.reserved_name(&name, true)?;
        let mut params = Vec::new();
        let mut has_params = false;
        if let Some(open) = c.peek()
            && open.kind == Tok::LParen
            && open.span.start == name.span.end
        {
            has_params = true;
            c.advance();
            loop {
                match c.peek() {
                    Some(tok) if tok.kind == Tok::Ident => params.push(tok.name()),
                    Some(tok) if tok.kind == Tok::Comma => {}
                    Some(tok) if tok.kind == Tok::RParen => {
                        c.advance();
                        break;
                    }
                    _ => {
                        let span = c.span();
                        return Err(self.err(
                            "asm::syntax",
                            span,
                            "expected parameter names and `)`",
                        ));
                    }
                }
                c.advance();
            }
        }
        let id = self.input.defines.len() as u32;
        self.input.defines.push(crate::asm::Define {
            params,
            has_params,
            tokens: c.rest().to_vec(),
        });
        if let Some(info) = self.names.info_mut(name.name()) {
            info.define_id = Some(id);
        }
        self.input.any_define = true;
        Ok(())
    }

    pub(super) fn undefine(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let Some(name) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected the name of a `.define`"));
        };
        c.advance();
        self.expect_end(c)?;
        if let Some(info) = self.names.info_mut(name.name()) {
            info.define_id = None;
        }
        Ok(())
    }
}

impl Asm<'_> {
    /// `.macpack NAME`: one of ca65's macro packages, read as if included
    /// (a second `.macpack` of it defines its macros again, an error as in
    /// ca65).
    pub(super) fn macpack(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err(
                "asm::syntax",
                span,
                format!(
                    "expected a macro package's name ({})",
                    crate::macpack::NAMES
                ),
            ));
        };
        c.advance();
        self.expect_end(c)?;
        let name = self.names.name(tok.name()).to_ascii_lowercase();
        let Some(text) = crate::macpack::package(&name) else {
            return Err(self.report(
                crate::diag::error(
                    "asm::macpack",
                    tok.span,
                    format!("no macro package `{name}`"),
                )
                .help(format!("the packages: {}", crate::macpack::NAMES)),
            ));
        };
        self.frame_room(tok.span)?;
        let ctx = self.new_ctx(CtxKind::Include, self.join(head.span, tok.span));
        self.push_file(
            format!("<macpack {name}>"),
            text.into_bytes(),
            std::path::PathBuf::new(),
            ctx,
        );
        Ok(())
    }
}
