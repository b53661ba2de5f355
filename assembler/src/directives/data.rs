//! Data: `.byte`, `.asciiz`, `.word`/`.addr`, `.dbyt`, `.dword`,
//! `.lobytes`/`.hibytes`/`.bankbytes`, `.res`, `.align`, `.charmap`.

use isa::objfmt::UnaryOp;

use crate::asm::{Asm, MAX_BYTES, PResult};
use crate::cursor::Cursor;
use crate::diag::{self, Span};
use crate::expr::EvalErr;
use crate::intern::Dir;
use crate::lexer::Tok;
use crate::model::{FixKind, Node, VarItem, VarKind};

impl Asm<'_> {
    pub(super) fn data(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        self.item(head.span, 0);
        if c.is_end() {
            if dir == Dir::Asciiz {
                self.emit(&[0]);
                return Ok(());
            }
            return Err(self.err(
                "asm::syntax",
                head.span,
                "this directive needs at least one value",
            ));
        }
        let kind = match dir {
            Dir::Word | Dir::Addr => FixKind::Word,
            Dir::Dbyt => FixKind::Dbyt,
            Dir::Dword => FixKind::Dword,
            Dir::Faraddr => FixKind::Far,
            _ => FixKind::Byte,
        };
        loop {
            let tok = c.current();
            let is_text = tok.kind == Tok::Str
                && matches!(dir, Dir::Byte | Dir::Asciiz)
                && matches!(c.peek_kind_at(1), None | Some(Tok::Comma));
            if is_text {
                let bytes: Vec<u8> = self
                    .string_bytes(&tok)
                    .iter()
                    .map(|b| self.charmap[usize::from(*b)])
                    .collect();
                self.emit(&bytes);
                c.advance();
            } else {
                let start = c.pos();
                let mut expr = self.expression(c)?;
                let span = self.join(c.span_of(start), c.last_span());
                let wrap = match dir {
                    Dir::Lobytes => Some(UnaryOp::LoByte),
                    Dir::Hibytes => Some(UnaryOp::HiByte),
                    Dir::Bankbytes => Some(UnaryOp::BankByte),
                    _ => None,
                };
                if let Some(op) = wrap {
                    expr = self.prog.node(Node::Unary(op, expr));
                }
                self.operand_bytes(expr, kind, span)?;
            }
            match c.peek_kind() {
                None => break,
                Some(Tok::Comma) if c.peek_at(1).is_some() => c.advance(),
                _ => {
                    let span = c.span();
                    return Err(self.err("asm::syntax", span, "expected `,` and another value"));
                }
            }
        }
        if dir == Dir::Asciiz {
            self.emit(&[0]);
        }
        Ok(())
    }

    /// Reserves `count` bytes (`.res`, `.tag`): zeros that do not make a
    /// segment `PROGBITS` unless a fill value is given.
    pub(super) fn reserve(&mut self, count: i64, fill: Option<u8>, span: Span) -> PResult<()> {
        if count < 0 || self.total_bytes.saturating_add(count as usize) > MAX_BYTES {
            let diag = if count < 0 {
                crate::resolver::range_diag(span, "reserved size", count, (0, MAX_BYTES as i64))
            } else {
                diag::error(
                    "asm::too-big",
                    span,
                    format!(
                        "reserving {count} bytes makes the program larger than {} MiB",
                        MAX_BYTES >> 20
                    ),
                )
            };
            return Err(self.report(diag));
        }
        let count = count as usize;
        let seg = &mut self.prog.segs[self.seg as usize];
        seg.data.resize(seg.data.len() + count, fill.unwrap_or(0));
        seg.used = true;
        if fill.is_some() {
            seg.has_data = true;
        }
        let chunk = &mut self.prog.chunks[seg.cur as usize];
        if fill.is_none() && count > 0 {
            // As ld65 does, the linker fills these with the area's value.
            self.prog.fills.push((seg.cur, chunk.len, count as u32));
        }
        chunk.len += count as u32;
        self.total_bytes += count;
        Ok(())
    }

    /// A fill value after a comma: `.res n, fill`, `.align n, fill`. An
    /// error underlines from token `from` (the value alone when `None`).
    fn fill_value(
        &mut self,
        c: &mut Cursor<'_>,
        what: &str,
        from: Option<usize>,
    ) -> PResult<Option<u8>> {
        if !c.eat(Tok::Comma) {
            return Ok(None);
        }
        let start = from.unwrap_or(c.pos());
        let value = self.const_expr(c, what)?;
        if !(0..=255).contains(&value) {
            let span = self.join(c.span_of(start), c.last_span());
            return Err(self.report(crate::resolver::range_diag(
                span,
                "fill value",
                value,
                (0, 255),
            )));
        }
        Ok(Some(value as u8))
    }

    pub(super) fn res(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let start = c.pos();
        // `.res $1E00 - *` after instructions whose size the layout passes
        // decide: the size follows the placement (ca65, one pass, knows
        // `*` here).
        let node = self.expression(c)?;
        let deferred = matches!(
            self.prog.eval(node),
            Err(EvalErr::NotYet(None)) | Ok(crate::expr::Value::Chunk { .. })
        );
        if !deferred {
            *c = c.at(start);
        }
        let count = if deferred {
            0
        } else {
            self.const_expr(c, "`.res`")?
        };
        let fill = self.fill_value(c, "the `.res` fill value", None)?;
        self.expect_end(c)?;
        self.item(head.span, 0);
        let span = self.join(c.span_of(start), c.last_span());
        if !deferred {
            return self.reserve(count, fill, span);
        }
        self.keep_nodes = true;
        let loc = self.loc(span);
        let id = self.prog.vars.len() as u32;
        self.prog.vars.push(VarItem {
            kind: VarKind::Res { count: node, fill },
            loc,
            size: 0,
        });
        let seg = self.seg as usize;
        let cur = self.prog.segs[seg].cur as usize;
        self.prog.chunks[cur].var = Some(id);
        self.prog.segs[seg].used = true;
        if fill.is_some() {
            self.prog.segs[seg].has_data = true;
        }
        let org = self.prog.chunks[cur].org;
        self.new_chunk(org, None);
        Ok(())
    }

    pub(super) fn align(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let start = c.pos();
        let align = self.const_expr(c, "`.align`")?;
        let span = self.join(c.span_of(start), c.last_span());
        let fill = self.fill_value(c, "the `.align` fill value", Some(start))?;
        self.expect_end(c)?;
        if !(1..=0x1_0000).contains(&align) || align & (align - 1) != 0 {
            return Err(self.report(
                diag::error(
                    "asm::range",
                    span,
                    format!("`.align` needs a power of two from 1 to 65536, not {align}"),
                )
                .help("write `.align 256` to start the next byte on a page"),
            ));
        }
        let align = align as u32;
        let seg = self.seg as usize;
        let cur = self.prog.segs[seg].cur as usize;
        // ca65 aligns the offset in the segment, and the segment, even
        // under `.org` (where `*` then moves by the padding whatever the
        // address).
        let s = &mut self.prog.segs[seg];
        s.align = s.align.max(align);
        let chunk = &self.prog.chunks[cur];
        let position = chunk.known_start.map(|start| i64::from(start + chunk.len));
        self.item(head.span, 0);
        match position {
            Some(position) => {
                let pad =
                    (i64::from(align) - position.rem_euclid(i64::from(align))) % i64::from(align);
                match fill {
                    Some(fill) => {
                        self.emit(&vec![fill; pad as usize]);
                        Ok(())
                    }
                    None => self.reserve(pad, None, span),
                }
            }
            None => {
                let loc = self.loc(span);
                let id = self.prog.vars.len() as u32;
                self.prog.vars.push(VarItem {
                    kind: VarKind::Align { align, fill },
                    loc,
                    size: 0,
                });
                self.prog.chunks[cur].var = Some(id);
                if fill.is_some() {
                    self.prog.segs[seg].has_data = true;
                }
                self.total_bytes += align as usize;
                let org = self.prog.chunks[cur].org;
                self.new_chunk(org, None);
                Ok(())
            }
        }
    }

    pub(super) fn charmap(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let from_start = c.pos();
        let from = self.const_expr(c, "`.charmap`")?;
        let from_span = self.join(c.span_of(from_start), c.last_span());
        self.comma(c)?;
        let to_start = c.pos();
        let to = self.const_expr(c, "`.charmap`")?;
        let to_span = self.join(c.span_of(to_start), c.last_span());
        self.expect_end(c)?;
        // The caret goes under the code that is out of range.
        for (value, span) in [(from, from_span), (to, to_span)] {
            if !(0..=255).contains(&value) {
                return Err(self.report(crate::resolver::range_diag(
                    span,
                    "`.charmap` code",
                    value,
                    (0, 255),
                )));
            }
        }
        self.charmap[from as usize] = to as u8;
        Ok(())
    }
}
