//! The front end: reads lines from files, macro and `.repeat` expansions,
//! applies `.define`s and conditionals, and hands each statement to the
//! instruction or directive code. It builds the [`Program`] in one pass.

use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

use rustc_hash::FxHashMap;

use crate::Options;
use crate::cursor::Cursor;
use crate::diag::{
    self, CtxId, CtxKind, CtxNode, Files, RawDiag, Reporter, Span, Text, count_chars,
};
use crate::intern::{Dir, Interner, Keyword, NameId};
use crate::lexer::{LexError, Lexer, LineInfo, Tok, Token};
use crate::listing::ListingBuilder;
use crate::model::{
    Chunk, ChunkId, GLOBAL_SCOPE, Item, LocId, Program, Scope, ScopeId, ScopeKind, SegId, Segment,
    Sym, SymDef, SymId, SymKind,
};
use crate::source::FileSource;

/// An error already reported; the caller abandons the statement.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reported;

pub(crate) type PResult<T> = Result<T, Reported>;

/// Most tokens in one line after macro arguments and `.define`s are
/// substituted: a recursive macro whose argument contains itself would
/// otherwise double the line at every level.
const MAX_LINE_TOKENS: usize = 16_384;
/// Deepest nesting of includes, macros and `.repeat`s.
const MAX_FRAMES: usize = 256;
/// Largest total of bytes in all segments (the 6502 sees 64 KiB, but a
/// program of `.org` chunks may be bigger).
pub(crate) const MAX_BYTES: usize = 16 << 20;

