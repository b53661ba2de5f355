//! Diagnostics: spans, the collector the assembler reports into, and the
//! public [`Diagnostic`] that miette renders.
//!
//! The assembler never stops at the first problem. Every stage pushes cheap
//! raw records (a span, a message, the expansion context) into a [`Reporter`];
//! only at the end are they turned into [`Diagnostic`]s with their source
//! text, line and column, and a backtrace of macro expansions and includes
//! as related notes.

use std::cell::OnceCell;
use std::fmt;
use std::sync::Arc;

use miette::{LabeledSpan, NamedSource, SourceCode};

/// The candidate most likely meant where `name` was written, for a "did
/// you mean" help: the nearest by edit distance (a swap of two letters
/// counts once, case is ignored), and only when near enough to be a typo:
/// one edit in a name of up to five characters, two in a longer one.
pub(crate) fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let wanted = name.to_ascii_lowercase();
    let limit = suggestion_limit(name);
    candidates
        .into_iter()
        // The distance is at least the difference in length: most
        // candidates are out before the edit distance is computed.
        .filter(|candidate| *candidate != name && candidate.len().abs_diff(name.len()) <= limit)
        .map(|candidate| {
            let distance = strsim::osa_distance(&wanted, &candidate.to_ascii_lowercase());
            (distance, candidate)
        })
        .filter(|(distance, _)| *distance <= limit)
        .min()
        .map(|(_, candidate)| candidate)
}

/// A name prepared for [`Pattern::distance`]: for each byte, the bit mask
/// of the positions where the name has it.
struct Pattern {
    masks: Box<[u64; 256]>,
    len: usize,
}

impl Pattern {
    /// `name` (lowercased), or `None` if it is too long for one word
    /// (then [`osa_within`] answers).
    fn new(name: &[u8]) -> Option<Pattern> {
        if name.is_empty() || name.len() > 64 {
            return None;
        }
        let mut masks = Box::new([0u64; 256]);
        for (i, &byte) in name.iter().enumerate() {
            masks[usize::from(byte)] |= 1 << i;
        }
        Some(Pattern {
            masks,
            len: name.len(),
        })
    }

    /// The optimal-string-alignment distance (strsim's `osa_distance`)
    /// from the pattern to `text`, by Hyyrö's bit-parallel algorithm
    /// (2003): one step of a few word operations per byte of `text`, so a
    /// comparison costs about as much as reading the name.
    fn distance(&self, text: &[u8]) -> usize {
        let last = 1u64 << (self.len - 1);
        let mut vp = if self.len == 64 {
            u64::MAX
        } else {
            (1u64 << self.len) - 1
        };
        let mut vn = 0u64;
        let mut d0_before = 0u64;
        let mut pm_before = 0u64;
        let mut score = self.len;
        for &byte in text {
            let pm = self.masks[usize::from(byte)];
            let tr = (((!d0_before) & pm) << 1) & pm_before;
            let d0 = ((((pm & vp).wrapping_add(vp)) ^ vp) | pm | vn) | tr;
            let hp = vn | !(d0 | vp);
            let hn = d0 & vp;
            if hp & last != 0 {
                score += 1;
            } else if hn & last != 0 {
                score -= 1;
            }
            let hp = (hp << 1) | 1;
            let hn = hn << 1;
            vp = hn | !(d0 | hp);
            vn = hp & d0;
            d0_before = d0;
            pm_before = pm;
        }
        score
    }
}

/// The optimal-string-alignment distance of `a` and `b` if it is at most
/// `limit` (strsim's, for names too long for [`Pattern`]).
fn osa_within(a: &[u8], b: &[u8], limit: usize) -> Option<usize> {
    if a.len().abs_diff(b.len()) > limit {
        return None;
    }
    let distance = match Pattern::new(a) {
        Some(pattern) => pattern.distance(b),
        None => strsim::osa_distance(&String::from_utf8_lossy(a), &String::from_utf8_lossy(b)),
    };
    (distance <= limit).then_some(distance)
}

/// The largest edit distance a suggestion for `name` may have.
fn suggestion_limit(name: &str) -> usize {
    if name.len() <= 5 { 1 } else { 2 }
}

