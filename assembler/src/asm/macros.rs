//! Macro calls (arguments into a frame) and the bodies of `.macro` and
//! `.repeat`, read up to their end directive.

use super::*;

impl<'a> Asm<'a> {
    pub(super) fn invoke_macro(&mut self, mac: u32, c: &mut Cursor<'_>) -> PResult<()> {
        let Some(head) = c.next_token() else {
            return Ok(());
        };
        self.frame_room(head.span)?;
        // Arguments: comma-separated token runs; `{...}` groups a run.
        let mut args: Vec<Vec<Token>> = Vec::new();
        if !c.is_end() {
            let mut current = Vec::new();
            let mut depth = 0usize;
            while let Some(tok) = c.next_token() {
                match tok.kind {
                    Tok::LBrace => {
                        if depth > 0 {
                            current.push(tok);
                        }
                        depth += 1;
                    }
                    Tok::RBrace if depth > 0 => {
                        depth -= 1;
                        if depth > 0 {
                            current.push(tok);
                        }
                    }
                    Tok::Comma if depth == 0 => args.push(std::mem::take(&mut current)),
                    _ => current.push(tok),
                }
            }
            args.push(current);
        }
        let Some(macro_def) = self.input.macros.get(mac as usize) else {
            return Ok(());
        };
        if args.len() > macro_def.params.len() {
            let name = self.names.name(macro_def.name).to_string();
            let count = macro_def.params.len();
            return Err(self.err(
                "asm::macro-args",
                self.join(head.span, c.last_span()),
                format!(
                    "macro `{name}` takes {count} parameter{}, {} given",
                    if count == 1 { "" } else { "s" },
                    args.len()
                ),
            ));
        }
        let body = Rc::clone(&macro_def.body);
        let name = self.names.name(macro_def.name).to_string();
        self.input.expansions += 1;
        let ctx = self.new_ctx(CtxKind::Macro(name), head.span);
        self.input.frames.push(Frame::Macro {
            body,
            line: 0,
            args,
            locals: Vec::new(),
            ctx,
            conds: self.input.conds.len(),
        });
        Ok(())
    }

    /// Reads a macro or `.repeat` body up to its end directive. `opener`
    /// and `closer` are the nesting directives. Returns `None` if the
    /// input ended first (reported).
    pub(crate) fn collect_body(
        &mut self,
        opener: Dir,
        closer: Dir,
        params: &[NameId],
        start: Span,
    ) -> Option<Body> {
        let mut body = Body::default();
        let mut depth = 0usize;
        let saved_line = self.input.line;
        loop {
            let Some(info) = self.fetch_raw() else {
                self.input.line = saved_line;
                let what = if opener == Dir::Macro {
                    "`.macro` has no `.endmacro`"
                } else {
                    "`.repeat` has no `.endrepeat`"
                };
                self.err("asm::unclosed", start, what);
                return None;
            };
            let first = self.input.toks.first().copied();
            if let Some(first) = first
                && first.kind == Tok::Directive
                && let Keyword::Directive(dir) = self.names.keyword(first.name())
            {
                if dir == opener {
                    depth += 1;
                } else if dir == closer {
                    if depth == 0 {
                        if self.input.toks.len() > 1 {
                            let span = self.input.toks[1].span;
                            self.err(
                                "asm::syntax",
                                span,
                                "unexpected text after the end directive",
                            );
                        }
                        return Some(body);
                    }
                    depth -= 1;
                }
            }
            let first_index = body.tokens.len() as u32;
            for tok in &self.input.toks {
                let kind = if tok.kind == Tok::Ident {
                    params.iter().position(|p| *p == tok.name())
                } else {
                    None
                };
                match kind {
                    Some(index) => body.tokens.push(Token {
                        kind: Tok::Param,
                        span: tok.span,
                        value: index as u64,
                    }),
                    None => body.tokens.push(*tok),
                }
            }
            body.lines.push(crate::asm::BodyLine {
                first: first_index,
                end: body.tokens.len() as u32,
                info,
            });
        }
    }
}
