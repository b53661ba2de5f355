//! A test that skips for want of an outside tool says so in `cargo test`'s
//! normal output (no `--nocapture`), and fails instead under `CI=true`.
//! Checked by running this test binary again as a child, as cargo runs it,
//! on a probe test that needs a tool no machine has.

use std::process::Command;

use scorpion_tests::tools;

const PROBE: &str = "SCORPION_SKIP_PROBE";

/// Only does something in the child run: needs a tool that is never there.
#[test]
fn probe_needs_a_missing_tool() {
    if std::env::var_os(PROBE).is_some() {
        assert!(tools::require("scorpion-no-such-tool", "tools_skip::probe").is_none());
    }
}

fn run_probe(ci: Option<&str>) -> (bool, String) {
    let mut child = Command::new(std::env::current_exe().expect("this test binary"));
    child
        .args([
            "--exact",
            "probe_needs_a_missing_tool",
            "--test-threads",
            "1",
        ])
        .env(PROBE, "1")
        .env_remove("CI");
    if let Some(ci) = ci {
        child.env("CI", ci);
    }
    let output = child.output().expect("the test binary runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    (output.status.success(), text)
}

#[test]
fn a_skip_shows_in_the_normal_output_and_fails_in_ci() {
    let (passed, text) = run_probe(None);
    assert!(passed, "{text}");
    assert!(
        text.contains("SKIPPED tools_skip::probe: `scorpion-no-such-tool` is not installed"),
        "the skip is not in cargo test's output:\n{text}"
    );
    let (passed, text) = run_probe(Some("true"));
    assert!(!passed, "a missing tool must fail under CI=true:\n{text}");
    assert!(text.contains("required in CI"), "{text}");
}
