//! Helpers shared by the linker's integration tests.

use linker::{Error, Image, Input, LinkOptions, Linked, MemorySources, SymbolFile, Target};

/// Links named objects with `target`, no symbol files, sources from `sources`.
pub(crate) fn link_with(
    objects: &[(&str, Vec<u8>)],
    target: &Target,
    just_symbols: &[SymbolFile<'_>],
    sources: &MemorySources,
) -> Result<Linked, Error> {
    let inputs: Vec<Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| Input { name, bytes })
        .collect();
    linker::link(
        &inputs,
        &LinkOptions {
            target,
            just_symbols,
            sources,
        },
    )
}

/// Links with the flat target at `start`.
pub(crate) fn link_flat(objects: &[(&str, Vec<u8>)], start: u64) -> Result<Linked, Error> {
    let target = Target::builtin("flat", Some(start)).expect("flat is a target");
    link_with(objects, &target, &[], &MemorySources::default())
}

pub(crate) use scorpion_tests::render;

/// A ROM image exporting the user-area bounds, as the reference ROM does.
pub(crate) fn fake_rom(extra: &[(&str, u32)]) -> Image {
    // `extra` comes first, so it can override a bound (the first wins).
    let mut symbols = extra.to_vec();
    symbols.extend_from_slice(&[
        ("USER_ZP_START", 0x80),
        ("USER_ZP_END", 0xFF),
        ("USER_RAM_START", 0x0400),
        ("USER_RAM_END", 0x0FFF),
    ]);
    Image {
        symbols: symbols
            .into_iter()
            .map(|(name, value)| linker::ImageSymbol {
                name: name.to_owned(),
                value,
                size: 0,
                global: true,
                section: None,
            })
            .collect(),
        ..Image::default()
    }
}
