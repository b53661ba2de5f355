//! Turning a placement into the image (loaded areas, sections, symbols,
//! entry) and into the map's data.

use std::collections::BTreeMap;

use isa::objfmt::{Hooks, SourceLoc, SrcMap, SrcMapEntry};

use crate::image::{Image, ImageSection, ImageSymbol, LoadArea};
use crate::input::{Binding, Definition, Object};
use crate::layout::{Layout, OutputFormat, SegmentKind};
use crate::map::{MapArea, MapData, MapModule, MapPart, MapSegment};
use crate::model::{Global, Origin};
use crate::output::{OutputFile, Part};
use crate::place::{self, Placement};

/// The image: areas split where the run address stops following the load
/// address, a section per non-empty segment, locals then globals; the
/// main output file (its areas are the image's); and the other output
/// files.
pub(crate) fn build_image(
    objects: &[Object],
    layout: &Layout,
    placement: &Placement,
    values: &[Vec<Option<i64>>],
    globals: &BTreeMap<String, Global>,
    hooks: Hooks,
) -> (Image, OutputFile, Vec<OutputFile>) {
    // Areas, split where the run address stops following the load address.
    let format_of = |file: &str| {
        layout
            .config
            .formats
            .iter()
            .find(|(name, ..)| name == file)
            .map_or(OutputFormat::Bin, |(_, format, _)| *format)
    };
    let mut main = OutputFile::new("%O", format_of("%O"));
    let mut others: Vec<OutputFile> = Vec::new();
    for placed in &placement.areas {
        if !placed.area.output {
            continue;
        }
        let file = match &placed.area.file {
            None => &mut main,
            Some(name) => {
                let index = match others.iter().position(|file| file.name == *name) {
                    Some(index) => index,
                    None => {
                        others.push(OutputFile::new(name, format_of(name)));
                        others.len() - 1
                    }
                };
                &mut others[index]
            }
        };
        // BSS inside a written area takes no room in ld65's binary files.
        let part = Part {
            area: placed.area.name.clone(),
            holes: placement
                .segments
                .iter()
                .filter(|s| s.rule.load == placed.area.name && s.rule.kind == SegmentKind::Bss)
                .map(|s| (s.load, s.load + s.size))
                .collect(),
        };
        let OutputFile { areas, parts, .. } = file;
        let area = &placed.area;
        if !area.output || placed.written_end <= area.start {
            continue;
        }
        let mut bytes = vec![area.fill_value; (placed.written_end - area.start) as usize];
        let mut written: Vec<&place::Placed> = placement
            .segments
            .iter()
            .filter(|s| s.written && s.rule.load == area.name)
            .collect();
        written.sort_by_key(|s| s.load);
        for segment in &written {
            let start = (segment.load - area.start) as usize;
            bytes[start..start + segment.bytes.len()].copy_from_slice(&segment.bytes);
        }
        let delta = |s: &place::Placed| s.run as i64 - s.load as i64;
        // A segment that runs elsewhere gets a piece of its own; gaps and
        // fill run where they load.
        let mut pieces: Vec<(u64, i64)> = vec![(area.start, 0)];
        for segment in &written {
            for (start, offset) in [
                (segment.load, delta(segment)),
                (segment.load + segment.size, 0),
            ] {
                if pieces.last().is_some_and(|last| last.0 == start) {
                    pieces.pop();
                }
                if pieces.last().is_none_or(|last| last.1 != offset) {
                    pieces.push((start, offset));
                }
            }
        }
        pieces.retain(|(start, _)| *start < placed.written_end);
        for (index, (start, offset)) in pieces.iter().enumerate() {
            let end = pieces
                .get(index + 1)
                .map_or(placed.written_end, |next| next.0);
            let from = (start - area.start) as usize;
            let to = (end - area.start) as usize;
            areas.push(LoadArea {
                load: *start as u32,
                run: (*start as i64 + offset) as u32,
                bytes: bytes[from..to].to_vec(),
            });
            parts.push(part.clone());
        }
    }

    let mut sections = Vec::new();
    let mut section_of_segment = vec![None; placement.segments.len()];
    for (index, segment) in placement.segments.iter().enumerate() {
        // Empty segments get no section header (their labels are plain
        // constants): a zero-size section has no place in any PT_LOAD.
        if segment.size == 0 {
            continue;
        }
        section_of_segment[index] = Some(sections.len());
        sections.push(ImageSection {
            name: segment.rule.name.clone(),
            run: segment.run as u32,
            load: segment.load as u32,
            size: segment.size as u32,
            exec: segment.exec,
            kind: if segment.written
                || !matches!(segment.rule.kind, SegmentKind::Bss | SegmentKind::ZeroPage)
            {
                segment.rule.kind
            } else if segment.zeropage {
                SegmentKind::ZeroPage
            } else {
                SegmentKind::Bss
            },
        });
    }

    let mut symbols = Vec::new();
    for (object_index, object) in objects.iter().enumerate() {
        for (symbol_index, symbol) in object.symbols.iter().enumerate() {
            if symbol.binding != Binding::Local
                || symbol.is_section_or_file
                || symbol.name.is_empty()
            {
                continue;
            }
            let Some(value) = values[object_index][symbol_index] else {
                continue;
            };
            let section = match symbol.definition {
                Definition::Section(section, _) => placement.sections[object_index][section]
                    .and_then(|(segment, _)| section_of_segment[segment]),
                _ => None,
            };
            symbols.push(ImageSymbol {
                name: symbol.name.clone(),
                value: value as u32,
                size: symbol.size,
                global: false,
                section,
            });
        }
    }
    for (name, global) in globals {
        let Some(value) = global.value else { continue };
        symbols.push(ImageSymbol {
            name: name.clone(),
            value: value as u32,
            size: global.size,
            global: true,
            section: global
                .segment
                .and_then(|segment| section_of_segment[segment]),
        });
    }

    let entry = ["__STARTUP__", "start"]
        .iter()
        .find_map(|name| globals.get(*name).and_then(|g| g.value))
        .or_else(|| {
            symbols
                .iter()
                .find(|s| s.name == "start" || s.name == "__STARTUP__")
                .map(|s| i64::from(s.value))
        })
        .or_else(|| {
            placement
                .segments
                .iter()
                .find(|s| s.rule.name == "CODE" && s.size > 0)
                .or_else(|| placement.segments.iter().find(|s| s.written))
                .map(|s| s.run as i64)
        })
        .unwrap_or(0);

    let image = Image {
        entry: entry as u32,
        flags: objects.iter().fold(0, |flags, object| flags | object.flags),
        // The main file's areas are the image's.
        areas: std::mem::take(&mut main.areas),
        sections,
        symbols,
        hooks,
        lines: lines(objects, placement),
    };
    (image, main, others)
}

