//! The map file (areas, segments, modules, symbols by name and by address)
//! and the VICE label file.

use core::fmt::Write as _;
use std::collections::BTreeMap;

use crate::layout::SegmentKind;
use crate::model::Linked;

#[derive(Debug, Clone)]
pub(crate) struct MapArea {
    pub(crate) name: String,
    pub(crate) start: u64,
    pub(crate) size: u64,
    pub(crate) used: u64,
    pub(crate) written: u64,
}

#[derive(Debug, Clone)]
pub(crate) struct MapSegment {
    pub(crate) name: String,
    pub(crate) load_area: String,
    pub(crate) run_area: String,
    pub(crate) run: u64,
    pub(crate) load: u64,
    pub(crate) size: u64,
    pub(crate) align: u64,
    pub(crate) kind: SegmentKind,
}

#[derive(Debug, Clone)]
pub(crate) struct MapPart {
    pub(crate) segment: String,
    pub(crate) section: String,
    pub(crate) offset: u64,
    pub(crate) size: u64,
    pub(crate) align: u64,
}

#[derive(Debug, Clone)]
pub(crate) struct MapModule {
    pub(crate) name: String,
    pub(crate) parts: Vec<MapPart>,
}

/// What the map shows besides the image.
#[derive(Debug, Clone)]
pub(crate) struct MapData {
    pub(crate) layout: String,
    pub(crate) areas: Vec<MapArea>,
    pub(crate) segments: Vec<MapSegment>,
    pub(crate) modules: Vec<MapModule>,
    /// Global symbol to the object (or layout, or symbol file) defining it.
    pub(crate) defined_in: BTreeMap<String, String>,
}

fn kind_name(kind: SegmentKind) -> &'static str {
    match kind {
        SegmentKind::ReadOnly => "ro",
        SegmentKind::ReadWrite => "rw",
        SegmentKind::Bss => "bss",
        SegmentKind::ZeroPage => "zp",
    }
}

fn range(start: u64, size: u64) -> String {
    if size == 0 {
        format!("${start:04X}      -")
    } else {
        format!("${start:04X}-${:04X}", start + size - 1)
    }
}

impl Linked {
    /// The map file: deterministic text for people and snapshot tests.
    #[must_use]
    pub fn map(&self) -> String {
        let map = &self.map;
        let mut out = String::new();
        let _ = writeln!(out, "Scorpion link map (layout {})", map.layout);
        let _ = writeln!(out, "entry ${:04X}", self.image.entry);

        let _ = writeln!(out, "\nMemory areas\n");
        let _ = writeln!(
            out,
            "{:<12} {:<13} {:>8} {:>8} {:>8} {:>8}",
            "area", "range", "size", "used", "free", "written"
        );
        for area in &map.areas {
            let _ = writeln!(
                out,
                "{:<12} {:<13} {:>8} {:>8} {:>8} {:>8}",
                area.name,
                range(area.start, area.size),
                area.size,
                area.used,
                area.size.saturating_sub(area.used),
                area.written
            );
        }

        let _ = writeln!(out, "\nSegments\n");
        let _ = writeln!(
            out,
            "{:<12} {:<4} {:<13} {:<13} {:>7} {:>6}  area",
            "segment", "kind", "run", "load", "size", "align"
        );
        for segment in &map.segments {
            let area = if segment.load_area == segment.run_area {
                segment.run_area.clone()
            } else {
                format!("{} (loads in {})", segment.run_area, segment.load_area)
            };
            let _ = writeln!(
                out,
                "{:<12} {:<4} {:<13} {:<13} {:>7} {:>6}  {area}",
                segment.name,
                kind_name(segment.kind),
                range(segment.run, segment.size),
                range(segment.load, segment.size),
                segment.size,
                segment.align
            );
        }

        let _ = writeln!(out, "\nModules\n");
        for module in &map.modules {
            let _ = writeln!(out, "{}", module.name);
            for part in &module.parts {
                let from = if part.section == part.segment {
                    String::new()
                } else {
                    format!("  (section {})", part.section)
                };
                let _ = writeln!(
                    out,
                    "    {:<12} offset ${:04X}  size {:>6}  align {}{from}",
                    part.segment, part.offset, part.size, part.align
                );
            }
        }

        let globals: Vec<_> = self.image.symbols.iter().filter(|s| s.global).collect();
        let _ = writeln!(out, "\nSymbols by name\n");
        for symbol in &globals {
            let _ = writeln!(
                out,
                "{:<32} ${:04X}  {}",
                symbol.name,
                symbol.value,
                map.defined_in.get(&symbol.name).map_or("", String::as_str)
            );
        }
        let mut by_address = globals.clone();
        by_address.sort_by(|a, b| a.value.cmp(&b.value).then_with(|| a.name.cmp(&b.name)));
        let _ = writeln!(out, "\nSymbols by address\n");
        for symbol in by_address {
            let _ = writeln!(out, "${:04X}  {}", symbol.value, symbol.name);
        }
        out
    }

    /// A VICE monitor label file (`al ADDRESS .name`, ld65's `-Ln` form):
    /// every symbol in a placed segment and every exported constant (ROM
    /// entry points are constants here) except the layout's `__NAME_SIZE__`
    /// sizes, sorted by address then name.
    #[must_use]
    pub fn vice_labels(&self) -> String {
        let mut labels: Vec<(u32, &str)> = self
            .image
            .symbols
            .iter()
            .filter(|symbol| {
                symbol.section.is_some()
                    || (symbol.global
                        && !(symbol.name.starts_with("__") && symbol.name.ends_with("_SIZE__")))
            })
            .map(|symbol| (symbol.value, symbol.name.as_str()))
            .collect();
        labels.sort_unstable();
        labels.dedup();
        let mut out = String::new();
        for (value, name) in labels {
            let _ = writeln!(out, "al {:06X} .{name}", value & 0xFF_FFFF);
        }
        out
    }
}
