//! The link: read, place, resolve, relocate, check, and build the image.

use std::collections::{BTreeMap, HashMap};

use isa::elf as mos;
use isa::objfmt::{AssertAction, EvalError, HookKind, HookRecord, Hooks};

use crate::error::Error;
use crate::image::{Image, ImageSection, ImageSymbol, LoadArea};
use crate::input::{self, Binding, Definition, Input, Object};
use crate::layout::{Layout, RomSymbols, SegmentKind, Target};
use crate::map::{MapArea, MapData, MapModule, MapPart, MapSegment};
use crate::place::{self, Placement};
use crate::source::{Place, SourceProvider};

/// A linked image whose symbols an object may use (`--just-symbols`): the
/// ROM, for an extension.
#[derive(Debug, Clone, Copy)]
pub struct SymbolFile<'a> {
    /// Its name, for messages.
    pub name: &'a str,
    /// The image.
    pub image: &'a Image,
}

/// What a link needs besides the objects.
#[derive(Clone, Copy)]
pub struct LinkOptions<'a> {
    /// Where things go.
    pub target: &'a Target,
    /// Images that supply absolute symbols for otherwise undefined references.
    pub just_symbols: &'a [SymbolFile<'a>],
    /// Source text for diagnostics.
    pub sources: &'a dyn SourceProvider,
}

impl core::fmt::Debug for LinkOptions<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LinkOptions")
            .field("target", &self.target.name())
            .field("just_symbols", &self.just_symbols)
            .finish_non_exhaustive()
    }
}

/// A successful link.
#[derive(Debug)]
pub struct Linked {
    /// The program.
    pub image: Image,
    /// The layout used.
    pub layout: Layout,
    /// Warnings (failed `.assert`s with the warning action, misaligned
    /// segments, empty required segments).
    pub warnings: Vec<Error>,
    pub(crate) map: MapData,
}

/// Where a global symbol comes from.
#[derive(Debug, Clone)]
enum Origin {
    Object { object: usize, symbol: usize },
    Layout,
    File(String),
}

#[derive(Debug, Clone)]
struct Global {
    value: Option<i64>,
    origin: Origin,
    weak: bool,
    /// Image section (segment index) it lies in.
    segment: Option<usize>,
    size: u32,
}

