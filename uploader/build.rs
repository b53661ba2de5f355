//! Assembles the RAM loader (`loader/loader.s`) with our own assembler
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
    }
    let name = "loader.s";
    let text = std::fs::read_to_string(manifest.join("loader").join(name))
        .unwrap_or_else(|error| panic!("cannot read loader/{name}: {error}"));
    for (object, ring) in [("loader.o", 0), ("loader_ring.o", 1)] {
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
                "loader/{name} (RING = {ring}) does not assemble: {error}\n{}",
                details.join("\n")
            )
        });
        std::fs::write(out.join(object), assembly.object).expect("OUT_DIR is writable");
    }
}
