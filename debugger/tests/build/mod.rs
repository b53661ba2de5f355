//! A handler's source for the debugger's tests: assembled with the
//! built-in `scorpion.inc` and linked against the reference ROM as an
//! extension, as `scorpion build` makes one.

use std::collections::BTreeMap;

/// The extension `source` (shown as `name`), ready to load.
pub(crate) fn extension(name: &str, source: &str) -> linker::Image {
    let files = assembler::MemorySource::new().with(name, source);
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&files, std::path::Path::new(name), &options)
        .expect("the handler assembles");
    romlib::link_against_rom(name, &assembly.object, "scorpion-ext").expect("the handler links")
}
