//! End-of-input checks: open scopes, names bound to outer scopes,
//! `.global`, undefined names.

use crate::asm::Asm;
use crate::diag;
use crate::model::{GLOBAL_SCOPE, ScopeKind, SymDef, SymId, SymKind};

impl Asm<'_> {
    /// End-of-input checks: open scopes, outer-scope binding of names
    /// used inside scopes, `.global`, undefined names.
    pub(crate) fn finish_front(&mut self) {
        while let Some((scope, loc)) = self.symtab.scope_stack.pop() {
            let kind = self.prog.scopes[scope as usize].kind;
            let what = if kind == ScopeKind::Proc {
                "`.proc` has no `.endproc`"
            } else {
                "`.scope` has no `.endscope`"
            };
            let span = self.loc_span(loc);
            self.report_at(loc, diag::error("asm::unclosed", span, what));
        }
        for sym in 0..self.prog.syms.len() {
            let s = &self.prog.syms[sym];
            if s.def != SymDef::Undefined || s.kind != SymKind::Normal || s.scope == GLOBAL_SCOPE {
                continue;
            }
            let (name, mut scope) = (s.name, s.scope);
            let (referenced, mut found) = (s.ref_loc, false);
            while scope != GLOBAL_SCOPE {
                scope = self.prog.scopes[scope as usize].parent;
                if let Some(outer) = self.find_sym(scope, name)
                    && self.prog.syms[outer as usize].is_defined()
                {
                    self.prog.syms[sym].def = SymDef::Alias(outer);
                    // The outer symbol is the one used (an import is
                    // written to the object only where it is used).
                    let o = &mut self.prog.syms[outer as usize];
                    o.ref_loc = o.ref_loc.or(referenced);
                    found = true;
                    break;
                }
            }
            // `.autoimport on`: a name used in a scope and defined nowhere
            // is the global one, which is imported below.
            if !found && self.autoimport && referenced.is_some() {
                let global = self.sym_in(GLOBAL_SCOPE, name);
                if global as usize != sym {
                    let g = &mut self.prog.syms[global as usize];
                    g.ref_loc = g.ref_loc.or(referenced);
                    self.prog.syms[sym].def = SymDef::Alias(global);
                }
            }
        }
        for sym in 0..self.prog.syms.len() {
            let s = &self.prog.syms[sym];
            // `.autoimport on`: a global name used and never defined is
            // another file's, as if imported.
            let auto = self.autoimport
                && s.kind == SymKind::Normal
                && s.scope == GLOBAL_SCOPE
                && s.ref_loc.is_some();
            if s.def == SymDef::Undefined && (s.global || auto) {
                let zp = s.export.unwrap_or(false);
                let s = &mut self.prog.syms[sym];
                s.def = SymDef::Import { zp };
                s.export = None;
                s.def_loc = s.export_loc;
            }
        }
        // Built only if a name is undefined: the defined names, for "did
        // you mean".
        let mut known: Option<diag::Suggestions> = None;
        for sym in 0..self.prog.syms.len() {
            let s = &self.prog.syms[sym];
            if s.def != SymDef::Undefined {
                continue;
            }
            let Some(loc) = s.ref_loc.or(s.export_loc) else {
                continue;
            };
            let name = self.sym_name(sym as SymId);
            let span = self.loc_span(loc);
            let diag = match s.kind {
                SymKind::Unnamed => diag::error(
                    "asm::undefined",
                    span,
                    "there is no unnamed label `:` after this",
                ),
                SymKind::Cheap => diag::error(
                    "asm::undefined",
                    span,
                    format!("cheap local `{name}` is not defined before the next normal label"),
                ),
                SymKind::Normal => {
                    let exported = s.ref_loc.is_none();
                    let message = if exported {
                        format!("`{name}` is exported but never defined")
                    } else {
                        format!("`{name}` is not defined")
                    };
                    let short = self.names.name(s.name).to_string();
                    // Only for the errors that are kept: a suggestion is
                    // the costly part of an error.
                    let similar = if self.rep.is_full() {
                        None
                    } else {
                        let known = known
                            .get_or_insert_with(|| diag::Suggestions::new(self.defined_names()));
                        known.suggest(&name).map(str::to_owned)
                    };
                    let help = match similar {
                        Some(similar) => format!("did you mean `{similar}`?"),
                        None => format!(
                            "define it, or import it with `.import {short}` if another file defines it"
                        ),
                    };
                    diag::error("asm::undefined", span, message).help(help)
                }
            };
            self.report_at(loc, diag);
        }
    }

    /// The place (file, line, column) of the outermost macro call in the
    /// expansion context `ctx`: the user's line that made the definition.
    pub(super) fn outermost_expansion(&self, mut ctx: u32) -> Option<(u32, u32, u32)> {
        let mut outermost = None;
        let mut guard = 0;
        while ctx != 0 && guard < 256 {
            let node = self.ctx.get(ctx as usize)?;
            if matches!(node.kind, crate::diag::CtxKind::Macro(_)) {
                outermost = Some(node.span);
            }
            ctx = node.parent;
            guard += 1;
        }
        outermost.map(|span| {
            let (line, column) = self.files.line_col(span.file, span.start);
            (span.file, line, column)
        })
    }

    /// The full names of the defined ordinary symbols.
    pub(super) fn defined_names(&self) -> Vec<String> {
        (0..self.prog.syms.len())
            .filter(|&sym| {
                let s = &self.prog.syms[sym];
                s.kind == SymKind::Normal && s.is_defined()
            })
            .map(|sym| self.sym_name(sym as SymId))
            .collect()
    }
}
