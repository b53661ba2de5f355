//! Directives, one file per topic: [`data`] (bytes, words, `.res`,
//! `.align`, `.charmap`), [`segments`] (`.segment`, `.org`, `.reloc`),
//! [`linkage`] (`.import`, `.export`), [`macros`] (`.macro`, `.repeat`,
//! `.define`), [`scopes`] (`.proc`, `.scope`, `.struct`, `.enum`, `.tag`),
//! [`messages`] (`.assert`, `.out`, `.warning`, `.error`), [`files`]
//! (`.include`, `.incbin`) and [`control`] (`.setcpu`, `.list`, `.feature`
//! and the directives that do nothing here). Conditionals live with the
//! expander (`asm::conditionals`), which must see them on skipped lines.
//!
//! Every handler takes the statement's [`Cursor`] at the directive.

mod control;
mod data;
mod files;
mod linkage;
mod macros;
mod messages;
mod scopes;
mod segments;

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::intern::Dir;
use crate::lexer::Tok;

impl Asm<'_> {
    /// Runs the directive `dir`; `c` is at its token.
    pub(crate) fn directive(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        match dir {
            Dir::Byte
            | Dir::Asciiz
            | Dir::Word
            | Dir::Addr
            | Dir::Dbyt
            | Dir::Dword
            | Dir::Faraddr
            | Dir::Lobytes
            | Dir::Hibytes
            | Dir::Bankbytes => self.data(dir, c),
            Dir::Res => self.res(c),
            Dir::Align => self.align(c),
            Dir::Charmap => self.charmap(c),
            Dir::Org => self.org(c),
            // ca65 2.19's `.linecont +`: `.feature line_continuations`.
            Dir::Linecont => {
                self.features.line_continuations = self.switch(c)?;
                Ok(())
            }
            Dir::Reloc => self.reloc(c),
            Dir::Pushseg | Dir::Popseg | Dir::Pushcpu | Dir::Popcpu => self.push_pop(dir, c),
            Dir::Segment => self.segment_directive(c),
            Dir::Code | Dir::Rodata | Dir::Data | Dir::Bss | Dir::Zeropage => {
                self.named_segment(dir, c)
            }
            Dir::Import | Dir::Importzp => self.import(c, dir == Dir::Importzp, false),
            Dir::Forceimport => self.import(c, false, true),
            Dir::Constructor => self.condes(c, Some(0)),
            Dir::Destructor => self.condes(c, Some(1)),
            Dir::Interruptor => self.condes(c, Some(2)),
            Dir::Condes => self.condes(c, None),
            Dir::Export | Dir::Exportzp | Dir::Global | Dir::Globalzp => self.export(
                c,
                matches!(dir, Dir::Exportzp | Dir::Globalzp),
                matches!(dir, Dir::Global | Dir::Globalzp),
            ),
            Dir::Macro => self.define_macro(c),
            Dir::Macpack => self.macpack(c),
            Dir::Endmacro => {
                Err(self.err("asm::unbalanced", head.span, "`.endmacro` without `.macro`"))
            }
            Dir::Endrepeat => Err(self.err(
                "asm::unbalanced",
                head.span,
                "`.endrepeat` without `.repeat`",
            )),
            Dir::Local => self.local(c),
            Dir::Exitmacro => self.exit_macro(c),
            Dir::Repeat => self.repeat(c),
            Dir::Elseif | Dir::Else | Dir::Endif => self.conditional(dir, c),
            _ if dir.opens_conditional() => self.conditional(dir, c),
            Dir::Define => self.define_text(c),
            Dir::Undefine => self.undefine(c),
            Dir::Struct | Dir::Union => self.structure(c, dir == Dir::Union),
            Dir::Endstruct | Dir::Endunion | Dir::Endenum => Err(self.err(
                "asm::unbalanced",
                head.span,
                format!(
                    "`{}` without its opening directive",
                    self.names.name(head.name())
                ),
            )),
            Dir::Enum => self.enumeration(c),
            Dir::Tag => self.tag(c),
            Dir::Assert => self.assert(c),
            Dir::Error | Dir::Warning | Dir::Out | Dir::Fatal => self.message(dir, c),
            Dir::Proc => self.open_scope(c, true),
            Dir::Scope => self.open_scope(c, false),
            Dir::Endproc | Dir::Endscope => self.close_scope(c, dir == Dir::Endproc),
            Dir::Setcpu => self.setcpu(c),
            Dir::P02 => self.p02(c),
            Dir::Autoimport => self.autoimport(c),
            Dir::Case => self.case(c),
            Dir::End => self.end(c),
            Dir::OtherCpu => self.other_cpu(c),
            Dir::NoEffect => self.no_effect(c),
            Dir::Feature => self.feature(c),
            Dir::List => self.list(c),
            Dir::Include => self.include(c),
            Dir::Incbin => self.incbin(c),
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

    /// Steps over a `,`, or reports that one is missing.
    pub(crate) fn comma(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        if c.eat(Tok::Comma) {
            return Ok(());
        }
        let span = c.span();
        Err(self.err("asm::syntax", span, "expected `,`"))
    }
}