/// The objects' source maps by run address: every entry of every placed
/// section moved to where its bytes run (and the macro calls that made
/// them), the files of all objects in one list.
fn lines(objects: &[Object], placement: &Placement) -> SrcMap {
    let mut lines = SrcMap::default();
    let mut file_numbers: BTreeMap<String, u32> = BTreeMap::new();
    for (object_index, object) in objects.iter().enumerate() {
        let Some(map) = &object.srcmap else {
            continue;
        };
        let mut moved = |entry: &SrcMapEntry| {
            let position = object
                .sections
                .iter()
                .position(|section| section.index == entry.section as usize)?;
            let (segment, offset) = placement.sections[object_index][position]?;
            let address = placement.segments[segment].run + offset + u64::from(entry.offset);
            let address = u32::try_from(address).ok()?;
            let name = map.file_name(entry.loc)?;
            let next = u32::try_from(file_numbers.len()).unwrap_or(u32::MAX);
            let file = *file_numbers.entry(name.to_owned()).or_insert(next);
            Some(SrcMapEntry {
                section: 0,
                offset: address,
                loc: SourceLoc { file, ..entry.loc },
            })
        };
        lines
            .entries
            .extend(map.entries.iter().filter_map(&mut moved));
        lines.calls.extend(map.calls.iter().filter_map(&mut moved));
    }
    lines.files = vec![String::new(); file_numbers.len()];
    for (name, number) in file_numbers {
        lines.files[number as usize] = name;
    }
    lines.entries.sort();
    lines.calls.sort();
    lines
}

/// What the map file shows besides the image.
pub(crate) fn map_data(
    objects: &[Object],
    layout: &Layout,
    placement: &Placement,
    globals: &BTreeMap<String, Global>,
) -> MapData {
    MapData {
        layout: layout.name.clone(),
        areas: placement
            .areas
            .iter()
            .map(|placed| MapArea {
                name: placed.area.name.clone(),
                start: placed.area.start,
                size: placed.area.size,
                used: placed.used_end - placed.area.start,
                written: if placed.area.output {
                    placed.written_end - placed.area.start
                } else {
                    0
                },
            })
            .collect(),
        segments: placement
            .segments
            .iter()
            .map(|segment| MapSegment {
                name: segment.rule.name.clone(),
                load_area: segment.rule.load.clone(),
                run_area: segment.rule.run_area().to_owned(),
                run: segment.run,
                load: segment.load,
                size: segment.size,
                align: segment.align,
                kind: segment.rule.kind,
            })
            .collect(),
        modules: objects
            .iter()
            .enumerate()
            .map(|(object_index, object)| MapModule {
                name: object.name.clone(),
                parts: object
                    .sections
                    .iter()
                    .enumerate()
                    .filter_map(|(section_index, section)| {
                        let (segment, offset) = placement.sections[object_index][section_index]?;
                        Some(MapPart {
                            segment: placement.segments[segment].rule.name.clone(),
                            section: section.name.clone(),
                            offset,
                            size: u64::from(section.size),
                            align: u64::from(section.align),
                        })
                    })
                    .collect(),
            })
            .collect(),
        defined_in: globals
            .iter()
            .map(|(name, global)| {
                let origin = match &global.origin {
                    Origin::Object { object, .. } => objects[*object].name.clone(),
                    Origin::Layout => "(layout)".to_owned(),
                    Origin::File(file) => file.clone(),
                };
                (name.clone(), origin)
            })
            .collect(),
    }
}
