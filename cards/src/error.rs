//! Errors of card and surroundings scripts, located in the script as the
//! assembler locates its own: file:line:col, the line, a caret.

use miette::{NamedSource, SourceSpan};

/// What loading or running a script can fail with.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum ScriptError {
    /// A syntax error, a runtime error or a spent operation budget, at a
    /// place in the script.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Script(Box<Located>),

    /// A script whose declarations do not make a card (no `SIZE`, a window
    /// outside the KIM bus).
    #[error("{file}: {message}")]
    #[diagnostic(code(cards::window))]
    Window {
        /// The script's name.
        file: String,
        /// What is wrong.
        message: String,
        /// What to do.
        #[help]
        help: Option<String>,
    },

    /// A mistake at a place in a world file (docs/WORLD.md): a TOML
    /// mistake, an unknown key, a value out of range, a shape that cannot
    /// be.
    #[error(transparent)]
    #[diagnostic(transparent)]
    World(Box<WorldMistake>),

    /// The script file cannot be read.
    #[error("cannot read the script {file}: {message}")]
    #[diagnostic(code(cards::read))]
    Read {
        /// The path.
        file: String,
        /// The system's reason.
        message: String,
    },
}

/// A failure at a place in a script: file:line:col, the line, a caret.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{file}:{line}:{column}: {message}")]
#[diagnostic(code(cards::script))]
pub struct Located {
    /// The script's name (its path as given).
    pub file: String,
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1.
    pub column: usize,
    /// What went wrong.
    pub message: String,
    /// The script.
    #[source_code]
    pub source_code: NamedSource<String>,
    /// Where.
    #[label("here")]
    pub at: SourceSpan,
    /// What to do about it, where that is clear.
    #[help]
    pub help: Option<String>,
}

/// A [`Located`] failure in a world file rather than a script: the same
/// place, line and caret, under its own code (`cards::world`).
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct WorldMistake(pub Located);

impl miette::Diagnostic for WorldMistake {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        Some(Box::new("cards::world"))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.0.help()
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.0.source_code()
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.0.labels()
    }
}

/// The byte offset of `line:column` (both from 1, the column in
/// characters) in `text`, clamped to the text.
pub(crate) fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut offset = 0;
    for (index, content) in text.split_inclusive('\n').enumerate() {
        if index + 1 == line {
            let within: usize = content
                .chars()
                .take(column.saturating_sub(1))
                .map(char::len_utf8)
                .sum();
            return (offset + within).min(text.len());
        }
        offset += content.len();
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_become_byte_offsets() {
        let text = "ab\ncdé\nf";
        assert_eq!(offset_of(text, 1, 1), 0);
        assert_eq!(offset_of(text, 2, 3), 5);
        assert_eq!(offset_of(text, 3, 1), 8);
        assert_eq!(offset_of(text, 9, 9), text.len());
    }
}