/// A stored run of lines: a macro or `.repeat` body.
#[derive(Debug, Default)]
pub(crate) struct Body {
    pub(crate) tokens: Vec<Token>,
    pub(crate) lines: Vec<BodyLine>,
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyLine {
    pub(crate) first: u32,
    pub(crate) end: u32,
    pub(crate) info: LineInfo,
}

#[derive(Debug)]
pub(crate) struct Macro {
    pub(crate) name: NameId,
    pub(crate) params: Vec<NameId>,
    pub(crate) body: Rc<Body>,
}

#[derive(Debug)]
pub(crate) struct Define {
    pub(crate) params: Vec<NameId>,
    pub(crate) has_params: bool,
    pub(crate) tokens: Vec<Token>,
}

#[derive(Debug)]
pub(crate) enum Frame {
    File {
        text: Text,
        lexer: Lexer,
        ctx: CtxId,
        conds: usize,
        dir: PathBuf,
    },
    Macro {
        body: Rc<Body>,
        line: usize,
        args: Vec<Vec<Token>>,
        locals: Vec<(NameId, NameId)>,
        ctx: CtxId,
        conds: usize,
    },
    Repeat {
        body: Rc<Body>,
        line: usize,
        iter: u32,
        count: u32,
        var: Option<NameId>,
        ctx: CtxId,
        conds: usize,
    },
}

impl Frame {
    fn conds(&self) -> usize {
        match self {
            Frame::File { conds, .. }
            | Frame::Macro { conds, .. }
            | Frame::Repeat { conds, .. } => *conds,
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Cond {
    pub(crate) span: Span,
    pub(crate) parent_active: bool,
    pub(crate) active: bool,
    pub(crate) taken: bool,
    pub(crate) seen_else: bool,
}

/// The assembler's whole state during one run.
pub(crate) struct Asm<'a> {
    pub(crate) prog: Program,
    pub(crate) names: Interner,
    pub(crate) files: Files,
    pub(crate) ctx: Vec<CtxNode>,
    pub(crate) rep: Reporter,
    pub(crate) source: &'a dyn FileSource,
    pub(crate) opts: &'a Options,

    /// Symbols of scopes other than the global one, by (scope, name).
    sym_map: FxHashMap<u64, SymId>,
    /// Global symbols by name ([`NO_SYM`] where there is none).
    global_syms: Vec<SymId>,
    pub(crate) scope_map: FxHashMap<u64, ScopeId>,
    cheap_map: FxHashMap<u64, SymId>,
    pub(crate) unnamed: Vec<SymId>,
    pub(crate) unnamed_count: usize,
    pub(crate) cheap_epoch: u32,
    pub(crate) scope: ScopeId,
    pub(crate) scope_stack: Vec<(ScopeId, LocId)>,
    pub(crate) seg: SegId,

    pub(crate) frames: Vec<Frame>,
    pub(crate) macros: Vec<Macro>,
    pub(crate) defines: Vec<Define>,
    pub(crate) any_define: bool,
    pub(crate) conds: Vec<Cond>,
    pub(crate) toks: Vec<Token>,
    tmp: Vec<Token>,
    lex_errors: Vec<LexError>,
    /// The current line was cut at [`MAX_LINE_TOKENS`].
    overlong: bool,
    /// The line being processed.
    pub(crate) line: LineInfo,
    pub(crate) line_ctx: CtxId,
    pub(crate) listing: Option<ListingBuilder>,
    pub(crate) charmap: [u8; 256],
    pub(crate) cpu_x: bool,
    pub(crate) used_undoc: bool,
    pub(crate) messages: Vec<String>,
    lines_read: u64,
    pub(crate) stop: bool,
    /// A missing include ended the assembly: the back end does not run
    /// on the part that was read, whose errors would only repeat it.
    pub(crate) fatal: bool,
    pub(crate) keep_nodes: bool,
    expansions: u32,
    pub(crate) total_bytes: usize,
    /// Main file's display name, for the `STT_FILE` symbol.
    pub(crate) main_name: String,
}

/// No symbol, in [`Asm::global_syms`].
const NO_SYM: SymId = SymId::MAX;

fn key(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

impl<'a> Asm<'a> {
    pub(crate) fn new(source: &'a dyn FileSource, opts: &'a Options) -> Asm<'a> {
        let mut charmap = [0u8; 256];
        for (i, slot) in charmap.iter_mut().enumerate() {
            *slot = i as u8;
        }
        let mut asm = Asm {
            prog: Program::default(),
            names: Interner::new(),
            files: Files::default(),
            ctx: vec![CtxNode {
                parent: 0,
                kind: CtxKind::Root,
                span: Span::default(),
            }],
            rep: Reporter::new(opts.max_errors),
            source,
            opts,
            sym_map: FxHashMap::default(),
            global_syms: Vec::new(),
            scope_map: FxHashMap::default(),
            cheap_map: FxHashMap::default(),
            unnamed: Vec::new(),
            unnamed_count: 0,
            cheap_epoch: 0,
            scope: GLOBAL_SCOPE,
            scope_stack: Vec::new(),
            seg: 0,
            frames: Vec::new(),
            macros: Vec::new(),
            defines: Vec::new(),
            any_define: false,
            conds: Vec::new(),
            toks: Vec::with_capacity(64),
            tmp: Vec::with_capacity(64),
            lex_errors: Vec::new(),
            overlong: false,
            line: LineInfo::default(),
            line_ctx: 0,
            listing: None,
            charmap,
            cpu_x: opts.undocumented,
            used_undoc: false,
            messages: Vec::new(),
            lines_read: 0,
            stop: false,
            fatal: false,
            keep_nodes: false,
            expansions: 0,
            total_bytes: 0,
            main_name: String::new(),
        };
        asm.prog.scopes.push(Scope {
            name: 0,
            parent: GLOBAL_SCOPE,
            kind: ScopeKind::Global,
            start: None,
            end: None,
            size: None,
        });
        asm.seg = asm.segment("CODE", false);
        asm
    }

    // ----- diagnostics -------------------------------------------------

    /// Reports `diag` in the current expansion context.
    pub(crate) fn report(&mut self, mut diag: RawDiag) -> Reported {
        diag.ctx = self.line_ctx;
        self.rep.push(diag);
        Reported
    }

    pub(crate) fn err(
        &mut self,
        code: &'static str,
        span: Span,
        message: impl Into<String>,
    ) -> Reported {
        self.report(diag::error(code, span, message))
    }

    /// Joins two spans on one line (see [`Files::join`]).
    pub(crate) fn join(&self, a: Span, b: Span) -> Span {
        let line = &self.line;
        if a.file == line.file
            && b.file == line.file
            && a.start >= line.start
            && b.end <= line.end
            && a.start <= b.end
        {
            // Both on the current line: no newline can be between them.
            return Span {
                file: a.file,
                start: a.start,
                end: b.end.max(a.end),
            };
        }
        self.files.join(a, b)
    }

    pub(crate) fn loc(&mut self, span: Span) -> LocId {
        self.prog.loc(span, self.line_ctx)
    }

    pub(crate) fn new_ctx(&mut self, kind: CtxKind, span: Span) -> CtxId {
        self.ctx.push(CtxNode {
            parent: self.line_ctx,
            kind,
            span,
        });
        (self.ctx.len() - 1) as CtxId
    }

    /// Column (from 1, in characters) of a span on the current line.
    pub(crate) fn column_of(&self, span: Span) -> u32 {
        if span.file != self.line.file || span.start < self.line.start {
            return 1;
        }
        if self.line.ascii {
            return span.start - self.line.start + 1;
        }
        let text = self.files.text(span.file);
        let start = self.line.start as usize;
        let end = (span.start as usize).min(text.len()).max(start);
        count_chars(&text[start..end]) + 1
    }

    // ----- segments and positions --------------------------------------

    /// The segment called `name`, created on first use.
    pub(crate) fn segment(&mut self, name: &str, zp: bool) -> SegId {
        if let Some(index) = self.prog.segs.iter().position(|s| s.name == name) {
            return index as SegId;
        }
        let seg = self.prog.segs.len() as SegId;
        let chunk = self.prog.chunks.len() as ChunkId;
        self.prog.chunks.push(Chunk {
            seg,
            org: false,
            org_base: None,
            data_start: 0,
            len: 0,
            var: None,
            known_start: Some(0),
            known_abs: None,
            start: 0,
            abs: 0,
        });
        self.prog.segs.push(Segment {
            name: name.to_string(),
            zp: zp || name == "ZEROPAGE",
            data: Vec::new(),
            chunks: vec![chunk],
            has_data: false,
            used: false,
            align: 1,
            cur: chunk,
            size: 0,
        });
        seg
    }

    /// The current chunk and the offset in it.
    pub(crate) fn here(&self) -> (ChunkId, u32) {
        let cur = self.prog.segs[self.seg as usize].cur;
        (cur, self.prog.chunks[cur as usize].len)
    }

    /// Starts a new chunk in the current segment (after a variable item,
    /// or for `.org`/`.reloc`).
    pub(crate) fn new_chunk(&mut self, org: bool, org_base: Option<i64>) {
        let seg = &self.prog.segs[self.seg as usize];
        let cur = &self.prog.chunks[seg.cur as usize];
        let continues = cur.var.is_none();
        let known_start = match cur.known_start {
            Some(start) if continues => Some(start + cur.len),
            _ => None,
        };
        let known_abs = match org_base {
            Some(base) => Some(base),
            None if org && cur.org && continues => {
                cur.known_abs.map(|abs| abs + i64::from(cur.len))
            }
            None => None,
        };
        let chunk = Chunk {
            seg: self.seg,
            org,
            org_base,
            data_start: seg.data.len() as u32,
            len: 0,
            var: None,
            known_start,
            known_abs,
            start: 0,
            abs: 0,
        };
        let id = self.prog.chunks.len() as ChunkId;
        self.prog.chunks.push(chunk);
        let seg = &mut self.prog.segs[self.seg as usize];
        seg.chunks.push(id);
        seg.cur = id;
    }

    /// Appends bytes to the current chunk.
    pub(crate) fn emit(&mut self, bytes: &[u8]) {
        let seg = &mut self.prog.segs[self.seg as usize];
        if bytes.len() <= 4 {
            // Instructions: a call to memcpy costs more than the bytes.
            for &byte in bytes {
                seg.data.push(byte);
            }
        } else {
            seg.data.extend_from_slice(bytes);
        }
        seg.has_data = true;
        seg.used = true;
        self.prog.chunks[seg.cur as usize].len += bytes.len() as u32;
        self.total_bytes += bytes.len();
        if self.total_bytes > MAX_BYTES && !self.stop {
            let span = Span {
                file: self.line.file,
                start: self.line.start,
                end: self.line.end,
            };
            self.err(
                "asm::too-big",
                span,
                format!(
                    "the program grows past {} MiB here; assembly stops",
                    MAX_BYTES >> 20
                ),
            );
            self.stop = true;
        }
    }

    /// Records an instruction or data item for the source map.
    pub(crate) fn item(&mut self, span: Span, instr_len: u8) {
        let (chunk, off) = self.here();
        let column = self.column_of(span);
        self.prog.items.push(Item {
            chunk,
            off,
            file: self.line.file,
            line: self.line.line,
            column,
            instr_len,
        });
    }

    // ----- symbols -----------------------------------------------------

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
                .global_syms
                .get(name as usize)
                .copied()
                .filter(|&sym| sym != NO_SYM);
        }
        self.sym_map.get(&key(scope, name)).copied()
    }

