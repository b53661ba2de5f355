//! Where bytes go: `.segment`, the named segments (`.code`, `.rodata`,
//! `.data`, `.bss`, `.zeropage`), `.org` and `.reloc`.

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::intern::Dir;
use crate::lexer::Tok;

/// The deepest `.pushseg`/`.pushcpu` stack, as ca65's.
const MAX_PUSHED: usize = 16;

impl Asm<'_> {
    pub(super) fn org(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let start = c.pos();
        // `.org VTOC + 256` after instructions whose size the layout
        // passes decide: the address follows the placement.
        let node = self.expression(c)?;
        if matches!(
            self.prog.eval(node),
            Err(crate::expr::EvalErr::NotYet(None)) | Ok(crate::expr::Value::Chunk { .. })
        ) {
            self.expect_end(c)?;
            let span = self.join(c.span_of(start), c.last_span());
            self.keep_nodes = true;
            self.new_chunk(true, None);
            let cur = self.prog.segs[self.seg as usize].cur;
            self.prog.chunks[cur as usize].org_expr = Some(node);
            self.prog.chunks[cur as usize].known_abs = None;
            let loc = self.loc(span);
            self.prog.deferred_orgs.push((cur, loc));
            self.org_global = !self.features.org_per_seg;
            return Ok(());
        }
        *c = c.at(start);
        let value = self.const_expr(c, "`.org`")?;
        self.expect_end(c)?;
        if !(0..=0xFF_FFFF).contains(&value) {
            let span = self.join(c.span_of(start), c.last_span());
            return Err(self.report(crate::resolver::range_diag(
                span,
                "`.org` address",
                value,
                (0, 0xFF_FFFF),
            )));
        }
        self.new_chunk(true, Some(value));
        self.org_global = !self.features.org_per_seg;
        Ok(())
    }

    pub(super) fn reloc(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        self.expect_end(c)?;
        self.new_chunk(false, None);
        self.org_global = false;
        Ok(())
    }

    /// `.pushseg`/`.popseg` (the current segment) and `.pushcpu`/`.popcpu`
    /// (whether the undocumented opcodes are on), as ca65's stacks of at
    /// most 16 entries.
    pub(super) fn push_pop(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        self.expect_end(c)?;
        let full = |len: usize| len >= MAX_PUSHED;
        match dir {
            Dir::Pushseg if full(self.pushed_segs.len()) => {}
            Dir::Pushseg => {
                self.pushed_segs.push(self.seg);
                return Ok(());
            }
            Dir::Pushcpu if full(self.pushed_cpus.len()) => {}
            Dir::Pushcpu => {
                self.pushed_cpus.push(self.cpu_x);
                return Ok(());
            }
            Dir::Popseg => {
                if let Some(seg) = self.pushed_segs.pop() {
                    self.switch_segment(seg);
                    return Ok(());
                }
            }
            _ => {
                if let Some(cpu_x) = self.pushed_cpus.pop() {
                    self.cpu_x = cpu_x;
                    return Ok(());
                }
            }
        }
        let message = match dir {
            Dir::Pushseg | Dir::Pushcpu => format!("more than {MAX_PUSHED} entries pushed"),
            _ => "nothing pushed to pop".to_string(),
        };
        Err(self.err("asm::unbalanced", head.span, message))
    }

    pub(super) fn named_segment(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        self.expect_end(c)?;
        let (name, zp) = match dir {
            Dir::Code => ("CODE", false),
            Dir::Rodata => ("RODATA", false),
            Dir::Data => ("DATA", false),
            Dir::Bss => ("BSS", false),
            _ => ("ZEROPAGE", true),
        };
        let seg = self.segment(name, zp);
        self.switch_segment(seg);
        Ok(())
    }

    pub(super) fn segment_directive(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let Some(name) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
            let span = c.span();
            return Err(self.err(
                "asm::syntax",
                span,
                "expected a segment name in quotes: `.segment \"CODE\"`",
            ));
        };
        c.advance();
        let text = String::from_utf8_lossy(&self.string_bytes(&name)).into_owned();
        if text.is_empty() || !text.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(self.err(
                "asm::syntax",
                name.span,
                "a segment name is letters, digits and `_`",
            ));
        }
        let mut zp = false;
        if c.eat(Tok::Colon) {
            let Some(kind) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected `zeropage` or `absolute`"));
            };
            let word = self.names.name(kind.name()).to_ascii_lowercase();
            zp = match word.as_str() {
                "zeropage" | "zp" | "direct" => true,
                "absolute" | "abs" => false,
                _ => {
                    return Err(self.err(
                        "asm::syntax",
                        kind.span,
                        "expected `zeropage` or `absolute`",
                    ));
                }
            };
            c.advance();
        }
        self.expect_end(c)?;
        let seg = self.segment(&text, zp);
        if zp && !self.prog.segs[seg as usize].zp {
            return Err(self.err(
                "asm::segment",
                name.span,
                format!("segment `{text}` was first used as an absolute segment"),
            ));
        }
        self.switch_segment(seg);
        Ok(())
    }
}