/// Links `inputs` into an image.
///
/// # Errors
/// [`Error::Failed`] with every problem found (unreadable objects, layout
/// overflows, undefined and duplicate symbols, range errors, failed
/// assertions), or a single layout error.
pub fn link(inputs: &[Input<'_>], options: &LinkOptions<'_>) -> Result<Linked, Error> {
    let mut errors = Vec::new();
    let mut objects = Vec::with_capacity(inputs.len());
    for input in inputs {
        match input::read_object(*input) {
            Ok(object) => objects.push(object),
            Err(error) => errors.push(error),
        }
    }
    if !errors.is_empty() {
        return Err(failed(errors));
    }

    let mut rom = RomSymbols::default();
    let mut file_symbols: HashMap<&str, (i64, &str)> = HashMap::new();
    for file in options.just_symbols {
        for symbol in file.image.symbols.iter().filter(|s| s.global) {
            rom.insert(&symbol.name, i64::from(symbol.value));
            file_symbols
                .entry(symbol.name.as_str())
                .or_insert((i64::from(symbol.value), file.name));
        }
    }
    for object in &objects {
        for symbol in &object.symbols {
            if let (Binding::Global, Definition::Absolute(value)) =
                (symbol.binding, symbol.definition)
            {
                rom.insert(&symbol.name, value);
            }
        }
    }
    let layout = options.target.resolve(&rom)?;

    let mut warnings = Vec::new();
    let placement = place::place(&objects, &layout, &mut errors, &mut warnings);

    // Values of defined symbols.
    let mut values: Vec<Vec<Option<i64>>> = objects
        .iter()
        .enumerate()
        .map(|(object_index, object)| {
            object
                .symbols
                .iter()
                .map(|symbol| match symbol.definition {
                    Definition::Undefined => None,
                    Definition::Absolute(value) => Some(value),
                    Definition::Section(section, offset) => placement
                        .section_run(object_index, section)
                        .map(|run| run as i64 + i64::from(offset)),
                })
                .collect()
        })
        .collect();

    let mut globals = layout_symbols(&layout, &placement);
    for (object_index, object) in objects.iter().enumerate() {
        for (symbol_index, symbol) in object.symbols.iter().enumerate() {
            if symbol.binding == Binding::Local
                || symbol.definition == Definition::Undefined
                || symbol.name.is_empty()
            {
                continue;
            }
            let weak = symbol.binding == Binding::Weak;
            let segment = match symbol.definition {
                Definition::Section(section, _) => {
                    placement.sections[object_index][section].map(|(segment, _)| segment)
                }
                _ => None,
            };
            let new = Global {
                value: values[object_index][symbol_index],
                origin: Origin::Object {
                    object: object_index,
                    symbol: symbol_index,
                },
                weak,
                segment,
                size: symbol.size,
            };
            match globals.get(&symbol.name) {
                None => {
                    globals.insert(symbol.name.clone(), new);
                }
                Some(old) if old.weak && !weak => {
                    globals.insert(symbol.name.clone(), new);
                }
                Some(_) if weak => {}
                Some(old) => {
                    let first = match &old.origin {
                        Origin::Object { object, symbol } => {
                            objects[*object].place_of_symbol(*symbol).text
                        }
                        Origin::Layout => format!("layout {} (define = true)", layout.name),
                        Origin::File(file) => file.clone(),
                    };
                    let second = object.place_of_symbol(symbol_index);
                    let (src, span) = second.snippet(options.sources);
                    errors.push(Error::Duplicate {
                        name: symbol.name.clone(),
                        first,
                        second: second.text,
                        src,
                        span,
                    });
                }
            }
        }
    }

    // Undefined references: globals, then --just-symbols, then weak zero.
    let mut undefined: BTreeMap<String, Vec<Place>> = BTreeMap::new();
    let mut unresolved: Vec<Vec<bool>> = Vec::with_capacity(objects.len());
    for (object_index, object) in objects.iter().enumerate() {
        let mut missing = vec![false; object.symbols.len()];
        for (symbol_index, symbol) in object.symbols.iter().enumerate().skip(1) {
            if symbol.definition != Definition::Undefined {
                // A global binds to the winning definition (a weak one may
                // have lost to a strong one elsewhere).
                if let (false, Some(global)) =
                    (symbol.binding == Binding::Local, globals.get(&symbol.name))
                {
                    values[object_index][symbol_index] = global.value;
                }
                continue;
            }
            if let Some(global) = globals.get(&symbol.name) {
                values[object_index][symbol_index] = global.value;
            } else if let Some((value, file)) = file_symbols.get(symbol.name.as_str()) {
                values[object_index][symbol_index] = Some(*value);
                globals.insert(
                    symbol.name.clone(),
                    Global {
                        value: Some(*value),
                        origin: Origin::File((*file).to_owned()),
                        weak: false,
                        segment: None,
                        size: 0,
                    },
                );
            } else if symbol.binding == Binding::Weak {
                values[object_index][symbol_index] = Some(0);
            } else {
                missing[symbol_index] = true;
            }
        }
        for (section_index, section) in object.sections.iter().enumerate() {
            for reloc in &section.relocs {
                if missing[reloc.symbol] {
                    undefined
                        .entry(object.symbols[reloc.symbol].name.clone())
                        .or_default()
                        .push(object.place_of_byte(section_index, reloc.offset));
                }
            }
        }
        for assertion in &object.asserts {
            for symbol in assertion.expr.symbols() {
                if missing[symbol as usize] {
                    undefined
                        .entry(object.symbols[symbol as usize].name.clone())
                        .or_default()
                        .push(Place::source(
                            &assertion.file,
                            assertion.line,
                            assertion.column,
                        ));
                }
            }
        }
        unresolved.push(missing);
    }
    for (name, mut places) in undefined {
        places.sort();
        places.dedup();
        let (src, span) = places[0].snippet(options.sources);
        let similar = globals
            .keys()
            .map(String::as_str)
            .chain(file_symbols.keys().copied())
            .filter(|candidate| edit_distance(candidate, &name) <= 2.min(name.len() / 2))
            .min_by_key(|candidate| (edit_distance(candidate, &name), *candidate));
        let help = if let Some(similar) = similar {
            format!("did you mean `{similar}`?")
        } else if name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
            && options.just_symbols.is_empty()
        {
            format!(
                "export `{name}` from one of the objects, or link against the ROM with --just-symbols ROM.elf if it is a ROM symbol"
            )
        } else {
            format!(
                "export `{name}` from one of the objects (`.export {name}`), or check its spelling"
            )
        };
        errors.push(Error::Undefined {
            name,
            places: places
                .iter()
                .map(|place| place.text.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            help,
            src,
            span,
        });
    }

    let mut placement = placement;
    crate::relocate::apply(
        &objects,
        &values,
        &mut placement.segments,
        options.sources,
        &mut errors,
    );

    check_asserts(
        &objects,
        &values,
        &unresolved,
        options.sources,
        &mut errors,
        &mut warnings,
    );

    let hooks = hooks(&objects, &globals, &mut errors);
    if !errors.is_empty() {
        // Warnings still matter when the link fails: show them after the errors.
        let count = errors.len();
        errors.append(&mut warnings);
        return Err(Error::Failed { count, errors });
    }

    let image = build_image(&objects, &placement, &values, &globals, hooks);
    if let Err(Error::BadImage { reason, .. }) = image.check_hooks("") {
        // Name where the hook symbols are defined, so the user finds them.
        let places: Vec<String> = HookKind::ALL
            .iter()
            .flat_map(|kind| [kind.handler_symbol(), kind.chain_symbol()])
            .map(|name| (name, defined_at(&objects, &globals, name)))
            .filter(|(_, place)| !place.is_empty())
            .map(|(name, place)| format!("{name}{place}"))
            .collect();
        return Err(failed(vec![Error::Hook {
            reason: format!("{reason}; {}", places.join(", ")),
        }]));
    }
    let map = map_data(&objects, &layout, &placement, &globals);
    Ok(Linked {
        image,
        layout,
        warnings,
        map,
    })
}

fn failed(errors: Vec<Error>) -> Error {
    Error::Failed {
        count: errors.len(),
        errors,
    }
}

/// `__NAME_LOAD__`, `__NAME_RUN__`, `__NAME_SIZE__` for segments and
/// `__NAME_START__`, `__NAME_SIZE__`, `__NAME_LAST__` for areas with
/// `define = true`, as ld65 defines them.
fn layout_symbols(layout: &Layout, placement: &Placement) -> BTreeMap<String, Global> {
    let mut globals = BTreeMap::new();
    let mut define = |name: String, value: u64| {
        globals.insert(
            name,
            Global {
                value: Some(value as i64),
                origin: Origin::Layout,
                weak: false,
                segment: None,
                size: 0,
            },
        );
    };
    for segment in placement.segments.iter().filter(|s| s.rule.define) {
        let name = &segment.rule.name;
        define(format!("__{name}_LOAD__"), segment.load);
        define(format!("__{name}_RUN__"), segment.run);
        define(format!("__{name}_SIZE__"), segment.size);
    }
    for area in placement.areas.iter().filter(|a| a.area.define) {
        let name = &area.area.name;
        define(format!("__{name}_START__"), area.area.start);
        define(format!("__{name}_SIZE__"), area.area.size);
        define(format!("__{name}_LAST__"), area.used_end);
    }
    let _ = layout;
    globals
}

fn check_asserts(
    objects: &[Object],
    values: &[Vec<Option<i64>>],
    unresolved: &[Vec<bool>],
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
    warnings: &mut Vec<Error>,
) {
    for (object_index, object) in objects.iter().enumerate() {
        for assertion in &object.asserts {
            let place = Place::source(&assertion.file, assertion.line, assertion.column);
            let result = assertion
                .expr
                .evaluate(|index| values[object_index].get(index as usize).copied().flatten());
            match result {
                Ok(0) => {
                    let (src, span) = place.snippet(sources);
                    let (message, at) = (assertion.message.clone(), place.text);
                    match assertion.action {
                        AssertAction::Error => errors.push(Error::AssertFailed {
                            message,
                            at,
                            src,
                            span,
                        }),
                        AssertAction::Warning => warnings.push(Error::AssertWarning {
                            message,
                            at,
                            src,
                            span,
                        }),
                    }
                }
                Ok(_) => {}
                // Already reported as an undefined symbol.
                Err(EvalError::UnresolvedSymbol(index))
                    if unresolved[object_index].get(index as usize) == Some(&true) => {}
                Err(error) => errors.push(Error::AssertInvalid {
                    at: place.text,
                    reason: error.to_string(),
                }),
            }
        }
    }
}

/// " (defined at main.s:12:1)" for a global an object defines, else "".
fn defined_at(objects: &[Object], globals: &BTreeMap<String, Global>, name: &str) -> String {
    match globals.get(name).map(|global| &global.origin) {
        Some(Origin::Object { object, symbol }) => {
            format!(
                " (defined at {})",
                objects[*object].place_of_symbol(*symbol).text
            )
        }
        _ => String::new(),
    }
}

fn hooks(objects: &[Object], globals: &BTreeMap<String, Global>, errors: &mut Vec<Error>) -> Hooks {
    let mut hooks = Hooks::default();
    let address = |name: &str, errors: &mut Vec<Error>| -> Option<u16> {
        let value = globals.get(name)?.value?;
        match u16::try_from(value) {
            Ok(address) => Some(address),
            Err(_) => {
                errors.push(Error::Hook {
                    reason: format!(
                        "{name}{} = {value:#X} is not a 16-bit address",
                        defined_at(objects, globals, name)
                    ),
                });
                None
            }
        }
    };
    for kind in HookKind::ALL {
        let handler = address(kind.handler_symbol(), errors);
        let chain = address(kind.chain_symbol(), errors);
        match (handler, chain) {
            (Some(handler), chain) => hooks.records.push(HookRecord {
                kind,
                handler,
                chain,
            }),
            (None, Some(_)) => errors.push(Error::Hook {
                reason: format!(
                    "{}{} is exported but {} is not: a chain slot needs a handler",
                    kind.chain_symbol(),
                    defined_at(objects, globals, kind.chain_symbol()),
                    kind.handler_symbol()
                ),
            }),
            (None, None) => {}
        }
    }
    hooks
}

fn build_image(
    objects: &[Object],
    placement: &Placement,
    values: &[Vec<Option<i64>>],
    globals: &BTreeMap<String, Global>,
    hooks: Hooks,
) -> Image {
    // Areas, split where the run address stops following the load address.
    let mut areas = Vec::new();
    for placed in &placement.areas {
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

    Image {
        entry: entry as u32,
        flags: objects.iter().fold(0, |flags, object| flags | object.flags),
        areas,
        sections,
        symbols,
        hooks,
    }
}

fn map_data(
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

/// The `R_MOS_*` name of a relocation type, for messages.
pub(crate) fn relocation_name(r_type: u32) -> &'static str {
    mos::relocation_name(r_type).unwrap_or("R_MOS_?")
}

/// Levenshtein distance, for "did you mean" suggestions.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = previous + usize::from(ca != *cb);
            previous = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(previous + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    #[test]
    fn edit_distance() {
        assert_eq!(super::edit_distance("prnt", "print"), 1);
        assert_eq!(super::edit_distance("PUTCH", "PUTHEX"), 3);
        assert_eq!(super::edit_distance("", "abc"), 3);
        assert_eq!(super::edit_distance("same", "same"), 0);
    }
}
