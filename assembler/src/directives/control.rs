//! Switches of the assembler itself: `.setcpu` and `.p02`, `.list`, and
//! the directives accepted for compatibility that change nothing here
//! (`.feature`, and those `Dir::NoEffect` groups).

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag;
use crate::lexer::Tok;

impl Asm<'_> {
    pub(super) fn setcpu(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        let Some(cpu) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
            let span = c.span();
            return Err(self.err(
                "asm::syntax",
                span,
                "expected a CPU name (`\"6502\"` or `\"6502X\"`)",
            ));
        };
        c.advance();
        self.expect_end(c)?;
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

    pub(super) fn p02(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        self.expect_end(c)?;
        self.cpu_x = false;
        Ok(())
    }

    /// `.p816`, `.pc02`, `.psc02`, `.p4510`: ca65's switches to other CPUs,
    /// refused by name (the robot has an NMOS 6502).
    pub(super) fn other_cpu(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let name = self.names.name(c.current().name()).to_ascii_lowercase();
        let name = name.trim_start_matches('.');
        let span = c.current().span;
        let cpu = match name {
            "p816" => "the 65816",
            "pc02" => "the 65C02",
            "psc02" => "the 65SC02",
            _ => "the 4510",
        };
        Err(self.report(
            diag::error(
                "asm::cpu",
                span,
                format!(
                    "`.{name}` selects {cpu}; this toolchain is for the NMOS 6502, the Scorpion's CPU"
                ),
            )
            .help("remove it (`.p02` is the default), or `.setcpu \"6502X\"` for the NMOS 6502's undocumented opcodes"),
        ))
    }

    /// `.end`: the forced end of the assembly, even inside an include:
    /// nothing after it is read (what is still open is reported as at the
    /// end of the input).
    pub(super) fn end(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        self.expect_end(c)?;
        // Every file and expansion ends here, each reporting the `.if`s it
        // leaves open; the input is then exhausted.
        while !self.input.frames.is_empty() {
            self.pop_frame();
        }
        Ok(())
    }

    /// The span from the directive at `c` to the end of the line.
    fn whole_statement(&self, c: &Cursor<'_>) -> diag::Span {
        self.join(c.current().span, c.span_of(c.tokens().len() - 1))
    }

    pub(super) fn no_effect(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let name = self.names.name(c.current().name()).to_string();
        let span = self.whole_statement(c);
        let diag = diag::warning(
            "asm::no-effect",
            span,
            format!("`{name}` has no effect with this assembler; the line is ignored"),
        );
        self.report(diag);
        Ok(())
    }

    /// `.feature name [+|-] {, name [+|-]}`: each switch on (or off with
    /// `-`); a ca65 feature this assembler does not implement is a warning
    /// naming it, a name ca65 does not know an error.
    pub(super) fn feature(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        c.advance();
        loop {
            let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected a feature's name"));
            };
            c.advance();
            let on = if c.eat(Tok::Minus) {
                false
            } else {
                c.eat(Tok::Plus);
                true
            };
            let name = self.names.name(tok.name()).to_ascii_lowercase();
            match self.features.set(&name, on) {
                Ok(()) => {}
                Err(crate::FeatureError::Unknown) => {
                    return Err(self.report(
                        diag::error("asm::feature", tok.span, format!("no feature `{name}`")).help(
                            format!("ca65's features: {}", crate::CA65_FEATURES.join(", ")),
                        ),
                    ));
                }
            }
            if !c.eat(Tok::Comma) {
                break;
            }
        }
        self.expect_end(c)
    }

    pub(super) fn list(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let on = self.switch(c)?;
        if let Some(listing) = self.listing.as_mut() {
            listing.enabled = on;
        }
        Ok(())
    }

    /// `.autoimport on|off|+|-`: names used and never defined become
    /// imports (as the C compiler's output expects) instead of errors; the
    /// setting at the end of the source decides, as in ca65.
    pub(super) fn autoimport(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        self.autoimport = self.switch(c)?;
        Ok(())
    }

    /// `.case on|off|+|-`: names are case-sensitive (on, the default);
    /// `off` is refused: this assembler keeps `Foo` and `foo` apart.
    pub(super) fn case(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let span = self.whole_statement(c);
        if !self.switch(c)? {
            return Err(self.report(
                diag::error(
                    "asm::case",
                    span,
                    "case-insensitive names are not supported",
                )
                .help("names are case-sensitive here, as with `.case on` (ca65's default)"),
            ));
        }
        Ok(())
    }

    /// The operand of a switch: `on`, `off`, `+` or `-`, then the end of
    /// the line.
    pub(super) fn switch(&mut self, c: &mut Cursor<'_>) -> PResult<bool> {
        c.advance();
        let on = match c.peek() {
            Some(tok) if tok.kind == Tok::Plus => true,
            Some(tok) if tok.kind == Tok::Minus => false,
            Some(tok) if tok.kind == Tok::Ident => {
                let word = self.names.name(tok.name()).to_ascii_lowercase();
                match word.as_str() {
                    "on" => true,
                    "off" => false,
                    _ => {
                        return Err(self.err("asm::syntax", tok.span, "expected `on` or `off`"));
                    }
                }
            }
            _ => {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected `on` or `off`"));
            }
        };
        c.advance();
        self.expect_end(c)?;
        Ok(on)
    }
}
