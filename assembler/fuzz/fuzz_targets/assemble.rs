//! Fuzz target: any bytes as the main source (with a second file to
//! include and a built-in include), listing on. The assembler must return
//! an object or diagnostics, never panic, hang or exhaust memory.

#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let source = assembler::MemorySource::new()
        .with("main.s", data.to_vec())
        .with(
            "inc.s",
            b"inc_value = 1\n.macro inc_macro p\n lda #p\n.endmacro\n".to_vec(),
        );
    let options = assembler::Options {
        listing: true,
        max_errors: 20,
        // A lower line budget than the default keeps each run fast under
        // the sanitizer; the limit itself is what is being exercised.
        max_lines: 200_000,
        builtin_includes: [("builtin.inc".to_string(), b"BUILTIN = 2\n".to_vec())]
            .into_iter()
            .collect(),
        ..assembler::Options::default()
    };
    match assembler::assemble(&source, Path::new("main.s"), &options) {
        Ok(assembly) => assert!(assembly.object.starts_with(b"\x7FELF")),
        Err(error) => {
            for diagnostic in error.diagnostics() {
                let _ = diagnostic.summary();
            }
        }
    }
});
