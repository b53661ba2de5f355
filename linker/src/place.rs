//! Placement: input sections into segments, segments into memory areas.
//!
//! ld65's model: each object's section is a fragment of the segment of its
//! name, aligned within the segment, in command-line order. Each area has
//! one cursor; the layout's segments are placed in the order it lists
//! them, in their run area and (when different) their load area.

use crate::error::Error;
use crate::input::Object;
use crate::layout::{Area, Layout, Segment, SegmentKind};

/// One object's section inside a segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fragment {
    pub(crate) object: usize,
    /// Position in the object's `sections`.
    pub(crate) section: usize,
    /// Offset from the segment's start.
    pub(crate) offset: u64,
    pub(crate) size: u64,
}

/// A segment after placement.
#[derive(Debug, Clone)]
pub(crate) struct Placed {
    pub(crate) rule: Segment,
    pub(crate) fragments: Vec<Fragment>,
    pub(crate) size: u64,
    /// The largest alignment its fragments ask for.
    pub(crate) align: u64,
    pub(crate) run: u64,
    pub(crate) load: u64,
    /// Its contents (fill where no input has bytes); empty for BSS and
    /// zero page.
    pub(crate) bytes: Vec<u8>,
    /// Whether its bytes go into the image.
    pub(crate) written: bool,
    /// Its inputs hold zero-page sections, or it is a zero-page segment.
    pub(crate) zeropage: bool,
    /// Some input holds code.
    pub(crate) exec: bool,
}

impl Placed {
    fn has_bytes(&self) -> bool {
        !matches!(self.rule.kind, SegmentKind::Bss | SegmentKind::ZeroPage)
    }
}

/// An area after placement.
#[derive(Debug, Clone)]
pub(crate) struct PlacedArea {
    pub(crate) area: Area,
    /// One past the last address any segment uses.
    pub(crate) used_end: u64,
    /// One past the last byte written to the image (`start` if none).
    pub(crate) written_end: u64,
}

/// The result of placement.
#[derive(Debug, Clone)]
pub(crate) struct Placement {
    pub(crate) segments: Vec<Placed>,
    pub(crate) areas: Vec<PlacedArea>,
    /// Per object, per section position: (segment, offset in segment).
    pub(crate) sections: Vec<Vec<Option<(usize, u64)>>>,
}

impl Placement {
    /// The run address of a section's first byte.
    pub(crate) fn section_run(&self, object: usize, section: usize) -> Option<u64> {
        let (segment, offset) = self.sections[object][section]?;
        Some(self.segments[segment].run + offset)
    }
}

fn align_up(value: u64, align: u64) -> u64 {
    value.div_ceil(align.max(1)) * align.max(1)
}

