//! The layout fixpoint: place the chunks, widen the operands that no
//! longer fit zero page, until nothing widens.

use crate::asm::Asm;
use crate::model::{ChunkId, SegId, VarKind};

impl Asm<'_> {
    /// Places every chunk with the current sizes. Chunks whose absolute
    /// address follows a chunk of another segment (global `.org`) take a
    /// few rounds to settle.
    pub(super) fn place(&mut self) {
        let carried = self.prog.chunks.iter().any(|c| c.org_after.is_some());
        for _ in 0..16 {
            let before: Vec<i64> = if carried {
                self.prog.chunks.iter().map(|c| c.abs).collect()
            } else {
                Vec::new()
            };
            self.place_once();
            if !carried || self.prog.chunks.iter().map(|c| c.abs).eq(before) {
                return;
            }
        }
    }

    fn place_once(&mut self) {
        let prog = &mut self.prog;
        for seg in &mut prog.segs {
            let mut offset: u32 = 0;
            let mut abs: i64 = 0;
            for &c in &seg.chunks {
                let chunk = &mut prog.chunks[c as usize];
                chunk.start = offset;
                if chunk.org {
                    chunk.abs = chunk.org_base.unwrap_or(abs);
                }
                let after = chunk.org_after;
                if let Some(after) = after.filter(|_| prog.chunks[c as usize].org_base.is_none()) {
                    let from = &prog.chunks[after as usize];
                    let var = from
                        .var
                        .and_then(|v| prog.vars.get(v as usize))
                        .map_or(0, |v| v.size);
                    let end = from.abs + i64::from(from.len) + i64::from(var);
                    prog.chunks[c as usize].abs = end;
                }
                let chunk = &mut prog.chunks[c as usize];
                let end = offset.saturating_add(chunk.len);
                let var_size = match chunk.var.and_then(|v| prog.vars.get_mut(v as usize)) {
                    None => 0,
                    Some(var) => {
                        let size = match var.kind {
                            VarKind::Instr { is_wide, .. } => 2 + u32::from(is_wide),
                            // The offset in the segment, under `.org` too,
                            // as ca65 aligns.
                            VarKind::Align { align, .. } => {
                                let position = i64::from(end);
                                let align = i64::from(align);
                                ((align - position.rem_euclid(align)) % align) as u32
                            }
                        };
                        var.size = size;
                        size
                    }
                };
                offset = end.saturating_add(var_size);
                abs = chunk.abs + i64::from(chunk.len) + i64::from(var_size);
            }
            seg.size = offset;
        }
    }

    /// Iterates layout passes until no undecided operand widens.
    pub(crate) fn layout(&mut self) {
        self.prog.placed = true;
        loop {
            self.place();
            self.prog.stamp += 1;
            let mut changed = false;
            for v in 0..self.prog.vars.len() {
                let VarKind::Instr {
                    expr,
                    is_wide: false,
                    ..
                } = self.prog.vars[v].kind
                else {
                    continue;
                };
                let fits = match self.prog.eval(expr) {
                    Ok(value) => self.value_fit(value).unwrap_or(false),
                    // Errors are reported in the final pass; stay narrow.
                    Err(_) => true,
                };
                if !fits && let VarKind::Instr { is_wide, .. } = &mut self.prog.vars[v].kind {
                    *is_wide = true;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        self.prog.stamp += 1;
    }

    pub(super) fn chunk_pos(&self, chunk: ChunkId, off: u32) -> (SegId, u32) {
        let c = &self.prog.chunks[chunk as usize];
        (c.seg, c.start + off)
    }
}
