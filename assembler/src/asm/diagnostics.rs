//! Reporting: diagnostics with spans, and the expansion contexts
//! (include, macro, `.repeat`) that give them their backtraces.

use super::*;

impl<'a> Asm<'a> {
    /// Reports `diag` in the current expansion context.
    pub(crate) fn report(&mut self, mut diag: RawDiag) -> Reported {
        diag.ctx = self.input.line_ctx;
        self.rep.push(diag);
        Reported
    }

    pub(crate) fn err(
        &mut self,
        code: &'static str,
        span: Span,
        message: impl Into<String>,
    ) -> Reported {
        self.report(diag::error(code, span, message))
    }

    /// Joins two spans on one line (see [`Files::join`]).
    pub(crate) fn join(&self, a: Span, b: Span) -> Span {
        let line = &self.input.line;
        if a.file == line.file
            && b.file == line.file
            && a.start >= line.start
            && b.end <= line.end
            && a.start <= b.end
        {
            // Both on the current line: no newline can be between them.
            return Span {
                file: a.file,
                start: a.start,
                end: b.end.max(a.end),
            };
        }
        self.files.join(a, b)
    }

    pub(crate) fn loc(&mut self, span: Span) -> LocId {
        self.prog.loc(span, self.input.line_ctx)
    }

    pub(crate) fn new_ctx(&mut self, kind: CtxKind, span: Span) -> CtxId {
        self.ctx.push(CtxNode {
            parent: self.input.line_ctx,
            kind,
            span,
        });
        (self.ctx.len() - 1) as CtxId
    }

    /// Column (from 1, in characters) of a span on the current line.
    pub(crate) fn column_of(&self, span: Span) -> u32 {
        if span.file != self.input.line.file || span.start < self.input.line.start {
            return 1;
        }
        if self.input.line.ascii {
            return span.start - self.input.line.start + 1;
        }
        let text = self.files.text(span.file);
        let start = self.input.line.start as usize;
        let end = (span.start as usize).min(text.len()).max(start);
        count_chars(&text[start..end]) + 1
    }
}