    /// Records `sym` as `name` in `scope`.
    fn bind_sym(&mut self, scope: ScopeId, name: NameId, sym: SymId) {
        if scope == GLOBAL_SCOPE {
            let index = name as usize;
            if self.global_syms.len() <= index {
                self.global_syms.resize(index + 1, NO_SYM);
            }
            self.global_syms[index] = sym;
        } else {
            self.sym_map.insert(key(scope, name), sym);
        }
    }

    /// A reference to `name` from the current scope: an existing symbol in
    /// this scope or an enclosing one, else a new one here (bound to an
    /// outer definition at the end if none appears here).
    pub(crate) fn ref_sym(&mut self, name: NameId, span: Span) -> SymId {
        let mut scope = self.scope;
        let sym = loop {
            if let Some(sym) = self.find_sym(scope, name) {
                break sym;
            }
            if scope == GLOBAL_SCOPE {
                let sym = self.new_sym(name, self.scope, SymKind::Normal);
                self.bind_sym(self.scope, name, sym);
                break sym;
            }
            scope = self.prog.scopes[scope as usize].parent;
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
        if let Some(&sym) = self.cheap_map.get(&key(self.cheap_epoch, name)) {
            return sym;
        }
        let sym = self.new_sym(name, self.scope, SymKind::Cheap);
        self.cheap_map.insert(key(self.cheap_epoch, name), sym);
        sym
    }

    /// Starts a new region for cheap locals. The old region's names can
    /// never be reached again, so the map forgets them: it stays as small
    /// as one region (in cache), not as large as the program.
    pub(crate) fn new_cheap_region(&mut self) {
        self.cheap_epoch += 1;
        if !self.cheap_map.is_empty() {
            if self.cheap_map.capacity() > 1024 {
                // After a region with very many locals: clearing costs the
                // capacity, so start small again.
                self.cheap_map = FxHashMap::default();
            } else {
                self.cheap_map.clear();
            }
        }
    }

    /// The unnamed label with index `index`.
    pub(crate) fn unnamed_sym(&mut self, index: usize) -> SymId {
        while self.unnamed.len() <= index {
            let name = self.names.intern(":");
            let sym = self.new_sym(name, GLOBAL_SCOPE, SymKind::Unnamed);
            self.unnamed.push(sym);
        }
        self.unnamed[index]
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
        s.def_file = self.line.file;
        s.def_line = self.line.line;
        s.def_column = column;
        s.def_ctx = self.line_ctx;
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
            Keyword::Mnemonic(mnemonic)
                if instructions_too && (mnemonic.is_documented() || self.cpu_x) =>
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
                let index = self.unnamed_count;
                self.unnamed_count += 1;
                self.unnamed_sym(index)
            }
            _ => self.sym_in(self.scope, tok.name()),
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
        self.scope_map.get(&key(parent, name)).copied()
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
        self.scope_map.insert(key(parent, name), id);
        id
    }

