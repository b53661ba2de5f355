//! Checks serde cannot make: an image's name becomes file names
//! (`target/scorpion/NAME.elf`, `tests/snapshots/NAME__KIND.snap`), so it
//! must be a plain, unique file name; an image needs a source; a define's
//! value must be one the assembler holds; the project needs a name. Each
//! refusal is at its line.

use std::collections::BTreeMap;

use crate::error::Located;
use crate::file::ProjectFile;
use crate::spans::{FileSpans, span};

const NAME_HELP: &str = "an image's name becomes file names (target/scorpion/NAME.elf, tests/snapshots/NAME__listing.snap): use letters, digits, `-`, `_` and `.`, not starting with `.`, one name per image";

/// Why `name` cannot name an image's files, if it cannot.
fn bad_name(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        return Some("an image's name is empty");
    }
    if name.split(['/', '\\']).any(|part| part == "..") {
        return Some("an image's name leads out of the project (`..`)");
    }
    if name.starts_with('.') {
        return Some(
            "an image's name starts with `.` (a hidden file, or a way out of the directory)",
        );
    }
    if std::path::Path::new(name).is_absolute() || name.starts_with('/') {
        return Some("an image's name is an absolute path");
    }
    if name.ends_with('.') {
        return Some("an image's name ends with `.` (its files would read `NAME..elf`)");
    }
    if name.contains(['/', '\\']) {
        return Some("an image's name holds a path separator");
    }
    if !name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
    {
        return Some("an image's name holds a character file names should not");
    }
    None
}

/// Checks `file`, read from `text` (the file `shown`).
pub(crate) fn check(shown: &str, text: &str, file: &ProjectFile) -> crate::Result<()> {
    let spans = FileSpans::of(text);
    let at = |index: usize, pick: fn(&crate::spans::ImageSpans) -> std::ops::Range<usize>| {
        spans.image.get(index).map(pick).unwrap_or(0..0)
    };
    // The name heads every report and the new project's files: a blank
    // one reads as a missing one.
    let name_at = spans
        .project
        .as_ref()
        .and_then(|p| p.name.as_ref())
        .map_or(0..0, span);
    let control = file.project.name.chars().find(|c| c.is_control());
    if let Some(c) = control {
        return Err(Located::new(
            shown,
            text,
            name_at,
            format!("the project's name holds a control character ({c:?}): it heads every report"),
            "name the project with printable characters: [project] name = \"probe\"",
        )
        .into());
    }
    if file.project.name.trim().is_empty() {
        return Err(Located::new(
            shown,
            text,
            name_at,
            format!("the project's name is empty: `{}`", file.project.name),
            "name the project: [project] name = \"probe\"",
        )
        .into());
    }
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for (index, image) in file.images.iter().enumerate() {
        let name_at = at(index, |s| span(&s.name));
        if let Some(why) = bad_name(&image.name) {
            return Err(Located::new(
                shown,
                text,
                name_at,
                format!("{why}: `{}`", image.name),
                NAME_HELP,
            )
            .into());
        }
        // Names that differ only in case are one file on some systems.
        if let Some(first) = seen.insert(image.name.to_ascii_lowercase(), index) {
            return Err(Located::new(
                shown,
                text,
                name_at,
                format!(
                    "two images are named `{}` (image {} and image {})",
                    image.name,
                    first + 1,
                    index + 1
                ),
                NAME_HELP,
            )
            .into());
        }
        if image.sources.is_empty() {
            return Err(Located::new(
                shown,
                text,
                at(index, |s| span(&s.sources)),
                format!("image `{}` has no sources", image.name),
                "list the image's sources in link order: sources = [\"src/myext.s\"]",
            )
            .into());
        }
        for (name, value) in &image.defines {
            if !assembler::DEFINE_VALUES.contains(value) {
                let value_at = spans
                    .image
                    .get(index)
                    .and_then(|s| s.defines.get(name))
                    .map_or(0..0, span);
                return Err(Located::new(
                    shown,
                    text,
                    value_at,
                    format!(
                        "define `{name}` = {value} is outside the assembler's values ({} to {})",
                        assembler::DEFINE_VALUES.start(),
                        assembler::DEFINE_VALUES.end()
                    ),
                    "the assembler's values are 32 bits, either sign; a larger one would be truncated",
                )
                .into());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::bad_name;

    #[test]
    fn names_that_would_leave_the_directory_are_refused() {
        for name in [
            "",
            "..",
            "../../../outside",
            "/tmp/x",
            "a/b",
            "a\\b",
            ".hidden",
            "a b",
        ] {
            assert!(bad_name(name).is_some(), "{name:?}");
        }
        for name in ["probe", "adc-2", "os_v1.2"] {
            assert_eq!(bad_name(name), None, "{name:?}");
        }
    }
}
