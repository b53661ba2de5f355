//! The link: read, place, resolve, relocate, check, and build the image.

use std::collections::{BTreeMap, HashMap};

use isa::elf as mos;
use isa::objfmt::HookKind;

use crate::checks::{check_asserts, defined_at, hooks};
use crate::emit::{build_image, map_data};
use crate::error::Error;
use crate::image::Image;
use crate::input::{self, Binding, Definition, Input};
use crate::layout::{Layout, RomSymbols, Target};
use crate::map::MapData;
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
pub(crate) enum Origin {
    Object { object: usize, symbol: usize },
    Layout,
    File(String),
}

#[derive(Debug, Clone)]
pub(crate) struct Global {
    /// `None` when its section could not be placed (already an error).
    pub(crate) value: Option<i64>,
    pub(crate) origin: Origin,
    pub(crate) weak: bool,
    /// The segment it lies in.
    pub(crate) segment: Option<usize>,
    pub(crate) size: u32,
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
