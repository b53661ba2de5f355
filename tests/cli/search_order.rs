//! `.incbin` and `.include` search in ca65's order: a binary file first
//! where the name stands (the working directory), then beside the
//! including file, then `--bin-include-dir`; an include beside the
//! including file, then `-I`, never the working directory. Checked with
//! files of the same name and different bytes, ca65 + ld65 beside, each
//! run in the same working directory.

use std::path::Path;
use std::process::Command;

use scorpion_tests::tools;

use crate::scorpion;

/// `src/a.s` includes `data.bin` and `defs.inc`; `data.bin` and `defs.inc`
/// exist both in the working directory and beside `src/a.s`, with other
/// bytes, and `bin/data.bin` is there for `--bin-include-dir`.
fn search_tree(dir: &Path, with_cwd_copies: bool) {
    std::fs::create_dir_all(dir.join("src")).expect("mkdir");
    std::fs::create_dir_all(dir.join("bin")).expect("mkdir");
    std::fs::write(
        dir.join("src/a.s"),
        ".include \"defs.inc\"\n.byte VALUE\n.incbin \"data.bin\"\n",
    )
    .expect("write");
    std::fs::write(dir.join("src/defs.inc"), "VALUE = $53\n").expect("write");
    std::fs::write(dir.join("src/data.bin"), b"S").expect("write");
    std::fs::write(dir.join("bin/data.bin"), b"B").expect("write");
    if with_cwd_copies {
        std::fs::write(dir.join("defs.inc"), "VALUE = $43\n").expect("write");
        std::fs::write(dir.join("data.bin"), b"C").expect("write");
    }
}

fn ca65_bytes(ca65: &Path, ld65: &Path, dir: &Path, extra: &[&str]) -> Vec<u8> {
    let status = Command::new(ca65)
        .current_dir(dir)
        .args(extra)
        .args(["src/a.s", "-o", "a.o"])
        .status()
        .expect("ca65 runs");
    assert!(status.success(), "ca65 assembles src/a.s");
    let status = Command::new(ld65)
        .current_dir(dir)
        .args(["-t", "none", "-o", "a.bin", "a.o"])
        .status()
        .expect("ld65 runs");
    assert!(status.success(), "ld65 links a.o");
    std::fs::read(dir.join("a.bin")).expect("the binary")
}

/// Our bytes for the same tree, through the `scorpion` binary run in `dir`
/// (the working directory is part of the search).
fn our_bytes(dir: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec!["build", "src/a.s", "-o", "ours.bin", "--target", "flat"];
    args.extend(["--start", "$0800", "--format", "bin"]);
    args.extend(extra);
    let output = scorpion(dir, &args);
    assert!(
        output.status.success(),
        "scorpion build: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(dir.join("ours.bin")).expect("our binary")
}

#[test]
fn incbin_and_include_search_in_ca65s_order() {
    let (Some(ca65), Some(ld65)) = (
        tools::require("ca65", "cli::search_order"),
        tools::require("ld65", "cli::search_order"),
    ) else {
        return;
    };
    for (with_cwd_copies, extra, expected) in [
        // The working directory's data.bin; the includer's defs.inc.
        (true, &[][..], b"SC".to_vec()),
        // No data.bin in the working directory: the includer's.
        (false, &[][..], b"SS".to_vec()),
        // The includer's data.bin comes before --bin-include-dir.
        (false, &["--bin-include-dir", "bin"][..], b"SS".to_vec()),
    ] {
        let dir = tempfile::tempdir().expect("a temporary directory");
        search_tree(dir.path(), with_cwd_copies);
        let reference = ca65_bytes(&ca65, &ld65, dir.path(), extra);
        assert_eq!(reference, expected, "ca65 + ld65, {extra:?}");
        assert_eq!(our_bytes(dir.path(), extra), reference, "ours, {extra:?}");
    }
    // Only --bin-include-dir has it.
    let dir = tempfile::tempdir().expect("a temporary directory");
    search_tree(dir.path(), false);
    std::fs::remove_file(dir.path().join("src/data.bin")).expect("rm");
    let extra = ["--bin-include-dir", "bin"];
    let reference = ca65_bytes(&ca65, &ld65, dir.path(), &extra);
    assert_eq!(reference, b"SB");
    assert_eq!(our_bytes(dir.path(), &extra), reference);
}
