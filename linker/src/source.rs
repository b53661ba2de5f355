//! Source files behind a trait, so diagnostics can show the line they are
//! about without the library touching the disk.
//!
//! Objects name their sources in `.scorpion.srcmap` (paths as the assembler
//! saw them). The CLI supplies the text: `scorpion build` from memory,
//! `scorpion link` from the disk; tests from a map.

use std::collections::HashMap;

use miette::{NamedSource, SourceSpan};

use crate::error::Snippet;

/// Supplies the text of source files named in objects' source maps.
pub trait SourceProvider {
    /// The text of `path`, or `None` when it is not available (the
    /// diagnostic then names the place without showing the line).
    fn source(&self, path: &str) -> Option<String> {
        let _ = path;
        None
    }
}

/// A provider with no files: diagnostics name places only.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoSources;

impl SourceProvider for NoSources {}

/// Sources held in memory, by path.
#[derive(Debug, Clone, Default)]
pub struct MemorySources {
    /// Path to text.
    pub files: HashMap<String, String>,
}

impl SourceProvider for MemorySources {
    fn source(&self, path: &str) -> Option<String> {
        self.files.get(path).cloned()
    }
}

/// A place in a source file, as diagnostics name it.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) struct Place {
    /// `file:line:col`, or `object(SECTION+$offset)` without a source map.
    pub(crate) text: String,
    /// File, line and column when the source map knew them.
    pub(crate) source: Option<(String, u32, u32)>,
}

impl Place {
    /// A place with no source location.
    pub(crate) fn bare(text: String) -> Place {
        Place { text, source: None }
    }

    /// A place in a source file.
    pub(crate) fn source(file: &str, line: u32, column: u32) -> Place {
        Place {
            text: format!("{file}:{line}:{column}"),
            source: Some((file.to_owned(), line, column)),
        }
    }

    /// The source text and span of this place, when the provider has it.
    pub(crate) fn snippet(&self, sources: &dyn SourceProvider) -> Snippet {
        let Some((file, line, column)) = &self.source else {
            return (None, None);
        };
        let Some(text) = sources.source(file) else {
            return (None, None);
        };
        let span = span_of(&text, *line, *column);
        match span {
            Some(span) => (
                Some(std::sync::Arc::new(NamedSource::new(file, text))),
                Some(span),
            ),
            None => (None, None),
        }
    }
}

/// The span from `column` to the end of the line's code (before a `;`
/// comment and trailing blanks); `None` if the line does not exist.
fn span_of(text: &str, line: u32, column: u32) -> Option<SourceSpan> {
    let mut offset = 0usize;
    for (number, content) in text.split_inclusive('\n').enumerate() {
        if number + 1 == line as usize {
            let content = content.trim_end_matches(['\n', '\r']);
            let code = content.split(';').next().unwrap_or("").trim_end();
            // Columns count characters; convert to a byte offset.
            let start = content
                .char_indices()
                .nth(column.saturating_sub(1) as usize)
                .map_or(content.len(), |(index, _)| index);
            let end = code.len().max(start);
            let len = (end - start).max(usize::from(start < content.len()));
            return Some(SourceSpan::new((offset + start).into(), len));
        }
        offset += content.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_cover_the_code_from_the_column() {
        let text = "start:\n    bne far ; comment\n";
        let span = span_of(text, 2, 5).unwrap();
        assert_eq!(&text[span.offset()..span.offset() + span.len()], "bne far");
        assert_eq!(span_of(text, 9, 1), None);
        let at_end = span_of(text, 1, 40).unwrap();
        assert_eq!(at_end.len(), 0);
    }
}
