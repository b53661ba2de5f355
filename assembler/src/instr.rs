//! Instructions: operand syntax, addressing-mode choice, encoding.
//!
//! Opcodes come only from `isa::encode`. Where an operand could be
//! zero-page or absolute and its value is not known yet (a symbol defined
//! later), the size is ca65's guess from what is known at the line
//! (`addrsize`), or with `Options::forward_zero_page` a variable-size
//! item that the layout passes settle; everything else is encoded at once.

use isa::objfmt::{BinaryOp, UnaryOp};
use isa::{AddressingMode as Mode, Mnemonic};

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag::{self, Span};
use crate::expr::{Base, EvalErr, Value};
use crate::intern::Keyword;
use crate::lexer::{Tok, Token};
use crate::model::{AssertRec, FixKind, Fixup, Node, NodeId, VarItem, VarKind};

/// An address-size override (`z:`, `a:`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Size {
    Auto,
    Zp,
    Abs,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Index {
    None,
    X,
    Y,
}

#[derive(Debug, Clone, Copy)]
enum Operand {
    None,
    Acc,
    Imm(NodeId),
    Direct(NodeId, Index, Size),
    Ind(NodeId),
    IndX(NodeId),
    IndY(NodeId),
}

/// Where an address-like value lands: zero page, absolute, or not known yet.
enum Fit {
    Zp,
    Abs,
    Unknown,
}

