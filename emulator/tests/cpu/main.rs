//! The CPU against things nobody here wrote: Klaus Dormann's functional and
//! interrupt test programs (from the `mos6502` crate's package), py65 on
//! random instruction streams and on every decimal-mode operand, and the
//! `isa` table for cycles; plus the interrupt sequences cycle by cycle.

mod cycles;
mod dormann;
mod interrupts;
mod programs;
mod py65;
mod undocumented;

use std::path::PathBuf;
use std::process::Command;

/// True under CI, where a missing reference must fail rather than skip.
pub(crate) fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| value == "true" || value == "1")
}

/// The `tests/assets` directory of the `mos6502` package (a dev-dependency,
/// so cargo has it unpacked), found with `cargo metadata`. `None` after
/// saying why `test` is skipped; panics under CI.
pub(crate) fn mos6502_assets(test: &str) -> Option<PathBuf> {
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let output = Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1"])
        .args(["--manifest-path", manifest])
        .output();
    let found = output.ok().filter(|o| o.status.success()).and_then(|o| {
        let metadata: serde_json::Value = serde_json::from_slice(&o.stdout).ok()?;
        metadata["packages"]
            .as_array()?
            .iter()
            .find(|package| package["name"] == "mos6502")
            .and_then(|package| package["manifest_path"].as_str())
            .map(|path| PathBuf::from(path).with_file_name("tests").join("assets"))
            .filter(|dir| dir.is_dir())
    });
    if found.is_none() {
        assert!(
            !in_ci(),
            "the mos6502 package (a dev-dependency) was not found with `cargo metadata`"
        );
        scorpion_tests::tools::skipped(test, "the mos6502 package's test assets were not found");
    }
    found
}
