//! The layout fixpoint: place the chunks, widen the operands that no
//! longer fit zero page, until nothing widens.

use crate::asm::Asm;
use crate::model::{ChunkId, SegId, VarKind};

/// The most bytes a `.res` sized by placement may take (the 16 MiB output
/// limit): a size that is still wrong in an early round stays bounded.
const MAX_DEFERRED_RES: u32 = 1 << 24;

impl Asm<'_> {
    /// Places every chunk with the current sizes. Chunks whose absolute
    /// address follows a chunk of another segment (global `.org`), `.org`s
    /// and `.res`es whose values depend on positions take a few rounds to
    /// settle.
    pub(super) fn place(&mut self) {
        let rounds = self
            .prog
            .chunks
            .iter()
            .any(|c| c.org_after.is_some() || c.org_expr.is_some())
            || self
                .prog
                .vars
                .iter()
                .any(|v| matches!(v.kind, VarKind::Res { .. }));
        for _ in 0..32 {
            let before: Vec<i64> = if rounds {
                self.prog.chunks.iter().map(|c| c.abs).collect()
            } else {
                Vec::new()
            };
            let settled = !rounds || self.settle_deferred();
            self.place_once();
            if !rounds || (settled && self.prog.chunks.iter().map(|c| c.abs).eq(before)) {
                return;
            }
        }
    }

    /// Evaluates the deferred `.org` values and `.res` sizes with the
    /// positions of the last placement; whether none changed.
    fn settle_deferred(&mut self) -> bool {
        let mut unchanged = true;
        for c in 0..self.prog.chunks.len() {
            if let Some(expr) = self.prog.chunks[c].org_expr {
                let value = match self.prog.eval(expr) {
                    Ok(crate::expr::Value::Const(value)) => value.clamp(0, 0xFF_FFFF),
                    _ => 0,
                };
                unchanged &= self.prog.chunks[c].org_base == Some(value);
                self.prog.chunks[c].org_base = Some(value);
            }
        }
        for v in 0..self.prog.vars.len() {
            if let VarKind::Res { count, .. } = self.prog.vars[v].kind {
                let size = match self.prog.eval(count) {
                    Ok(crate::expr::Value::Const(size)) => {
                        size.clamp(0, i64::from(MAX_DEFERRED_RES))
                    }
                    _ => 0,
                } as u32;
                unchanged &= self.prog.vars[v].size == size;
                self.prog.vars[v].size = size;
            }
        }
        unchanged
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
                            VarKind::Res { .. } => var.size,
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
        self.check_absolute_guesses();
    }

    pub(super) fn chunk_pos(&self, chunk: ChunkId, off: u32) -> (SegId, u32) {
        let c = &self.prog.chunks[chunk as usize];
        (c.seg, c.start + off)
    }
}