    /// Finds scope `name` from the current scope outward.
    pub(crate) fn lookup_scope(&self, name: NameId) -> Option<ScopeId> {
        let mut scope = self.scope;
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

    // ----- input -------------------------------------------------------

    /// The places `.include` (`binary` false) or `.incbin` (`binary` true)
    /// looks for a relative `name`, in ca65's order: an include next to the
    /// including file, then in each `-I` directory; a binary file first as
    /// the name stands (the working directory), then next to the including
    /// file, then in each `--bin-include-dir` directory. Built-in includes
    /// come after all of these.
    pub(crate) fn search_path(&self, binary: bool, from_dir: &Path) -> Vec<PathBuf> {
        let mut dirs = Vec::new();
        if binary {
            dirs.push(PathBuf::new());
        }
        dirs.push(from_dir.to_path_buf());
        let extra = if binary {
            &self.opts.bin_include_dirs
        } else {
            &self.opts.include_dirs
        };
        dirs.extend(extra.iter().cloned());
        dirs.dedup();
        dirs
    }

    /// Reads a file through the source for `.include` or `.incbin`,
    /// following [`Asm::search_path`].
    pub(crate) fn find_file(
        &self,
        name: &str,
        binary: bool,
        from_dir: &Path,
    ) -> Option<(PathBuf, Vec<u8>)> {
        let path = Path::new(name);
        let candidates = if path.is_absolute() {
            vec![path.to_path_buf()]
        } else {
            self.search_path(binary, from_dir)
                .into_iter()
                .map(|dir| dir.join(path))
                .collect()
        };
        for candidate in candidates {
            if let Ok(bytes) = self.source.read(&candidate) {
                return Some((candidate, bytes));
            }
        }
        if binary {
            return None;
        }
        self.opts
            .builtin_includes
            .get(name)
            .map(|bytes| (PathBuf::from(name), bytes.clone()))
    }

    /// Pushes a file to read next.
    pub(crate) fn push_file(&mut self, name: String, bytes: Vec<u8>, dir: PathBuf, ctx: CtxId) {
        if self.frames.is_empty() {
            // About one item per 16 bytes of source: reserving once saves
            // the repeated growth of the biggest vectors.
            let estimate = bytes.len() / 16;
            self.prog.items.reserve(estimate);
            self.prog.segs[self.seg as usize].data.reserve(estimate * 2);
            self.prog.nodes.reserve(estimate / 2);
            self.prog.locs.reserve(estimate / 4);
            self.prog.fixups.reserve(estimate / 4);
        }
        // Shared with the file table for diagnostics, without a copy.
        let text: Text = Arc::new(bytes);
        let file = self.files.add(name, Arc::clone(&text));
        self.frames.push(Frame::File {
            text,
            lexer: Lexer::new(file),
            ctx,
            conds: self.conds.len(),
            dir,
        });
    }

    /// The directory of the innermost file being read.
    pub(crate) fn current_dir(&self) -> PathBuf {
        for frame in self.frames.iter().rev() {
            if let Frame::File { dir, .. } = frame {
                return dir.clone();
            }
        }
        PathBuf::new()
    }

    pub(crate) fn frame_room(&mut self, span: Span) -> PResult<()> {
        if self.frames.len() >= MAX_FRAMES {
            return Err(self.err(
                "asm::too-deep",
                span,
                format!("includes, macros and `.repeat`s are nested more than {MAX_FRAMES} deep"),
            ));
        }
        Ok(())
    }

    /// Reads the next line into `self.toks`. `Some(None)` means the
    /// innermost frame ended; `None` that no input is left.
    fn fetch(&mut self) -> Option<Option<LineInfo>> {
        let frame = self.frames.last_mut()?;
        self.toks.clear();
        match frame {
            Frame::File {
                text, lexer, ctx, ..
            } => {
                self.line_ctx = *ctx;
                Some(lexer.next_line(text, &mut self.names, &mut self.toks, &mut self.lex_errors))
            }
            Frame::Macro {
                body,
                line,
                args,
                locals,
                ctx,
                ..
            } => {
                self.line_ctx = *ctx;
                let Some(body_line) = body.lines.get(*line).copied() else {
                    return Some(None);
                };
                *line += 1;
                if let Some(listing) = self.listing.as_mut() {
                    listing.expanded = Some(expanded_text(&self.files, body, body_line, |tok| {
                        if tok.kind != Tok::Param {
                            return None;
                        }
                        let arg = args.get(tok.value as usize).map_or(&[][..], Vec::as_slice);
                        Some(token_run_text(&self.files, arg))
                    }));
                }
                for tok in &body.tokens[body_line.first as usize..body_line.end as usize] {
                    match tok.kind {
                        Tok::Param => {
                            if let Some(arg) = args.get(tok.value as usize) {
                                if self.toks.len() + arg.len() > MAX_LINE_TOKENS {
                                    self.overlong = true;
                                    break;
                                }
                                self.toks.extend_from_slice(arg);
                            }
                        }
                        Tok::Ident if !locals.is_empty() => {
                            let renamed = locals
                                .iter()
                                .find(|(from, _)| *from == tok.name())
                                .map_or(tok.value, |(_, to)| u64::from(*to));
                            self.toks.push(Token {
                                value: renamed,
                                ..*tok
                            });
                        }
                        _ => self.toks.push(*tok),
                    }
                }
                Some(Some(body_line.info))
            }
            Frame::Repeat {
                body,
                line,
                iter,
                count,
                var,
                ctx,
                ..
            } => {
                self.line_ctx = *ctx;
                if *iter >= *count || body.lines.is_empty() {
                    // Stays ended, however often it is asked.
                    return Some(None);
                }
                if *line >= body.lines.len() {
                    *iter += 1;
                    *line = 0;
                    if *iter >= *count {
                        return Some(None);
                    }
                }
                let body_line = body.lines[*line];
                *line += 1;
                if let Some(listing) = self.listing.as_mut() {
                    let counter = *iter;
                    listing.expanded = Some(expanded_text(&self.files, body, body_line, |tok| {
                        (tok.kind == Tok::Ident && Some(tok.name()) == *var)
                            .then(|| counter.to_string())
                    }));
                }
                for tok in &body.tokens[body_line.first as usize..body_line.end as usize] {
                    if tok.kind == Tok::Ident && Some(tok.name()) == *var {
                        self.toks.push(Token {
                            kind: Tok::Number,
                            span: tok.span,
                            value: u64::from(*iter),
                        });
                    } else {
                        self.toks.push(*tok);
                    }
                }
                Some(Some(body_line.info))
            }
        }
    }

    /// Reads the next raw line for a macro or `.repeat` body (no defines,
    /// no conditionals). `None` when the innermost frame ends.
    pub(crate) fn fetch_raw(&mut self) -> Option<LineInfo> {
        if self.lines_read > self.opts.max_lines {
            return None;
        }
        match self.fetch() {
            Some(Some(info)) => {
                self.lex_errors.clear();
                self.lines_read += 1;
                self.line = info;
                self.check_overlong(info);
                if let Some(listing) = self.listing.as_mut() {
                    listing.text_line(&self.frames, info);
                }
                Some(info)
            }
            _ => None,
        }
    }

    /// Reports (and empties) a line that macro substitution made too long.
    fn check_overlong(&mut self, info: LineInfo) {
        if !std::mem::take(&mut self.overlong) {
            return;
        }
        let span = Span {
            file: info.file,
            start: info.start,
            end: info.end,
        };
        self.err(
            "asm::too-long",
            span,
            format!(
                "this line grows past {MAX_LINE_TOKENS} tokens when its macro arguments are substituted (a macro whose argument contains itself?)"
            ),
        );
        self.toks.clear();
    }

    fn pop_frame(&mut self) {
        let Some(frame) = self.frames.pop() else {
            return;
        };
        let base = frame.conds();
        while self.conds.len() > base {
            if let Some(cond) = self.conds.pop() {
                let diag = diag::error(
                    "asm::unclosed",
                    cond.span,
                    "this `.if` has no `.endif` before the end of its file or expansion",
                );
                self.report(diag);
            }
        }
        if let Frame::File { ctx, .. } = frame {
            self.line_ctx = ctx;
        }
    }

    /// Runs the whole input.
    pub(crate) fn run(&mut self) {
        while !self.stop {
            if self.rep.overwhelmed() {
                self.rep.stopped = true;
                break;
            }
            match self.fetch() {
                None => break,
                Some(None) => self.pop_frame(),
                Some(Some(info)) => {
                    self.lines_read += 1;
                    self.check_overlong(info);
                    if self.lines_read > self.opts.max_lines {
                        let span = self.toks.first().map_or(
                            Span {
                                file: info.file,
                                start: info.start,
                                end: info.start,
                            },
                            |t| t.span,
                        );
                        self.err(
                            "asm::too-many-lines",
                            span,
                            format!(
                                "more than {} lines to assemble (a runaway `.repeat` or recursive macro?)",
                                self.opts.max_lines
                            ),
                        );
                        break;
                    }
                    self.line = info;
                    self.process_line();
                }
            }
        }
    }

    pub(crate) fn active(&self) -> bool {
        self.conds.last().is_none_or(|c| c.active)
    }

    fn process_line(&mut self) {
        if let Some(listing) = self.listing.as_mut() {
            listing.begin_line(&self.frames, self.line, &self.prog, self.seg);
        }
        if !self.active() {
            self.lex_errors.clear();
            self.skipped_line();
        } else if !self.lex_errors.is_empty() {
            let errors = std::mem::take(&mut self.lex_errors);
            for (span, message) in errors {
                self.err("asm::syntax", span, message);
            }
        } else {
            if self.any_define && !self.toks.is_empty() {
                self.substitute_defines();
            }
            let toks = std::mem::take(&mut self.toks);
            let mark = self.prog.nodes.len();
            self.keep_nodes = false;
            let _ = self.statement(&toks);
            if !self.keep_nodes {
                self.prog.nodes.truncate(mark);
            }
            self.toks = toks;
        }
        if let Some(listing) = self.listing.as_mut() {
            listing.end_line(&self.prog, self.seg);
        }
    }

    /// A line inside a false conditional: only nesting matters.
    fn skipped_line(&mut self) {
        let Some(first) = self.toks.first().copied() else {
            return;
        };
        if first.kind != Tok::Directive {
            return;
        }
        let Keyword::Directive(dir) = self.names.keyword(first.name()) else {
            return;
        };
        match dir {
            _ if dir.opens_conditional() => self.conds.push(Cond {
                span: first.span,
                parent_active: false,
                active: false,
                taken: true,
                seen_else: false,
            }),
            Dir::Else | Dir::Elseif | Dir::Endif => {
                let toks = std::mem::take(&mut self.toks);
                let mut c = self.cursor(&toks);
                let _ = self.conditional(dir, &mut c);
                self.toks = toks;
            }
            _ => {}
        }
    }

    /// Replaces `.define`d names in the current line.
    fn substitute_defines(&mut self) {
        // `.define`, `.undefine` and `.ifdef`-like lines name a define
        // rather than use it.
        if let Some(first) = self.toks.first()
            && first.kind == Tok::Directive
            && matches!(
                self.names.keyword(first.name()),
                Keyword::Directive(Dir::Define | Dir::Undefine)
            )
        {
            return;
        }
        let mut rounds = 0;
        loop {
            let mut changed = false;
            self.tmp.clear();
            let mut i = 0;
            let toks = std::mem::take(&mut self.toks);
            while i < toks.len() {
                if self.tmp.len() > MAX_LINE_TOKENS {
                    break;
                }
                let tok = toks[i];
                let define = if tok.kind == Tok::Ident {
                    self.names
                        .info
                        .get(tok.value as usize)
                        .and_then(|info| info.define_id)
                } else {
                    None
                };
                let Some(define) = define.and_then(|d| self.defines.get(d as usize)) else {
                    self.tmp.push(tok);
                    i += 1;
                    continue;
                };
                changed = true;
                if !define.has_params {
                    self.tmp.extend_from_slice(&define.tokens);
                    i += 1;
                    continue;
                }
                // name(arg, arg): split the arguments at top-level commas.
                let mut args: Vec<Vec<Token>> = Vec::new();
                let mut j = i + 1;
                if toks.get(j).map(|t| t.kind) == Some(Tok::LParen) {
                    j += 1;
                    let mut depth = 0;
                    let mut current = Vec::new();
                    while j < toks.len() {
                        let t = toks[j];
                        match t.kind {
                            Tok::LParen => depth += 1,
                            Tok::RParen if depth == 0 => break,
                            Tok::RParen => depth -= 1,
                            Tok::Comma if depth == 0 => {
                                args.push(std::mem::take(&mut current));
                                j += 1;
                                continue;
                            }
                            _ => {}
                        }
                        current.push(t);
                        j += 1;
                    }
                    args.push(current);
                    j += 1;
                }
                for t in &define.tokens {
                    let param = if t.kind == Tok::Ident {
                        define.params.iter().position(|p| *p == t.name())
                    } else {
                        None
                    };
                    match param {
                        Some(index) => {
                            if let Some(arg) = args.get(index) {
                                self.tmp.extend_from_slice(arg);
                            }
                        }
                        None => self.tmp.push(*t),
                    }
                }
                i = j;
            }
            self.toks = toks;
            std::mem::swap(&mut self.toks, &mut self.tmp);
            rounds += 1;
            if !changed {
                break;
            }
            if rounds > 64 || self.toks.len() > MAX_LINE_TOKENS {
                let span = self.toks.first().map(|t| t.span).unwrap_or_default();
                self.err(
                    "asm::define-loop",
                    span,
                    "`.define` substitution does not end (a define that uses itself?)",
                );
                self.toks.clear();
                break;
            }
        }
    }

    // ----- statements --------------------------------------------------

    /// The cursor over a line's tokens, placing what is missing at the
    /// line's end.
    pub(crate) fn cursor<'t>(&self, toks: &'t [Token]) -> Cursor<'t> {
        Cursor::new(
            toks,
            Span {
                file: self.line.file,
                start: self.line.end,
                end: self.line.end,
            },
        )
    }