/// Names to suggest from, indexed by length: a suggestion for a name
/// compares it only with names whose length is within the edit-distance
/// limit, so an error costs what the names of about its length cost,
/// not the whole symbol table ([`did_you_mean`]'s answer, faster).
#[derive(Debug, Default)]
pub(crate) struct Suggestions {
    /// By length: (lowercased, as written), sorted, for the same ties as
    /// [`did_you_mean`].
    by_len: Vec<Vec<(String, String)>>,
}

impl Suggestions {
    /// The index of `names`.
    pub(crate) fn new(names: impl IntoIterator<Item = String>) -> Suggestions {
        let mut by_len: Vec<Vec<(String, String)>> = Vec::new();
        for name in names {
            let len = name.len();
            if by_len.len() <= len {
                by_len.resize_with(len + 1, Vec::new);
            }
            by_len[len].push((name.to_ascii_lowercase(), name));
        }
        Suggestions { by_len }
    }

    /// The closest name to `name` within the limit, as [`did_you_mean`].
    pub(crate) fn suggest(&self, name: &str) -> Option<&str> {
        let wanted = name.to_ascii_lowercase();
        let limit = suggestion_limit(name);
        let pattern = Pattern::new(wanted.as_bytes());
        let lengths = name.len().saturating_sub(limit)..=name.len() + limit;
        lengths
            .filter_map(|len| self.by_len.get(len))
            .flatten()
            .filter(|(_, written)| written != name)
            .filter_map(|(lower, written)| {
                let distance = match &pattern {
                    Some(pattern) => pattern.distance(lower.as_bytes()),
                    None => osa_within(wanted.as_bytes(), lower.as_bytes(), limit)?,
                };
                (distance <= limit).then_some((distance, written.as_str()))
            })
            .min()
            .map(|(_, written)| written)
    }
}

/// A byte range in one source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub(crate) struct Span {
    /// Index in [`Files`].
    pub(crate) file: u32,
    /// First byte.
    pub(crate) start: u32,
    /// One past the last byte.
    pub(crate) end: u32,
}

/// A source file's bytes, shared by the reader and the diagnostics.
pub(crate) type Text = Arc<Vec<u8>>;

/// One source file the assembler read.
#[derive(Debug)]
pub(crate) struct SourceFile {
    /// The name shown to users (the path as given or as resolved).
    pub(crate) name: String,
    /// The bytes.
    pub(crate) text: Text,
    /// Offsets of the line starts, built on the first diagnostic that
    /// needs a line number (a scan from the top per diagnostic made 50
    /// diagnostics in a large file cost 50 reads of it).
    line_starts: OnceCell<Vec<u32>>,
}

/// Every file read during one assembly, indexed by [`Span::file`].
#[derive(Debug, Default)]
pub(crate) struct Files {
    pub(crate) files: Vec<SourceFile>,
}

impl Files {
    pub(crate) fn add(&mut self, name: String, text: Text) -> u32 {
        self.files.push(SourceFile {
            name,
            text,
            line_starts: OnceCell::new(),
        });
        (self.files.len() - 1) as u32
    }

    pub(crate) fn text(&self, file: u32) -> &[u8] {
        self.files.get(file as usize).map_or(&[], |f| &f.text)
    }

    pub(crate) fn name(&self, file: u32) -> &str {
        self.files
            .get(file as usize)
            .map_or("<unknown>", |f| f.name.as_str())
    }

    /// The span from `a` to `b` when both are on one line of one file in
    /// order; else `a`. Tokens of a macro expansion come from the body and
    /// from the arguments, and a span must never run across lines.
    pub(crate) fn join(&self, a: Span, b: Span) -> Span {
        if a.file != b.file || b.end < a.start {
            return a;
        }
        let text = self.text(a.file);
        let (start, end) = (a.start as usize, (b.end as usize).min(text.len()));
        if start > end || text[start..end].contains(&b'\n') {
            return a;
        }
        Span {
            file: a.file,
            start: a.start,
            end: b.end.max(a.end),
        }
    }

    /// The text of a span, lossily decoded.
    pub(crate) fn snippet(&self, span: Span) -> String {
        let text = self.text(span.file);
        let start = (span.start as usize).min(text.len());
        let end = (span.end as usize).clamp(start, text.len());
        String::from_utf8_lossy(&text[start..end]).into_owned()
    }

