//! Symbol resolution, the stage between placement and relocation: the
//! value of every symbol of every object, the global symbols (the layout's
//! `define = yes` ones, the objects' exports, `--just-symbols` files), and
//! the references nothing defines, each reported with the places that use
//! it and a "did you mean".

use std::collections::{BTreeMap, HashMap};

use crate::error::Error;
use crate::input::{Binding, Definition, Object};
use crate::layout::{Layout, SymbolKind};
use crate::model::{Global, Origin};
use crate::place::Placement;
use crate::source::{Place, SourceProvider};

/// What resolution found.
pub(crate) struct Resolved {
    /// Per object, per symbol: its value (`None` where it has none).
    pub(crate) values: Vec<Vec<Option<i64>>>,
    /// The global symbols by name.
    pub(crate) globals: BTreeMap<String, Global>,
    /// Per object, per symbol: referenced and defined nowhere.
    pub(crate) unresolved: Vec<Vec<bool>>,
}

/// Resolves every symbol of `objects` placed by `placement`; duplicate and
/// undefined symbols go to `errors`. `file_symbols` are the
/// `--just-symbols` files' (value, file name) by name; `link_against_rom`
/// says whether there are any, for the help of an undefined name.
pub(crate) fn resolve(
    objects: &[Object],
    layout: &Layout,
    placement: &Placement,
    file_symbols: &HashMap<&str, (i64, &str)>,
    link_against_rom: bool,
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
) -> Resolved {
    // Values of defined symbols.
    let mut values: Vec<Vec<Option<i64>>> = objects
        .iter()
        .enumerate()
        .map(|(object_index, object)| {
            object
                .symbols
                .iter()
                .map(|symbol| match symbol.definition {
                    Definition::Undefined | Definition::Computed(_) => None,
                    Definition::Absolute(value) => Some(value),
                    Definition::Section(section, offset) => placement
                        .section_run(object_index, section)
                        .map(|run| run as i64 + i64::from(offset)),
                })
                .collect()
        })
        .collect();

    let mut globals = layout_symbols(layout, placement);
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
                        Origin::Layout => format!("layout {}", layout.name),
                        Origin::File(file) => file.clone(),
                    };
                    let second = object.place_of_symbol(symbol_index);
                    let (src, span) = second.snippet(sources);
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

    computed_symbols(
        objects,
        &mut values,
        &mut globals,
        file_symbols,
        sources,
        errors,
    );
    layout_imports(layout, placement, &globals, errors);

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
        let (src, span) = places[0].snippet(sources);
        let candidates = globals
            .keys()
            .map(String::as_str)
            .chain(file_symbols.keys().copied());
        let similar = similar(&name, candidates);
        let help = if let Some(similar) = similar {
            format!("did you mean `{similar}`?")
        } else if name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
            && !link_against_rom
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

    Resolved {
        values,
        globals,
        unresolved,
    }
}

