//! Where ca65 says no, we say no. Every case in
//! `assembler/tests/cases/ca65_refuses/` marks the lines that must fail
//! with `; ca65: <ca65 2.19's first words>` (and a cascade that only ca65
//! reports with `; ca65 only:`). ca65 must refuse exactly the marked lines,
//! and our assembler exactly the `ca65:` ones. The rendered errors are
//! snapshots beside the other assembler cases. (`.incbin`'s search order
//! is checked against ca65 in `tests/cli/search_order.rs`: it depends on
//! the working directory.)

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use scorpion_tests::tools;

fn cases_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assembler/tests/cases/ca65_refuses")
}

/// The lines whose comment starts with `marker`, from 1.
fn marked_lines(text: &str, marker: &str) -> BTreeSet<u32> {
    text.lines()
        .zip(1..)
        .filter(|(line, _)| {
            line.split_once(';').is_some_and(|(code, comment)| {
                !code.trim().is_empty() && comment.trim_start().starts_with(marker)
            })
        })
        .map(|(_, number)| number)
        .collect()
}

/// The lines ca65 reports an error on (`file.s(12): Error: ...`).
fn ca65_error_lines(ca65: &Path, dir: &Path, name: &str) -> BTreeSet<u32> {
    let output = Command::new(ca65)
        .current_dir(dir)
        .args([name, "-o", "/dev/null"])
        .output()
        .expect("ca65 runs");
    String::from_utf8_lossy(&output.stderr)
        .lines()
        .filter(|line| line.contains("): Error:"))
        .filter_map(|line| {
            let open = line.find('(')?;
            let close = line.find(')')?;
            line.get(open + 1..close)?.parse().ok()
        })
        .collect()
}

/// The lines our assembler reports an error on.
fn our_error_lines(path: &Path) -> BTreeSet<u32> {
    match assembler::assemble(&assembler::FsSource, path, &assembler::Options::default()) {
        Ok(_) => BTreeSet::new(),
        Err(error) => error
            .diagnostics()
            .iter()
            .filter(|d| d.severity() == assembler::Severity::Error)
            .filter_map(|d| d.location().map(|l| l.line))
            .collect(),
    }
}

#[test]
fn ca65_and_we_refuse_the_same_lines() {
    let Some(ca65) = tools::require("ca65", "asm_ca65_refuses::same_lines") else {
        return;
    };
    let dir = cases_dir();
    let mut cases = 0;
    for entry in std::fs::read_dir(&dir).expect("the case directory") {
        let path = entry.expect("an entry").path();
        if path.extension().is_none_or(|ext| ext != "s") {
            continue;
        }
        cases += 1;
        let name = path.file_name().expect("a name").to_string_lossy();
        let text = std::fs::read_to_string(&path).expect("a case");
        let both = marked_lines(&text, "ca65:");
        let ca65_only = marked_lines(&text, "ca65 only:");
        assert!(!both.is_empty(), "{name} marks no line `; ca65:`");
        let expected_ca65: BTreeSet<u32> = both.union(&ca65_only).copied().collect();
        assert_eq!(
            ca65_error_lines(&ca65, &dir, &name),
            expected_ca65,
            "{name}: the lines ca65 refuses"
        );
        assert_eq!(our_error_lines(&path), both, "{name}: the lines we refuse");
    }
    assert!(cases >= 3, "only {cases} cases found in {}", dir.display());
}
