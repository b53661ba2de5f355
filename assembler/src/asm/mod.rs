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

mod conditionals;
mod diagnostics;
mod input;

pub(crate) use input::Expander;
pub(crate) use symbols::SymbolTable;
mod macros;
mod segments;
mod statements;
mod symbols;
mod tokenfns;

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

    /// Names to symbols, scopes and the current scope.
    pub(crate) symtab: SymbolTable,
    /// Where the next line comes from: files, macro and `.repeat` frames,
    /// `.define`s and the conditional stack.
    pub(crate) input: Expander,
    /// The segment bytes go to now.
    pub(crate) seg: SegId,
    pub(crate) listing: Option<ListingBuilder>,
    pub(crate) charmap: [u8; 256],
    pub(crate) cpu_x: bool,
    /// The `.feature` switches in force.
    pub(crate) features: crate::Features,
    /// ca65's global absolute mode: a `.org` is in force (until `.reloc`)
    /// in whichever segment is current.
    pub(crate) org_global: bool,
    /// `.autoimport on`: names never defined are imported.
    pub(crate) autoimport: bool,
    /// Labels' sizes: the bytes their line emits (`.sizeof(label)`).
    pub(crate) label_sizes: std::collections::HashMap<SymId, i64>,
    pub(crate) used_undoc: bool,
    pub(crate) messages: Vec<String>,
    pub(crate) stop: bool,
    /// A missing include ended the assembly: the back end does not run
    /// on the part that was read, whose errors would only repeat it.
    pub(crate) fatal: bool,
    pub(crate) keep_nodes: bool,
    /// `.pushseg`'s stack of segments.
    pub(crate) pushed_segs: Vec<SegId>,
    /// `.pushcpu`'s stack: whether the undocumented opcodes were on.
    pub(crate) pushed_cpus: Vec<bool>,
    pub(crate) total_bytes: usize,
    /// Main file's display name, for the `STT_FILE` symbol.
    pub(crate) main_name: String,
}

impl<'a> Asm<'a> {
    pub(crate) fn new(source: &'a dyn FileSource, opts: &'a Options) -> Asm<'a> {
        // A target system's character set (`-t c64`: PETSCII).
        let charmap = opts
            .system
            .map_or(crate::systems::Charset::Ascii, |s| s.charset)
            .table();
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
            symtab: SymbolTable::new(),
            input: Expander::new(),
            seg: 0,
            listing: None,
            charmap,
            cpu_x: opts.undocumented,
            features: opts.features,
            org_global: false,
            autoimport: false,
            label_sizes: std::collections::HashMap::new(),
            used_undoc: false,
            messages: Vec::new(),
            stop: false,
            fatal: false,
            keep_nodes: false,
            pushed_segs: Vec::new(),
            pushed_cpus: Vec::new(),
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
