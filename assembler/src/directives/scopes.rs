//! Names in nested scopes and the sizes of things: `.proc`/`.endproc`,
//! `.scope`/`.endscope`, `.struct`/`.union` with their members, `.enum`,
//! and `.tag`.

use crate::asm::{Asm, PResult};
use crate::cursor::Cursor;
use crate::diag::Span;
use crate::expr::Value;
use crate::intern::{Dir, Keyword};
use crate::lexer::Tok;
use crate::model::{GLOBAL_SCOPE, Node, NodeId, ScopeId, ScopeKind, SymDef};
use isa::objfmt::BinaryOp;

impl Asm<'_> {
    /// Resolves a scope name (`s`, `a::s`, `::s`) that must exist.
    fn scope_name(&mut self, c: &mut Cursor<'_>) -> PResult<ScopeId> {
        let start = c.span();
        let mut scope: Option<ScopeId> = None;
        if c.eat(Tok::ColonColon) {
            scope = Some(GLOBAL_SCOPE);
        }
        loop {
            let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected a struct name"));
            };
            c.advance();
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
            if !c.eat(Tok::ColonColon) {
                return Ok(found);
            }
        }
    }

    /// `.tag s`: as many bytes as the struct `s` has.
    pub(super) fn tag(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        c.advance();
        let scope = self.scope_name(c)?;
        self.expect_end(c)?;
        let size = self.prog.scopes[scope as usize].size.unwrap_or(0);
        self.item(head.span, 0);
        self.reserve(size, None, head.span)
    }

    /// The optional name after `.struct`, `.union` or `.enum`, which ends
    /// the line.
    fn block_name(&mut self, c: &mut Cursor<'_>) -> PResult<Option<crate::lexer::Token>> {
        c.advance();
        let name = c.peek().filter(|t| t.kind == Tok::Ident).copied();
        if name.is_some() {
            c.advance();
        }
        self.expect_end(c)?;
        if let Some(name) = name {
            // Reported; the members are still read up to the end.
            let _ = self.reserved_name(&name, false);
        }
        Ok(name)
    }

    /// `.struct` / `.union`: member offsets as constants in a scope.
    pub(super) fn structure(&mut self, c: &mut Cursor<'_>, union: bool) -> PResult<()> {
        let head = c.current();
        let name = self.block_name(c)?;
        let (closer, kind) = if union {
            (Dir::Endunion, ScopeKind::Union)
        } else {
            (Dir::Endstruct, ScopeKind::Struct)
        };
        let scope = match name {
            Some(name) => {
                let scope = self.child_scope_or_new(self.symtab.scope, name.name(), kind);
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
            None => self.symtab.scope,
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
            let t = std::mem::take(&mut self.input.toks);
            let mut c = self.cursor(&t);
            let result = self.struct_member(&mut c, scope, union, closer, offset, depth);
            self.input.toks = t;
            match result {
                Ok(Line::Member(member_size)) => {
                    if union {
                        size = size.max(member_size);
                    } else {
                        offset = offset.saturating_add(member_size);
                        size = size.saturating_add(member_size);
                    }
                }
                // `.org n`: the next members start at n; the size still
                // counts the members only, as ca65's.
                Ok(Line::Org(at)) => offset = at,
                Ok(Line::End) => return Ok(size),
                Err(_) => {}
            }
        }
    }

    /// One member line.
    fn struct_member(
        &mut self,
        c: &mut Cursor<'_>,
        scope: ScopeId,
        union: bool,
        closer: Dir,
        offset: i64,
        depth: u32,
    ) -> PResult<Line> {
        let Some(&first) = c.peek() else {
            return Ok(Line::Member(0));
        };
        let mut name = None;
        if first.kind == Tok::Ident {
            name = Some(first);
            c.advance();
        }
        let Some(dir_tok) = c.next_token() else {
            return Err(self.err(
                "asm::syntax",
                first.span,
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
            self.expect_end(c)?;
            return Ok(Line::End);
        }
        if dir == Dir::Org && name.is_none() {
            let at = self.const_expr(c, "a member offset")?;
            self.expect_end(c)?;
            return Ok(Line::Org(at));
        }
        let member_size = match dir {
            Dir::Byte
            | Dir::Word
            | Dir::Addr
            | Dir::Faraddr
            | Dir::Dword
            | Dir::Dbyt
            | Dir::Res => {
                let unit = match dir {
                    Dir::Byte | Dir::Res => 1,
                    Dir::Faraddr => 3,
                    Dir::Dword => 4,
                    _ => 2,
                };
                let count = if !c.is_end() {
                    self.const_expr(c, "a member size")?
                } else if dir == Dir::Res {
                    return Err(self.err("asm::syntax", dir_tok.span, "`.res` needs a size"));
                } else {
                    1
                };
                // Up to 16 MiB, as a 65816's banks (cx16.inc's VRAM).
                if !(0..=0xFF_FFFF).contains(&count) {
                    return Err(self.report(crate::resolver::range_diag(
                        dir_tok.span,
                        "member size",
                        count,
                        (0, 0xFF_FFFF),
                    )));
                }
                unit * count
            }
            Dir::Tag => {
                let tagged = self.scope_name(c)?;
                let unit = self.prog.scopes[tagged as usize].size.unwrap_or(0);
                let count = if c.is_end() {
                    1
                } else {
                    self.const_expr(c, "a member count")?
                };
                unit.saturating_mul(count.clamp(0, 0xFFFF))
            }
            // A nested block: its members belong to this struct, offset
            // from here; a named one (`JUMPTAB .struct`) is also a member
            // itself, as in ca65.
            Dir::Struct | Dir::Union if depth < 16 => {
                self.expect_end(c)?;
                let closer = if dir == Dir::Union {
                    Dir::Endunion
                } else {
                    Dir::Endstruct
                };
                let here = if union { 0 } else { offset };
                let before = self.prog.syms.len();
                let size =
                    self.struct_members(scope, dir == Dir::Union, closer, dir_tok.span, depth + 1)?;
                for sym in before..self.prog.syms.len() {
                    if let SymDef::Const(value) = self.prog.syms[sym].def
                        && self.prog.syms[sym].scope == scope
                    {
                        self.prog.syms[sym].def = SymDef::Const(value + here);
                    }
                }
                if let Some(name) = name {
                    self.reserved_name(&name, false)?;
                    let sym = self.sym_in(scope, name.name());
                    self.define(sym, SymDef::Const(here), name.span)?;
                    self.label_sizes.insert(sym, size);
                }
                return Ok(Line::Member(size));
            }
            _ => {
                return Err(self.err(
                    "asm::syntax",
                    dir_tok.span,
                    "a member needs a size: `.byte`, `.word`, `.res n`, `.tag s`",
                ));
            }
        };
        self.expect_end(c)?;
        if let Some(name) = name {
            self.reserved_name(&name, false)?;
            let sym = self.sym_in(scope, name.name());
            let value = if union { 0 } else { offset };
            self.define(sym, SymDef::Const(value), name.span)?;
            // `.sizeof(S::member)`.
            self.label_sizes.insert(sym, member_size);
        }
        Ok(Line::Member(member_size))
    }

    pub(super) fn enumeration(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        let name = self.block_name(c)?;
        let scope = match name {
            Some(name) => self.child_scope_or_new(self.symtab.scope, name.name(), ScopeKind::Enum),
            None => self.symtab.scope,
        };
        // The next member's value: a constant, or (after a member that
        // a later one defines, `red = green - 1`) that member plus one.
        let mut next = self.prog.node(Node::Const(0));
        let mut count: i64 = 0;
        loop {
            let Some(_) = self.fetch_raw() else {
                return Err(self.err("asm::unclosed", head.span, "`.enum` has no `.endenum`"));
            };
            let t = std::mem::take(&mut self.input.toks);
            let mut c = self.cursor(&t);
            // Names in a member's value are looked up in the enum first
            // (`red = green - 1` is the enum's `green`), as in ca65.
            let outer = std::mem::replace(&mut self.symtab.scope, scope);
            let result = self.enum_member(&mut c, scope, next);
            self.symtab.scope = outer;
            self.input.toks = t;
            match result {
                Ok(Member::Defined(following)) => {
                    next = following;
                    count += 1;
                }
                Ok(Member::Blank) => {}
                Ok(Member::End) => break,
                Err(_) => {}
            }
        }
        if name.is_some() {
            self.prog.scopes[scope as usize].size = Some(count);
        }
        Ok(())
    }

    /// One line of an `.enum`: a member (`name` or `name = value`, its
    /// value `next` when not given), a blank line, or `.endenum`.
    fn enum_member(&mut self, c: &mut Cursor<'_>, scope: ScopeId, next: NodeId) -> PResult<Member> {
        let Some(first) = c.next_token() else {
            return Ok(Member::Blank);
        };
        if first.kind == Tok::Directive
            && self.names.keyword(first.name()) == Keyword::Directive(Dir::Endenum)
        {
            self.expect_end(c)?;
            return Ok(Member::End);
        }
        if first.kind != Tok::Ident {
            return Err(self.err("asm::syntax", first.span, "expected a member name"));
        }
        let expr = if c.eat(Tok::Eq) {
            self.expression(c)?
        } else {
            next
        };
        self.expect_end(c)?;
        self.reserved_name(&first, false)?;
        let sym = self.sym_in(scope, first.name());
        // Known now: a constant; else (a later member or symbol defines
        // it, as ca65 allows) settled when that is known.
        let (def, following) = match self.prog.eval(expr) {
            Ok(Value::Const(value)) => {
                let after = BinaryOp::Add.apply(value, 1).unwrap_or(value);
                (SymDef::Const(value), self.prog.node(Node::Const(after)))
            }
            _ => {
                self.keep_nodes = true;
                let this = self.prog.node(Node::Sym(sym));
                let one = self.prog.node(Node::Const(1));
                (
                    SymDef::Expr(expr),
                    self.prog.node(Node::Binary(BinaryOp::Add, this, one)),
                )
            }
        };
        self.define(sym, def, first.span)?;
        Ok(Member::Defined(following))
    }

    pub(super) fn open_scope(&mut self, c: &mut Cursor<'_>, proc_: bool) -> PResult<()> {
        let head = c.current();
        c.advance();
        let name_tok = c.peek().filter(|t| t.kind == Tok::Ident).copied();
        if name_tok.is_some() {
            c.advance();
        }
        // `.proc name: near` (the C compiler writes it): the name's address
        // size, which for code on a 6502 is absolute.
        if name_tok.is_some() && c.peek_kind() == Some(Tok::Colon) {
            c.advance();
            let size = c.peek().filter(|t| t.kind == Tok::Ident).copied();
            let word = size.map(|t| self.names.name(t.name()).to_ascii_lowercase());
            match word.as_deref() {
                Some("near" | "abs" | "absolute") => c.advance(),
                _ => {
                    // Reported; the scope still opens, so its end matches.
                    let span = size.map_or(c.span(), |t| t.span);
                    let _ = self.err(
                        "asm::syntax",
                        span,
                        "a scope's address size here is `near` (absolute): code on the 6502 lives in 16-bit addresses",
                    );
                    while c.peek().is_some() {
                        c.advance();
                    }
                }
            }
        }
        self.expect_end(c)?;
        if let Some(tok) = name_tok {
            // Reported; the scope still opens, so its end matches.
            let _ = self.reserved_name(&tok, false);
        }
        let name = match name_tok {
            Some(tok) => tok.name(),
            None if proc_ => {
                let span = c.span();
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
        let scope = self.child_scope_or_new(self.symtab.scope, name, kind);
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
        self.symtab.scope_stack.push((scope, loc));
        self.symtab.scope = scope;
        Ok(())
    }

    pub(super) fn close_scope(&mut self, c: &mut Cursor<'_>, proc_: bool) -> PResult<()> {
        let head = c.current();
        c.advance();
        self.expect_end(c)?;
        let Some(&(scope, _)) = self.symtab.scope_stack.last() else {
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
        self.symtab.scope_stack.pop();
        self.symtab.scope = self.prog.scopes[scope as usize].parent;
        Ok(())
    }
}

/// What a line of an `.enum` was.
enum Member {
    /// A member; the next member's value (unless it gives its own).
    Defined(NodeId),
    /// Nothing.
    Blank,
    /// `.endenum`.
    End,
}

/// What one line inside a `.struct` or `.union` was.
enum Line {
    /// A member (or a blank line) of this many bytes.
    Member(i64),
    /// `.org n`: the next member's offset.
    Org(i64),
    /// The closing directive.
    End,
}
