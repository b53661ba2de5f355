//! Issue 23, items 13 and 14: project files the toolchain must refuse, one
//! case a file in `tests/refused/`, each with its expected message (and
//! the line and column it names) on its first line, `# expect: ...`.
//! Image names become paths (`target/scorpion/NAME.elf`, snapshots), so a
//! name that leaves the directory, is empty or repeats is refused; so is
//! an image without sources, and a define the assembler would truncate.

use std::path::Path;

use scorpion_project::{Error, Project};

#[test]
fn every_refused_case_is_refused_at_its_place() {
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/refused");
    let mut entries: Vec<_> = std::fs::read_dir(&cases)
        .expect("the cases")
        .map(|e| e.expect("an entry").path())
        .collect();
    entries.sort();
    assert!(entries.len() >= 8, "{entries:?}");
    for case in entries {
        let text = std::fs::read_to_string(&case).expect("the case");
        let expected = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .expect("the expectation on the first line");
        let dir = tempfile::tempdir().expect("a directory");
        std::fs::write(dir.path().join("Scorpion.toml"), &text).expect("write");
        match Project::load(dir.path()) {
            Ok(project) => panic!("{}: accepted: {:?}", case.display(), project.file),
            Err(Error::Located(located)) => {
                let said = format!("{}:{}: {}", located.line, located.column, located.message);
                assert!(
                    said.starts_with(expected),
                    "{}: said `{said}`, expected `{expected}`",
                    case.display()
                );
            }
            Err(other) => panic!("{}: not located: {other}", case.display()),
        }
    }
}
