//! Layout files: TOML, read with serde, errors with spans.

use std::ops::Range;

use miette::{NamedSource, SourceSpan};
use serde::Deserialize;
use toml::Spanned;

use super::{Area, Layout, Segment, SegmentKind};
use crate::error::Error;

/// A number written as a TOML integer or as `"$FFFA"`, `"0xFFFA"`, `"%1010"`.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Number {
    Int(i64),
    Text(String),
}

impl Number {
    fn value(&self) -> Result<u64, String> {
        match self {
            Number::Int(value) => u64::try_from(*value).map_err(|_| format!("{value} is negative")),
            Number::Text(text) => {
                let clean = text.trim().replace('_', "");
                let (digits, radix) = if let Some(hex) = clean.strip_prefix('$') {
                    (hex, 16)
                } else if let Some(hex) = clean
                    .strip_prefix("0x")
                    .or_else(|| clean.strip_prefix("0X"))
                {
                    (hex, 16)
                } else if let Some(bin) = clean.strip_prefix('%') {
                    (bin, 2)
                } else {
                    (clean.as_str(), 10)
                };
                u64::from_str_radix(digits, radix).map_err(|_| {
                    format!("`{text}` is not a number (write 4096, \"$1000\" or \"0x1000\")")
                })
            }
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileLayout {
    name: Option<String>,
    #[serde(default)]
    area: Vec<FileArea>,
    #[serde(default)]
    segment: Vec<FileSegment>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct FileArea {
    name: Spanned<String>,
    start: Spanned<Number>,
    size: Option<Spanned<Number>>,
    end: Option<Spanned<Number>>,
    #[serde(default)]
    fill: bool,
    fill_value: Option<Spanned<Number>>,
    #[serde(default = "yes")]
    output: bool,
    #[serde(default)]
    define: bool,
}

#[derive(Debug, Clone, Copy, Deserialize)]
enum FileKind {
    #[serde(rename = "ro")]
    ReadOnly,
    #[serde(rename = "rw")]
    ReadWrite,
    #[serde(rename = "bss")]
    Bss,
    #[serde(rename = "zp")]
    ZeroPage,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct FileSegment {
    name: Spanned<String>,
    load: Spanned<String>,
    run: Option<Spanned<String>>,
    kind: Option<FileKind>,
    align: Option<Spanned<Number>>,
    align_load: Option<Spanned<Number>>,
    start: Option<Spanned<Number>>,
    #[serde(default)]
    optional: bool,
    #[serde(default)]
    define: bool,
    sections: Option<Vec<String>>,
}

fn yes() -> bool {
    true
}

struct Parser<'a> {
    path: &'a str,
    text: &'a str,
}

impl Parser<'_> {
    fn error(&self, message: String, span: Option<Range<usize>>) -> Error {
        Error::LayoutSyntax {
            path: self.path.to_owned(),
            message,
            src: Some(std::sync::Arc::new(NamedSource::new(
                self.path,
                self.text.to_owned(),
            ))),
            span: span.map(|range| SourceSpan::from(range.start..range.end)),
        }
    }

    fn number(&self, number: &Spanned<Number>, max: u64, what: &str) -> Result<u64, Error> {
        let value = number
            .get_ref()
            .value()
            .map_err(|message| self.error(message, Some(number.span())))?;
        if value > max {
            return Err(self.error(
                format!("{what} {value:#X} is larger than {max:#X}"),
                Some(number.span()),
            ));
        }
        Ok(value)
    }
}

pub(super) fn parse(path: &str, text: &str) -> Result<Layout, Error> {
    let parser = Parser { path, text };
    let file: FileLayout = toml::from_str(text)
        .map_err(|error| parser.error(error.message().to_owned(), error.span()))?;
    let mut areas = Vec::with_capacity(file.area.len());
    for area in &file.area {
        let start = parser.number(&area.start, 0xFFFF_FFFF, "start")?;
        let size = match (&area.size, &area.end) {
            (Some(size), None) => parser.number(size, 1 << 32, "size")?,
            (None, Some(end)) => {
                let last = parser.number(end, 0xFFFF_FFFF, "end")?;
                if last < start {
                    return Err(parser.error(
                        format!("end ${last:X} is below start ${start:X}"),
                        Some(end.span()),
                    ));
                }
                last - start + 1
            }
            _ => {
                return Err(parser.error(
                    format!(
                        "area {} needs exactly one of `size` and `end`",
                        area.name.get_ref()
                    ),
                    Some(area.name.span()),
                ));
            }
        };
        let fill_value = match &area.fill_value {
            Some(value) => parser.number(value, 0xFF, "fill-value")? as u8,
            None => 0,
        };
        areas.push(Area {
            name: area.name.get_ref().clone(),
            start,
            size,
            fill: area.fill,
            fill_value,
            output: area.output,
            define: area.define,
            file: None,
            exprs: None,
        });
    }
    let mut segments = Vec::with_capacity(file.segment.len());
    for segment in &file.segment {
        for reference in std::iter::once(&segment.load).chain(segment.run.as_ref()) {
            if !areas.iter().any(|area| area.name == *reference.get_ref()) {
                return Err(parser.error(
                    format!(
                        "segment {} names area {}, which is not defined",
                        segment.name.get_ref(),
                        reference.get_ref()
                    ),
                    Some(reference.span()),
                ));
            }
        }
        let align = |value: &Option<Spanned<Number>>| -> Result<Option<u64>, Error> {
            let Some(value) = value else { return Ok(None) };
            let align = parser.number(value, 1 << 24, "alignment")?;
            if !align.is_power_of_two() {
                return Err(parser.error(
                    format!("alignment {align} is not a power of two"),
                    Some(value.span()),
                ));
            }
            Ok(Some(align))
        };
        let name = segment.name.get_ref().clone();
        segments.push(Segment {
            sections: segment
                .sections
                .clone()
                .unwrap_or_else(|| vec![name.clone()]),
            name,
            load: segment.load.get_ref().clone(),
            run: segment.run.as_ref().map(|run| run.get_ref().clone()),
            kind: match segment.kind.unwrap_or(FileKind::ReadOnly) {
                FileKind::ReadOnly => SegmentKind::ReadOnly,
                FileKind::ReadWrite => SegmentKind::ReadWrite,
                FileKind::Bss => SegmentKind::Bss,
                FileKind::ZeroPage => SegmentKind::ZeroPage,
            },
            align: align(&segment.align)?,
            align_load: align(&segment.align_load)?,
            start: match &segment.start {
                Some(start) => Some(parser.number(start, 0xFFFF_FFFF, "start")?),
                None => None,
            },
            offset: None,
            optional: segment.optional,
            define: segment.define,
        });
    }
    let layout = Layout {
        name: file.name.unwrap_or_else(|| path.to_owned()),
        areas,
        segments,
        ld65_alignment: false,
        config: super::Config::default(),
    };
    layout.validate()?;
    Ok(layout)
}
