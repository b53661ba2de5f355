//! Where bytes go: segments, chunks (`.org` and relocatable runs), and
//! the items the listing and the source map are made of.

use super::*;

impl<'a> Asm<'a> {
    /// The segment called `name`, created on first use.
    pub(crate) fn segment(&mut self, name: &str, zp: bool) -> SegId {
        if let Some(index) = self.prog.segs.iter().position(|s| s.name == name) {
            return index as SegId;
        }
        let seg = self.prog.segs.len() as SegId;
        let chunk = self.prog.chunks.len() as ChunkId;
        self.prog.chunks.push(Chunk {
            seg,
            org: false,
            org_base: None,
            org_after: None,
            org_expr: None,
            data_start: 0,
            len: 0,
            var: None,
            known_start: Some(0),
            known_abs: None,
            start: 0,
            abs: 0,
        });
        self.prog.segs.push(Segment {
            name: name.to_string(),
            zp: zp || name == "ZEROPAGE",
            data: Vec::new(),
            chunks: vec![chunk],
            has_data: false,
            used: false,
            align: 1,
            cur: chunk,
            size: 0,
        });
        seg
    }

    /// The current chunk and the offset in it.
    pub(crate) fn here(&self) -> (ChunkId, u32) {
        let cur = self.prog.segs[self.seg as usize].cur;
        (cur, self.prog.chunks[cur as usize].len)
    }

    /// Starts a new chunk in the current segment (after a variable item,
    /// or for `.org`/`.reloc`).
    pub(crate) fn new_chunk(&mut self, org: bool, org_base: Option<i64>) {
        self.new_chunk_from(org, org_base, None);
    }

    /// Makes `seg` current. Under ca65's global `.org` (no `.feature
    /// org_per_seg`), absolute mode follows: the segment goes on at the
    /// address where the one left ends; after `.reloc`, it is relocatable
    /// again.
    pub(crate) fn switch_segment(&mut self, seg: SegId) {
        if seg == self.seg {
            return;
        }
        let left = self.prog.segs[self.seg as usize].cur;
        self.seg = seg;
        if self.features.org_per_seg {
            return;
        }
        let target_org = self.prog.chunks[self.prog.segs[seg as usize].cur as usize].org;
        if self.org_global {
            self.new_chunk_from(true, None, Some(left));
        } else if target_org {
            self.new_chunk(false, None);
        }
    }

    fn new_chunk_from(&mut self, org: bool, org_base: Option<i64>, org_after: Option<ChunkId>) {
        let seg = &self.prog.segs[self.seg as usize];
        let cur = &self.prog.chunks[seg.cur as usize];
        let continues = cur.var.is_none();
        let known_start = match cur.known_start {
            Some(start) if continues => Some(start + cur.len),
            _ => None,
        };
        let known_abs = match (org_base, org_after) {
            (Some(base), _) => Some(base),
            (None, Some(after)) => {
                let after = &self.prog.chunks[after as usize];
                after
                    .known_abs
                    .filter(|_| after.var.is_none())
                    .map(|abs| abs + i64::from(after.len))
            }
            (None, None) if org && cur.org && continues => {
                cur.known_abs.map(|abs| abs + i64::from(cur.len))
            }
            (None, None) => None,
        };
        let chunk = Chunk {
            seg: self.seg,
            org,
            org_base,
            org_after,
            org_expr: None,
            data_start: seg.data.len() as u32,
            len: 0,
            var: None,
            known_start,
            known_abs,
            start: 0,
            abs: 0,
        };
        let id = self.prog.chunks.len() as ChunkId;
        self.prog.chunks.push(chunk);
        let seg = &mut self.prog.segs[self.seg as usize];
        seg.chunks.push(id);
        seg.cur = id;
    }

    /// Appends bytes to the current chunk.
    pub(crate) fn emit(&mut self, bytes: &[u8]) {
        let seg = &mut self.prog.segs[self.seg as usize];
        if bytes.len() <= 4 {
            // Instructions: a call to memcpy costs more than the bytes.
            for &byte in bytes {
                seg.data.push(byte);
            }
        } else {
            seg.data.extend_from_slice(bytes);
        }
        seg.has_data = true;
        seg.used = true;
        self.prog.chunks[seg.cur as usize].len += bytes.len() as u32;
        self.total_bytes += bytes.len();
        if self.total_bytes > MAX_BYTES && !self.stop {
            let span = Span {
                file: self.input.line.file,
                start: self.input.line.start,
                end: self.input.line.end,
            };
            self.err(
                "asm::too-big",
                span,
                format!(
                    "the program grows past {} MiB here; assembly stops",
                    MAX_BYTES >> 20
                ),
            );
            self.stop = true;
        }
    }

    /// Records an instruction or data item for the source map.
    pub(crate) fn item(&mut self, span: Span, instr_len: u8) {
        let (chunk, off) = self.here();
        let column = self.column_of(span);
        self.prog.items.push(Item {
            chunk,
            off,
            file: self.input.line.file,
            line: self.input.line.line,
            column,
            instr_len,
            ctx: self.input.line_ctx,
        });
    }
}