/// Places every allocated section of `objects`; problems go to `errors`
/// (placement goes on, so that later stages can report more).
pub(crate) fn place(
    objects: &[Object],
    layout: &Layout,
    errors: &mut Vec<Error>,
    warnings: &mut Vec<Error>,
) -> Placement {
    let mut segments: Vec<Placed> = layout
        .segments
        .iter()
        .map(|rule| Placed {
            rule: rule.clone(),
            fragments: Vec::new(),
            size: 0,
            align: 1,
            run: 0,
            load: 0,
            bytes: Vec::new(),
            written: false,
            zeropage: rule.kind == SegmentKind::ZeroPage,
            exec: false,
        })
        .collect();
    let mut sections = Vec::with_capacity(objects.len());
    for (object_index, object) in objects.iter().enumerate() {
        let mut positions = vec![None; object.sections.len()];
        for (section_index, section) in object.sections.iter().enumerate() {
            let Some(segment_index) = segments.iter().position(|s| s.rule.takes(&section.name))
            else {
                errors.push(Error::UnplacedSection {
                    file: object.name.clone(),
                    section: section.name.clone(),
                    layout: layout.name.clone(),
                    help: format!(
                        "{} places segments {}; use one of them, or a layout file (--target FILE.toml) that places {}",
                        layout.name,
                        layout
                            .segments
                            .iter()
                            .map(|s| s.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", "),
                        section.name
                    ),
                });
                continue;
            };
            let segment = &mut segments[segment_index];
            let align = u64::from(section.align);
            let offset = align_up(segment.size, align);
            segment.fragments.push(Fragment {
                object: object_index,
                section: section_index,
                offset,
                size: u64::from(section.size),
            });
            segment.size = offset + u64::from(section.size);
            segment.align = segment.align.max(align);
            segment.zeropage |= section.zeropage;
            segment.exec |= section.exec;
            positions[section_index] = Some((segment_index, offset));
        }
        sections.push(positions);
    }

    for segment in &segments {
        if segment.fragments.is_empty() && !segment.rule.optional {
            // Not an error: ld65 warns too. A layout lists what it may take.
            warnings.push(Error::EmptySegment {
                layout: layout.name.clone(),
                segment: segment.rule.name.clone(),
            });
        }
    }

    let mut areas = Vec::with_capacity(layout.areas.len());
    for area in &layout.areas {
        let mut cursor = area.start;
        // The highest address reached: a fixed start may move the cursor back.
        let mut reached = area.start;
        let mut written_end = area.start;
        let mut last: Option<usize> = None;
        let mut overflow: Option<usize> = None;
        for index in 0..segments.len() {
            let segment = &segments[index];
            let runs_here = segment.rule.run_area() == area.name;
            let loads_here = segment.rule.load == area.name;
            if !runs_here && !loads_here {
                continue;
            }
            let address = if runs_here {
                if let Some(start) = segment.rule.start {
                    if cursor > start {
                        errors.push(Error::FixedStartOverlap {
                            segment: segment.rule.name.clone(),
                            start,
                            area: area.name.clone(),
                            reached: cursor,
                            by: last.map_or_else(
                                || "the area's start".to_owned(),
                                |last| format!("segment {}", segments[last].rule.name),
                            ),
                            overlap: cursor - start,
                        });
                    }
                    start
                } else {
                    let align = match segment.rule.align {
                        Some(align) => align,
                        None if layout.ld65_alignment => 1,
                        None => segment.align,
                    };
                    align_up(cursor, align)
                }
            } else {
                align_up(cursor, segment.rule.align_load.unwrap_or(1))
            };
            let segment = &mut segments[index];
            if runs_here {
                segment.run = address;
            }
            if loads_here {
                segment.load = address;
                if segment.has_bytes() && segment.size > 0 {
                    if area.output {
                        segment.written = true;
                        written_end = written_end.max(address + segment.size);
                    } else {
                        errors.push(Error::NotLoaded {
                            segment: segment.rule.name.clone(),
                            area: area.name.clone(),
                        });
                    }
                }
            }
            cursor = address + segment.size;
            reached = reached.max(cursor);
            if cursor > area.end() && overflow.is_none() {
                overflow = Some(index);
            }
            last = Some(index);
        }
        if let Some(index) = overflow {
            errors.push(Error::Overflow {
                segment: segments[index].rule.name.clone(),
                area: area.name.clone(),
                amount: reached - area.end(),
                contributors: contributors(objects, &segments, &area.name),
            });
        }
        if area.fill && area.output {
            written_end = area.end();
        }
        areas.push(PlacedArea {
            area: area.clone(),
            used_end: reached,
            written_end,
        });
    }

    for segment in &mut segments {
        if segment.run % segment.align != 0 && segment.size > 0 {
            warnings.push(Error::MisalignedSegment {
                segment: segment.rule.name.clone(),
                start: segment.run,
                align: segment.align,
            });
        }
        if segment.zeropage && segment.size > 0 && segment.run + segment.size > 0x100 {
            errors.push(Error::ZeroPagePlacement {
                segment: segment.rule.name.clone(),
                start: segment.run,
                end: segment.run + segment.size - 1,
            });
        }
        let load_area = layout
            .areas
            .iter()
            .find(|area| area.name == segment.rule.load);
        // A segment that does not fit its area (already an error) gets no
        // buffer: a corrupt size must not make the linker allocate it.
        let fits = load_area.is_some_and(|area| segment.load + segment.size <= area.end());
        if segment.has_bytes() && fits {
            let fill = load_area.map_or(0, |area| area.fill_value);
            let size = usize::try_from(segment.size).unwrap_or(0);
            let mut bytes = vec![fill; size];
            for fragment in &segment.fragments {
                let section = &objects[fragment.object].sections[fragment.section];
                let start = fragment.offset as usize;
                if let Some(target) = bytes.get_mut(start..start + section.data.len()) {
                    target.copy_from_slice(&section.data);
                    // Reserved bytes (`.res`, `.align` without a value)
                    // take the area's fill value, as ld65 gives them.
                    for &(offset, length) in &section.fills {
                        let run = offset as usize..(offset + length) as usize;
                        if let Some(gap) = target.get_mut(run) {
                            gap.fill(fill);
                        }
                    }
                }
            }
            segment.bytes = bytes;
        } else if !segment.has_bytes() {
            for fragment in &segment.fragments {
                let section = &objects[fragment.object].sections[fragment.section];
                if !section.nobits && section.data.iter().any(|byte| *byte != 0) {
                    errors.push(Error::NotLoaded {
                        segment: format!(
                            "{} ({}'s {} section)",
                            segment.rule.name, objects[fragment.object].name, section.name
                        ),
                        area: segment.rule.load.clone(),
                    });
                }
            }
        }
    }

    Placement {
        segments,
        areas,
        sections,
    }
}

/// "main.o CODE 812 bytes, lib.o CODE 300 bytes, ...": the three largest
/// fragments placed (run or load) in `area`.
fn contributors(objects: &[Object], segments: &[Placed], area: &str) -> String {
    let mut all: Vec<(u64, String)> = segments
        .iter()
        .filter(|s| s.rule.load == area || s.rule.run_area() == area)
        .flat_map(|s| {
            s.fragments.iter().map(|fragment| {
                let object = &objects[fragment.object];
                (
                    fragment.size,
                    format!(
                        "{} {} {} byte{}",
                        object.name,
                        object.sections[fragment.section].name,
                        fragment.size,
                        if fragment.size == 1 { "" } else { "s" }
                    ),
                )
            })
        })
        .collect();
    all.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    let shown: Vec<String> = all.iter().take(3).map(|(_, text)| text.clone()).collect();
    let mut text = format!("largest inputs: {}", shown.join(", "));
    if all.len() > 3 {
        text.push_str(&format!(" (and {} more)", all.len() - 3));
    }
    text
}
