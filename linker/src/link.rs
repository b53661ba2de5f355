//! The link: read, place, resolve, relocate, check, and build the image.

use std::collections::{BTreeMap, HashMap};

use isa::objfmt::HookKind;

use crate::checks::{check_asserts, defined_at, hooks};
use crate::emit::{build_image, map_data};
use crate::error::Error;
use crate::image::Image;
use crate::input::{self, Binding, Definition, Input, Object};
use crate::layout::{Layout, RomSymbols, Target};
use crate::model::{Global, Linked};
use crate::output::OutputFile;
use crate::place;
use crate::resolve::{Resolved, resolve};
use crate::source::SourceProvider;

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

/// Links one object (`name` for messages) for `target` against one symbol
/// file, with no sources to quote: a ROM profile's extension, the RAM
/// loader against a profile's services.
///
/// # Errors
/// As [`link`].
pub fn link_one(
    name: &str,
    object: &[u8],
    target: &Target,
    symbols: SymbolFile<'_>,
) -> Result<Linked, Error> {
    link(
        &[Input {
            name,
            bytes: object,
        }],
        &LinkOptions {
            target,
            just_symbols: &[symbols],
            sources: &crate::NoSources,
        },
    )
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

    let (rom, file_symbols) = known_values(&objects, options.just_symbols);
    let mut layout = options.target.resolve(&rom)?;

    let mut warnings = Vec::new();
    let placement = place::place(&objects, &layout, &rom, &mut errors, &mut warnings);
    // Areas whose bounds are expressions have them now.
    for (area, placed) in layout.areas.iter_mut().zip(&placement.areas) {
        area.clone_from(&placed.area);
    }

    let Resolved {
        values,
        globals,
        unresolved,
    } = resolve(
        &objects,
        &layout,
        &placement,
        &file_symbols,
        !options.just_symbols.is_empty(),
        options.sources,
        &mut errors,
    );

    let mut placement = placement;
    crate::relocate::apply(
        &objects,
        &values,
        &mut placement.segments,
        options.sources,
        &mut errors,
    );

    crate::relocate::apply_fields(
        &objects,
        &values,
        &unresolved,
        &mut placement.segments,
        options.sources,
        &mut errors,
    );
    fill_tables(&mut placement, &values);

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

    let (image, mut main_file, mut other_files) =
        build_image(&objects, &layout, &placement, &values, &globals, hooks);
    for file in std::iter::once(&mut main_file).chain(&mut other_files) {
        atari_vectors(file, &layout, &globals);
    }
    if let Err(Error::BadImage { reason, .. }) = image.check_hooks("") {
        return Err(failed(vec![hook_error(&reason, &objects, &globals)]));
    }
    let map = map_data(&objects, &layout, &placement, &globals);
    Ok(Linked {
        image,
        layout,
        warnings,
        other_files,
        main_file,
        map,
    })
}

/// The Atari format's RUNAD and INITAD addresses for `file`, from the
/// symbols the layout names (each checked defined by resolution).
fn atari_vectors(file: &mut OutputFile, layout: &Layout, globals: &BTreeMap<String, Global>) {
    let value = |name: &str| globals.get(name).and_then(|g| g.value).map(|v| v as u16);
    let options = &layout.config.atari;
    file.run = options.runad.as_ref().and_then(|(name, _)| value(name));
    file.inits = options
        .initad
        .iter()
        .filter_map(|(area, name, _)| Some((area.clone(), value(name)?)))
        .collect();
}

/// Writes each table's routine addresses into its segment, low byte first.
fn fill_tables(placement: &mut place::Placement, values: &[Vec<Option<i64>>]) {
    for table in &placement.tables {
        let Some(segment) = table.segment else {
            continue;
        };
        let segment = &mut placement.segments[segment];
        for (index, (object, symbol)) in table.entries.iter().enumerate() {
            let at = (table.offset + 2 * index as u64) as usize;
            let value = values[*object][*symbol].unwrap_or(0) as u16;
            if let Some(slot) = segment.bytes.get_mut(at..at + 2) {
                slot.copy_from_slice(&value.to_le_bytes());
            }
        }
    }
}

/// What the layout may refer to before anything is placed (the ROM's
/// user-memory bounds, absolute exports), and the `--just-symbols` files'
/// symbols with the file each comes from.
fn known_values<'a>(
    objects: &[Object],
    just_symbols: &'a [SymbolFile<'a>],
) -> (RomSymbols, HashMap<&'a str, (i64, &'a str)>) {
    let mut rom = RomSymbols::default();
    let mut file_symbols: HashMap<&str, (i64, &str)> = HashMap::new();
    for file in just_symbols {
        for symbol in file.image.symbols.iter().filter(|s| s.global) {
            rom.insert(&symbol.name, i64::from(symbol.value));
            file_symbols
                .entry(symbol.name.as_str())
                .or_insert((i64::from(symbol.value), file.name));
        }
    }
    for object in objects {
        for symbol in &object.symbols {
            if let (Binding::Global, Definition::Absolute(value)) =
                (symbol.binding, symbol.definition)
            {
                rom.insert(&symbol.name, value);
            }
        }
    }
    (rom, file_symbols)
}

/// A hook record the image cannot keep, naming where the hook symbols are
/// defined so the user finds them.
fn hook_error(reason: &str, objects: &[Object], globals: &BTreeMap<String, Global>) -> Error {
    let places: Vec<String> = HookKind::ALL
        .iter()
        .flat_map(|kind| [kind.handler_symbol(), kind.chain_symbol()])
        .map(|name| (name, defined_at(objects, globals, name)))
        .filter(|(_, place)| !place.is_empty())
        .map(|(name, place)| format!("{name}{place}"))
        .collect();
    Error::Hook {
        reason: format!("{reason}; {}", places.join(", ")),
    }
}

fn failed(errors: Vec<Error>) -> Error {
    Error::Failed {
        count: errors.len(),
        errors,
    }
}
