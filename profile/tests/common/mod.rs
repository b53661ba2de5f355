//! The profiler tests' set-up: an extension assembled against the
//! built-in `scorpion.inc` and linked against the reference ROM.

use std::collections::BTreeMap;

/// `source`, as the file `q.s`, assembled and linked as an extension.
pub(crate) fn extension(source: &str) -> linker::Image {
    let files = assembler::MemorySource::new().with("q.s", source);
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&files, std::path::Path::new("q.s"), &options)
        .expect("the handler assembles");
    romlib::link_against_rom("q.s", &assembly.object, "scorpion-ext").expect("the handler links")
}