impl Asm<'_> {
    fn reg(&self, tok: Option<&Token>) -> Option<Keyword> {
        let tok = tok?;
        if tok.kind != Tok::Ident {
            return None;
        }
        match self.names.keyword(tok.name()) {
            k @ (Keyword::RegA | Keyword::RegX | Keyword::RegY) => Some(k),
            _ => None,
        }
    }

    /// The span of the tokens `from..to` (an expression's own tokens).
    fn tokens_span(&self, c: &Cursor<'_>, from: usize, to: usize) -> Span {
        let t = c.tokens();
        match (t.get(from), to.checked_sub(1).and_then(|last| t.get(last))) {
            (Some(first), Some(last)) if to > from => self.join(first.span, last.span),
            _ => c.span_of(from),
        }
    }

    /// The operand (from `c` to the end of the statement) and the span of
    /// its expression.
    fn operand(&mut self, mnemonic: Mnemonic, c: &mut Cursor<'_>) -> PResult<(Operand, Span)> {
        let start = c.pos();
        let mut expr_start = start;
        let operand = self.operand_inner(mnemonic, c, &mut expr_start)?;
        let n = c.tokens().len();
        let end = match operand.1 {
            0 => n,
            end => end,
        };
        let span = if expr_start < end {
            self.tokens_span(c, expr_start, end)
        } else {
            self.tokens_span(c, start, n)
        };
        Ok((operand.0, span))
    }

    /// Parses the operand; returns it with the end of its expression's
    /// tokens (0 for "to the end"), and sets `expr_start`.
    fn operand_inner(
        &mut self,
        mnemonic: Mnemonic,
        c: &mut Cursor<'_>,
        expr_start: &mut usize,
    ) -> PResult<(Operand, usize)> {
        let Some(&first) = c.peek() else {
            return Ok((Operand::None, 0));
        };
        if c.rest().len() == 1
            && self.reg(Some(&first)) == Some(Keyword::RegA)
            && isa::has_mode(mnemonic, Mode::Accumulator)
        {
            return Ok((Operand::Acc, 0));
        }
        if c.eat(Tok::Hash) {
            *expr_start = c.pos();
            let expr = self.expression(c)?;
            self.expect_end(c)?;
            return Ok((Operand::Imm(expr), c.pos()));
        }
        let mut size = Size::Auto;
        if first.kind == Tok::Ident && c.peek_kind_at(1) == Some(Tok::Colon) {
            size = match self.names.keyword(first.name()) {
                Keyword::SizeZ => Size::Zp,
                Keyword::RegA => Size::Abs,
                Keyword::SizeF => {
                    return Err(self.err(
                        "asm::mode",
                        first.span,
                        "`f:` (far, 24-bit) addressing does not exist on the 6502",
                    ));
                }
                _ => {
                    return Err(self.err(
                        "asm::syntax",
                        self.join(first.span, c.span_of(c.pos() + 1)),
                        "an address-size prefix is `z:` (zero page) or `a:` (absolute)",
                    ));
                }
            };
            c.advance_by(2);
        }
        if c.eat(Tok::LParen) {
            return self.indirect_operand(c, expr_start);
        }
        *expr_start = c.pos();
        let expr = self.expression(c)?;
        let expr_end = c.pos();
        let mut index = Index::None;
        if c.peek_kind() == Some(Tok::Comma) {
            index = match self.reg(c.peek_at(1)) {
                Some(Keyword::RegX) => Index::X,
                Some(Keyword::RegY) => Index::Y,
                _ => {
                    let span = c.span_of(c.pos() + 1);
                    return Err(self.err(
                        "asm::syntax",
                        span,
                        "expected `x` or `y` after the comma",
                    ));
                }
            };
            c.advance_by(2);
        }
        self.expect_end(c)?;
        Ok((Operand::Direct(expr, index, size), expr_end))
    }

    /// An operand that opens with `(` (read already): `(zp,x)`, `(zp),y` or
    /// `(abs)`. As in ca65, a leading parenthesis always means indirection,
    /// so a typo such as `(zp),x` is an error rather than another
    /// instruction.
    fn indirect_operand(
        &mut self,
        c: &mut Cursor<'_>,
        expr_start: &mut usize,
    ) -> PResult<(Operand, usize)> {
        *expr_start = c.pos();
        let inner = self.expression(c)?;
        let inner_end = c.pos();
        // Offsets from the end of the inner expression.
        let (ahead, message, help) = match c.peek_kind() {
            Some(Tok::Comma) if self.reg(c.peek_at(1)) == Some(Keyword::RegX) => {
                if c.peek_kind_at(2) == Some(Tok::RParen) {
                    c.advance_by(3);
                    self.expect_end(c)?;
                    return Ok((Operand::IndX(inner), inner_end));
                }
                (2, "expected `)` to close `(zp,x)`", None)
            }
            Some(Tok::Comma) => (
                1,
                "expected `x`: inside the parentheses the index is `x`, as in `(zp,x)`",
                Some("`(zp,x)` indexes before the indirection, `(zp),y` after it"),
            ),
            Some(Tok::RParen) if c.rest().len() == 1 => {
                return Ok((Operand::Ind(inner), inner_end));
            }
            Some(Tok::RParen) if c.peek_kind_at(1) == Some(Tok::Comma) => {
                if self.reg(c.peek_at(2)) == Some(Keyword::RegY) {
                    c.advance_by(3);
                    self.expect_end(c)?;
                    return Ok((Operand::IndY(inner), inner_end));
                }
                (
                    2,
                    "expected `y`: after the parentheses the index is `y`, as in `(zp),y`",
                    Some("the 6502 has `(zp),y` and `(zp,x)`; there is no `(zp),x`"),
                )
            }
            Some(Tok::RParen) => (
                1,
                "unexpected text after an indirect operand",
                Some(
                    "an operand that starts with `(` is indirect (as in ca65); \
                     for arithmetic, start it otherwise: `0+(a+b)*2`",
                ),
            ),
            _ => (
                0,
                "expected `,x)` or `)` to close the indirect operand",
                None,
            ),
        };
        let span = c.span_of(c.pos() + ahead);
        let mut diag = diag::error("asm::syntax", span, message);
        if let Some(help) = help {
            diag = diag.help(help);
        }
        Err(self.report(diag))
    }

    /// Encodes one instruction; `c` is at its mnemonic.
    pub(crate) fn instruction(&mut self, mnemonic: Mnemonic, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        // The whole operand as written (`#3`, `table,x`, `($12),y`): where
        // a mode error points.
        let whole = match c.peek() {
            Some(first) => self.join(first.span, c.span_of(c.tokens().len() - 1)),
            None => head.span,
        };
        let (operand, operand_span) = self.operand(mnemonic, c)?;
        match operand {
            Operand::None => {
                let mode = if isa::has_mode(mnemonic, Mode::Implied) {
                    Mode::Implied
                } else if isa::has_mode(mnemonic, Mode::Accumulator) {
                    Mode::Accumulator
                } else {
                    let help = self.mode_help(mnemonic);
                    let diag = diag::error(
                        "asm::mode",
                        head.span,
                        format!(
                            "`{}` needs an operand",
                            mnemonic.name().to_ascii_lowercase()
                        ),
                    )
                    .help(help);
                    return Err(self.report(diag));
                };
                let code = self.opcode(mnemonic, mode, head.span, whole)?;
                self.item(head.span, 1);
                self.emit(&[code]);
                Ok(())
            }
            Operand::Acc => {
                let code = self.opcode(mnemonic, Mode::Accumulator, head.span, whole)?;
                self.item(head.span, 1);
                self.emit(&[code]);
                Ok(())
            }
            Operand::Imm(expr) => {
                let code = self.opcode(mnemonic, Mode::Immediate, head.span, whole)?;
                self.item(head.span, 2);
                self.emit(&[code]);
                self.operand_bytes(expr, FixKind::Imm8, operand_span)
            }
            Operand::Ind(expr) => {
                let code = self.opcode(mnemonic, Mode::Indirect, head.span, whole)?;
                self.item(head.span, 3);
                self.emit(&[code]);
                self.page_wrap_check(expr, whole);
                self.operand_bytes(expr, FixKind::Abs, operand_span)
            }
            Operand::IndX(expr) | Operand::IndY(expr) => {
                let mode = if matches!(operand, Operand::IndX(_)) {
                    Mode::IndirectX
                } else {
                    Mode::IndirectY
                };
                let code = self.opcode(mnemonic, mode, head.span, whole)?;
                self.item(head.span, 2);
                self.emit(&[code]);
                self.operand_bytes(expr, FixKind::Zp, operand_span)
            }
            Operand::Direct(expr, index, size) => {
                if mnemonic.is_branch() {
                    if index != Index::None || size != Size::Auto {
                        return Err(self.err(
                            "asm::mode",
                            operand_span,
                            "a branch takes a plain target address",
                        ));
                    }
                    let code = self.opcode(mnemonic, Mode::Relative, head.span, whole)?;
                    return self.branch(code, expr, head.span, operand_span);
                }
                let (zp_mode, abs_mode) = match index {
                    Index::None => (Mode::ZeroPage, Mode::Absolute),
                    Index::X => (Mode::ZeroPageX, Mode::AbsoluteX),
                    Index::Y => (Mode::ZeroPageY, Mode::AbsoluteY),
                };
                let narrow = isa::encode(mnemonic, zp_mode);
                let wide = isa::encode(mnemonic, abs_mode);
                let choice = match (narrow, wide, size) {
                    (None, None, _) => {
                        let mode = abs_mode;
                        return Err(self.no_mode(mnemonic, mode, whole));
                    }
                    (Some(_), _, Size::Zp) | (Some(_), None, Size::Auto) => Some(Fit::Zp),
                    (_, Some(_), Size::Abs) | (None, Some(_), Size::Auto) => Some(Fit::Abs),
                    (None, Some(_), Size::Zp) => return Err(self.no_mode(mnemonic, zp_mode, whole)),
                    (Some(_), None, Size::Abs) => {
                        return Err(self.no_mode(mnemonic, abs_mode, whole));
                    }
                    // Both exist: the operand's value decides.
                    (Some(_), Some(_), Size::Auto) => None,
                };
                // Evaluated once: the choice and the operand bytes use the
                // same value.
                let value = self.prog.eval(expr);
                let choice = match choice {
                    Some(fit) => fit,
                    None => self.fit(expr, value, operand_span)?,
                };
                self.direct(
                    mnemonic,
                    choice,
                    (zp_mode, abs_mode),
                    expr,
                    value,
                    head.span,
                    operand_span,
                    whole,
                )
            }
        }
    }

    /// Emits a direct-addressed instruction once its size is chosen.
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &mut self,
        mnemonic: Mnemonic,
        choice: Fit,
        (zp_mode, abs_mode): (Mode, Mode),
        expr: NodeId,
        value: Result<Value, EvalErr>,
        head: Span,
        operand_span: Span,
        whole: Span,
    ) -> PResult<()> {
        match choice {
            Fit::Zp => {
                let code = self.opcode(mnemonic, zp_mode, head, whole)?;
                self.item(head, 2);
                self.emit(&[code]);
                self.operand_value(expr, value, FixKind::Zp, operand_span)
            }
            Fit::Abs => {
                let code = self.opcode(mnemonic, abs_mode, head, whole)?;
                self.item(head, 3);
                self.emit(&[code]);
                self.operand_value(expr, value, FixKind::Abs, operand_span)
            }
            Fit::Unknown => {
                let narrow = self.opcode(mnemonic, zp_mode, head, whole)?;
                let wide = self.opcode(mnemonic, abs_mode, head, whole)?;
                self.item(head, 2);
                self.pending(narrow, wide, expr, operand_span);
                Ok(())
            }
        }
    }

    /// The opcode, refusing undocumented ones unless enabled.
    fn opcode(&mut self, mnemonic: Mnemonic, mode: Mode, span: Span, whole: Span) -> PResult<u8> {
        let Some(code) = isa::encode(mnemonic, mode) else {
            return Err(self.no_mode(mnemonic, mode, whole));
        };
        if !isa::opcode(code).is_documented() {
            if !self.cpu_x {
                let diag = diag::error(
                    "asm::undocumented",
                    span,
                    format!(
                        "`{}` ({mode}, opcode ${code:02X}) is an undocumented NMOS opcode",
                        mnemonic.name().to_ascii_lowercase(),
                    ),
                )
                .help("enable the undocumented opcodes with `.setcpu \"6502X\"`");
                return Err(self.report(diag));
            }
            self.used_undoc = true;
        }
        Ok(code)
    }

    fn mode_help(&self, mnemonic: Mnemonic) -> String {
        let modes: Vec<String> = isa::AddressingMode::ALL
            .iter()
            .filter(|mode| {
                isa::encode(mnemonic, **mode)
                    .is_some_and(|code| self.cpu_x || isa::opcode(code).is_documented())
            })
            .map(ToString::to_string)
            .collect();
        format!(
            "`{}` has: {}",
            mnemonic.name().to_ascii_lowercase(),
            modes.join(", ")
        )
    }

    /// `span` is the operand as written.
    fn no_mode(&mut self, mnemonic: Mnemonic, mode: Mode, span: Span) -> crate::asm::Reported {
        let help = self.mode_help(mnemonic);
        let diag = diag::error(
            "asm::mode",
            span,
            format!(
                "`{}` has no {mode} addressing mode",
                mnemonic.name().to_ascii_lowercase()
            ),
        )
        .label(format!("this operand is {mode}"))
        .help(help);
        self.report(diag)
    }

    /// Whether an operand is zero-page, absolute or not known yet.
    /// A value not known yet is ca65's guess from what is known now
    /// ([`Asm::guess_zero_page`]), or with
    /// [`forward_zero_page`](crate::Options::forward_zero_page) left to
    /// the layout passes.
    fn fit(&mut self, expr: NodeId, value: Result<Value, EvalErr>, span: Span) -> PResult<Fit> {
        match value {
            Ok(value) => Ok(match self.value_fit(value) {
                Some(true) => Fit::Zp,
                Some(false) => Fit::Abs,
                None => Fit::Unknown,
            }),
            Err(EvalErr::NotYet(_)) if self.opts.forward_zero_page => Ok(Fit::Unknown),
            Err(EvalErr::NotYet(_)) => {
                if self.guess_zero_page(expr) {
                    return Ok(Fit::Zp);
                }
                let loc = self.loc(span);
                self.keep_nodes = true;
                self.prog
                    .absolute_guesses
                    .push(crate::addrsize::AbsoluteGuess { expr, loc });
                Ok(Fit::Abs)
            }
            Err(error) => Err(self.eval_error(error, span)),
        }
    }

    /// `Some(true)` if the value is a zero-page address, `None` if unknown.
    pub(crate) fn value_fit(&self, value: Value) -> Option<bool> {
        Some(match value {
            Value::Const(v) => (0..=0xFF).contains(&v),
            Value::Addr { base, .. } => self.base_is_zp(base),
            Value::Byte { .. } => true,
            Value::Chunk { chunk, .. } => {
                let c = &self.prog.chunks[chunk as usize];
                if c.org {
                    return None;
                }
                self.prog.segs[c.seg as usize].zp
            }
        })
    }

    pub(crate) fn base_is_zp(&self, base: Base) -> bool {
        match base {
            Base::Sec(seg) => self.prog.segs[seg as usize].zp,
            Base::Ext(sym) => matches!(
                self.prog.syms[sym as usize].def,
                crate::model::SymDef::Import { zp: true }
            ),
        }
    }

    /// Writes an operand or data value: bytes now if constant, else a
    /// placeholder and a fixup resolved after layout.
    pub(crate) fn operand_bytes(&mut self, expr: NodeId, kind: FixKind, span: Span) -> PResult<()> {
        let mut expr = expr;
        if self.features.force_range && matches!(kind, FixKind::Imm8 | FixKind::Byte) {
            // `.feature force_range`: the low byte, whatever the value.
            expr = self.prog.node(Node::Unary(UnaryOp::LoByte, expr));
        }
        let mut value = self.prog.eval(expr);
        if self.features.force_range
            && kind == FixKind::Word
            && let Ok(Value::Const(v)) = value
        {
            value = Ok(Value::Const(v & 0xFFFF));
        }
        self.operand_value(expr, value, kind, span)
    }

    /// [`Asm::operand_bytes`] with the value already evaluated.
    fn operand_value(
        &mut self,
        expr: NodeId,
        value: Result<Value, EvalErr>,
        kind: FixKind,
        span: Span,
    ) -> PResult<()> {
        match value {
            Ok(Value::Const(value)) => {
                let bytes = crate::output::const_bytes(kind, value).map_err(|(what, range)| {
                    self.report(crate::resolver::field_range_diag(
                        span, kind, value, what, range,
                    ))
                });
                match bytes {
                    Ok(bytes) => {
                        self.emit(&bytes[..kind.len() as usize]);
                        Ok(())
                    }
                    Err(reported) => {
                        self.emit(&[0; 4][..kind.len() as usize]);
                        Err(reported)
                    }
                }
            }
            // Arithmetic on addresses (`(a - b) / 2`) waits for the
            // resolver, which leaves it to the linker if it must.
            Ok(_) | Err(EvalErr::NotYet(_) | EvalErr::NotRelocatable) => {
                let (chunk, off) = self.here();
                let loc = self.loc(span);
                self.prog.fixups.push(Fixup {
                    chunk,
                    off,
                    kind,
                    expr,
                    loc,
                });
                self.keep_nodes = true;
                self.emit(&[0; 4][..kind.len() as usize]);
                Ok(())
            }
            Err(error) => {
                self.emit(&[0; 4][..kind.len() as usize]);
                Err(self.eval_error(error, span))
            }
        }
    }

    /// An instruction whose size the layout passes decide.
    fn pending(&mut self, narrow: u8, wide: u8, expr: NodeId, span: Span) {
        let loc = self.loc(span);
        let id = self.prog.vars.len() as u32;
        self.prog.vars.push(VarItem {
            kind: VarKind::Instr {
                narrow,
                wide,
                expr,
                is_wide: false,
            },
            loc,
            size: 2,
        });
        self.keep_nodes = true;
        let seg = self.seg as usize;
        let cur = self.prog.segs[seg].cur as usize;
        self.prog.chunks[cur].var = Some(id);
        self.prog.segs[seg].has_data = true;
        self.prog.segs[seg].used = true;
        self.total_bytes += 3;
        let org = self.prog.chunks[cur].org;
        self.new_chunk(org, None);
    }

    fn branch(&mut self, code: u8, expr: NodeId, head: Span, span: Span) -> PResult<()> {
        self.item(head, 2);
        let (chunk, off) = self.here();
        self.emit(&[code]);
        let loc = self.loc(span);
        self.prog.branches.push((chunk, off + 1, loc));
        let target = self.prog.eval(expr);
        let next = self.prog.position(chunk, i64::from(off) + 2);
        let distance = match target {
            Ok(target) => self.prog.binary(BinaryOp::Sub, target, next),
            Err(error) => Err(error),
        };
        match distance {
            Ok(Value::Const(distance)) => {
                if !(-128..=127).contains(&distance) {
                    self.emit(&[0]);
                    return Err(self.report(crate::resolver::branch_diag(span, distance)));
                }
                self.emit(&[distance as u8]);
                Ok(())
            }
            Err(error @ (EvalErr::DivZero | EvalErr::Circular(_) | EvalErr::TooComplex)) => {
                self.emit(&[0]);
                Err(self.eval_error(error, span))
            }
            _ => {
                let (chunk, off) = self.here();
                self.prog.fixups.push(Fixup {
                    chunk,
                    off,
                    kind: FixKind::Branch,
                    expr,
                    loc,
                });
                self.keep_nodes = true;
                self.emit(&[0]);
                Ok(())
            }
        }
    }

    /// `jmp ($xxFF)` reads its target across the page wrap on the NMOS
    /// part: warn now if the pointer is known, else leave the check to the
    /// linker as a deferred warning.
    fn page_wrap_check(&mut self, expr: NodeId, span: Span) {
        let message = "`jmp (pointer)` with the pointer at $xxFF reads its high byte from $xx00 on the NMOS 6502";
        match self.prog.eval(expr) {
            Ok(Value::Const(value)) => {
                if value & 0xFF == 0xFF {
                    let diag = diag::warning(
                        "asm::jmp-page-wrap",
                        span,
                        format!(
                            "`jmp (${value:04X})` reads its target from ${value:04X} and ${:04X}, not ${:04X}",
                            value & 0xFF00,
                            (value + 1) & 0xFFFF
                        ),
                    )
                    .help("move the pointer so that it does not start at the last byte of a page");
                    self.report(diag);
                }
            }
            Ok(_) | Err(EvalErr::NotYet(_)) => {
                let low = self.prog.node(Node::Unary(UnaryOp::LoByte, expr));
                let ff = self.prog.node(Node::Const(0xFF));
                let check = self.prog.node(Node::Binary(BinaryOp::Ne, low, ff));
                let loc = self.loc(span);
                let column = self.column_of(span);
                self.keep_nodes = true;
                self.prog.asserts.push(AssertRec {
                    expr: check,
                    error: false,
                    link_only: false,
                    message: message.to_string(),
                    loc,
                    line: self.input.line.line,
                    column,
                });
            }
            Err(_) => {}
        }
    }
}
