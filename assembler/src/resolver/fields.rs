//! Final resolution: every fixup into bytes or a relocation, the output
//! symbols and fills, branch distances and assertions.

use isa::elf::{
    R_MOS_ADDR8, R_MOS_ADDR16, R_MOS_ADDR16_HI, R_MOS_ADDR16_LO, R_MOS_ADDR24, R_MOS_ADDR24_BANK,
    R_MOS_IMM8, R_MOS_PCREL_8,
};
use isa::objfmt::{BinaryOp, FillRun, SourceLoc, SrcMapEntry, UnaryOp};

use super::{branch_diag, field_range_diag};
use crate::asm::Asm;
use crate::diag::{self, RawDiag};
use crate::expr::{Base, EvalErr, Sel, Value};
use crate::model::{ChunkId, FixKind, LocId, Node, NodeId, SegId, SymDef, SymId, SymKind, VarKind};
use crate::output::{
    AssertOp, OutAssert, OutField, OutReloc, OutSection, OutSym, OutSymKind, Output, Target,
    const_bytes,
};

impl Asm<'_> {
    /// Builds the output: section bytes, relocations, symbols, asserts.
    pub(crate) fn resolve(&mut self) -> Output {
        let mut out = Output::default();
        // Sections for used segments.
        let mut seg_section = vec![None; self.prog.segs.len()];
        let mut datas: Vec<Vec<u8>> = Vec::with_capacity(self.prog.segs.len());
        let mut var_fixups: Vec<(ChunkId, u32, FixKind, NodeId, LocId)> = Vec::new();
        for (index, seg) in self.prog.segs.iter_mut().enumerate() {
            let has_var = seg
                .chunks
                .iter()
                .any(|c| self.prog.chunks[*c as usize].var.is_some());
            let data = if has_var {
                let mut data = Vec::with_capacity(seg.size as usize);
                for &c in &seg.chunks {
                    let chunk = &self.prog.chunks[c as usize];
                    let start = chunk.data_start as usize;
                    data.extend_from_slice(&seg.data[start..start + chunk.len as usize]);
                    let Some(var) = chunk.var.and_then(|v| self.prog.vars.get(v as usize)) else {
                        continue;
                    };
                    match var.kind {
                        VarKind::Instr {
                            narrow,
                            wide,
                            expr,
                            is_wide,
                        } => {
                            data.push(if is_wide { wide } else { narrow });
                            let kind = if is_wide { FixKind::Abs } else { FixKind::Zp };
                            var_fixups.push((c, chunk.len + 1, kind, expr, var.loc));
                            data.extend_from_slice(&[0; 2][..kind.len() as usize]);
                        }
                        VarKind::Align { fill, .. } | VarKind::Res { fill, .. } => {
                            data.resize(data.len() + var.size as usize, fill.unwrap_or(0));
                        }
                    }
                }
                data
            } else {
                std::mem::take(&mut seg.data)
            };
            if seg.used || !data.is_empty() {
                seg_section[index] = Some(out.sections.len());
                out.sections.push(OutSection {
                    name: seg.name.clone(),
                    zp: seg.zp,
                    nobits: !seg.has_data,
                    data: Vec::new(),
                    size: seg.size,
                    align: seg.align,
                    relocs: Vec::new(),
                });
            }
            datas.push(data);
        }
        out.seg_section = seg_section;
        self.check_deferred();
        // Symbols first: relocations against imports need their indices.
        let sym_index = self.collect_symbols(&mut out);
        self.symbol_values(&mut out, &sym_index);
        let fixups = std::mem::take(&mut self.prog.fixups);
        for fixup in &fixups {
            self.resolve_field(
                &mut out,
                &mut datas,
                &sym_index,
                fixup.chunk,
                fixup.off,
                fixup.kind,
                fixup.expr,
                fixup.loc,
            );
        }
        self.prog.fixups = fixups;
        for (chunk, off, kind, expr, loc) in var_fixups {
            self.resolve_field(
                &mut out, &mut datas, &sym_index, chunk, off, kind, expr, loc,
            );
        }
        self.check_branches(&out, &datas);
        for (seg, data) in datas.into_iter().enumerate() {
            if let Some(section) = out.seg_section[seg] {
                let s = &mut out.sections[section];
                s.relocs.sort_by_key(|r| r.offset);
                if !s.nobits {
                    s.data = data;
                }
            }
        }
        self.collect_fills(&mut out);
        // Source map items.
        out.items.reserve(self.prog.items.len());
        for item in &self.prog.items {
            let (seg, offset) = self.chunk_pos(item.chunk, item.off);
            if let Some(section) = out.seg_section[seg as usize] {
                out.items.push(SrcMapEntry {
                    section: section as u32,
                    offset,
                    loc: SourceLoc {
                        file: item.file,
                        line: item.line,
                        column: item.column,
                    },
                });
                if let Some((file, line, column)) = self.outermost_expansion(item.ctx) {
                    out.calls.push(SrcMapEntry {
                        section: section as u32,
                        offset,
                        loc: SourceLoc { file, line, column },
                    });
                }
            }
        }
        self.check_asserts(&mut out, &sym_index);
        for &(sym, kind, priority) in &self.prog.condes {
            if let Some(index) = sym_index[sym as usize] {
                out.condes.push((index, kind, priority));
            }
        }
        out
    }

    /// The reserved runs of sections that have bytes: `.res`s, and
    /// `.align`s without a fill value (placed now that layout is done).
    fn collect_fills(&self, out: &mut Output) {
        let vars = self
            .prog
            .chunks
            .iter()
            .enumerate()
            .filter_map(|(c, chunk)| {
                let var = self.prog.vars.get(chunk.var? as usize)?;
                match var.kind {
                    VarKind::Align { fill: None, .. } | VarKind::Res { fill: None, .. } => {
                        Some((c as ChunkId, chunk.len, var.size))
                    }
                    _ => None,
                }
            });
        for (chunk, off, length) in self.prog.fills.iter().copied().chain(vars) {
            let (seg, offset) = self.chunk_pos(chunk, off);
            let Some(section) = out.seg_section[seg as usize] else {
                continue;
            };
            if length > 0 && !out.sections[section].nobits {
                out.fills.push(FillRun {
                    section: section as u32,
                    offset,
                    length,
                });
            }
        }
    }

    /// `.res` sizes and `.org` values that waited for placement must have
    /// settled to a constant in range.
    fn check_deferred(&mut self) {
        for v in 0..self.prog.vars.len() {
            let VarKind::Res { count, .. } = self.prog.vars[v].kind else {
                continue;
            };
            let loc = self.prog.vars[v].loc;
            let span = self.loc_span(loc);
            match self.prog.eval(count) {
                Ok(Value::Const(size)) if size < 0 => self.report_at(
                    loc,
                    diag::error(
                        "asm::range",
                        span,
                        format!("`.res` comes to {size} bytes here, which is negative"),
                    )
                    .help("the code before it reaches past the address it pads to"),
                ),
                // Placement clamps the size to the output limit.
                Ok(Value::Const(size)) => {
                    if i64::from(self.prog.vars[v].size) != size {
                        self.report_at(
                            loc,
                            diag::error(
                                "asm::too-big",
                                span,
                                format!(
                                    "`.res` of {size} bytes makes the program larger than 16 MiB"
                                ),
                            ),
                        );
                    }
                }
                _ => self.report_at(
                    loc,
                    diag::error(
                        "asm::not-constant",
                        span,
                        "`.res` needs a constant size, and this one never became one",
                    ),
                ),
            }
        }
        for (chunk, loc) in std::mem::take(&mut self.prog.deferred_orgs) {
            let span = self.loc_span(loc);
            let Some(expr) = self.prog.chunks[chunk as usize].org_expr else {
                continue;
            };
            match self.prog.eval(expr) {
                Ok(Value::Const(value)) if (0..=0xFF_FFFF).contains(&value) => {}
                Ok(Value::Const(value)) => self.report_at(
                    loc,
                    crate::resolver::range_diag(span, "`.org` address", value, (0, 0xFF_FFFF)),
                ),
                _ => self.report_at(
                    loc,
                    diag::error(
                        "asm::not-constant",
                        span,
                        "`.org` needs a constant address, and this one never became one",
                    ),
                ),
            }
        }
    }

    /// The exported symbols whose value is an expression of others,
    /// compiled to bytecode for the linker; an expression that cannot be
    /// is reported where the symbol is exported.
    fn symbol_values(&mut self, out: &mut Output, sym_index: &[Option<usize>]) {
        for (index, sym) in std::mem::take(&mut out.pending_values) {
            let node = self.prog.node(Node::Sym(sym));
            let mut ops = Vec::new();
            if self.compile(node, out, sym_index, &mut ops, 0).is_some() {
                out.values.push((index, ops));
            } else if let Some(loc) = self.prog.syms[sym as usize].export_loc {
                let name = self.sym_name(sym);
                let span = self.loc_span(loc);
                self.report_at(
                    loc,
                    diag::error(
                        "asm::export",
                        span,
                        format!("`{name}` cannot be exported: its value is neither a constant nor an expression of addresses"),
                    ),
                );
            }
        }
    }

    /// The output symbols; returns, per symbol id, its output index.
    fn collect_symbols(&mut self, out: &mut Output) -> Vec<Option<usize>> {
        let mut index = vec![None; self.prog.syms.len()];
        for (sym, slot) in index.iter_mut().enumerate() {
            let s = &self.prog.syms[sym];
            if s.kind != SymKind::Normal {
                if s.export.is_some()
                    && let Some(loc) = s.export_loc
                {
                    let span = self.loc_span(loc);
                    self.report_at(
                        loc,
                        diag::error(
                            "asm::export",
                            span,
                            "cheap locals and unnamed labels cannot be exported",
                        ),
                    );
                }
                continue;
            }
            let exported = s.export.is_some();
            let place = Some(s.place());
            let expanded_at = self.outermost_expansion(s.def_ctx);
            let export_loc = s.export_loc;
            let kind = match s.def {
                SymDef::Undefined | SymDef::Alias(_) => continue,
                // A `.set` variable is written with its last value, and only
                // when exported (its value changes along the file).
                SymDef::Var(_) if !exported => continue,
                SymDef::Import { zp } => {
                    if s.ref_loc.is_none() && !s.global {
                        continue;
                    }
                    OutSymKind::Undef { zp }
                }
                SymDef::Const(value) => OutSymKind::Abs(value),
                SymDef::Label { .. } | SymDef::Expr(_) | SymDef::Var(_) => {
                    match self.prog.eval_sym(sym as SymId) {
                        Ok(Value::Const(value)) => OutSymKind::Abs(value),
                        Ok(Value::Addr {
                            base: Base::Sec(seg),
                            off,
                        }) => match out.seg_section[seg as usize] {
                            Some(section) => OutSymKind::Sec(section, off as u32),
                            None => continue,
                        },
                        // An exported expression of imports (`alias =
                        // return0`): the linker computes it.
                        Ok(Value::Addr { .. } | Value::Byte { .. })
                        | Err(EvalErr::NotRelocatable)
                            if exported =>
                        {
                            out.pending_values.push((out.symbols.len(), sym as SymId));
                            OutSymKind::Abs(0)
                        }
                        other => {
                            if exported
                                && let Some(loc) = export_loc
                                && !matches!(other, Err(EvalErr::Undefined(_)))
                            {
                                let name = self.sym_name(sym as SymId);
                                let span = self.loc_span(loc);
                                self.report_at(
                                loc,
                                diag::error(
                                    "asm::export",
                                    span,
                                    format!("`{name}` cannot be exported: its value is neither a constant nor an address in this file"),
                                ),
                            );
                            }
                            continue;
                        }
                    }
                }
            };
            let global = exported || matches!(kind, OutSymKind::Undef { .. });
            *slot = Some(out.symbols.len());
            out.symbols.push(OutSym {
                name: self.sym_name(sym as SymId),
                kind,
                global,
                place: if matches!(kind, OutSymKind::Undef { .. }) {
                    None
                } else {
                    place
                },
                expanded_at,
            });
        }
        index
    }

    fn base_target(&self, base: Base, out: &Output, sym_index: &[Option<usize>]) -> Option<Target> {
        match base {
            Base::Sec(seg) => out.seg_section[seg as usize].map(Target::Section),
            Base::Ext(sym) => sym_index
                .get(sym as usize)
                .copied()
                .flatten()
                .map(Target::Symbol),
        }
    }

    /// A relocation at `pos` of segment `seg` against `base` (none when the
    /// segment or the symbol has no place in the object, which an error
    /// elsewhere has reported).
    #[allow(clippy::too_many_arguments)]
    fn push_reloc(
        &self,
        out: &mut Output,
        sym_index: &[Option<usize>],
        base: Base,
        seg: SegId,
        pos: u32,
        r_type: u32,
        addend: i64,
    ) {
        if let (Some(target), Some(section)) = (
            self.base_target(base, out, sym_index),
            out.seg_section[seg as usize],
        ) {
            out.sections[section].relocs.push(OutReloc {
                offset: pos,
                r_type,
                target,
                addend,
            });
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn resolve_field(
        &mut self,
        out: &mut Output,
        datas: &mut [Vec<u8>],
        sym_index: &[Option<usize>],
        chunk: ChunkId,
        off: u32,
        kind: FixKind,
        expr: NodeId,
        loc: LocId,
    ) {
        let (seg, pos) = self.chunk_pos(chunk, off);
        let span = self.loc_span(loc);
        let value = if kind == FixKind::Branch {
            let next = self.prog.position(chunk, i64::from(off) + 1);
            match self.prog.eval(expr) {
                Ok(target @ Value::Addr { base, off: addend }) => {
                    match self.prog.binary(BinaryOp::Sub, target, next) {
                        Ok(distance) => Ok(distance),
                        Err(_) if !self.prog.chunks[chunk as usize].org => {
                            // Different section or an import: the linker's job.
                            if let Some(target) = self.base_target(base, out, sym_index)
                                && let Some(section) = out.seg_section[seg as usize]
                            {
                                out.sections[section].relocs.push(OutReloc {
                                    offset: pos,
                                    r_type: R_MOS_PCREL_8,
                                    target,
                                    addend,
                                });
                            }
                            return;
                        }
                        Err(_) => {
                            self.report_at(
                                loc,
                                diag::error(
                                    "asm::not-relocatable",
                                    span,
                                    "a branch in `.org` code cannot reach a label the linker places",
                                )
                                .help("use `jmp`, or put the branch in relocatable code"),
                            );
                            return;
                        }
                    }
                }
                Ok(target @ Value::Const(address)) => {
                    match self.prog.binary(BinaryOp::Sub, target, next) {
                        Ok(distance) => Ok(distance),
                        Err(_) => {
                            // Relocatable code branching to a fixed address.
                            if let Some(section) = out.seg_section[seg as usize] {
                                out.sections[section].relocs.push(OutReloc {
                                    offset: pos,
                                    r_type: R_MOS_PCREL_8,
                                    target: Target::Absolute,
                                    addend: address,
                                });
                            }
                            return;
                        }
                    }
                }
                Ok(_) => Err(EvalErr::NotRelocatable),
                Err(error) => Err(error),
            }
        } else {
            self.prog.eval(expr)
        };
        let data = &mut datas[seg as usize];
        let pos_usize = pos as usize;
        let value = match value {
            Ok(value) => value,
            // Arithmetic on addresses that ELF relocations cannot carry:
            // the linker finishes it from bytecode, as ld65 does.
            Err(EvalErr::NotRelocatable)
                if kind != FixKind::Branch && out.seg_section[seg as usize].is_some() =>
            {
                let mut ops = Vec::new();
                if self.compile(expr, out, sym_index, &mut ops, 0).is_some()
                    && let Some(section) = out.seg_section[seg as usize]
                {
                    out.fields.push(OutField {
                        section,
                        offset: pos,
                        kind,
                        ops,
                    });
                } else {
                    let saved = self.input.line_ctx;
                    self.input.line_ctx = self.prog.locs.get(loc as usize).map_or(0, |l| l.ctx);
                    self.eval_error(EvalErr::NotRelocatable, span);
                    self.input.line_ctx = saved;
                }
                return;
            }
            Err(error) => {
                let saved = self.input.line_ctx;
                self.input.line_ctx = self.prog.locs.get(loc as usize).map_or(0, |l| l.ctx);
                self.eval_error(error, span);
                self.input.line_ctx = saved;
                return;
            }
        };
        let (base, addend, r_type) = match value {
            Value::Const(v) => {
                if kind == FixKind::Branch {
                    if !(-128..=127).contains(&v) {
                        self.report_at(loc, branch_diag(span, v));
                        return;
                    }
                    if let Some(slot) = data.get_mut(pos_usize) {
                        *slot = v as u8;
                    }
                    return;
                }
                match const_bytes(kind, v) {
                    Ok(bytes) => {
                        let len = kind.len() as usize;
                        if let Some(slots) = data.get_mut(pos_usize..pos_usize + len) {
                            slots.copy_from_slice(&bytes[..len]);
                        }
                    }
                    Err((what, range)) => {
                        self.report_at(loc, field_range_diag(span, kind, v, what, range))
                    }
                }
                return;
            }
            Value::Addr { base, off } => {
                let r_type = match kind {
                    FixKind::Imm8 | FixKind::Byte => R_MOS_IMM8,
                    FixKind::Zp => R_MOS_ADDR8,
                    FixKind::Abs | FixKind::Word | FixKind::Dword => R_MOS_ADDR16,
                    FixKind::Far => R_MOS_ADDR24,
                    FixKind::Dbyt => {
                        // Big-endian: the high byte first, then the low byte.
                        self.push_reloc(out, sym_index, base, seg, pos, R_MOS_ADDR16_HI, off);
                        self.push_reloc(out, sym_index, base, seg, pos + 1, R_MOS_ADDR16_LO, off);
                        return;
                    }
                    FixKind::Branch => R_MOS_PCREL_8,
                };
                (base, off, r_type)
            }
            Value::Byte { sel, base, off } => {
                let r_type = match sel {
                    Sel::Lo => R_MOS_ADDR16_LO,
                    Sel::Hi => R_MOS_ADDR16_HI,
                    Sel::Bank => R_MOS_ADDR24_BANK,
                };
                // `.dbyt <x`: the byte goes in the low (second) position.
                let pos = if kind == FixKind::Dbyt { pos + 1 } else { pos };
                self.push_reloc(out, sym_index, base, seg, pos, r_type, off);
                return;
            }
            Value::Chunk { .. } => return,
        };
        self.push_reloc(out, sym_index, base, seg, pos, r_type, addend);
    }

    /// Warns about branches that land inside an instruction (typically
    /// `*+n` off by one, into the next instruction's operand).
    fn check_branches(&mut self, out: &Output, datas: &[Vec<u8>]) {
        if self.prog.branches.is_empty() {
            return;
        }
        // Instruction starts per segment, in order.
        let mut starts: Vec<Vec<(u32, u8, ChunkId)>> = vec![Vec::new(); self.prog.segs.len()];
        for item in &self.prog.items {
            if item.instr_len > 1 {
                let (seg, offset) = self.chunk_pos(item.chunk, item.off);
                starts[seg as usize].push((offset, item.instr_len, item.chunk));
            }
        }
        let mut relocated: Vec<Vec<u32>> = vec![Vec::new(); self.prog.segs.len()];
        for (seg, section) in out.seg_section.iter().enumerate() {
            if let Some(section) = section {
                relocated[seg] = out.sections[*section]
                    .relocs
                    .iter()
                    .map(|r| r.offset)
                    .collect();
                relocated[seg].sort_unstable();
            }
        }
        let branches = std::mem::take(&mut self.prog.branches);
        for &(chunk, off, loc) in &branches {
            let (seg, pos) = self.chunk_pos(chunk, off);
            if relocated[seg as usize].binary_search(&pos).is_ok() {
                continue;
            }
            let Some(&byte) = datas[seg as usize].get(pos as usize) else {
                continue;
            };
            let target = i64::from(pos) + 1 + i64::from(byte as i8);
            let list = &starts[seg as usize];
            let index = list.partition_point(|(start, _, _)| i64::from(*start) <= target);
            let Some(&(start, len, target_chunk)) = index.checked_sub(1).and_then(|i| list.get(i))
            else {
                continue;
            };
            let inside = target > i64::from(start) && target < i64::from(start) + i64::from(len);
            // Only when both ends are in one contiguous address run.
            let same_run = {
                let a = self
                    .prog
                    .position(chunk, i64::from(off) + 1 + i64::from(byte as i8));
                let c = &self.prog.chunks[target_chunk as usize];
                let b = self
                    .prog
                    .position(target_chunk, target - i64::from(c.start));
                a == b
            };
            if inside && same_run {
                let span = self.loc_span(loc);
                let into = target - i64::from(start);
                self.report_at(
                    loc,
                    diag::warning(
                        "asm::branch-into-instruction",
                        span,
                        format!("this branch lands on byte {into} of a {len}-byte instruction, not on its opcode"),
                    )
                    .help("check the target: `*+n` counts bytes from this branch's own first byte"),
                );
            }
        }
        self.prog.branches = branches;
    }

    fn check_asserts(&mut self, out: &mut Output, sym_index: &[Option<usize>]) {
        let asserts = std::mem::take(&mut self.prog.asserts);
        for a in &asserts {
            let span = self.loc_span(a.loc);
            let value = self.prog.eval(a.expr);
            match value {
                // `lderror`/`ldwarning`: the linker's to check, always.
                Ok(Value::Const(v)) if !a.link_only => {
                    if v == 0 {
                        let diag = if a.error {
                            diag::error("asm::assert", span, a.message.clone())
                        } else {
                            diag::warning("asm::assert", span, a.message.clone())
                        };
                        let diag = if a.message.starts_with("`jmp (pointer)`") {
                            RawDiag { code: "asm::jmp-page-wrap", ..diag }
                                .help("move the pointer so that it does not start at the last byte of a page")
                        } else {
                            diag
                        };
                        self.report_at(a.loc, diag);
                    }
                }
                Err(EvalErr::Undefined(_)) => {}
                Ok(_) | Err(EvalErr::NotRelocatable) => {
                    let mut ops = Vec::new();
                    if self.compile(a.expr, out, sym_index, &mut ops, 0).is_some() {
                        out.asserts.push(OutAssert {
                            error: a.error,
                            file: self.prog.locs[a.loc as usize].span.file,
                            line: a.line,
                            column: a.column,
                            message: a.message.clone(),
                            ops,
                        });
                    } else {
                        let saved = self.input.line_ctx;
                        self.input.line_ctx = self.prog.locs[a.loc as usize].ctx;
                        self.eval_error(EvalErr::NotRelocatable, span);
                        self.input.line_ctx = saved;
                    }
                }
                Err(error) => {
                    let saved = self.input.line_ctx;
                    self.input.line_ctx = self.prog.locs[a.loc as usize].ctx;
                    self.eval_error(error, span);
                    self.input.line_ctx = saved;
                }
            }
        }
        self.prog.asserts = asserts;
    }

    fn push_value(
        &self,
        value: Value,
        out: &Output,
        sym_index: &[Option<usize>],
        ops: &mut Vec<AssertOp>,
    ) -> Option<()> {
        match value {
            Value::Const(v) => ops.push(AssertOp::Const(v)),
            Value::Addr { base, off } => {
                ops.push(AssertOp::Target(self.base_target(base, out, sym_index)?));
                ops.push(AssertOp::Const(off));
                ops.push(AssertOp::Binary(BinaryOp::Add));
            }
            Value::Byte { sel, base, off } => {
                ops.push(AssertOp::Target(self.base_target(base, out, sym_index)?));
                ops.push(AssertOp::Const(off));
                ops.push(AssertOp::Binary(BinaryOp::Add));
                ops.push(AssertOp::Unary(match sel {
                    Sel::Lo => UnaryOp::LoByte,
                    Sel::Hi => UnaryOp::HiByte,
                    Sel::Bank => UnaryOp::BankByte,
                }));
            }
            Value::Chunk { .. } => return None,
        }
        Some(())
    }

    /// Compiles an expression to assertion bytecode.
    fn compile(
        &mut self,
        node: NodeId,
        out: &Output,
        sym_index: &[Option<usize>],
        ops: &mut Vec<AssertOp>,
        depth: u32,
    ) -> Option<()> {
        if depth > 200 {
            return None;
        }
        if let Ok(value) = self.prog.eval(node) {
            return self.push_value(value, out, sym_index, ops);
        }
        match *self.prog.nodes.get(node as usize)? {
            Node::Unary(op, inner) => {
                self.compile(inner, out, sym_index, ops, depth + 1)?;
                ops.push(AssertOp::Unary(op));
            }
            Node::Binary(op, left, right) => {
                self.compile(left, out, sym_index, ops, depth + 1)?;
                self.compile(right, out, sym_index, ops, depth + 1)?;
                ops.push(AssertOp::Binary(op));
            }
            Node::Sym(sym) => match self.prog.syms.get(sym as usize)?.def {
                SymDef::Expr(inner) | SymDef::Var(inner) => {
                    self.compile(inner, out, sym_index, ops, depth + 1)?
                }
                SymDef::Alias(other) => {
                    let node = self.prog.node(Node::Sym(other));
                    self.compile(node, out, sym_index, ops, depth + 1)?;
                }
                _ => return None,
            },
            _ => return None,
        }
        Some(())
    }
}