    /// Line and column (both from 1, the column in characters) of a byte offset.
    pub(crate) fn line_col(&self, file: u32, offset: u32) -> (u32, u32) {
        let Some(source) = self.files.get(file as usize) else {
            return (1, 1);
        };
        let text = &source.text;
        let offset = (offset as usize).min(text.len());
        let starts = source.line_starts.get_or_init(|| {
            std::iter::once(0)
                .chain(
                    text.iter()
                        .enumerate()
                        .filter(|(_, b)| **b == b'\n')
                        .map(|(i, _)| i as u32 + 1),
                )
                .collect()
        });
        // The last line start at or before `offset` (there is always one: 0).
        let line = starts.partition_point(|&start| start as usize <= offset);
        let line_start = starts.get(line.wrapping_sub(1)).map_or(0, |&s| s as usize);
        let column = count_chars(&text[line_start..offset]) + 1;
        (line as u32, column)
    }
}

/// Characters in a UTF-8 byte string (continuation bytes are not counted).
pub(crate) fn count_chars(bytes: &[u8]) -> u32 {
    bytes.iter().filter(|b| (**b & 0xC0) != 0x80).count() as u32
}

/// Index in the expansion-context tree; 0 is the main file.
pub(crate) type CtxId = u32;

/// Why the assembler is reading a line: the chain of includes and
/// expansions, kept as a tree so that a deferred diagnostic can name it.
#[derive(Debug, Clone)]
pub(crate) enum CtxKind {
    /// The main source file.
    Root,
    /// A file included at `span`.
    Include,
    /// Macro `name` expanded at `span`.
    Macro(String),
    /// A `.repeat` block started at `span`.
    Repeat,
}

#[derive(Debug, Clone)]
pub(crate) struct CtxNode {
    pub(crate) parent: CtxId,
    pub(crate) kind: CtxKind,
    pub(crate) span: Span,
}

/// How serious a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Severity {
    /// The object is not written.
    Error,
    /// Likely a mistake; the object is still written.
    Warning,
}

/// A diagnostic as recorded during assembly, before rendering.
#[derive(Debug, Clone)]
pub(crate) struct RawDiag {
    pub(crate) severity: Severity,
    pub(crate) code: &'static str,
    pub(crate) message: String,
    pub(crate) span: Span,
    pub(crate) label: Option<String>,
    pub(crate) secondary: Vec<(Span, String)>,
    pub(crate) help: Option<String>,
    pub(crate) ctx: CtxId,
}

impl RawDiag {
    pub(crate) fn label(mut self, label: impl Into<String>) -> RawDiag {
        self.label = Some(label.into());
        self
    }

    pub(crate) fn help(mut self, help: impl Into<String>) -> RawDiag {
        self.help = Some(help.into());
        self
    }

    pub(crate) fn also(mut self, span: Span, label: impl Into<String>) -> RawDiag {
        self.secondary.push((span, label.into()));
        self
    }
}

/// Collects diagnostics; stores at most `max_errors` errors but counts all.
#[derive(Debug)]
pub(crate) struct Reporter {
    pub(crate) diags: Vec<RawDiag>,
    pub(crate) errors: usize,
    pub(crate) max_errors: usize,
    pub(crate) dropped: usize,
    warnings_kept: usize,
    /// Reading stopped early because of the number of errors.
    pub(crate) stopped: bool,
}

impl Reporter {
    pub(crate) fn new(max_errors: usize) -> Reporter {
        Reporter {
            diags: Vec::new(),
            errors: 0,
            max_errors: max_errors.max(1),
            dropped: 0,
            warnings_kept: 0,
            stopped: false,
        }
    }

    pub(crate) fn push(&mut self, diag: RawDiag) {
        match diag.severity {
            Severity::Error => {
                self.errors += 1;
                if self.errors > self.max_errors {
                    self.dropped += 1;
                    return;
                }
            }
            Severity::Warning => {
                // Warnings share the cap so a noisy file cannot flood output.
                if self.warnings_kept >= self.max_errors {
                    self.dropped += 1;
                    return;
                }
                self.warnings_kept += 1;
            }
        }
        self.diags.push(diag);
    }

    /// Whether another error would only be counted, not kept.
    pub(crate) fn is_full(&self) -> bool {
        self.errors >= self.max_errors
    }

    /// So many errors that going on only costs time (ten times the cap):
    /// the front end stops reading.
    pub(crate) fn overwhelmed(&self) -> bool {
        self.errors >= self.max_errors.saturating_mul(10)
    }

