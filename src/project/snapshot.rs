//! Snapshot files in insta's format (a `---` header with `source` and
//! `expression`, then the text), so `cargo insta review` can show them as
//! well; and the `-`/`+` diff of a changed one.

use std::fmt::Write as _;
use std::path::Path;

/// A snapshot file's text for `content`.
pub(crate) fn render(source: &str, expression: &str, content: &str) -> String {
    format!("---\nsource: {source}\nexpression: {expression}\n---\n{content}")
}

/// The content of a snapshot file (after its header), if it has one.
pub(crate) fn content(file: &str) -> Option<&str> {
    let rest = file.strip_prefix("---\n")?;
    let end = rest.find("\n---\n")?;
    Some(&rest[end + 5..])
}

/// How a snapshot compares.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// The same.
    Same,
    /// There was none.
    New,
    /// Different: the diff, `-` old `+` new.
    Changed(String),
}

/// Compares `content` with the snapshot at `path`.
pub(crate) fn compare(path: &Path, content: &str) -> Outcome {
    let Ok(old) = hostfs::read_text(path, hostfs::TEXT) else {
        return Outcome::New;
    };
    let old = self::content(&old).unwrap_or(&old);
    if old == content {
        return Outcome::Same;
    }
    let diff = similar::TextDiff::from_lines(old, content);
    let mut text = String::new();
    for group in diff.grouped_ops(2) {
        for op in group {
            for change in diff.iter_changes(&op) {
                let sign = match change.tag() {
                    similar::ChangeTag::Delete => '-',
                    similar::ChangeTag::Insert => '+',
                    similar::ChangeTag::Equal => ' ',
                };
                let _ = write!(text, "{sign} {change}");
                if change.missing_newline() {
                    text.push('\n');
                }
            }
        }
        text.push_str("  ...\n");
    }
    Outcome::Changed(text)
}
