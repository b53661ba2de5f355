//! Other files: `.include` (source read in place) and `.incbin` (bytes
//! copied in), found along ca65's search paths.

use std::path::Path;

use crate::asm::{Asm, Frame, MAX_BYTES, PResult};
use crate::cursor::Cursor;
use crate::diag::{self, CtxKind};
use crate::lexer::{Tok, Token};

impl Asm<'_> {
    /// The file name operand of `.include`/`.incbin`, after the directive
    /// at `c`.
    fn file_operand(&mut self, c: &mut Cursor<'_>) -> PResult<(Token, String)> {
        c.advance();
        let Some(tok) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected a file name in quotes"));
        };
        c.advance();
        let name = String::from_utf8_lossy(&self.string_bytes(&tok)).into_owned();
        Ok((tok, name))
    }

    /// A file `.include` or `.incbin` cannot find: the error names every
    /// place searched, in order. A missing include ends the assembly, as
    /// in ca65: what follows it depends on it, and every error there would
    /// only repeat this one.
    fn not_found(&mut self, tok: Token, name: &str, binary: bool) -> crate::asm::Reported {
        let including = self.current_dir();
        let mut places: Vec<String> = self
            .search_path(binary, &including)
            .iter()
            .map(|dir| {
                let shown = match dir.as_os_str().is_empty() {
                    true => "`.`".to_string(),
                    false => format!("`{}`", dir.display()),
                };
                let role = if *dir == including {
                    " (the including file's directory)"
                } else if dir.as_os_str().is_empty() {
                    " (the working directory)"
                } else if binary {
                    " (--bin-include-dir)"
                } else if self.opts.system_include_dirs.contains(dir)
                    && !self.opts.include_dirs.contains(dir)
                {
                    " (ca65's include path)"
                } else {
                    " (-I)"
                };
                format!("{shown}{role}")
            })
            .collect();
        let mut help_tail = String::new();
        if !binary {
            let builtin: Vec<&str> = self
                .opts
                .builtin_includes
                .keys()
                .map(String::as_str)
                .collect();
            if !builtin.is_empty() {
                places.push(format!("the built-in `{}`", builtin.join("`, `")));
            }
            if let Some(close) = diag::did_you_mean(name, builtin.iter().copied()) {
                help_tail = format!("; did you mean `{close}`?");
            }
            self.fatal = true;
            self.stop = true;
        }
        let option = if binary { "--bin-include-dir" } else { "-I" };
        let diag = diag::error(
            "asm::file-not-found",
            tok.span,
            format!("cannot find `{name}`"),
        )
        .label("not found")
        .help(format!(
            "searched {}{help_tail}\nadd a directory to search with `{option} DIR`",
            places.join(", ")
        ));
        self.report(diag)
    }

    /// A file `.include` or `.incbin` found but cannot read (a device, a
    /// FIFO, a file over the size limit): the error says what it is. Like
    /// a missing include, an unreadable one ends the assembly.
    fn unreadable(
        &mut self,
        tok: Token,
        name: &str,
        binary: bool,
        error: &std::io::Error,
    ) -> crate::asm::Reported {
        if !binary {
            self.fatal = true;
            self.stop = true;
        }
        let diag = diag::error(
            "asm::file-unreadable",
            tok.span,
            format!("cannot read `{name}`: {error}"),
        )
        .label("not readable")
        .help("name a regular file within the size limit");
        self.report(diag)
    }

    pub(super) fn include(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        let (tok, name) = self.file_operand(c)?;
        self.expect_end(c)?;
        self.frame_room(tok.span)?;
        let dir = self.current_dir();
        let (path, bytes, builtin) = match self.find_file(&name, false, &dir) {
            Ok(Some(found)) => found,
            Ok(None) => return Err(self.not_found(tok, &name, false)),
            Err(error) => return Err(self.unreadable(tok, &name, false, &error)),
        };
        let ctx = self.new_ctx(CtxKind::Include, self.join(head.span, tok.span));
        let parent = path.parent().map(Path::to_path_buf).unwrap_or_default();
        self.push_file(path.display().to_string(), bytes, parent, ctx);
        self.defer_file_after_expansions();
        if builtin
            && !self.opts.list_builtin_includes
            && let Some(listing) = self.listing.as_mut()
        {
            // The file sits below any expansions it was deferred after:
            // its depth is its own place in the stack, not the stack's top.
            let depth = self
                .input
                .frames
                .iter()
                .rposition(|frame| matches!(frame, Frame::File { .. }))
                .map_or(self.input.frames.len(), |index| index + 1);
            listing.unlisted_from(depth);
        }
        Ok(())
    }

    pub(super) fn incbin(&mut self, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        let (tok, name) = self.file_operand(c)?;
        let mut offset = 0i64;
        let mut size = None;
        if c.eat(Tok::Comma) {
            offset = self.const_expr(c, "the `.incbin` offset")?;
            if c.eat(Tok::Comma) {
                size = Some(self.const_expr(c, "the `.incbin` size")?);
            }
        }
        self.expect_end(c)?;
        let dir = self.current_dir();
        let (_, bytes, _) = match self.find_file(&name, true, &dir) {
            Ok(Some(found)) => found,
            Ok(None) => return Err(self.not_found(tok, &name, true)),
            Err(error) => return Err(self.unreadable(tok, &name, true, &error)),
        };
        let len = bytes.len() as i64;
        let end = match size {
            Some(size) => offset.saturating_add(size),
            None => len,
        };
        if offset < 0 || offset > len || end < offset || end > len {
            return Err(self.err(
                "asm::range",
                self.join(tok.span, c.last_span()),
                format!(
                    "`{name}` has {len} bytes; offset {offset} and size {} do not fit",
                    end - offset
                ),
            ));
        }
        if self.total_bytes + (end - offset) as usize > MAX_BYTES {
            return Err(self.err("asm::range", tok.span, "the program is too large"));
        }
        self.item(head.span, 0);
        self.emit(&bytes[offset as usize..end as usize]);
        Ok(())
    }
}
