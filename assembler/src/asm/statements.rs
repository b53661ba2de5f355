//! One statement: labels, assignments, then an instruction, a directive
//! or a macro call.

use super::*;

/// The 65C02's and 65SC02's instructions that the NMOS 6502 lacks (the
/// Rockwell/WDC bit instructions aside).
const CMOS_MNEMONICS: [&str; 8] = ["bra", "phx", "phy", "plx", "ply", "stz", "trb", "tsb"];

impl<'a> Asm<'a> {
    /// The cursor over a line's tokens, placing what is missing at the
    /// line's end.
    pub(crate) fn cursor<'t>(&self, toks: &'t [Token]) -> Cursor<'t> {
        Cursor::new(
            toks,
            Span {
                file: self.input.line.file,
                start: self.input.line.end,
                end: self.input.line.end,
            },
        )
    }

    /// A line's statement; a label at its start gets the size of what
    /// the rest of the line emits (ca65's size of a label: `.sizeof(msg)`
    /// after `msg: .byte "hello"` is 5).
    pub(super) fn statement(&mut self, t: &[Token]) -> PResult<()> {
        let before = self.total_bytes;
        let mut label = None;
        let result = self.labelled_statement(t, &mut label);
        if let Some(sym) = label {
            let size = i64::try_from(self.total_bytes - before).unwrap_or(i64::MAX);
            self.label_sizes.insert(sym, size);
        }
        result
    }

    fn labelled_statement(&mut self, t: &[Token], label: &mut Option<SymId>) -> PResult<()> {
        if t.is_empty() {
            return Ok(());
        }
        let mut c = self.cursor(t);
        // Labels and assignments.
        if matches!(
            t.get(1).map(|t| t.kind),
            Some(Tok::Eq | Tok::Assign | Tok::Colon | Tok::Directive)
        ) && (t[1].kind != Tok::Directive
            || self.names.keyword(t[1].name()) == Keyword::Directive(Dir::Set))
        {
            self.reserved_name(&t[0], true)?;
        }
        match (t[0].kind, t.get(1).map(|t| t.kind)) {
            (Tok::Ident | Tok::Local, Some(Tok::Eq | Tok::Assign)) => {
                return self.assignment(&mut c);
            }
            // `.feature pc_assignment`: `* = addr` is `.org addr`.
            (Tok::Star, Some(Tok::Eq)) if self.features.pc_assignment => {
                // `.org` reads its value after the token at the cursor.
                c.advance();
                return self.directive(Dir::Org, &mut c);
            }
            (Tok::Ident, Some(Tok::Directive))
                if self.names.keyword(t[1].name()) == Keyword::Directive(Dir::Set) =>
            {
                let sym = self.sym_in(self.symtab.scope, t[0].name());
                return self.set_variable(&mut c, sym);
            }
            // `::name .set expr`, `scope::name .set expr`: a variable of
            // another scope (a global counter bumped inside a scope).
            (Tok::ColonColon, _) | (Tok::Ident, Some(Tok::ColonColon))
                if self.scoped_set(t).is_some() =>
            {
                let at = self.scoped_set(t).unwrap_or(0);
                let mut path = self.cursor(&t[..at]);
                let sym = self.symbol_ref(&mut path)?;
                c.advance_by(at - 1);
                return self.set_variable(&mut c, sym);
            }
            (Tok::Ident | Tok::Local, Some(Tok::Colon)) => {
                // `name:` is a label even where a macro has the name.
                *label = Some(self.define_label(&t[0])?);
                c.advance_by(2);
            }
            (Tok::Colon, _) => {
                self.define_label(&t[0])?;
                c.advance();
            }
            _ => {}
        }
        let Some(&head) = c.peek() else {
            return Ok(());
        };
        match head.kind {
            Tok::Ident => {
                let info = self.names.info[head.value as usize];
                if let Some(mac) = info.macro_id {
                    return self.invoke_macro(mac, &mut c);
                }
                match info.keyword {
                    Keyword::Mnemonic(mnemonic) => self.instruction(mnemonic, &mut c),
                    // `.feature labels_without_colons`: a name at the very
                    // start of the line is a label.
                    _ if self.features.labels_without_colons
                        && c.pos() == 0
                        && head.span.start == self.input.line.start =>
                    {
                        *label = Some(self.define_label(&head)?);
                        self.labelled_statement(&t[1..], &mut None)
                    }
                    _ => {
                        let name = self.names.name(head.name()).to_string();
                        // A 65C02 instruction (`-t apple2enh` sources): named
                        // as such, where it is used.
                        if CMOS_MNEMONICS.contains(&name.to_ascii_lowercase().as_str()) {
                            let diag = diag::error(
                                "asm::cpu",
                                head.span,
                                format!("`{name}` is a 65C02 instruction; the Scorpion's CPU is an NMOS 6502"),
                            )
                            .help("write it with NMOS instructions (`stz x` is `lda #0` + `sta x`, `bra` a `jmp`); ca65 refuses it too after `.setcpu \"6502\"`");
                            return Err(self.report(diag));
                        }
                        // `name` alone, or before an instruction: a label
                        // missing its colon.
                        let label_like = match c.peek_at(1) {
                            None => true,
                            Some(next) if next.kind == Tok::Directive => true,
                            Some(next) if next.kind == Tok::Ident => {
                                let info = self.names.info[next.value as usize];
                                matches!(info.keyword, Keyword::Mnemonic(_))
                                    || info.macro_id.is_some()
                            }
                            _ => false,
                        };
                        let suggestion = if self.rep.is_full() {
                            None
                        } else {
                            self.similar_statement_head(&name)
                        };
                        let help = match suggestion {
                            Some(similar) if label_like => Some(format!(
                                "did you mean `{similar}`? (a label needs a colon: `{name}:`)"
                            )),
                            Some(similar) => Some(format!("did you mean `{similar}`?")),
                            None => label_like.then(|| format!("a label needs a colon: `{name}:`")),
                        };
                        let mut diag = diag::error(
                            "asm::unknown",
                            head.span,
                            format!("`{name}` is not an instruction, directive or macro"),
                        );
                        if let Some(help) = help {
                            diag = diag.help(help);
                        }
                        Err(self.report(diag))
                    }
                }
            }
            Tok::Directive => {
                let Keyword::Directive(dir) = self.names.keyword(head.name()) else {
                    let name = self.names.name(head.name()).to_string();
                    let mut diag = diag::error(
                        "asm::unknown-directive",
                        head.span,
                        format!("`{name}` is not a directive this assembler knows"),
                    );
                    let written = name.trim_start_matches('.');
                    if let Some(similar) = diag::did_you_mean(
                        &written.to_ascii_lowercase(),
                        crate::intern::DIRECTIVE_NAMES.iter().copied(),
                    ) {
                        diag = diag.help(format!("did you mean `.{similar}`?"));
                    }
                    return Err(self.report(diag));
                };
                self.directive(dir, &mut c)
            }
            _ => Err(self.err(
                "asm::syntax",
                head.span,
                "expected a label, an instruction, a directive or a macro here",
            )),
        }
    }

    /// An instruction or macro whose name is near `name`, for the error on
    /// a statement that starts with an unknown name.
    fn similar_statement_head(&self, name: &str) -> Option<String> {
        let lower = name.to_ascii_lowercase();
        let mnemonics = isa::Mnemonic::ALL
            .iter()
            .filter(|m| m.is_documented() || self.cpu_x)
            .map(|m| m.name().to_ascii_lowercase());
        let macros = self
            .input
            .macros
            .iter()
            .map(|m| self.names.name(m.name).to_string());
        let candidates: Vec<String> = mnemonics.chain(macros).collect();
        diag::did_you_mean(&lower, candidates.iter().map(String::as_str)).map(|similar| {
            if similar.len() == 3 && name.chars().all(|c| c.is_ascii_uppercase()) {
                similar.to_ascii_uppercase()
            } else {
                similar.to_string()
            }
        })
    }

    /// `name = expr` and `name := expr`.
    fn assignment(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let name = c.current();
        c.advance_by(2);
        let expr = self.expression(c)?;
        self.expect_end(c)?;
        let sym = match name.kind {
            Tok::Local => self.cheap_sym(name.name()),
            _ => self.sym_in(self.symtab.scope, name.name()),
        };
        let def = match self.prog.eval(expr) {
            Ok(crate::expr::Value::Const(value)) => SymDef::Const(value),
            _ => {
                self.keep_nodes = true;
                SymDef::Expr(expr)
            }
        };
        self.define(sym, def, name.span)
    }

    /// Where `.set` is in `t` when `t` starts with a scoped name
    /// (`::name`, `a::b::name`) followed by `.set`.
    fn scoped_set(&self, t: &[Token]) -> Option<usize> {
        let mut i = usize::from(t.first()?.kind == Tok::ColonColon);
        loop {
            if t.get(i)?.kind != Tok::Ident {
                return None;
            }
            i += 1;
            match t.get(i)? {
                tok if tok.kind == Tok::ColonColon => i += 1,
                tok if tok.kind == Tok::Directive
                    && self.names.keyword(tok.name()) == Keyword::Directive(Dir::Set) =>
                {
                    return Some(i);
                }
                _ => return None,
            }
        }
    }

    /// `name .set expr` (the cursor on the name, `sym` the variable): a
    /// variable, taken by value where it is used.
    fn set_variable(&mut self, c: &mut Cursor<'_>, sym: SymId) -> PResult<()> {
        let name = c.current();
        c.advance_by(2);
        let start = c.pos();
        let expr = self.expression(c)?;
        self.expect_end(c)?;
        let span = self.join(c.span_of(start), c.last_span());
        let node = match self.eval_now(expr, span) {
            Ok(crate::expr::Value::Const(value)) => {
                self.prog.node(crate::model::Node::Const(value))
            }
            Ok(_) | Err(crate::expr::EvalErr::NotYet(_)) => expr,
            Err(error) => {
                return Err(self.eval_error(error, self.join(c.span_of(start), c.last_span())));
            }
        };
        self.keep_nodes = true;
        self.new_cheap_region();
        self.prog.defs = self.prog.defs.wrapping_add(1);
        let s = &mut self.prog.syms[sym as usize];
        match s.def {
            SymDef::Undefined | SymDef::Var(_) => {
                s.def = SymDef::Var(node);
                if s.def_loc.is_none() {
                    let loc = self.loc(name.span);
                    self.prog.syms[sym as usize].def_loc = Some(loc);
                }
                Ok(())
            }
            _ => {
                let text = self.sym_name(sym);
                Err(self.err(
                    "asm::duplicate",
                    name.span,
                    format!("`{text}` is a constant or label, not a `.set` variable"),
                ))
            }
        }
    }

    /// Reports unexpected tokens after a complete statement.
    pub(crate) fn expect_end(&mut self, c: &Cursor<'_>) -> PResult<()> {
        if let Some(extra) = c.peek() {
            let last = c.span_of(c.tokens().len() - 1);
            return Err(self.err(
                "asm::syntax",
                self.join(extra.span, last),
                "unexpected text at the end of this statement",
            ));
        }
        Ok(())
    }
}
