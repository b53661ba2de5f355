//! Directives: data, segments, linkage, scopes, macros, structs, includes.

use std::path::Path;

use isa::objfmt::UnaryOp;

use crate::asm::{Asm, Frame, MAX_BYTES, PResult};
use crate::diag::{self, CtxKind, Span};
use crate::intern::{Dir, Keyword, NameId};
use crate::lexer::{Tok, Token};
use crate::model::{AssertRec, FixKind, Node, ScopeId, ScopeKind, SymDef, VarItem, VarKind};

/// A name in an `.import`/`.export` list, with `(label_like, expression
/// start)` when it is `name = expr` or `name := expr`.
type NameItem = (Token, Option<(bool, usize)>);

/// Largest `.repeat` count.
const MAX_REPEAT: i64 = 1 << 20;

impl Asm<'_> {
    pub(crate) fn directive(&mut self, dir: Dir, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        match dir {
            Dir::Byte
            | Dir::Asciiz
            | Dir::Word
            | Dir::Addr
            | Dir::Dbyt
            | Dir::Dword
            | Dir::Lobytes
            | Dir::Hibytes
            | Dir::Bankbytes => self.data(dir, t, p),
            Dir::Res => self.res(t, p),
            Dir::Align => self.align(t, p),
            Dir::Org => {
                let mut i = p + 1;
                let value = self.const_expr(t, &mut i, "`.org`")?;
                self.expect_end(t, i)?;
                if !(0..=0xFF_FFFF).contains(&value) {
                    let span = self.join(t[p + 1].span, t[i - 1].span);
                    return Err(self.report(crate::layout::range_diag(
                        span,
                        "`.org` address",
                        value,
                        (0, 0xFF_FFFF),
                    )));
                }
                self.new_chunk(true, Some(value));
                Ok(())
            }
            Dir::Reloc => {
                self.expect_end(t, p + 1)?;
                self.new_chunk(false, None);
                Ok(())
            }
            Dir::Segment => self.segment_directive(t, p),
            Dir::Code | Dir::Rodata | Dir::Data | Dir::Bss | Dir::Zeropage => {
                self.expect_end(t, p + 1)?;
                let (name, zp) = match dir {
                    Dir::Code => ("CODE", false),
                    Dir::Rodata => ("RODATA", false),
                    Dir::Data => ("DATA", false),
                    Dir::Bss => ("BSS", false),
                    _ => ("ZEROPAGE", true),
                };
                self.seg = self.segment(name, zp);
                Ok(())
            }
            Dir::Import | Dir::Importzp => self.import(t, p, dir == Dir::Importzp),
            Dir::Export | Dir::Exportzp | Dir::Global | Dir::Globalzp => self.export(
                t,
                p,
                matches!(dir, Dir::Exportzp | Dir::Globalzp),
                matches!(dir, Dir::Global | Dir::Globalzp),
            ),
            Dir::Macro => self.define_macro(t, p),
            Dir::Endmacro => {
                Err(self.err("asm::unbalanced", head.span, "`.endmacro` without `.macro`"))
            }
            Dir::Endrepeat => Err(self.err(
                "asm::unbalanced",
                head.span,
                "`.endrepeat` without `.repeat`",
            )),
            Dir::Local => self.local(t, p),
            Dir::Exitmacro => self.exit_macro(t, p),
            Dir::Repeat => self.repeat(t, p),
            Dir::Elseif | Dir::Else | Dir::Endif => self.conditional(dir, &t[p..]),
            _ if dir.opens_conditional() => self.conditional(dir, &t[p..]),
            Dir::Define => self.define_text(t, p),
            Dir::Undefine => {
                let Some(name) = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied() else {
                    let span = self.span_at(t, p + 1);
                    return Err(self.err("asm::syntax", span, "expected the name of a `.define`"));
                };
                self.expect_end(t, p + 2)?;
                if let Some(info) = self.names.info_mut(name.name()) {
                    info.define_id = None;
                }
                Ok(())
            }
            Dir::Struct | Dir::Union => self.structure(t, p, dir == Dir::Union),
            Dir::Endstruct | Dir::Endunion | Dir::Endenum => Err(self.err(
                "asm::unbalanced",
                head.span,
                format!(
                    "`{}` without its opening directive",
                    self.names.name(head.name())
                ),
            )),
            Dir::Enum => self.enumeration(t, p),
            Dir::Tag => {
                let mut i = p + 1;
                let scope = self.scope_name(t, &mut i)?;
                self.expect_end(t, i)?;
                let size = self.prog.scopes[scope as usize].size.unwrap_or(0);
                self.item(head.span, 0);
                self.reserve(size, None, head.span)
            }
            Dir::Charmap => {
                let mut i = p + 1;
                let from = self.const_expr(t, &mut i, "`.charmap`")?;
                let from_span = self.join(t[p + 1].span, t[i - 1].span);
                self.comma(t, &mut i)?;
                let to_start = i;
                let to = self.const_expr(t, &mut i, "`.charmap`")?;
                let to_span = self.join(t[to_start].span, t[i - 1].span);
                self.expect_end(t, i)?;
                // The caret goes under the code that is out of range.
                for (value, span) in [(from, from_span), (to, to_span)] {
                    if !(0..=255).contains(&value) {
                        return Err(self.report(crate::layout::range_diag(
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
            Dir::Assert => self.assert(t, p),
            Dir::Error | Dir::Warning | Dir::Out | Dir::Fatal => self.message(dir, t, p),
            Dir::Proc => self.open_scope(t, p, true),
            Dir::Scope => self.open_scope(t, p, false),
            Dir::Endproc | Dir::Endscope => self.close_scope(t, p, dir == Dir::Endproc),
            Dir::Setcpu => {
                let Some(cpu) = t.get(p + 1).filter(|t| t.kind == Tok::Str).copied() else {
                    let span = self.span_at(t, p + 1);
                    return Err(self.err(
                        "asm::syntax",
                        span,
                        "expected a CPU name (`\"6502\"` or `\"6502X\"`)",
                    ));
                };
                self.expect_end(t, p + 2)?;
                let name = String::from_utf8_lossy(&self.string_bytes(&cpu)).to_ascii_uppercase();
                match name.as_str() {
                    "6502" => self.cpu_x = false,
                    "6502X" => self.cpu_x = true,
                    _ => {
                        return Err(self.report(
                            diag::error(
                                "asm::cpu",
                                cpu.span,
                                format!("the Scorpion's CPU is an NMOS 6502; `{name}` is not supported"),
                            )
                            .help("use `.setcpu \"6502\"`, or `\"6502X\"` for the undocumented opcodes"),
                        ));
                    }
                }
                Ok(())
            }
            Dir::P02 => {
                self.expect_end(t, p + 1)?;
                self.cpu_x = false;
                Ok(())
            }
            Dir::NoEffect => {
                let name = self.names.name(head.name()).to_string();
                let span = self.join(head.span, t[t.len() - 1].span);
                let diag = diag::warning(
                    "asm::no-effect",
                    span,
                    format!("`{name}` has no effect with this assembler; the line is ignored"),
                );
                self.report(diag);
                Ok(())
            }
            Dir::Feature => {
                let span = self.join(head.span, t[t.len() - 1].span);
                let diag = diag::warning(
                    "asm::feature",
                    span,
                    "`.feature` switches are not supported; this line is ignored",
                );
                self.report(diag);
                Ok(())
            }
            Dir::List => {
                let on = match t.get(p + 1) {
                    Some(tok) if tok.kind == Tok::Plus => true,
                    Some(tok) if tok.kind == Tok::Minus => false,
                    Some(tok) if tok.kind == Tok::Ident => {
                        let word = self.names.name(tok.name()).to_ascii_lowercase();
                        match word.as_str() {
                            "on" => true,
                            "off" => false,
                            _ => {
                                return Err(self.err(
                                    "asm::syntax",
                                    tok.span,
                                    "expected `on` or `off`",
                                ));
                            }
                        }
                    }
                    _ => {
                        let span = self.span_at(t, p + 1);
                        return Err(self.err("asm::syntax", span, "expected `on` or `off`"));
                    }
                };
                self.expect_end(t, p + 2)?;
                if let Some(listing) = self.listing.as_mut() {
                    listing.enabled = on;
                }
                Ok(())
            }
            Dir::Include => self.include(t, p),
            Dir::Incbin => self.incbin(t, p),
            Dir::Set => Err(self.err(
                "asm::syntax",
                head.span,
                "`.set` goes after a name: `counter .set counter + 1`",
            )),
            _ => {
                let name = self.names.name(head.name()).to_string();
                Err(self.err(
                    "asm::syntax",
                    head.span,
                    format!("`{name}` is a function for expressions, not a statement"),
                ))
            }
        }
    }

    fn comma(&mut self, t: &[Token], i: &mut usize) -> PResult<()> {
        if t.get(*i).map(|t| t.kind) == Some(Tok::Comma) {
            *i += 1;
            return Ok(());
        }
        let span = self.span_at(t, *i);
        Err(self.err("asm::syntax", span, "expected `,`"))
    }

    fn data(&mut self, dir: Dir, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let mut i = p + 1;
        self.item(head.span, 0);
        if i == t.len() {
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
            _ => FixKind::Byte,
        };
        loop {
            let tok = t[i];
            let is_text = tok.kind == Tok::Str
                && matches!(dir, Dir::Byte | Dir::Asciiz)
                && matches!(t.get(i + 1).map(|t| t.kind), None | Some(Tok::Comma));
            if is_text {
                let bytes: Vec<u8> = self
                    .string_bytes(&tok)
                    .iter()
                    .map(|b| self.charmap[usize::from(*b)])
                    .collect();
                self.emit(&bytes);
                i += 1;
            } else {
                let start = i;
                let mut expr = self.expression(t, &mut i)?;
                let span = self.join(t[start].span, t[i - 1].span);
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
            match t.get(i).map(|t| t.kind) {
                None => break,
                Some(Tok::Comma) if i + 1 < t.len() => i += 1,
                _ => {
                    let span = self.span_at(t, i);
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
    fn reserve(&mut self, count: i64, fill: Option<u8>, span: Span) -> PResult<()> {
        if count < 0 || self.total_bytes.saturating_add(count as usize) > MAX_BYTES {
            let diag = if count < 0 {
                crate::layout::range_diag(span, "reserved size", count, (0, MAX_BYTES as i64))
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

    fn res(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let mut i = p + 1;
        let count = self.const_expr(t, &mut i, "`.res`")?;
        let mut fill = None;
        if t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
            i += 1;
            let start = i;
            let value = self.const_expr(t, &mut i, "the `.res` fill value")?;
            if !(0..=255).contains(&value) {
                let span = self.join(t[start].span, t[i - 1].span);
                return Err(self.report(crate::layout::range_diag(
                    span,
                    "fill value",
                    value,
                    (0, 255),
                )));
            }
            fill = Some(value as u8);
        }
        self.expect_end(t, i)?;
        self.item(head.span, 0);
        let span = self.join(t[p + 1].span, t[i - 1].span);
        self.reserve(count, fill, span)
    }

    fn align(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let mut i = p + 1;
        let align = self.const_expr(t, &mut i, "`.align`")?;
        let span = self.join(t[p + 1].span, t[i - 1].span);
        let mut fill = 0u8;
        let mut filled = false;
        if t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
            i += 1;
            let value = self.const_expr(t, &mut i, "the `.align` fill value")?;
            if !(0..=255).contains(&value) {
                let span = self.join(t[p + 1].span, t[i - 1].span);
                return Err(self.report(crate::layout::range_diag(
                    span,
                    "fill value",
                    value,
                    (0, 255),
                )));
            }
            fill = value as u8;
            filled = true;
        }
        self.expect_end(t, i)?;
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
        let chunk = &self.prog.chunks[cur];
        if !chunk.org {
            let s = &mut self.prog.segs[seg];
            s.align = s.align.max(align);
        }
        let position = if chunk.org {
            chunk.known_abs.map(|abs| abs + i64::from(chunk.len))
        } else {
            chunk.known_start.map(|start| i64::from(start + chunk.len))
        };
        self.item(t[p].span, 0);
        match position {
            Some(position) => {
                let pad =
                    (i64::from(align) - position.rem_euclid(i64::from(align))) % i64::from(align);
                if filled {
                    self.emit(&vec![fill; pad as usize]);
                    Ok(())
                } else {
                    self.reserve(pad, None, span)
                }
            }
            None => {
                let loc = self.loc(span);
                let id = self.prog.vars.len() as u32;
                self.prog.vars.push(VarItem {
                    kind: VarKind::Align {
                        align,
                        fill: filled.then_some(fill),
                    },
                    loc,
                    size: 0,
                });
                self.prog.chunks[cur].var = Some(id);
                if filled {
                    self.prog.segs[seg].has_data = true;
                }
                self.total_bytes += align as usize;
                let org = self.prog.chunks[cur].org;
                self.new_chunk(org, None);
                Ok(())
            }
        }
    }

    fn segment_directive(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let Some(name) = t.get(p + 1).filter(|t| t.kind == Tok::Str).copied() else {
            let span = self.span_at(t, p + 1);
            return Err(self.err(
                "asm::syntax",
                span,
                "expected a segment name in quotes: `.segment \"CODE\"`",
            ));
        };
        let text = String::from_utf8_lossy(&self.string_bytes(&name)).into_owned();
        if text.is_empty() || !text.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(self.err(
                "asm::syntax",
                name.span,
                "a segment name is letters, digits and `_`",
            ));
        }
        let mut zp = false;
        let mut i = p + 2;
        if t.get(i).map(|t| t.kind) == Some(Tok::Colon) {
            let Some(kind) = t.get(i + 1).filter(|t| t.kind == Tok::Ident).copied() else {
                let span = self.span_at(t, i + 1);
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
            i += 2;
        }
        self.expect_end(t, i)?;
        let seg = self.segment(&text, zp);
        if zp && !self.prog.segs[seg as usize].zp {
            return Err(self.err(
                "asm::segment",
                name.span,
                format!("segment `{text}` was first used as an absolute segment"),
            ));
        }
        self.seg = seg;
        Ok(())
    }

    /// A comma-separated list of names for `.import`/`.export`.
    fn name_list(&mut self, t: &[Token], p: usize) -> PResult<Vec<NameItem>> {
        let mut names = Vec::new();
        let mut i = p + 1;
        loop {
            let Some(tok) = t.get(i).filter(|t| t.kind == Tok::Ident).copied() else {
                let span = self.span_at(t, i);
                return Err(self.err("asm::syntax", span, "expected a symbol name"));
            };
            i += 1;
            // `.export name = expr` / `name := expr`.
            let mut assignment = None;
            if matches!(t.get(i).map(|t| t.kind), Some(Tok::Eq | Tok::Assign)) {
                assignment = Some((t[i].kind == Tok::Assign, i + 1));
                let mut depth = 0;
                i += 1;
                while let Some(next) = t.get(i) {
                    match next.kind {
                        Tok::LParen => depth += 1,
                        Tok::RParen => depth -= 1,
                        Tok::Comma if depth == 0 => break,
                        _ => {}
                    }
                    i += 1;
                }
            }
            names.push((tok, assignment));
            match t.get(i).map(|t| t.kind) {
                None => return Ok(names),
                Some(Tok::Comma) => i += 1,
                _ => {
                    let span = self.span_at(t, i);
                    return Err(self.err("asm::syntax", span, "expected `,` and another name"));
                }
            }
        }
    }

    fn import(&mut self, t: &[Token], p: usize, zp: bool) -> PResult<()> {
        for (tok, assignment) in self.name_list(t, p)? {
            if assignment.is_some() {
                return Err(self.err("asm::syntax", tok.span, "an import has no value here"));
            }
            self.reserved_name(&tok, false)?;
            let sym = self.sym_in(self.scope, tok.name());
            match self.prog.syms[sym as usize].def {
                SymDef::Undefined => {
                    self.define(sym, SymDef::Import { zp }, tok.span)?;
                }
                SymDef::Import { zp: was } if was == zp => {}
                _ => {
                    let name = self.sym_name(sym);
                    let mut diag = diag::error(
                        "asm::duplicate",
                        tok.span,
                        format!("`{name}` is defined in this file and cannot be imported"),
                    );
                    if let Some(loc) = self.prog.syms[sym as usize].def_loc {
                        diag = diag.also(self.prog.locs[loc as usize].span, "defined here");
                    }
                    return Err(self.report(diag));
                }
            }
        }
        Ok(())
    }

    fn export(&mut self, t: &[Token], p: usize, zp: bool, global: bool) -> PResult<()> {
        for (tok, assignment) in self.name_list(t, p)? {
            let sym = self.sym_in(self.scope, tok.name());
            if let Some((_, start)) = assignment {
                let mut i = start;
                let expr = self.expression(t, &mut i)?;
                let def = match self.prog.eval(expr) {
                    Ok(crate::expr::Value::Const(value)) => SymDef::Const(value),
                    _ => {
                        self.keep_nodes = true;
                        SymDef::Expr(expr)
                    }
                };
                self.define(sym, def, tok.span)?;
            }
            let loc = self.loc(tok.span);
            let s = &mut self.prog.syms[sym as usize];
            s.export = Some(zp);
            s.global |= global;
            if s.export_loc.is_none() {
                s.export_loc = Some(loc);
            }
        }
        Ok(())
    }

    fn define_macro(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let Some(name) = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied() else {
            let span = self.span_at(t, p + 1);
            // Still skip the body so it is not assembled.
            let _ = self.collect_body(Dir::Macro, Dir::Endmacro, &[], head.span);
            return Err(self.err("asm::syntax", span, "expected the macro's name"));
        };
        let reserved = self.reserved_name(&name, true);
        let mut params: Vec<NameId> = Vec::new();
        let mut i = p + 2;
        let mut bad = None;
        while i < t.len() {
            match t[i].kind {
                Tok::Ident if !params.contains(&t[i].name()) => params.push(t[i].name()),
                Tok::Comma => {}
                _ => {
                    bad.get_or_insert(t[i].span);
                }
            }
            i += 1;
        }
        let body = self.collect_body(Dir::Macro, Dir::Endmacro, &params, head.span);
        reserved?;
        for param in t[p + 2..].iter().filter(|tok| tok.kind == Tok::Ident) {
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
            return Err(crate::asm::Reported);
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
        let id = self.macros.len() as u32;
        self.macros.push(crate::asm::Macro {
            name: name.name(),
            params,
            body: std::rc::Rc::new(body),
        });
        if let Some(info) = self.names.info_mut(name.name()) {
            info.macro_id = Some(id);
        }
        Ok(())
    }

    fn local(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let Some(index) = self
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
        let mut i = p + 1;
        while i < t.len() {
            match t[i].kind {
                Tok::Ident => names.push(t[i].name()),
                Tok::Comma => {}
                _ => return Err(self.err("asm::syntax", t[i].span, "expected a name")),
            }
            i += 1;
        }
        let serial = self.ctx.len();
        let renamed: Vec<(NameId, NameId)> = names
            .iter()
            .map(|name| {
                let text = format!("{}.{serial}", self.names.name(*name));
                (*name, self.names.intern(&text))
            })
            .collect();
        if let Some(Frame::Macro { locals, .. }) = self.frames.get_mut(index) {
            locals.extend(renamed);
        }
        Ok(())
    }

    fn exit_macro(&mut self, t: &[Token], p: usize) -> PResult<()> {
        self.expect_end(t, p + 1)?;
        let Some(index) = self
            .frames
            .iter()
            .rposition(|frame| matches!(frame, Frame::Macro { .. }))
        else {
            return Err(self.err("asm::syntax", t[p].span, "`.exitmacro` outside a macro"));
        };
        let conds = match &self.frames[index] {
            Frame::Macro { conds, .. } => *conds,
            _ => self.conds.len(),
        };
        self.frames.truncate(index);
        self.conds.truncate(conds);
        Ok(())
    }

    fn repeat(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let mut i = p + 1;
        let count = self.const_expr(t, &mut i, "`.repeat`");
        let mut var = None;
        if count.is_ok() && t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
            match t.get(i + 1).filter(|t| t.kind == Tok::Ident) {
                Some(tok) => var = Some(tok.name()),
                None => {
                    let span = self.span_at(t, i + 1);
                    self.err("asm::syntax", span, "expected the name of the counter");
                }
            }
            i += 2;
        }
        let end_ok = count.is_ok() && self.expect_end(t, i).is_ok();
        let body = self.collect_body(Dir::Repeat, Dir::Endrepeat, &[], head.span);
        let count = count?;
        if !end_ok {
            return Err(crate::asm::Reported);
        }
        let Some(body) = body else {
            return Err(crate::asm::Reported);
        };
        if !(0..=MAX_REPEAT).contains(&count) {
            let span = t[p + 1].span;
            return Err(self.report(crate::layout::range_diag(
                span,
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
        self.frames.push(Frame::Repeat {
            body: std::rc::Rc::new(body),
            line: 0,
            iter: 0,
            count: count as u32,
            var,
            ctx,
            conds: self.conds.len(),
        });
        Ok(())
    }

    fn define_text(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let Some(name) = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied() else {
            let span = self.span_at(t, p + 1);
            return Err(self.err("asm::syntax", span, "expected the name to define"));
        };
        self.reserved_name(&name, true)?;
        let mut i = p + 2;
        let mut params = Vec::new();
        let mut has_params = false;
        if let Some(open) = t.get(i)
            && open.kind == Tok::LParen
            && open.span.start == name.span.end
        {
            has_params = true;
            i += 1;
            loop {
                match t.get(i).map(|t| t.kind) {
                    Some(Tok::Ident) => params.push(t[i].name()),
                    Some(Tok::Comma) => {}
                    Some(Tok::RParen) => {
                        i += 1;
                        break;
                    }
                    _ => {
                        let span = self.span_at(t, i);
                        return Err(self.err(
                            "asm::syntax",
                            span,
                            "expected parameter names and `)`",
                        ));
                    }
                }
                i += 1;
            }
        }
        let id = self.defines.len() as u32;
        self.defines.push(crate::asm::Define {
            params,
            has_params,
            tokens: t[i..].to_vec(),
        });
        if let Some(info) = self.names.info_mut(name.name()) {
            info.define_id = Some(id);
        }
        self.any_define = true;
        Ok(())
    }

    /// Resolves a scope name (`s`, `a::s`, `::s`) that must exist.
    fn scope_name(&mut self, t: &[Token], i: &mut usize) -> PResult<ScopeId> {
        let start = self.span_at(t, *i);
        let mut scope: Option<ScopeId> = None;
        if t.get(*i).map(|t| t.kind) == Some(Tok::ColonColon) {
            scope = Some(crate::model::GLOBAL_SCOPE);
            *i += 1;
        }
        loop {
            let Some(tok) = t.get(*i).filter(|t| t.kind == Tok::Ident).copied() else {
                let span = self.span_at(t, *i);
                return Err(self.err("asm::syntax", span, "expected a struct name"));
            };
            *i += 1;
            let found = match scope {
                None => self.lookup_scope(tok.name()),
                Some(s) => self.child_scope(s, tok.name()),
            };
            let Some(found) = found else {
                let name = self.names.name(tok.name()).to_string();
                return Err(self.err(
                    "asm::undefined",
                    self.join(start, tok.span),
                    format!("no struct, union or scope named `{name}` is defined here"),
                ));
            };
            scope = Some(found);
            if t.get(*i).map(|t| t.kind) == Some(Tok::ColonColon) {
                *i += 1;
            } else {
                return Ok(found);
            }
        }
    }

    /// `.struct` / `.union`: member offsets as constants in a scope.
    fn structure(&mut self, t: &[Token], p: usize, union: bool) -> PResult<()> {
        let head = t[p];
        let name = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied();
        self.expect_end(t, p + if name.is_some() { 2 } else { 1 })?;
        if let Some(name) = name {
            // Reported; the members are still read up to the end.
            let _ = self.reserved_name(&name, false);
        }
        let (closer, kind) = if union {
            (Dir::Endunion, ScopeKind::Union)
        } else {
            (Dir::Endstruct, ScopeKind::Struct)
        };
        let scope = match name {
            Some(name) => {
                let scope = self.child_scope_or_new(self.scope, name.name(), kind);
                if self.prog.scopes[scope as usize].size.is_some() {
                    let text = self.names.name(name.name()).to_string();
                    self.err(
                        "asm::duplicate",
                        name.span,
                        format!("`{text}` is already defined"),
                    );
                }
                scope
            }
            None => self.scope,
        };
        let size = self.struct_members(scope, union, closer, head.span, 0)?;
        if name.is_some() {
            self.prog.scopes[scope as usize].size = Some(size);
            self.prog.scopes[scope as usize].kind = kind;
        }
        Ok(())
    }

    /// Reads members up to `closer`; returns the size. Nested anonymous
    /// `.struct`/`.union` members add their members to the same scope.
    fn struct_members(
        &mut self,
        scope: ScopeId,
        union: bool,
        closer: Dir,
        start: Span,
        depth: u32,
    ) -> PResult<i64> {
        let mut offset: i64 = 0;
        let mut size: i64 = 0;
        loop {
            let Some(_) = self.fetch_raw() else {
                return Err(self.err("asm::unclosed", start, "this struct has no end directive"));
            };
            let t = std::mem::take(&mut self.toks);
            let result = self.struct_member(&t, scope, union, closer, offset, depth);
            self.toks = t;
            match result {
                Ok(Some(member_size)) => {
                    if union {
                        size = size.max(member_size);
                    } else {
                        offset = offset.saturating_add(member_size);
                        size = offset;
                    }
                }
                Ok(None) => return Ok(size),
                Err(_) => {}
            }
        }
    }

    /// One member line; `Ok(None)` at the closing directive.
    fn struct_member(
        &mut self,
        t: &[Token],
        scope: ScopeId,
        union: bool,
        closer: Dir,
        offset: i64,
        depth: u32,
    ) -> PResult<Option<i64>> {
        if t.is_empty() {
            return Ok(Some(0));
        }
        let mut i = 0;
        let mut name = None;
        if t[0].kind == Tok::Ident {
            name = Some(t[0]);
            i = 1;
        }
        let Some(dir_tok) = t.get(i).copied() else {
            return Err(self.err(
                "asm::syntax",
                t[0].span,
                "a member needs a size: `.byte`, `.word`, `.res n`, `.tag s`",
            ));
        };
        let dir = match (dir_tok.kind, self.names.keyword(dir_tok.name())) {
            (Tok::Directive, Keyword::Directive(dir)) => dir,
            _ => {
                return Err(self.err(
                    "asm::syntax",
                    dir_tok.span,
                    "a member needs a size: `.byte`, `.word`, `.res n`, `.tag s`",
                ));
            }
        };
        if dir == closer && name.is_none() {
            self.expect_end(t, i + 1)?;
            return Ok(None);
        }
        i += 1;
        let member_size = match dir {
            Dir::Byte | Dir::Word | Dir::Addr | Dir::Dword | Dir::Dbyt | Dir::Res => {
                let unit = match dir {
                    Dir::Byte | Dir::Res => 1,
                    Dir::Dword => 4,
                    _ => 2,
                };
                let count = if i < t.len() {
                    self.const_expr(t, &mut i, "a member size")?
                } else if dir == Dir::Res {
                    return Err(self.err("asm::syntax", dir_tok.span, "`.res` needs a size"));
                } else {
                    1
                };
                if !(0..=0xFFFF).contains(&count) {
                    return Err(self.report(crate::layout::range_diag(
                        dir_tok.span,
                        "member size",
                        count,
                        (0, 0xFFFF),
                    )));
                }
                unit * count
            }
            Dir::Tag => {
                let tagged = self.scope_name(t, &mut i)?;
                let unit = self.prog.scopes[tagged as usize].size.unwrap_or(0);
                let count = if i < t.len() {
                    self.const_expr(t, &mut i, "a member count")?
                } else {
                    1
                };
                unit.saturating_mul(count.clamp(0, 0xFFFF))
            }
            Dir::Struct | Dir::Union if name.is_none() && depth < 16 => {
                let closer = if dir == Dir::Union {
                    Dir::Endunion
                } else {
                    Dir::Endstruct
                };
                // Members of the nested block are offset from here.
                let before = self.prog.syms.len();
                let size =
                    self.struct_members(scope, dir == Dir::Union, closer, dir_tok.span, depth + 1)?;
                for sym in before..self.prog.syms.len() {
                    if let SymDef::Const(value) = self.prog.syms[sym].def
                        && self.prog.syms[sym].scope == scope
                    {
                        self.prog.syms[sym].def = SymDef::Const(value + offset);
                    }
                }
                return Ok(Some(size));
            }
            _ => {
                return Err(self.err(
                    "asm::syntax",
                    dir_tok.span,
                    "a member needs a size: `.byte`, `.word`, `.res n`, `.tag s`",
                ));
            }
        };
        self.expect_end(t, i)?;
        if let Some(name) = name {
            self.reserved_name(&name, false)?;
            let sym = self.sym_in(scope, name.name());
            let value = if union { 0 } else { offset };
            self.define(sym, SymDef::Const(value), name.span)?;
        }
        Ok(Some(member_size))
    }

    fn enumeration(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let name = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied();
        self.expect_end(t, p + if name.is_some() { 2 } else { 1 })?;
        if let Some(name) = name {
            // Reported; the members are still read up to the end.
            let _ = self.reserved_name(&name, false);
        }
        let scope = match name {
            Some(name) => self.child_scope_or_new(self.scope, name.name(), ScopeKind::Enum),
            None => self.scope,
        };
        let mut next: i64 = 0;
        let mut count: i64 = 0;
        loop {
            let Some(_) = self.fetch_raw() else {
                return Err(self.err("asm::unclosed", head.span, "`.enum` has no `.endenum`"));
            };
            let t = std::mem::take(&mut self.toks);
            let result = self.enum_member(&t, scope, next);
            self.toks = t;
            match result {
                Ok(Some(value)) => {
                    next = isa::objfmt::BinaryOp::Add.apply(value, 1).unwrap_or(value);
                    count += 1;
                }
                Ok(None) => break,
                Err(_) => {}
            }
        }
        if name.is_some() {
            self.prog.scopes[scope as usize].size = Some(count);
        }
        Ok(())
    }

    fn enum_member(&mut self, t: &[Token], scope: ScopeId, next: i64) -> PResult<Option<i64>> {
        let Some(first) = t.first().copied() else {
            return Ok(Some(next.wrapping_sub(1)));
        };
        if first.kind == Tok::Directive
            && self.names.keyword(first.name()) == Keyword::Directive(Dir::Endenum)
        {
            self.expect_end(t, 1)?;
            return Ok(None);
        }
        if first.kind != Tok::Ident {
            return Err(self.err("asm::syntax", first.span, "expected a member name"));
        }
        let mut value = next;
        let mut i = 1;
        if t.get(1).map(|t| t.kind) == Some(Tok::Eq) {
            i = 2;
            value = self.const_expr(t, &mut i, "an `.enum` value")?;
        }
        self.expect_end(t, i)?;
        self.reserved_name(&first, false)?;
        let sym = self.sym_in(scope, first.name());
        self.define(sym, SymDef::Const(value), first.span)?;
        Ok(Some(value))
    }

    fn assert(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let mut i = p + 1;
        let start = i;
        let expr = self.expression(t, &mut i)?;
        let span = self.join(self.span_at(t, start), t[i - 1].span);
        self.comma(t, &mut i)?;
        let Some(action) = t.get(i).filter(|t| t.kind == Tok::Ident).copied() else {
            let span = self.span_at(t, i);
            return Err(self.err(
                "asm::syntax",
                span,
                "expected `error`, `warning`, `lderror` or `ldwarning`",
            ));
        };
        i += 1;
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
        if t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
            i += 1;
            let Some(text) = t.get(i).filter(|t| t.kind == Tok::Str).copied() else {
                let span = self.span_at(t, i);
                return Err(self.err("asm::syntax", span, "expected the message in quotes"));
            };
            message = String::from_utf8_lossy(&self.string_bytes(&text)).into_owned();
            i += 1;
        }
        self.expect_end(t, i)?;
        let loc = self.loc(span);
        let column = self.column_of(head.span);
        self.keep_nodes = true;
        self.prog.asserts.push(AssertRec {
            expr,
            error,
            link_only,
            message,
            loc,
            line: self.line.line,
            column,
        });
        Ok(())
    }

    fn message(&mut self, dir: Dir, t: &[Token], p: usize) -> PResult<()> {
        let head = t[p];
        let Some(text) = t.get(p + 1).filter(|t| t.kind == Tok::Str).copied() else {
            let span = self.span_at(t, p + 1);
            return Err(self.err("asm::syntax", span, "expected a message in quotes"));
        };
        self.expect_end(t, p + 2)?;
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

    fn open_scope(&mut self, t: &[Token], p: usize, proc_: bool) -> PResult<()> {
        let head = t[p];
        let name_tok = t.get(p + 1).filter(|t| t.kind == Tok::Ident).copied();
        let end = p + if name_tok.is_some() { 2 } else { 1 };
        self.expect_end(t, end)?;
        if let Some(tok) = name_tok {
            // Reported; the scope still opens, so its end matches.
            let _ = self.reserved_name(&tok, false);
        }
        let name = match name_tok {
            Some(tok) => tok.name(),
            None if proc_ => {
                let span = self.span_at(t, p + 1);
                return Err(self.err("asm::syntax", span, "`.proc` needs a name"));
            }
            None => {
                let text = format!(".anonymous{}", self.prog.scopes.len());
                self.names.intern(&text)
            }
        };
        if proc_ && let Some(tok) = name_tok {
            self.define_label(&tok)?;
        }
        let kind = if proc_ {
            ScopeKind::Proc
        } else {
            ScopeKind::Scope
        };
        let scope = self.child_scope_or_new(self.scope, name, kind);
        if self.prog.scopes[scope as usize].start.is_some() {
            let text = self.names.name(name).to_string();
            return Err(self.err(
                "asm::duplicate",
                name_tok.map_or(head.span, |t| t.span),
                format!("scope `{text}` is already defined"),
            ));
        }
        let here = self.here();
        let info = &mut self.prog.scopes[scope as usize];
        info.start = Some(here);
        info.kind = kind;
        let loc = self.loc(head.span);
        self.scope_stack.push((scope, loc));
        self.scope = scope;
        Ok(())
    }

    fn close_scope(&mut self, t: &[Token], p: usize, proc_: bool) -> PResult<()> {
        let head = t[p];
        self.expect_end(t, p + 1)?;
        let Some(&(scope, _)) = self.scope_stack.last() else {
            return Err(self.err(
                "asm::unbalanced",
                head.span,
                format!("`{}` without an open scope", self.names.name(head.name())),
            ));
        };
        let kind = self.prog.scopes[scope as usize].kind;
        if (kind == ScopeKind::Proc) != proc_ {
            let want = if kind == ScopeKind::Proc {
                ".endproc"
            } else {
                ".endscope"
            };
            return Err(self.err(
                "asm::unbalanced",
                head.span,
                format!("the open scope is closed with `{want}`"),
            ));
        }
        let here = self.here();
        self.prog.scopes[scope as usize].end = Some(here);
        self.scope_stack.pop();
        self.scope = self.prog.scopes[scope as usize].parent;
        Ok(())
    }

    /// The file name operand of `.include`/`.incbin`.
    fn file_operand(&mut self, t: &[Token], p: usize) -> PResult<(Token, String)> {
        let Some(tok) = t.get(p + 1).filter(|t| t.kind == Tok::Str).copied() else {
            let span = self.span_at(t, p + 1);
            return Err(self.err("asm::syntax", span, "expected a file name in quotes"));
        };
        let name = String::from_utf8_lossy(&self.string_bytes(&tok)).into_owned();
        Ok((tok, name))
    }

    /// A file `.include` or `.incbin` cannot find: the error names every
    /// place searched, in order. A missing include ends the assembly, as
    /// in ca65: what follows it depends on it, and every error there would
    /// only repeat this one.
    fn not_found(&mut self, tok: Token, name: &str, binary: bool) -> crate::asm::Reported {
        let including = self.current_dir();
        let mut places: Vec<String> = self
            .search_path(binary, &including)
            .iter()
            .map(|dir| {
                let shown = match dir.as_os_str().is_empty() {
                    true => "`.`".to_string(),
                    false => format!("`{}`", dir.display()),
                };
                let role = if *dir == including {
                    " (the including file's directory)"
                } else if dir.as_os_str().is_empty() {
                    " (the working directory)"
                } else if binary {
                    " (--bin-include-dir)"
                } else {
                    " (-I)"
                };
                format!("{shown}{role}")
            })
            .collect();
        let mut help_tail = String::new();
        if !binary {
            let builtin: Vec<&str> = self
                .opts
                .builtin_includes
                .keys()
                .map(String::as_str)
                .collect();
            if !builtin.is_empty() {
                places.push(format!("the built-in `{}`", builtin.join("`, `")));
            }
            if let Some(close) = diag::did_you_mean(name, builtin.iter().copied()) {
                help_tail = format!("; did you mean `{close}`?");
            }
            self.fatal = true;
            self.stop = true;
        }
        let option = if binary { "--bin-include-dir" } else { "-I" };
        let diag = diag::error(
            "asm::file-not-found",
            tok.span,
            format!("cannot find `{name}`"),
        )
        .label("not found")
        .help(format!(
            "searched {}{help_tail}\nadd a directory to search with `{option} DIR`",
            places.join(", ")
        ));
        self.report(diag)
    }

    fn include(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let (tok, name) = self.file_operand(t, p)?;
        self.expect_end(t, p + 2)?;
        self.frame_room(tok.span)?;
        let dir = self.current_dir();
        let Some((path, bytes)) = self.find_file(&name, false, &dir) else {
            return Err(self.not_found(tok, &name, false));
        };
        let ctx = self.new_ctx(CtxKind::Include, self.join(t[p].span, tok.span));
        let parent = path.parent().map(Path::to_path_buf).unwrap_or_default();
        self.push_file(path.display().to_string(), bytes, parent, ctx);
        Ok(())
    }

    fn incbin(&mut self, t: &[Token], p: usize) -> PResult<()> {
        let (tok, name) = self.file_operand(t, p)?;
        let mut i = p + 2;
        let mut offset = 0i64;
        let mut size = None;
        if t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
            i += 1;
            offset = self.const_expr(t, &mut i, "the `.incbin` offset")?;
            if t.get(i).map(|t| t.kind) == Some(Tok::Comma) {
                i += 1;
                size = Some(self.const_expr(t, &mut i, "the `.incbin` size")?);
            }
        }
        self.expect_end(t, i)?;
        let dir = self.current_dir();
        let Some((_, bytes)) = self.find_file(&name, true, &dir) else {
            return Err(self.not_found(tok, &name, true));
        };
        let len = bytes.len() as i64;
        let end = match size {
            Some(size) => offset.saturating_add(size),
            None => len,
        };
        if offset < 0 || offset > len || end < offset || end > len {
            return Err(self.err(
                "asm::range",
                self.join(tok.span, t[i - 1].span),
                format!(
                    "`{name}` has {len} bytes; offset {offset} and size {} do not fit",
                    end - offset
                ),
            ));
        }
        if self.total_bytes + (end - offset) as usize > MAX_BYTES {
            return Err(self.err("asm::range", tok.span, "the program is too large"));
        }
        self.item(t[p].span, 0);
        self.emit(&bytes[offset as usize..end as usize]);
        Ok(())
    }
}
