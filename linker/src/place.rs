//! Placement: input sections into segments, segments into memory areas.
//!
//! ld65's model: each object's section is a fragment of the segment of its
//! name, aligned within the segment, in command-line order. Each area has
//! one cursor; the layout's segments are placed in the order it lists
//! them, in their run area and (when different) their load area.

use std::collections::HashMap;

use crate::error::Error;
use crate::input::Object;
use crate::layout::{
    Area, EvalError, Expr, Layout, RomSymbols, START_ADDRESS_SYMBOL, Segment, SegmentKind,
    SymbolKind,
};

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

/// A table the linker builds (ld65's `CONDES`), after placement.
#[derive(Debug, Clone)]
pub(crate) struct PlacedTable {
    /// Its position in the layout's tables.
    pub(crate) table: usize,
    /// `None` when the layout does not define the table's segment (ld65
    /// then gives the label 0; an entry is an error).
    pub(crate) segment: Option<usize>,
    /// Offset from the segment's start.
    pub(crate) offset: u64,
    /// The routines it lists, in table order: (object, symbol).
    pub(crate) entries: Vec<(usize, usize)>,
}

/// A symbol the layout defines (`SYMBOLS`, tables' labels and counts).
#[derive(Debug, Clone)]
pub(crate) struct LayoutValue {
    pub(crate) name: String,
    pub(crate) value: i64,
    /// Loses to an object's definition.
    pub(crate) weak: bool,
}

/// The result of placement.
#[derive(Debug, Clone)]
pub(crate) struct Placement {
    pub(crate) segments: Vec<Placed>,
    pub(crate) areas: Vec<PlacedArea>,
    /// Per object, per section position: (segment, offset in segment).
    pub(crate) sections: Vec<Vec<Option<(usize, u64)>>>,
    pub(crate) tables: Vec<PlacedTable>,
    /// Symbols the layout defines besides `define = yes` ones.
    pub(crate) values: Vec<LayoutValue>,
    /// Empty sections an ld65 configuration has no segment for, by
    /// (object, section): ld65 links them, their labels at address 0
    /// (ca65's `CODE` holding only a label before the first `.segment`).
    pub(crate) nowhere: Vec<(usize, usize)>,
}

impl Placement {
    /// The run address of a section's first byte.
    pub(crate) fn section_run(&self, object: usize, section: usize) -> Option<u64> {
        let Some((segment, offset)) = self.sections[object][section] else {
            return self.nowhere.contains(&(object, section)).then_some(0);
        };
        Some(self.segments[segment].run + offset)
    }
}

/// The segments ca65 puts in every object.
const CA65_SEGMENTS: [&str; 6] = ["CODE", "RODATA", "BSS", "DATA", "ZEROPAGE", "NULL"];

fn align_up(value: u64, align: u64) -> u64 {
    value.div_ceil(align.max(1)) * align.max(1)
}