    pub(crate) fn has_errors(&self) -> bool {
        self.errors > 0
    }
}

/// Builds a raw error.
pub(crate) fn error(code: &'static str, span: Span, message: impl Into<String>) -> RawDiag {
    RawDiag {
        severity: Severity::Error,
        code,
        message: message.into(),
        span,
        label: None,
        secondary: Vec::new(),
        help: None,
        ctx: 0,
    }
}

/// Builds a raw warning.
pub(crate) fn warning(code: &'static str, span: Span, message: impl Into<String>) -> RawDiag {
    RawDiag {
        severity: Severity::Warning,
        ..error(code, span, message)
    }
}

/// Where a diagnostic points: file, line and column (from 1).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Location {
    /// The file's name as the assembler knows it.
    pub file: String,
    /// Line, from 1.
    pub line: u32,
    /// Column in characters, from 1.
    pub column: u32,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// One rendered assembler diagnostic (error, warning or backtrace note),
/// with its source snippet for miette.
#[derive(Debug, Clone)]
pub struct Diagnostic {
    severity: Severity,
    code: &'static str,
    message: String,
    location: Option<Location>,
    source: Option<NamedSource<Text>>,
    labels: Vec<LabeledSpan>,
    help: Option<String>,
    related: Vec<Diagnostic>,
    advice: bool,
}

impl Diagnostic {
    /// Error or warning.
    #[must_use]
    pub fn severity(&self) -> Severity {
        self.severity
    }

