//! Names: the symbol table (scoped, cheap-local and unnamed labels),
//! definitions, references and scopes.

use super::*;

/// No symbol, in [`SymbolTable::global_syms`].
const NO_SYM: SymId = SymId::MAX;

fn key(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

/// The assembler's symbol table: which symbol a name means in which
/// scope. The symbols themselves live in the [`Program`], which the back
/// end reads; this is the index the front end looks names up in.
#[derive(Debug, Default)]
pub(crate) struct SymbolTable {
    /// Symbols of scopes other than the global one, by (scope, name).
    sym_map: FxHashMap<u64, SymId>,
    /// Global symbols by name ([`NO_SYM`] where there is none).
    global_syms: Vec<SymId>,
    /// Child scopes by (parent, name).
    scope_map: FxHashMap<u64, ScopeId>,
    /// Cheap locals (`@name`) by (region, name).
    cheap_map: FxHashMap<u64, SymId>,
    /// Unnamed labels (`:`) in order of definition.
    unnamed: Vec<SymId>,
    /// How many unnamed labels are defined so far.
    pub(crate) unnamed_count: usize,
    /// The region cheap locals belong to: a new one at each normal label.
    cheap_epoch: u32,
    /// The scope names are defined in now.
    pub(crate) scope: ScopeId,
    /// The open `.proc`/`.scope`s, innermost last, with where each opened.
    pub(crate) scope_stack: Vec<(ScopeId, LocId)>,
}

impl SymbolTable {
    /// An empty table, in the global scope.
    pub(crate) fn new() -> SymbolTable {
        SymbolTable {
            scope: GLOBAL_SCOPE,
            ..SymbolTable::default()
        }
    }
}

impl<'a> Asm<'a> {
    fn new_sym(&mut self, name: NameId, scope: ScopeId, kind: SymKind) -> SymId {
        self.prog.syms.push(Sym::new(name, scope, kind));
        (self.prog.syms.len() - 1) as SymId
    }

    /// The symbol `name` exactly in `scope`, created if missing.
    pub(crate) fn sym_in(&mut self, scope: ScopeId, name: NameId) -> SymId {
        if let Some(sym) = self.find_sym(scope, name) {
            return sym;
        }
        let sym = self.new_sym(name, scope, SymKind::Normal);
        self.bind_sym(scope, name, sym);
        sym
    }

    /// Looks `name` up in `scope` only.
    pub(crate) fn find_sym(&self, scope: ScopeId, name: NameId) -> Option<SymId> {
        if scope == GLOBAL_SCOPE {
            // Most lookups end here: a dense table indexed by name stays
            // in cache where a hash probe into a table of every symbol of
            // a large program would not.
            return self
                .symtab
                .global_syms
                .get(name as usize)
                .copied()
                .filter(|&sym| sym != NO_SYM);
        }
        self.symtab.sym_map.get(&key(scope, name)).copied()
    }

    /// Records `sym` as `name` in `scope`.
    fn bind_sym(&mut self, scope: ScopeId, name: NameId, sym: SymId) {
        if scope == GLOBAL_SCOPE {
            let index = name as usize;
            if self.symtab.global_syms.len() <= index {
                self.symtab.global_syms.resize(index + 1, NO_SYM);
            }
            self.symtab.global_syms[index] = sym;
        } else {
            self.symtab.sym_map.insert(key(scope, name), sym);
        }
    }

    /// A reference to `name` from the current scope. As in ca65, a name
    /// the current scope does not define is its own symbol all the same,
    /// which the scope may define further down (`bmi done` before the
    /// proc's `done:`); at the end of the input an undefined one is bound
    /// to the outer definition. The outer symbol visible now is noted
    /// ([`Program::outer`]) for its address size and for constants needed
    /// at once.
    pub(crate) fn ref_sym(&mut self, name: NameId, span: Span) -> SymId {
        let here = self.symtab.scope;
        let sym = match self.find_sym(here, name) {
            Some(sym) => sym,
            None => {
                let sym = self.new_sym(name, here, SymKind::Normal);
                self.bind_sym(here, name, sym);
                let mut scope = here;
                while scope != GLOBAL_SCOPE {
                    scope = self.prog.scopes[scope as usize].parent;
                    if let Some(outer) = self.find_sym(scope, name) {
                        self.prog
                            .outer
                            .insert(sym, crate::model::OuterUse { outer, used: None });
                        break;
                    }
                }
                sym
            }
        };
        self.note_ref(sym, span);
        sym
    }

    pub(crate) fn note_ref(&mut self, sym: SymId, span: Span) {
        if self.prog.syms[sym as usize].ref_loc.is_none() {
            let loc = self.loc(span);
            self.prog.syms[sym as usize].ref_loc = Some(loc);
        }
    }

    /// The cheap local `name` of the current label's region.
    pub(crate) fn cheap_sym(&mut self, name: NameId) -> SymId {
        if let Some(&sym) = self
            .symtab
            .cheap_map
            .get(&key(self.symtab.cheap_epoch, name))
        {
            return sym;
        }
        let sym = self.new_sym(name, self.symtab.scope, SymKind::Cheap);
        self.symtab
            .cheap_map
            .insert(key(self.symtab.cheap_epoch, name), sym);
        sym
    }

    /// Starts a new region for cheap locals. The old region's names can
    /// never be reached again, so the map forgets them: it stays as small
    /// as one region (in cache), not as large as the program.
    pub(crate) fn new_cheap_region(&mut self) {
        self.symtab.cheap_epoch += 1;
        if !self.symtab.cheap_map.is_empty() {
            if self.symtab.cheap_map.capacity() > 1024 {
                // After a region with very many locals: clearing costs the
                // capacity, so start small again.
                self.symtab.cheap_map = FxHashMap::default();
            } else {
                self.symtab.cheap_map.clear();
            }
        }
    }

    /// The unnamed label with index `index`.
    pub(crate) fn unnamed_sym(&mut self, index: usize) -> SymId {
        while self.symtab.unnamed.len() <= index {
            let name = self.names.intern(":");
            let sym = self.new_sym(name, GLOBAL_SCOPE, SymKind::Unnamed);
            self.symtab.unnamed.push(sym);
        }
        self.symtab.unnamed[index]
    }

    /// Defines `sym`; reports a duplicate.
    pub(crate) fn define(&mut self, sym: SymId, def: SymDef, span: Span) -> PResult<()> {
        let existing = &self.prog.syms[sym as usize];
        match existing.def {
            SymDef::Undefined => {}
            SymDef::Import { .. } => {
                let name = self.sym_name(sym);
                let mut diag = diag::error(
                    "asm::duplicate",
                    span,
                    format!("`{name}` is imported and cannot also be defined here"),
                );
                if let Some(loc) = existing.def_loc {
                    let first = self.prog.locs[loc as usize].span;
                    diag = diag.also(first, "imported here");
                }
                return Err(self.report(diag));
            }
            _ => {
                let name = self.sym_name(sym);
                let mut diag = diag::error(
                    "asm::duplicate",
                    span,
                    format!("`{name}` is already defined"),
                )
                .label("defined again here");
                if let Some(loc) = existing.def_loc {
                    let first = self.prog.locs[loc as usize].span;
                    diag = diag.also(first, "first defined here");
                }
                return Err(self.report(
                    diag.help("rename one of them, or use `.set` for a value that changes"),
                ));
            }
        }
        if let Some(use_) = self.prog.outer.remove(&sym)
            && let Some(used) = use_.used
        {
            let name = self.sym_name(sym);
            let outer = self.sym_name(use_.outer);
            let first = self.prog.locs[used as usize].span;
            let diag = diag::error(
                "asm::scope-order",
                span,
                format!("`{name}` is defined here, after a use above took the value of `{outer}`"),
            )
            .label("the scope's own definition")
            .also(first, "used here as a constant before this definition")
            .help(format!(
                "ca65 binds that use to this definition and refuses it (not a constant yet); write `{outer}` there if the outer one is meant, or move this definition up"
            ));
            return Err(self.report(diag));
        }
        self.prog.defs = self.prog.defs.wrapping_add(1);
        let loc = self.loc(span);
        let column = self.column_of(span);
        // As in ca65, defining any normal symbol (label, constant, struct
        // member...) starts a new region for cheap locals.
        if self.prog.syms[sym as usize].kind == SymKind::Normal
            && !matches!(def, SymDef::Import { .. })
        {
            self.new_cheap_region();
        }
        let s = &mut self.prog.syms[sym as usize];
        s.def = def;
        s.def_loc = Some(loc);
        s.def_file = self.input.line.file;
        s.def_line = self.input.line.line;
        s.def_column = column;
        s.def_ctx = self.input.line_ctx;
        if let SymDef::Label { chunk, .. } = def {
            let seg = self.prog.chunks[chunk as usize].seg;
            self.prog.segs[seg as usize].used = true;
        }
        Ok(())
    }

    /// Refuses a name ca65 reserves where a symbol, scope or macro is
    /// declared: the registers `a`, `x`, `y` everywhere, and the
    /// instructions (the undocumented ones only under `.setcpu "6502X"`)
    /// where the name starts a statement or names a macro, since ca65 reads
    /// `adc:` and `.define adc 5` as the instruction. A typo of this kind
    /// would otherwise assemble quietly to other bytes than ca65's.
    pub(crate) fn reserved_name(&mut self, tok: &Token, instructions_too: bool) -> PResult<()> {
        if tok.kind != Tok::Ident {
            return Ok(());
        }
        let what = match self.names.keyword(tok.name()) {
            Keyword::RegA | Keyword::RegX | Keyword::RegY => "a register",
            // `.feature ubiquitous_idents`: instruction names are free.
            Keyword::Mnemonic(mnemonic)
                if instructions_too
                    && !self.features.ubiquitous_idents
                    && (mnemonic.is_documented() || self.cpu_x) =>
            {
                "an instruction"
            }
            _ => return Ok(()),
        };
        let name = self.names.name(tok.name()).to_string();
        Err(self.report(
            diag::error(
                "asm::reserved-name",
                tok.span,
                format!("`{name}` is {what} and cannot be used as a name here"),
            )
            .label("reserved")
            .help(format!(
                "ca65 refuses it too; choose another name, such as `{}_`",
                name.to_ascii_lowercase()
            )),
        ))
    }

    /// A label at the current position: `name:`.
    pub(crate) fn define_label(&mut self, tok: &Token) -> PResult<SymId> {
        let (chunk, off) = self.here();
        let def = SymDef::Label { chunk, off };
        let sym = match tok.kind {
            Tok::Local => self.cheap_sym(tok.name()),
            Tok::Colon => {
                let index = self.symtab.unnamed_count;
                self.symtab.unnamed_count += 1;
                self.unnamed_sym(index)
            }
            _ => self.sym_in(self.symtab.scope, tok.name()),
        };
        self.define(sym, def, tok.span)?;
        Ok(sym)
    }

    /// The full name of a symbol, with its scopes (`motor::step`).
    pub(crate) fn sym_name(&self, sym: SymId) -> String {
        let s = &self.prog.syms[sym as usize];
        let name = self.names.name(s.name);
        if s.kind != SymKind::Normal {
            return name.to_string();
        }
        let mut path = self.scope_path(s.scope);
        path.push_str(name);
        path
    }

    /// `a::b::` for a scope (empty for the global scope).
    pub(crate) fn scope_path(&self, scope: ScopeId) -> String {
        let mut parts = Vec::new();
        let mut s = scope;
        let mut guard = 0;
        while s != GLOBAL_SCOPE && guard < 1000 {
            let info = &self.prog.scopes[s as usize];
            parts.push(self.names.name(info.name));
            s = info.parent;
            guard += 1;
        }
        let mut out = String::new();
        for part in parts.iter().rev() {
            out.push_str(part);
            out.push_str("::");
        }
        out
    }

    /// The child scope `name` of `parent`, if it exists.
    pub(crate) fn child_scope(&self, parent: ScopeId, name: NameId) -> Option<ScopeId> {
        self.symtab.scope_map.get(&key(parent, name)).copied()
    }

    /// The child scope `name` of `parent`, created if missing.
    pub(crate) fn child_scope_or_new(
        &mut self,
        parent: ScopeId,
        name: NameId,
        kind: ScopeKind,
    ) -> ScopeId {
        if let Some(scope) = self.child_scope(parent, name) {
            return scope;
        }
        let id = self.prog.scopes.len() as ScopeId;
        self.prog.scopes.push(Scope {
            name,
            parent,
            kind,
            start: None,
            end: None,
            size: None,
        });
        self.symtab.scope_map.insert(key(parent, name), id);
        id
    }

    /// Finds scope `name` from the current scope outward.
    pub(crate) fn lookup_scope(&self, name: NameId) -> Option<ScopeId> {
        let mut scope = self.symtab.scope;
        loop {
            if let Some(found) = self.child_scope(scope, name) {
                return Some(found);
            }
            if scope == GLOBAL_SCOPE {
                return None;
            }
            scope = self.prog.scopes[scope as usize].parent;
        }
    }
}