    fn statement(&mut self, t: &[Token]) -> PResult<()> {
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
            (Tok::Ident, Some(Tok::Directive))
                if self.names.keyword(t[1].name()) == Keyword::Directive(Dir::Set) =>
            {
                return self.set_variable(&mut c);
            }
            (Tok::Ident | Tok::Local, Some(Tok::Colon)) => {
                // `name:` is a label even where a macro has the name.
                self.define_label(&t[0])?;
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
                    _ => {
                        let name = self.names.name(head.name()).to_string();
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
                        let suggestion = self.similar_statement_head(&name);
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
            _ => self.sym_in(self.scope, name.name()),
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

    /// `name .set expr`: a variable, taken by value where it is used.
    fn set_variable(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let name = c.current();
        c.advance_by(2);
        let start = c.pos();
        let expr = self.expression(c)?;
        self.expect_end(c)?;
        let sym = self.sym_in(self.scope, name.name());
        let node = match self.prog.eval(expr) {
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

    // ----- macros ------------------------------------------------------

    fn invoke_macro(&mut self, mac: u32, c: &mut Cursor<'_>) -> PResult<()> {
        let Some(head) = c.next_token() else {
            return Ok(());
        };
        self.frame_room(head.span)?;
        // Arguments: comma-separated token runs; `{...}` groups a run.
        let mut args: Vec<Vec<Token>> = Vec::new();
        if !c.is_end() {
            let mut current = Vec::new();
            let mut depth = 0usize;
            while let Some(tok) = c.next_token() {
                match tok.kind {
                    Tok::LBrace => {
                        if depth > 0 {
                            current.push(tok);
                        }
                        depth += 1;
                    }
                    Tok::RBrace if depth > 0 => {
                        depth -= 1;
                        if depth > 0 {
                            current.push(tok);
                        }
                    }
                    Tok::Comma if depth == 0 => args.push(std::mem::take(&mut current)),
                    _ => current.push(tok),
                }
            }
            args.push(current);
        }
        let Some(macro_def) = self.macros.get(mac as usize) else {
            return Ok(());
        };
        if args.len() > macro_def.params.len() {
            let name = self.names.name(macro_def.name).to_string();
            let count = macro_def.params.len();
            return Err(self.err(
                "asm::macro-args",
                self.join(head.span, c.last_span()),
                format!(
                    "macro `{name}` takes {count} parameter{}, {} given",
                    if count == 1 { "" } else { "s" },
                    args.len()
                ),
            ));
        }
        let body = Rc::clone(&macro_def.body);
        let name = self.names.name(macro_def.name).to_string();
        self.expansions += 1;
        let ctx = self.new_ctx(CtxKind::Macro(name), head.span);
        self.frames.push(Frame::Macro {
            body,
            line: 0,
            args,
            locals: Vec::new(),
            ctx,
            conds: self.conds.len(),
        });
        Ok(())
    }

    /// Reads a macro or `.repeat` body up to its end directive. `opener`
    /// and `closer` are the nesting directives. Returns `None` if the
    /// input ended first (reported).
    pub(crate) fn collect_body(
        &mut self,
        opener: Dir,
        closer: Dir,
        params: &[NameId],
        start: Span,
    ) -> Option<Body> {
        let mut body = Body::default();
        let mut depth = 0usize;
        let saved_line = self.line;
        loop {
            let Some(info) = self.fetch_raw() else {
                self.line = saved_line;
                let what = if opener == Dir::Macro {
                    "`.macro` has no `.endmacro`"
                } else {
                    "`.repeat` has no `.endrepeat`"
                };
                self.err("asm::unclosed", start, what);
                return None;
            };
            let first = self.toks.first().copied();
            if let Some(first) = first
                && first.kind == Tok::Directive
                && let Keyword::Directive(dir) = self.names.keyword(first.name())
            {
                if dir == opener {
                    depth += 1;
                } else if dir == closer {
                    if depth == 0 {
                        if self.toks.len() > 1 {
                            let span = self.toks[1].span;
                            self.err(
                                "asm::syntax",
                                span,
                                "unexpected text after the end directive",
                            );
                        }
                        return Some(body);
                    }
                    depth -= 1;
                }
            }
            let first_index = body.tokens.len() as u32;
            for tok in &self.toks {
                let kind = if tok.kind == Tok::Ident {
                    params.iter().position(|p| *p == tok.name())
                } else {
                    None
                };
                match kind {
                    Some(index) => body.tokens.push(Token {
                        kind: Tok::Param,
                        span: tok.span,
                        value: index as u64,
                    }),
                    None => body.tokens.push(*tok),
                }
            }
            body.lines.push(crate::asm::BodyLine {
                first: first_index,
                end: body.tokens.len() as u32,
                info,
            });
        }
    }

    // ----- conditionals ------------------------------------------------

    /// `c` is at the directive.
    pub(crate) fn conditional(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        let base = self.frames.last().map_or(0, Frame::conds);
        match dir {
            Dir::Else | Dir::Elseif => {
                if self.conds.len() <= base {
                    return Err(self.err(
                        "asm::unbalanced",
                        head.span,
                        format!("`{}` without `.if`", self.names.name(head.name())),
                    ));
                }
                let cond = *self.conds.last().unwrap_or(&Cond {
                    span: head.span,
                    parent_active: false,
                    active: false,
                    taken: true,
                    seen_else: false,
                });
                if cond.seen_else {
                    let diag = diag::error(
                        "asm::unbalanced",
                        head.span,
                        format!("`{}` after `.else`", self.names.name(head.name())),
                    )
                    .also(cond.span, "in this `.if`");
                    return Err(self.report(diag));
                }
                let mut next = cond;
                if dir == Dir::Else {
                    next.active = cond.parent_active && !cond.taken;
                    next.taken = true;
                    next.seen_else = true;
                } else if !cond.parent_active || cond.taken {
                    next.active = false;
                } else {
                    c.advance();
                    let value = self.const_expr(c, "`.elseif`")?;
                    self.expect_end(c)?;
                    next.active = value != 0;
                    next.taken = next.active;
                }
                if let Some(top) = self.conds.last_mut() {
                    *top = next;
                }
                Ok(())
            }
            Dir::Endif => {
                if self.conds.len() <= base {
                    return Err(self.err("asm::unbalanced", head.span, "`.endif` without `.if`"));
                }
                self.conds.pop();
                c.advance();
                self.expect_end(c)
            }
            _ => {
                let truth = self.condition(dir, c);
                let active = truth.unwrap_or(false);
                self.conds.push(Cond {
                    span: head.span,
                    parent_active: true,
                    active,
                    // A failed condition takes no branch but also enables
                    // none, so errors do not cascade.
                    taken: active || truth.is_err(),
                    seen_else: false,
                });
                truth.map(|_| ())
            }
        }
    }

    fn condition(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<bool> {
        c.advance();
        let result = match dir {
            Dir::If => self.const_expr(c, "`.if`")? != 0,
            Dir::Ifdef | Dir::Ifndef | Dir::Ifref | Dir::Ifnref => {
                let sym = self.parse_symbol_name(c)?;
                let defined = sym.is_some_and(|s| {
                    if matches!(dir, Dir::Ifref | Dir::Ifnref) {
                        self.prog.syms[s as usize].ref_loc.is_some()
                    } else {
                        self.prog.syms[s as usize].is_defined()
                    }
                });
                defined == matches!(dir, Dir::Ifdef | Dir::Ifref)
            }
            Dir::Ifblank | Dir::Ifnblank => {
                let blank = c.is_end();
                c.advance_by(c.rest().len());
                blank == (dir == Dir::Ifblank)
            }
            Dir::Ifconst => {
                let expr = self.expression(c)?;
                matches!(self.prog.eval(expr), Ok(crate::expr::Value::Const(_)))
            }
            Dir::Ifp02 => true,
            _ => false,
        };
        self.expect_end(c)?;
        Ok(result)
    }
}

/// The text of a body line with some tokens replaced (macro arguments,
/// the `.repeat` counter), for the listing.
fn expanded_text(
    files: &Files,
    body: &Body,
    line: BodyLine,
    mut replace: impl FnMut(&Token) -> Option<String>,
) -> String {
    let text = files.text(line.info.file);
    let end = (line.info.end as usize).min(text.len());
    let mut prev = (line.info.start as usize).min(end);
    let mut out = String::new();
    for tok in &body.tokens[line.first as usize..line.end as usize] {
        if tok.span.file != line.info.file {
            continue;
        }
        let Some(with) = replace(tok) else {
            continue;
        };
        let start = (tok.span.start as usize).clamp(prev, end);
        out.push_str(&String::from_utf8_lossy(&text[prev..start]));
        out.push_str(&with);
        prev = (tok.span.end as usize).clamp(start, end);
    }
    out.push_str(&String::from_utf8_lossy(&text[prev..end]));
    out
}

/// The source text of a run of tokens (a macro argument): the source as
/// written when the tokens are contiguous, else their texts with spaces.
fn token_run_text(files: &Files, toks: &[Token]) -> String {
    if let (Some(first), Some(last)) = (toks.first(), toks.last()) {
        let joined = files.join(first.span, last.span);
        if joined.end == last.span.end.max(first.span.end)
            && toks
                .windows(2)
                .all(|w| w[0].span.end <= w[1].span.start && w[0].span.file == w[1].span.file)
        {
            return files.snippet(joined);
        }
    }
    let mut out = String::new();
    for (i, tok) in toks.iter().enumerate() {
        if i > 0 && toks[i - 1].span.end != tok.span.start {
            out.push(' ');
        }
        out.push_str(&files.snippet(tok.span));
    }
    out
}

/// Source map entries need the symbol's place; kept beside the symbol.
impl Sym {
    pub(crate) fn place(&self) -> (u32, u32, u32) {
        (self.def_file, self.def_line, self.def_column)
    }
}