/// Gives the symbols the linker computes (`alias = imported + 1`,
/// exported) their values, in as many rounds as they depend on each other;
/// one that never gets a value is an error at its definition.
fn computed_symbols(
    objects: &[Object],
    values: &mut [Vec<Option<i64>>],
    globals: &mut BTreeMap<String, Global>,
    file_symbols: &HashMap<&str, (i64, &str)>,
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
) {
    let computed: Vec<(usize, usize, usize)> = objects
        .iter()
        .enumerate()
        .flat_map(|(o, object)| {
            object
                .symbols
                .iter()
                .enumerate()
                .filter_map(move |(s, symbol)| match symbol.definition {
                    Definition::Computed(k) => Some((o, s, k)),
                    _ => None,
                })
        })
        .collect();
    if computed.is_empty() {
        return;
    }
    let mut failures: Vec<(usize, usize, String)> = Vec::new();
    loop {
        let mut progress = false;
        failures.clear();
        for &(o, s, k) in &computed {
            if values[o][s].is_some() {
                continue;
            }
            let object = &objects[o];
            let result = object.values[k].evaluate(|index| {
                let index = index as usize;
                values[o].get(index).copied().flatten().or_else(|| {
                    let symbol = object.symbols.get(index)?;
                    if symbol.binding == Binding::Local {
                        return None;
                    }
                    globals
                        .get(&symbol.name)
                        .and_then(|g| g.value)
                        .or_else(|| file_symbols.get(symbol.name.as_str()).map(|(v, _)| *v))
                })
            });
            match result {
                Ok(value) => {
                    values[o][s] = Some(value);
                    let name = &object.symbols[s].name;
                    if let Some(global) = globals.get_mut(name)
                        && matches!(global.origin, Origin::Object { object, symbol } if object == o && symbol == s)
                    {
                        global.value = Some(value);
                    }
                    progress = true;
                }
                Err(isa::objfmt::EvalError::UnresolvedSymbol(index)) => {
                    let missing = object
                        .symbols
                        .get(index as usize)
                        .map_or_else(|| format!("symbol #{index}"), |m| format!("`{}`", m.name));
                    failures.push((o, s, format!("it names {missing}, which has no value")));
                }
                Err(error) => failures.push((o, s, error.to_string())),
            }
        }
        if !progress {
            break;
        }
    }
    for (o, s, reason) in failures {
        let place = objects[o].place_of_symbol(s);
        let (src, span) = place.snippet(sources);
        errors.push(Error::ExpressionInvalid {
            at: format!(
                "{} (the value of `{}`)",
                place.text, objects[o].symbols[s].name
            ),
            reason,
            src,
            span,
        });
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
    for value in &placement.values {
        globals.insert(
            value.name.clone(),
            Global {
                value: Some(value.value),
                origin: Origin::Layout,
                weak: value.weak,
                segment: None,
                size: 0,
            },
        );
    }
    let _ = layout;
    globals
}

/// The layout's imports (`SYMBOLS { name: type = import; }`, a
/// non-empty table's `import`, the Atari format's run and init routines)
/// that no object defines.
fn layout_imports(
    layout: &Layout,
    placement: &Placement,
    globals: &BTreeMap<String, Global>,
    errors: &mut Vec<Error>,
) {
    let symbols = layout
        .config
        .symbols
        .iter()
        .filter(|symbol| symbol.kind == SymbolKind::Import)
        .map(|symbol| (symbol.name.as_str(), symbol.span.clone()));
    let tables = placement
        .tables
        .iter()
        .filter(|placed| !placed.entries.is_empty())
        .filter_map(|placed| {
            let table = &layout.config.tables[placed.table];
            Some((table.import.as_deref()?, table.segment_span.clone()))
        });
    let atari = &layout.config.atari;
    let vectors = atari
        .runad
        .iter()
        .map(|(name, span)| (name.as_str(), span.clone()))
        .chain(
            atari
                .initad
                .iter()
                .map(|(_, name, span)| (name.as_str(), span.clone())),
        );
    for (name, span) in symbols.chain(tables).chain(vectors) {
        let defined = globals
            .get(name)
            .is_some_and(|global| matches!(global.origin, Origin::Object { .. }));
        if !defined {
            let error = layout.value_error(
                format!("the layout imports `{name}`, which no object exports"),
                "export it from one of the objects (`.export`), as the target's start-up code would",
                Some(span),
            );
            errors.push(error);
        }
    }
}

/// The defined name nearest `name` by edit distance, if near enough to be
/// a typo of it (two edits, and no more than half its length).
fn similar<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .map(|candidate| (strsim::levenshtein(candidate, name), candidate))
        .filter(|(distance, _)| *distance <= 2.min(name.len() / 2))
        .min()
        .map(|(_, candidate)| candidate)
}

#[cfg(test)]
mod tests {
    use super::similar;

    #[test]
    fn a_typo_is_near_and_another_name_is_not() {
        let names = ["print", "PUTHEX", "pointer"];
        assert_eq!(similar("prnt", names.into_iter()), Some("print"));
        assert_eq!(similar("PUTCH", names.into_iter()), None, "three edits");
        assert_eq!(
            similar("ab", names.into_iter()),
            None,
            "short names need exact"
        );
        assert_eq!(similar("pointr", names.into_iter()), Some("pointer"));
    }
}
