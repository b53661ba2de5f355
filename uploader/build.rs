//! Assembles the debug stub (`stub/stub.s`, linked at attach time) and
//! the RAM loader (`loader/loader.s`) with our own assembler
//! when this crate is built, twice: taking its data through the ROM's
//! `CHKCH` (`RING = 0`), and straight from the ROM's receive ring
//! (`RING = 1`, for ROM profiles that export it). The objects are embedded
//! and linked at upload time, at an address the image leaves free,
//! against the ROM profile's services (`--just-symbols`), so one build
//! serves every placement.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets it"));
    #[allow(clippy::print_stdout, reason = "build-script directives go to stdout")]
    {
        println!("cargo:rerun-if-changed=loader");
        println!("cargo:rerun-if-changed=stub");
    }
    assemble(&manifest.join("stub"), "stub.s", &out.join("stub.o"), 0);
    for (object, ring) in [("loader.o", 0), ("loader_ring.o", 1)] {
        assemble(
            &manifest.join("loader"),
            "loader.s",
            &out.join(object),
            ring,
        );
    }
}

/// Assembles `dir/name` with `RING` defined as `ring` into `object`.
fn assemble(dir: &std::path::Path, name: &str, object: &std::path::Path, ring: i64) {
    let text = std::fs::read_to_string(dir.join(name))
        .unwrap_or_else(|error| panic!("cannot read {name}: {error}"));
    {
        let options = assembler::Options {
            defines: vec![("RING".to_owned(), ring)],
            ..assembler::Options::default()
        };
        // Assembled under its bare name, so the object (and its source
        // map) does not depend on where the repository is checked out.
        let assembly = assembler::assemble_str(name, &text, &options).unwrap_or_else(|error| {
            let details: Vec<String> = error
                .diagnostics()
                .iter()
                .map(|diagnostic| format!("{diagnostic:?}"))
                .collect();
            panic!(
                "{name} (RING = {ring}) does not assemble: {error}\n{}",
                details.join("\n")
            )
        });
        std::fs::write(object, assembly.object).expect("OUT_DIR is writable");
    }
}