/// Places every allocated section of `objects`; problems go to `errors`
/// (placement goes on, so that later stages can report more).
pub(crate) fn place(
    objects: &[Object],
    layout: &Layout,
    known: &RomSymbols,
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
    let mut nowhere = Vec::new();
    for (object_index, object) in objects.iter().enumerate() {
        let mut positions = vec![None; object.sections.len()];
        for (section_index, section) in object.sections.iter().enumerate() {
            let Some(segment_index) = segments.iter().position(|s| s.rule.takes(&section.name))
            else {
                if layout.config.ld65 && section.size == 0 {
                    nowhere.push((object_index, section_index));
                    continue;
                }
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
        // ca65 writes its standard segments into every object, empty or
        // not, so ld65 never misses them: neither do we with its layouts.
        let standard = layout.config.ld65 && CA65_SEGMENTS.contains(&segment.rule.name.as_str());
        if segment.fragments.is_empty() && !segment.rule.optional && !standard {
            // Not an error: ld65 warns too. A layout lists what it may take.
            warnings.push(Error::EmptySegment {
                layout: layout.name.clone(),
                segment: segment.rule.name.clone(),
            });
        }
    }

    let tables = append_tables(objects, layout, &mut segments);

    // What the layout's expressions may name, growing as areas are placed.
    let mut env: HashMap<String, i64> = known
        .iter()
        .map(|(name, value)| (name.to_owned(), value))
        .collect();
    env.insert(
        START_ADDRESS_SYMBOL.to_owned(),
        layout.config.start_address as i64,
    );
    let mut areas = Vec::with_capacity(layout.areas.len());
    for area in &layout.areas {
        let mut area = area.clone();
        if let Some((start, size)) = &area.exprs {
            settle_symbols(layout, &mut env);
            match area_bounds(layout, &area.name, start, size, &mut env) {
                Ok((start, size)) => {
                    area.start = start;
                    area.size = size;
                }
                Err(error) => {
                    errors.push(error);
                    area.size = 0;
                    areas.push(PlacedArea {
                        used_end: area.start,
                        written_end: area.start,
                        area,
                    });
                    continue;
                }
            }
        }
        let area = &area;
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
                let fixed = segment
                    .rule
                    .start
                    .or(segment.rule.offset.map(|offset| area.start + offset));
                if let Some(start) = fixed {
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
                    } else if layout.config.ld65 {
                        // ld65 drops bytes loaded where no file goes
                        // (`file = ""`), which configurations use to hide
                        // headers they do not want.
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
        if area.define {
            let name = &area.name;
            env.insert(format!("__{name}_START__"), area.start as i64);
            env.insert(format!("__{name}_SIZE__"), area.size as i64);
            env.insert(format!("__{name}_LAST__"), reached as i64);
        }
        for segment in segments.iter().filter(|s| {
            s.rule.define && (s.rule.load == area.name || s.rule.run_area() == area.name)
        }) {
            let name = &segment.rule.name;
            env.insert(format!("__{name}_LOAD__"), segment.load as i64);
            env.insert(format!("__{name}_RUN__"), segment.run as i64);
            env.insert(format!("__{name}_SIZE__"), segment.size as i64);
        }
        areas.push(PlacedArea {
            area: area.clone(),
            used_end: reached,
            written_end,
        });
    }
    let values = layout_values(layout, &segments, &tables, &mut env, errors);

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
        let load_area = areas
            .iter()
            .map(|placed| &placed.area)
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
        tables,
        values,
        nowhere,
    }
}

/// Appends each table of the layout to its segment: two bytes per routine
/// of its kind that the objects declare, sorted by priority (stable, so
/// equal priorities keep the objects' order).
fn append_tables(objects: &[Object], layout: &Layout, segments: &mut [Placed]) -> Vec<PlacedTable> {
    let mut placed = Vec::new();
    for (index, table) in layout.config.tables.iter().enumerate() {
        let segment = segments.iter().position(|s| s.rule.name == table.segment);
        let mut entries: Vec<(u8, usize, usize)> = Vec::new();
        for (object_index, object) in objects.iter().enumerate() {
            for entry in object
                .condes
                .iter()
                .filter(|e| e.kind == table.kind.number())
            {
                entries.push((entry.priority, object_index, entry.symbol as usize));
            }
        }
        entries.sort_by_key(|(priority, ..)| *priority);
        if !table.increasing {
            entries.reverse();
        }
        let mut offset = 0;
        if let Some(segment) = segment {
            offset = segments[segment].size;
            segments[segment].size += 2 * entries.len() as u64;
        }
        placed.push(PlacedTable {
            table: index,
            segment,
            offset,
            entries: entries.into_iter().map(|(_, o, s)| (o, s)).collect(),
        });
    }
    placed
}

/// Gives the layout's `SYMBOLS` the values they can have now, weak ones
/// only where no object defines the name.
fn settle_symbols(layout: &Layout, env: &mut HashMap<String, i64>) {
    loop {
        let mut progress = false;
        for symbol in &layout.config.symbols {
            let Some(expr) = &symbol.value else { continue };
            if env.contains_key(&symbol.name) {
                continue;
            }
            if let Ok(value) = expr.eval(env) {
                env.insert(symbol.name.clone(), value);
                progress = true;
            }
        }
        if !progress {
            return;
        }
    }
}

/// An area's start and size from its expressions. The size may name the
/// area's own start (`__MAIN_START__`): ld65 defines it first.
fn area_bounds(
    layout: &Layout,
    area: &str,
    start: &Expr,
    size: &Expr,
    env: &mut HashMap<String, i64>,
) -> Result<(u64, u64), Error> {
    let start_value = area_value(layout, area, "start", start, env)?;
    if !(0..=0xFFFF_FFFF).contains(&start_value) {
        return Err(layout.value_error(
            format!("memory area {area} starts at {start_value}, outside $0-$FFFFFFFF"),
            "check the SYMBOLS its start uses",
            start.span(),
        ));
    }
    // Known for the size only; `define = yes` makes it a symbol later.
    let own_start = format!("__{area}_START__");
    let before = env.insert(own_start.clone(), start_value);
    let size_value = area_value(layout, area, "size", size, env);
    match before {
        Some(value) => env.insert(own_start, value),
        None => env.remove(&own_start),
    };
    let size_value = size_value?;
    // Size 0 is an area nothing may use (ld65's overlays before a program
    // sets `__OVERLAYSIZE__`).
    if size_value < 0 || start_value + size_value > 1 << 32 {
        return Err(layout.value_error(
            format!("memory area {area} comes out {size_value} bytes long from ${start_value:04X}"),
            "an area's size must not be negative and must end by $FFFFFFFF; check the SYMBOLS its size uses",
            size.span(),
        ));
    }
    Ok((start_value as u64, size_value as u64))
}

/// One of an area's expressions, `what` naming it for errors.
fn area_value(
    layout: &Layout,
    area: &str,
    what: &str,
    expr: &Expr,
    env: &HashMap<String, i64>,
) -> Result<i64, Error> {
    expr.eval(env).map_err(|error| match error {
        EvalError::Undefined(name, span) => layout.value_error(
            format!("the {what} of memory area {area} names `{name}`, which has no value here"),
            "an area may use the SYMBOLS, the objects' constants and the `define = yes` symbols of the areas before it",
            Some(span),
        ),
        EvalError::DivisionByZero => layout.value_error(
            format!("the {what} of memory area {area} divides by zero"),
            "check the SYMBOLS it uses",
            expr.span(),
        ),
    })
}

/// The layout's own symbols once everything is placed: `SYMBOLS` with a
/// value, and each table's label and count.
fn layout_values(
    layout: &Layout,
    segments: &[Placed],
    tables: &[PlacedTable],
    env: &mut HashMap<String, i64>,
    errors: &mut Vec<Error>,
) -> Vec<LayoutValue> {
    settle_symbols(layout, env);
    let mut values = Vec::new();
    for symbol in &layout.config.symbols {
        let Some(expr) = &symbol.value else { continue };
        match expr.eval(env) {
            Ok(value) => values.push(LayoutValue {
                name: symbol.name.clone(),
                value,
                weak: symbol.kind == SymbolKind::Weak,
            }),
            Err(EvalError::Undefined(name, span)) => errors.push(layout.value_error(
                format!("symbol {} names `{name}`, which nothing defines", symbol.name),
                "a symbol's value may use numbers, %S, the other SYMBOLS, the objects' constants and `define = yes` symbols",
                Some(span),
            )),
            Err(EvalError::DivisionByZero) => errors.push(layout.value_error(
                format!("symbol {} divides by zero", symbol.name),
                "check the SYMBOLS it uses",
                Some(symbol.span.clone()),
            )),
        }
    }
    for placed in tables {
        let table = &layout.config.tables[placed.table];
        let label = match placed.segment {
            Some(segment) => (segments[segment].run + placed.offset) as i64,
            None if placed.entries.is_empty() => 0,
            None => {
                errors.push(layout.value_error(
                    format!(
                        "{} routines go to a table in segment {}, which SEGMENTS does not define",
                        placed.entries.len(),
                        table.segment
                    ),
                    "define the segment, or leave the routines out of the link",
                    Some(table.segment_span.clone()),
                ));
                0
            }
        };
        values.push(LayoutValue {
            name: table.label.clone(),
            value: label,
            weak: false,
        });
        if let Some(count) = &table.count {
            values.push(LayoutValue {
                name: count.clone(),
                value: placed.entries.len() as i64,
                weak: false,
            });
        }
    }
    values
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
