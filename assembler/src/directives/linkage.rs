//! Linkage: `.import`/`.importzp` and `.export`/`.exportzp`/`.global`/
//! `.globalzp`, with `name = expr` and `name := expr` in export lists.

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag;
use crate::lexer::{Tok, Token};
use crate::model::SymDef;

/// A name in an `.import`/`.export` list, with `(label_like, expression
/// start)` when it is `name = expr` or `name := expr`, and its address
/// size when given (`name: zp` is `Some(true)`, `name: abs` `Some(false)`).
type NameItem = (Token, Option<(bool, usize)>, Option<bool>);

impl Asm<'_> {
    /// A comma-separated list of names after the directive at `c`.
    fn name_list(&mut self, c: &mut Cursor<'_>) -> PResult<Vec<NameItem>> {
        let mut names = Vec::new();
        c.advance();
        loop {
            let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected a symbol name"));
            };
            c.advance();
            // `name: zp`, `name: abs` (ca65's address sizes).
            let mut size = None;
            if c.peek_kind() == Some(Tok::Colon) {
                c.advance();
                let word = c
                    .peek()
                    .filter(|t| t.kind == Tok::Ident)
                    .copied()
                    .map(|t| (t, self.names.name(t.name()).to_ascii_lowercase()));
                size = match word.as_ref().map(|(_, w)| w.as_str()) {
                    Some("zp" | "zeropage" | "direct") => Some(true),
                    Some("abs" | "absolute" | "near") => Some(false),
                    _ => {
                        let span = word.map_or(c.span(), |(t, _)| t.span);
                        return Err(self.report(
                            diag::error("asm::syntax", span, "expected an address size: `zp` or `abs`")
                                .help("the 6502 has 8-bit (zero page) and 16-bit addresses; `far` and `long` are the 65816's"),
                        ));
                    }
                };
                c.advance();
            }
            // `.export name = expr` / `name := expr`.
            let mut assignment = None;
            if let Some(kind @ (Tok::Eq | Tok::Assign)) = c.peek_kind() {
                c.advance();
                assignment = Some((kind == Tok::Assign, c.pos()));
                let mut depth = 0;
                while let Some(next) = c.peek() {
                    match next.kind {
                        Tok::LParen => depth += 1,
                        Tok::RParen => depth -= 1,
                        Tok::Comma if depth == 0 => break,
                        _ => {}
                    }
                    c.advance();
                }
            }
            names.push((tok, assignment, size));
            match c.peek_kind() {
                None => return Ok(names),
                Some(Tok::Comma) => c.advance(),
                _ => {
                    let span = c.span();
                    return Err(self.err("asm::syntax", span, "expected `,` and another name"));
                }
            }
        }
    }

    /// `.import`/`.importzp`; `.forceimport` (`force`) writes the import
    /// to the object even if nothing here uses it, so the linker pulls in
    /// the module that defines it (ld65's libraries; cc65's `__STARTUP__`).
    pub(super) fn import(&mut self, c: &mut Cursor<'_>, zp: bool, force: bool) -> PResult<()> {
        for (tok, assignment, size) in self.name_list(c)? {
            let zp = size.unwrap_or(zp);
            if assignment.is_some() {
                return Err(self.err("asm::syntax", tok.span, "an import has no value here"));
            }
            self.reserved_name(&tok, false)?;
            let sym = self.sym_in(self.symtab.scope, tok.name());
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
            if force {
                self.prog.syms[sym as usize].global = true;
            }
        }
        Ok(())
    }

    /// `.constructor name [, priority]` (type 0), `.destructor` (1),
    /// `.interruptor` (2), `.condes name, type [, priority]`: exports
    /// `name` and lists it for the linker's table of that type (a layout's
    /// `CONDES`), priority 1 to 32, 7 by default, as ca65's.
    pub(super) fn condes(&mut self, c: &mut Cursor<'_>, kind: Option<u8>) -> PResult<()> {
        c.advance();
        let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected the routine's name"));
        };
        c.advance();
        let kind = match kind {
            Some(kind) => kind,
            None => {
                if !c.eat(Tok::Comma) {
                    let span = c.span();
                    return Err(self.err("asm::syntax", span, "expected `,` and the table type"));
                }
                let span = c.span();
                let kind = self.const_expr(c, "a table type")?;
                match u8::try_from(kind)
                    .ok()
                    .filter(|kind| *kind <= isa::objfmt::MAX_CONDES_TYPE)
                {
                    Some(kind) => kind,
                    None => {
                        return Err(self.err(
                            "asm::range",
                            span,
                            format!("table type {kind} is outside 0 to 6 (0 constructor, 1 destructor, 2 interruptor)"),
                        ));
                    }
                }
            }
        };
        let mut priority = 7;
        if c.eat(Tok::Comma) {
            let span = c.span();
            let value = self.const_expr(c, "a priority")?;
            priority = match u8::try_from(value).ok().filter(|p| (1..=32).contains(p)) {
                Some(priority) => priority,
                None => {
                    return Err(self.err(
                        "asm::range",
                        span,
                        format!("priority {value} is outside 1 to 32"),
                    ));
                }
            };
        }
        self.expect_end(c)?;
        let sym = self.sym_in(self.symtab.scope, tok.name());
        let loc = self.loc(tok.span);
        let s = &mut self.prog.syms[sym as usize];
        s.export = Some(s.export.unwrap_or(false));
        if s.export_loc.is_none() {
            s.export_loc = Some(loc);
        }
        self.prog.condes.push((sym, kind, priority));
        Ok(())
    }

    pub(super) fn export(&mut self, c: &mut Cursor<'_>, zp: bool, global: bool) -> PResult<()> {
        for (tok, assignment, size) in self.name_list(c)? {
            let zp = size.unwrap_or(zp);
            let sym = self.sym_in(self.symtab.scope, tok.name());
            if let Some((_, start)) = assignment {
                let mut value = c.at(start);
                let expr = self.expression(&mut value)?;
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
}
