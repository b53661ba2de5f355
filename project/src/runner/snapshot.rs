//! Snapshot files in insta's format, so that `cargo insta review` and
//! `cargo insta pending-snapshots` work on a project as on a crate: an
//! accepted snapshot is `NAME.snap` (a `---` header with `source` and
//! `expression`, then the text, trailing blank lines trimmed, one newline
//! at the end: byte for byte what `cargo insta accept` writes); a failing
//! one leaves the new text beside it as `NAME.snap.new`, as insta's
//! assertions do. Texts compare as insta compares them: trailing
//! whitespace of the whole text does not count.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A snapshot file's text for `content`.
pub fn render(source: &str, expression: &str, content: &str) -> String {
    format!(
        "---\nsource: {}\nexpression: {}\n---\n{}\n",
        yaml_string(source),
        yaml_string(expression),
        content.trim_end()
    )
}

/// `text` as a YAML scalar insta reads back as the same string: plain when
/// nothing in it means something to YAML, else double-quoted (a JSON string
/// is a YAML double-quoted scalar).
fn yaml_string(text: &str) -> String {
    let plain = text
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c))
        && !matches!(
            text.to_ascii_lowercase().as_str(),
            "true" | "false" | "yes" | "no" | "on" | "off" | "null" | "y" | "n"
        );
    if plain {
        text.to_owned()
    } else {
        serde_json::to_string(text).unwrap_or_else(|_| format!("{text:?}"))
    }
}

/// The content of a snapshot file (after its header), if it has one.
pub fn content(file: &str) -> Option<&str> {
    let rest = file.strip_prefix("---\n")?;
    let end = rest.find("\n---\n")?;
    Some(&rest[end + 5..])
}

/// Where the pending (new, not yet accepted) text of the snapshot at
/// `path` goes: `NAME.snap.new`, as insta names it.
pub fn pending_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".new");
    PathBuf::from(name)
}

/// The accepted snapshot a pending file `NAME.snap.new` stands beside.
pub fn accepted_path(pending: &Path) -> Option<PathBuf> {
    let text = pending.to_str()?;
    text.strip_suffix(".new").map(PathBuf::from)
}

/// How a snapshot compares.
#[derive(Debug, PartialEq, Eq)]
pub enum Compared {
    /// The same.
    Same,
    /// There was none.
    New,
    /// Different: the diff, `-` old `+` new.
    Changed(String),
}

/// Compares `content` with the snapshot at `path`.
pub fn compare(path: &Path, content: &str) -> Compared {
    let Ok(old) = hostfs::read_text(path, hostfs::TEXT) else {
        return Compared::New;
    };
    let old = self::content(&old).unwrap_or(&old);
    match diff(old, content) {
        None => Compared::Same,
        Some(diff) => Compared::Changed(diff),
    }
}

/// The `-`/`+` lines that differ between `old` and `new` (two lines of
/// context), or `None` if they are the same as insta compares them.
pub fn diff(old: &str, new: &str) -> Option<String> {
    let (old, new) = (old.trim_end(), new.trim_end());
    if old == new {
        return None;
    }
    let (old, new) = (format!("{old}\n"), format!("{new}\n"));
    let diff = similar::TextDiff::from_lines(&old, &new);
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
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rendered_snapshot_reads_back_and_compares_as_insta_does() {
        let text = render("Scorpion.toml", "probe/listing", "a\nb\n\n");
        assert_eq!(
            text,
            "---\nsource: Scorpion.toml\nexpression: probe/listing\n---\na\nb\n"
        );
        assert_eq!(content(&text), Some("a\nb\n"));
        assert_eq!(diff("a\nb\n", "a\nb"), None);
        assert!(diff("a\nb\n", "a\nc\n").is_some_and(|d| d.contains("- b\n+ c\n")));
    }

    #[test]
    fn names_yaml_would_misread_are_quoted() {
        for (name, written) in [
            ("probe/bytes", "probe/bytes"),
            ("my image/bytes", "\"my image/bytes\""),
            ("a: b", "\"a: b\""),
            ("yes", "\"yes\""),
            ("1up/map", "\"1up/map\""),
        ] {
            assert_eq!(yaml_string(name), written, "{name}");
        }
    }

    #[test]
    fn the_pending_file_is_beside_the_accepted_one() {
        let accepted = Path::new("tests/snapshots/probe__map.snap");
        let pending = pending_path(accepted);
        assert_eq!(pending, Path::new("tests/snapshots/probe__map.snap.new"));
        assert_eq!(accepted_path(&pending).as_deref(), Some(accepted));
    }
}
