//! The expander: lines from files, macro and `.repeat` bodies, with
//! `.define`s substituted and conditionals applied, one statement at a
//! time.

use super::*;

/// The expander's state: the stack of frames lines come from, the macros
/// and `.define`s known so far, the conditional stack, and the tokens of
/// the line being read.
#[derive(Debug)]
pub(crate) struct Expander {
    /// Files, macro expansions and `.repeat`s, innermost last.
    pub(crate) frames: Vec<Frame>,
    pub(crate) macros: Vec<Macro>,
    pub(crate) defines: Vec<Define>,
    /// Whether any `.define` exists (lines are scanned for them only then).
    pub(crate) any_define: bool,
    pub(crate) conds: Vec<Cond>,
    /// The current line's tokens.
    pub(crate) toks: Vec<Token>,
    /// Scratch space for `.define` substitution.
    tmp: Vec<Token>,
    lex_errors: Vec<LexError>,
    /// The current line was cut at [`MAX_LINE_TOKENS`].
    overlong: bool,
    /// The line being processed.
    pub(crate) line: LineInfo,
    pub(crate) line_ctx: CtxId,
    lines_read: u64,
    pub(crate) expansions: u32,
    /// Sources made by token functions (`.concat`...), by text.
    pub(crate) generated: std::collections::HashMap<Vec<u8>, u32>,
}

impl Expander {
    /// Nothing to read yet.
    pub(crate) fn new() -> Expander {
        Expander {
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
            lines_read: 0,
            expansions: 0,
            generated: std::collections::HashMap::new(),
        }
    }
}

