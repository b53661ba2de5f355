//! Outside tools that differential tests compare against.
//!
//! The rule (CONTRIBUTING.md): a test that needs an outside tool fails when
//! the tool is missing and `CI=true`; locally it skips, saying so on stderr
//! past the test harness's capture, so that `cargo test` shows it.
//! `.ci/install-test-tools` installs every tool named here.

use std::path::PathBuf;
use std::process::Command;

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| value == "true" || value == "1")
}

fn missing(what: &str, test: &str) {
    assert!(
        !in_ci(),
        "{what} is required in CI but missing; run .ci/install-test-tools"
    );
    skipped(
        test,
        &format!("{what} is not installed (run .ci/install-test-tools)"),
    );
}

/// Says that `test` is skipped and why, where `cargo test` shows it: the
/// test harness captures `eprintln!` of passing tests, so the line goes to
/// the process's stderr directly and appears among the `ok` lines.
pub fn skipped(test: &str, why: &str) {
    use std::io::Write as _;
    let line = format!("SKIPPED {test}: {why}\n");
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}

fn find_on_path(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(program))
        .find(|candidate| candidate.is_file())
}

/// The path of `program` (`"ca65"`, `"64tass"`, `"srec_cat"`...), or `None`
/// after printing why `test` is skipped. Panics when the tool is missing
/// under `CI=true`.
#[must_use]
pub fn require(program: &str, test: &str) -> Option<PathBuf> {
    let found = find_on_path(program);
    if found.is_none() {
        missing(&format!("`{program}`"), test);
    }
    found
}

/// The Python interpreter, if it can `import module` (`"py65"`), or `None`
/// after printing why `test` is skipped. Panics when missing under `CI=true`.
#[must_use]
pub fn require_python_module(module: &str, test: &str) -> Option<PathBuf> {
    let python = find_on_path("python3").or_else(|| find_on_path("python"));
    let usable = python.filter(|python| {
        Command::new(python)
            .args(["-c", &format!("import {module}")])
            .output()
            .is_ok_and(|output| output.status.success())
    });
    if usable.is_none() {
        missing(&format!("the Python module `{module}`"), test);
    }
    usable
}

/// Node.js, if it is on `PATH` and `dir` (a package with a committed
/// `package-lock.json`) has each of `packages` installed in its
/// `node_modules` (`npm ci` there), or `None` after printing why `test` is
/// skipped. Panics when either is missing under `CI=true`.
#[must_use]
pub fn require_npm_packages(
    dir: &std::path::Path,
    packages: &[&str],
    test: &str,
) -> Option<PathBuf> {
    let node = require("node", test)?;
    let absent: Vec<&str> = packages
        .iter()
        .copied()
        .filter(|package| {
            !dir.join("node_modules")
                .join(package)
                .join("package.json")
                .is_file()
        })
        .collect();
    if absent.is_empty() {
        Some(node)
    } else {
        missing(
            &format!(
                "the node_modules of {} (`npm ci` there; wanted: {})",
                dir.display(),
                absent.join(", ")
            ),
            test,
        );
        None
    }
}
