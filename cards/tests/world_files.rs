//! World files a hostile tester wrote (issue 28), one case a file in
//! tests/world_files/ with what must come of it beside it: `# expect:
//! TEXT`, the whole message of the located error (file:line:col), or
//! `# expect: ok`. Never a value taken that the room cannot use: a length
//! of 1e300, a polygon that crosses itself, a point of three numbers, a
//! robot that starts inside a wall.

use std::path::Path;

use cards::Room;

/// The case's expectation and whether it was met.
fn check(path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let expect = text
        .lines()
        .find_map(|line| line.strip_prefix("# expect: "))
        .ok_or("no `# expect:` line")?
        .trim()
        .to_owned();
    let name = path
        .file_name()
        .and_then(|name| name.to_str())
        .ok_or("a file name")?;
    match (Room::load(name, &text), expect.as_str()) {
        (Ok(_), "ok") => Ok(()),
        (Ok(_), _) => Err(format!("taken, expected the error `{expect}`")),
        (Err(error), "ok") => Err(format!("refused: {error}")),
        (Err(error), _) if error.to_string() == expect => Ok(()),
        (Err(error), _) => Err(format!("said `{error}`\n  expected `{expect}`")),
    }
}

#[test]
fn hostile_world_files_are_refused_at_their_place() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/world_files");
    let mut cases: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/world_files")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 15, "the cases are there");
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|path| {
            check(path)
                .err()
                .map(|why| format!("{}: {why}", path.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