impl<'a> Asm<'a> {
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
        if binary {
            dirs.extend(self.opts.bin_include_dirs.iter().cloned());
        } else {
            dirs.extend(self.opts.include_dirs.iter().cloned());
            dirs.extend(self.opts.system_include_dirs.iter().cloned());
        }
        dirs.dedup();
        dirs
    }

    /// Reads a file through the source for `.include` or `.incbin`,
    /// following [`Asm::search_path`]; `true` beside it when it is one of
    /// [`crate::Options::builtin_includes`]. Only a file that is not there
    /// sends the search on; one that is there but cannot be read (a device,
    /// a FIFO, one too large) ends it with that error.
    pub(crate) fn find_file(
        &self,
        name: &str,
        binary: bool,
        from_dir: &Path,
    ) -> std::io::Result<Option<(PathBuf, Vec<u8>, bool)>> {
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
            match self.source.read(&candidate) {
                Ok(bytes) => return Ok(Some((candidate, bytes, false))),
                Err(error) if error.kind() == std::io::ErrorKind::NotFound => {}
                Err(error) => return Err(error),
            }
        }
        if binary {
            return Ok(None);
        }
        Ok(self
            .opts
            .builtin_includes
            .get(name)
            .map(|bytes| (PathBuf::from(name), bytes.clone(), true)))
    }

    /// Pushes a file to read next.
    pub(crate) fn push_file(&mut self, name: String, bytes: Vec<u8>, dir: PathBuf, ctx: CtxId) {
        if self.input.frames.is_empty() {
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
        self.input.frames.push(Frame::File {
            text,
            lexer: Lexer::new(file),
            ctx,
            conds: self.input.conds.len(),
            dir,
        });
    }

    /// Moves the file just pushed (by `.include`) below the macro and
    /// `.repeat` expansions being read, if any: ca65 reads an include
    /// met inside an expansion after the expansions end (its input files
    /// are a stack of their own), so a second include of the same
    /// expansion is read before the first.
    pub(crate) fn defer_file_after_expansions(&mut self) {
        let frames = &mut self.input.frames;
        let Some(file) = frames.pop() else {
            return;
        };
        let at = frames
            .iter()
            .rposition(|frame| matches!(frame, Frame::File { .. }))
            .map_or(0, |index| index + 1);
        let Some(conds) = frames.get(at).map(Frame::conds) else {
            frames.push(file);
            return;
        };
        let file = match file {
            Frame::File {
                text,
                lexer,
                ctx,
                dir,
                ..
            } => Frame::File {
                text,
                lexer,
                ctx,
                conds,
                dir,
            },
            other => other,
        };
        frames.insert(at, file);
    }

    /// The directory of the innermost file being read.
    pub(crate) fn current_dir(&self) -> PathBuf {
        for frame in self.input.frames.iter().rev() {
            if let Frame::File { dir, .. } = frame {
                return dir.clone();
            }
        }
        PathBuf::new()
    }

    pub(crate) fn frame_room(&mut self, span: Span) -> PResult<()> {
        if self.input.frames.len() >= MAX_FRAMES {
            return Err(self.err(
                "asm::too-deep",
                span,
                format!("includes, macros and `.repeat`s are nested more than {MAX_FRAMES} deep"),
            ));
        }
        Ok(())
    }

    /// Reads the next line into `self.input.toks`. `Some(None)` means the
    /// innermost frame ended; `None` that no input is left.
    fn fetch(&mut self) -> Option<Option<LineInfo>> {
        let features = self.features.lexer();
        let frame = self.input.frames.last_mut()?;
        self.input.toks.clear();
        match frame {
            Frame::File {
                text, lexer, ctx, ..
            } => {
                self.input.line_ctx = *ctx;
                lexer.features = features;
                Some(lexer.next_line(
                    text,
                    &mut self.names,
                    &mut self.input.toks,
                    &mut self.input.lex_errors,
                ))
            }
            Frame::Macro {
                body,
                line,
                args,
                locals,
                ctx,
                ..
            } => {
                self.input.line_ctx = *ctx;
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
                                if self.input.toks.len() + arg.len() > MAX_LINE_TOKENS {
                                    self.input.overlong = true;
                                    break;
                                }
                                self.input.toks.extend_from_slice(arg);
                            }
                        }
                        Tok::Ident | Tok::Local if !locals.is_empty() => {
                            let renamed = locals
                                .iter()
                                .find(|(from, _)| *from == tok.name())
                                .map_or(tok.value, |(_, to)| u64::from(*to));
                            self.input.toks.push(Token {
                                value: renamed,
                                ..*tok
                            });
                        }
                        _ => self.input.toks.push(*tok),
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
                self.input.line_ctx = *ctx;
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
                        self.input.toks.push(Token {
                            kind: Tok::Number,
                            span: tok.span,
                            value: u64::from(*iter),
                        });
                    } else {
                        self.input.toks.push(*tok);
                    }
                }
                Some(Some(body_line.info))
            }
        }
    }

    /// Reads the next raw line for a macro or `.repeat` body (no defines,
    /// no conditionals). `None` when the innermost frame ends.
    pub(crate) fn fetch_raw(&mut self) -> Option<LineInfo> {
        if self.input.lines_read > self.opts.max_lines {
            return None;
        }
        match self.fetch() {
            Some(Some(info)) => {
                self.input.lex_errors.clear();
                self.input.lines_read += 1;
                self.input.line = info;
                self.check_overlong(info);
                if let Some(listing) = self.listing.as_mut() {
                    listing.text_line(&self.input.frames, info);
                }
                Some(info)
            }
            _ => None,
        }
    }

    /// Reports (and empties) a line that macro substitution made too long.
    fn check_overlong(&mut self, info: LineInfo) {
        if !std::mem::take(&mut self.input.overlong) {
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
        self.input.toks.clear();
    }

    pub(crate) fn pop_frame(&mut self) {
        let Some(frame) = self.input.frames.pop() else {
            return;
        };
        if let Some(listing) = self.listing.as_mut() {
            listing.frame_ended(self.input.frames.len());
        }
        let base = frame.conds();
        while self.input.conds.len() > base {
            if let Some(cond) = self.input.conds.pop() {
                let diag = diag::error(
                    "asm::unclosed",
                    cond.span,
                    "this `.if` has no `.endif` before the end of its file or expansion",
                );
                self.report(diag);
            }
        }
        if let Frame::File { ctx, .. } = frame {
            self.input.line_ctx = ctx;
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
                    self.input.lines_read += 1;
                    self.check_overlong(info);
                    if self.input.lines_read > self.opts.max_lines {
                        let span = self.input.toks.first().map_or(
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
                    self.input.line = info;
                    self.process_line();
                }
            }
        }
    }

    pub(crate) fn active(&self) -> bool {
        self.input.conds.last().is_none_or(|c| c.active)
    }

    fn process_line(&mut self) {
        if let Some(listing) = self.listing.as_mut() {
            listing.begin_line(&self.input.frames, self.input.line, &self.prog, self.seg);
        }
        if !self.active() {
            self.input.lex_errors.clear();
            self.skipped_line();
        } else if !self.input.lex_errors.is_empty() {
            let errors = std::mem::take(&mut self.input.lex_errors);
            for (span, message) in errors {
                self.err("asm::syntax", span, message);
            }
        } else {
            if !self.expand_line() {
                self.input.toks.clear();
            }
            let toks = std::mem::take(&mut self.input.toks);
            let mark = self.prog.nodes.len();
            self.keep_nodes = false;
            let _ = self.statement(&toks);
            if !self.keep_nodes {
                self.prog.nodes.truncate(mark);
            }
            self.input.toks = toks;
        }
        if let Some(listing) = self.listing.as_mut() {
            listing.end_line(&self.prog, self.seg);
        }
    }

    /// Substitutes the `.define`s in the current line, then expands its
    /// token functions; `false` when one failed (reported: the line is to
    /// be dropped). A `.define`'s body keeps its token functions, as in
    /// ca65: they work on the arguments of each use
    /// (`.define IV(arg) .match(.left(1,{arg}),#)`,
    /// `.define NAME(b) .concat(b, "x")`).
    fn expand_line(&mut self) -> bool {
        if self.names_a_define() {
            return true;
        }
        if self.input.any_define && !self.input.toks.is_empty() {
            self.substitute_defines();
        }
        !(self.has_token_functions() && self.expand_token_functions().is_err())
    }

    /// Whether the current line is `.define` or `.undefine`, which name a
    /// define rather than use one.
    fn names_a_define(&self) -> bool {
        self.input.toks.first().is_some_and(|first| {
            first.kind == Tok::Directive
                && matches!(
                    self.names.keyword(first.name()),
                    Keyword::Directive(Dir::Define | Dir::Undefine)
                )
        })
    }

    /// A line inside a false conditional: only nesting matters.
    fn skipped_line(&mut self) {
        let Some(first) = self.input.toks.first().copied() else {
            return;
        };
        if first.kind != Tok::Directive {
            return;
        }
        let Keyword::Directive(dir) = self.names.keyword(first.name()) else {
            return;
        };
        match dir {
            _ if dir.opens_conditional() => self.input.conds.push(Cond {
                span: first.span,
                parent_active: false,
                active: false,
                taken: true,
                seen_else: false,
            }),
            Dir::Else | Dir::Elseif | Dir::Endif => {
                // An `.elseif` condition reads as any line: defines and
                // token functions first.
                if dir == Dir::Elseif && !self.expand_line() {
                    return;
                }
                let toks = std::mem::take(&mut self.input.toks);
                let mut c = self.cursor(&toks);
                let _ = self.conditional(dir, &mut c);
                self.input.toks = toks;
            }
            _ => {}
        }
    }

    /// Replaces `.define`d names in the current line.
    fn substitute_defines(&mut self) {
        let mut rounds = 0;
        loop {
            let mut changed = false;
            self.input.tmp.clear();
            let mut i = 0;
            let toks = std::mem::take(&mut self.input.toks);
            while i < toks.len() {
                if self.input.tmp.len() > MAX_LINE_TOKENS {
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
                let Some(define) = define.and_then(|d| self.input.defines.get(d as usize)) else {
                    self.input.tmp.push(tok);
                    i += 1;
                    continue;
                };
                changed = true;
                if !define.has_params {
                    self.input.tmp.extend_from_slice(&define.tokens);
                    i += 1;
                    continue;
                }
                // The arguments as ca65 reads them (`StartExpDefine`): one
                // per parameter, each a braced list (up to the first `}`,
                // braces dropped) or the tokens up to the next comma or
                // the end of the line. Parentheses are not special:
                // `SQ(2+1)` passes `(2+1)`, as ca65 does.
                let mut args: Vec<Vec<Token>> = Vec::new();
                let mut j = i + 1;
                for index in 0..define.params.len() {
                    if index > 0 {
                        if toks.get(j).map(|t| t.kind) != Some(Tok::Comma) {
                            break;
                        }
                        j += 1;
                    }
                    let braced = toks.get(j).map(|t| t.kind) == Some(Tok::LBrace);
                    if braced {
                        j += 1;
                    }
                    let term = if braced { Tok::RBrace } else { Tok::Comma };
                    let mut current = Vec::new();
                    while let Some(&t) = toks.get(j) {
                        if t.kind == term {
                            break;
                        }
                        current.push(t);
                        j += 1;
                    }
                    if braced && toks.get(j).map(|t| t.kind) == Some(Tok::RBrace) {
                        j += 1;
                    }
                    args.push(current);
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
                                self.input.tmp.extend_from_slice(arg);
                            }
                        }
                        None => self.input.tmp.push(*t),
                    }
                }
                i = j;
            }
            self.input.toks = toks;
            std::mem::swap(&mut self.input.toks, &mut self.input.tmp);
            rounds += 1;
            if !changed {
                break;
            }
            if rounds > 64 || self.input.toks.len() > MAX_LINE_TOKENS {
                let span = self.input.toks.first().map(|t| t.span).unwrap_or_default();
                self.err(
                    "asm::define-loop",
                    span,
                    "`.define` substitution does not end (a define that uses itself?)",
                );
                self.input.toks.clear();
                break;
            }
        }
    }
}