    /// The stable code (`asm::range`, `asm::undefined`...).
    #[must_use]
    pub fn code(&self) -> &'static str {
        self.code
    }

    /// The message, without location.
    #[must_use]
    pub fn message(&self) -> &str {
        &self.message
    }

    /// Where the diagnostic points, if it points into a source file.
    #[must_use]
    pub fn location(&self) -> Option<&Location> {
        self.location.as_ref()
    }

    /// Suggested fix, if any.
    #[must_use]
    pub fn help_text(&self) -> Option<&str> {
        self.help.as_deref()
    }

    /// The backtrace and secondary notes (macro expansions, includes,
    /// "defined here").
    #[must_use]
    pub fn notes(&self) -> &[Diagnostic] {
        &self.related
    }

    /// A one-line summary: `file:line:col: error: message`.
    #[must_use]
    pub fn summary(&self) -> String {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        match &self.location {
            Some(location) => format!("{location}: {kind}: {}", self.message),
            None => format!("{kind}: {}", self.message),
        }
    }

    /// A diagnostic with no source position (used for whole-file problems).
    pub(crate) fn plain(severity: Severity, code: &'static str, message: String) -> Diagnostic {
        Diagnostic {
            severity,
            code,
            message,
            location: None,
            source: None,
            labels: Vec::new(),
            help: None,
            related: Vec::new(),
            advice: false,
        }
    }

    fn at(
        files: &Files,
        severity: Severity,
        code: &'static str,
        message: String,
        span: Span,
        label: Option<String>,
    ) -> Diagnostic {
        let file = files.files.get(span.file as usize);
        let Some(file) = file else {
            return Diagnostic::plain(severity, code, message);
        };
        let (line, column) = files.line_col(span.file, span.start);
        let len = file.text.len();
        let start = (span.start as usize).min(len);
        let end = (span.end as usize).clamp(start, len);
        Diagnostic {
            severity,
            code,
            message,
            location: Some(Location {
                file: file.name.clone(),
                line,
                column,
            }),
            source: Some(NamedSource::new(file.name.clone(), Arc::clone(&file.text))),
            labels: vec![LabeledSpan::new_primary_with_span(
                label,
                (start, end - start),
            )],
            help: None,
            related: Vec::new(),
            advice: false,
        }
    }

    /// Renders a raw diagnostic with its context chain.
    pub(crate) fn render(files: &Files, ctx: &[CtxNode], raw: &RawDiag) -> Diagnostic {
        let mut diagnostic = Diagnostic::at(
            files,
            raw.severity,
            raw.code,
            raw.message.clone(),
            raw.span,
            raw.label.clone(),
        );
        diagnostic.help = raw.help.clone();
        for (span, label) in &raw.secondary {
            if span.file == raw.span.file {
                let len = files.text(span.file).len();
                let start = (span.start as usize).min(len);
                let end = (span.end as usize).clamp(start, len);
                diagnostic.labels.push(LabeledSpan::new_with_span(
                    Some(label.clone()),
                    (start, end - start),
                ));
            } else {
                let mut note =
                    Diagnostic::at(files, raw.severity, "asm::note", label.clone(), *span, None);
                note.advice = true;
                diagnostic.related.push(note);
            }
        }
        let mut id = raw.ctx;
        let mut guard = 0;
        while id != 0 && guard < 64 {
            guard += 1;
            let Some(node) = ctx.get(id as usize) else {
                break;
            };
            let message = match &node.kind {
                CtxKind::Root => break,
                CtxKind::Include => "in the file included from here".to_string(),
                CtxKind::Macro(name) => format!("in the expansion of macro `{name}`"),
                CtxKind::Repeat => "in this `.repeat` block".to_string(),
            };
            let mut note = Diagnostic::at(
                files,
                raw.severity,
                "asm::backtrace",
                message,
                node.span,
                Some("from here".to_string()),
            );
            note.advice = true;
            diagnostic.related.push(note);
            id = node.parent;
        }
        diagnostic
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Diagnostic {}

impl miette::Diagnostic for Diagnostic {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        if self.advice {
            return None;
        }
        Some(Box::new(self.code))
    }

    fn severity(&self) -> Option<miette::Severity> {
        Some(if self.advice {
            miette::Severity::Advice
        } else {
            match self.severity {
                Severity::Error => miette::Severity::Error,
                Severity::Warning => miette::Severity::Warning,
            }
        })
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.help
            .as_ref()
            .map(|help| Box::new(help) as Box<dyn fmt::Display>)
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.source.as_ref().map(|source| source as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.labels.is_empty() {
            return None;
        }
        Some(Box::new(self.labels.iter().cloned()))
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        if self.related.is_empty() {
            return None;
        }
        Some(Box::new(
            self.related
                .iter()
                .map(|diagnostic| diagnostic as &dyn miette::Diagnostic),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::{Suggestions, did_you_mean, osa_within};

    /// The bounded distance is strsim's wherever that is within the limit.
    #[test]
    fn bounded_distance_is_strsims() {
        let words = [
            "",
            "a",
            "ab",
            "ba",
            "abc",
            "acb",
            "bca",
            "value_00012",
            "valeu_00012",
            "value_0012",
            "vlaue_00021",
            "label",
            "lable",
            "labels",
            "missing_name_7",
            "CA",
            "ac",
            "abcdef",
            "badcfe",
            "xyzzy",
        ];
        for a in words {
            for b in words {
                let exact = strsim::osa_distance(a, b);
                for limit in 0..4 {
                    let bounded = osa_within(a.as_bytes(), b.as_bytes(), limit);
                    assert_eq!(
                        bounded,
                        (exact <= limit).then_some(exact),
                        "{a} {b} {limit}"
                    );
                }
            }
        }
    }

    /// Every pair of strings over three letters up to five long: the
    /// bit-parallel distance is strsim's.
    #[test]
    fn bit_parallel_distance_is_strsims_exhaustively() {
        let mut words = vec![String::new()];
        let mut last = vec![String::new()];
        for _ in 0..5 {
            last = last
                .iter()
                .flat_map(|w| ["a", "b", "c"].map(|c| format!("{w}{c}")))
                .collect();
            words.extend(last.iter().cloned());
        }
        for a in &words {
            for b in &words {
                let exact = strsim::osa_distance(a, b);
                assert_eq!(
                    osa_within(a.as_bytes(), b.as_bytes(), 99),
                    Some(exact),
                    "{a} {b}"
                );
            }
        }
    }

    /// The index suggests what the plain search suggests.
    #[test]
    fn the_index_agrees_with_the_plain_search() {
        let names: Vec<String> = [
            "value_00012",
            "value_00013",
            "label_1",
            "Label_2",
            "lda_x",
            "start",
        ]
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
        let index = Suggestions::new(names.clone());
        for wanted in [
            "valeu_00012",
            "label_2",
            "strat",
            "nothing_like_it",
            "lda_y",
            "value_00012",
        ] {
            assert_eq!(
                index.suggest(wanted),
                did_you_mean(wanted, names.iter().map(String::as_str)),
                "{wanted}"
            );
        }
    }
}
