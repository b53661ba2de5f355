//! Where the values checked after parsing stand in the file: a second,
//! lenient reading of the same text that keeps each value's byte range, so
//! a name or a define refused after serde read the file is shown at its
//! line, and `scorpion config` can say which line a setting came from.

use std::collections::BTreeMap;
use std::ops::Range;

use serde::Deserialize;
use toml::Spanned;

/// The spans of a project file's checked values (any key not here is
/// ignored: the strict reading has checked the keys).
#[derive(Debug, Default, Deserialize)]
pub(crate) struct FileSpans {
    #[serde(default)]
    pub(crate) project: Option<MetaSpans>,
    #[serde(default)]
    pub(crate) image: Vec<ImageSpans>,
}

/// `[project]`'s spans.
#[derive(Debug, Deserialize)]
pub(crate) struct MetaSpans {
    pub(crate) name: Option<Spanned<toml::Value>>,
}

/// One `[[image]]`'s spans.
#[derive(Debug, Deserialize)]
pub(crate) struct ImageSpans {
    pub(crate) name: Spanned<String>,
    pub(crate) sources: Spanned<Vec<toml::Value>>,
    #[serde(default)]
    pub(crate) defines: BTreeMap<String, Spanned<i64>>,
}

/// `[robot]`'s spans (in either file).
#[derive(Debug, Default, Deserialize)]
pub(crate) struct RobotSpans {
    pub(crate) port: Option<Spanned<toml::Value>>,
    pub(crate) baud: Option<Spanned<toml::Value>>,
    pub(crate) cards: Option<Spanned<Vec<toml::Value>>>,
    pub(crate) world: Option<Spanned<toml::Value>>,
    pub(crate) rom: Option<Spanned<toml::Value>>,
}

impl FileSpans {
    /// The spans of `text`, already read strictly; nothing if it cannot be
    /// read this way either (no span is then better than an error).
    pub(crate) fn of(text: &str) -> FileSpans {
        toml::from_str(text).unwrap_or_default()
    }
}

/// The span of a spanned value.
pub(crate) fn span<T>(value: &Spanned<T>) -> Range<usize> {
    value.span()
}
