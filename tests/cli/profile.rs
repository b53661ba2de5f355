//! `scorpion profile` on the examples' projects: the tables name their
//! routines and commands, and the folded stacks and the flame graph hold
//! them (checked for content, not only for existence).

use std::path::Path;

use crate::{scorpion, transcript};

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// Profiles `examples/NAME` into `out`: the report, the folded stacks,
/// the SVG.
fn profile(name: &str, out: &Path) -> (String, String, String) {
    let folded = out.join(format!("{name}.folded"));
    let svg = out.join(format!("{name}.svg"));
    let output = scorpion(
        &example(name),
        &[
            "profile",
            "--folded",
            folded.to_str().expect("UTF-8"),
            "--flamegraph",
            svg.to_str().expect("UTF-8"),
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    (
        String::from_utf8_lossy(&output.stdout).into_owned(),
        std::fs::read_to_string(&folded).expect("the folded stacks"),
        std::fs::read_to_string(&svg).expect("the flame graph"),
    )
}

#[test]
fn the_adc_extension_profiled_by_routine_command_and_line() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let (report, folded, svg) = profile("adc", out.path());
    // Its transcript sends /2A three times (two channels, one refused)
    // and the ROM's /1X once.
    let row = |key: &str| {
        report
            .lines()
            .find(|line| line.starts_with(key))
            .unwrap_or_else(|| panic!("no `{key}` row in:\n{report}"))
            .to_owned()
    };
    let a = row("/2A ");
    let fields: Vec<&str> = a.split_whitespace().collect();
    assert_eq!(fields[1], "3", "three /2A runs: {a}");
    assert!(a.contains("adc.expect:"), "the worst run's line: {a}");
    assert!(row("/1X ").split_whitespace().nth(1) == Some("1"));
    assert!(
        report.contains("one character at 9600 baud: 1041 cycles"),
        "{report}"
    );
    // The ROM's services the handler calls are routines; IRQ a root.
    for routine in ["PUTCH", "PUTHEX", "IRQ", "main"] {
        assert!(
            report.lines().any(|l| l.starts_with(routine)),
            "no {routine} in:\n{report}"
        );
    }
    // The busy wait on the card's status (`@wait: bit ADC_STATUS`, 15
    // laps a conversion) is the hottest line of adc.s.
    let hot = report
        .lines()
        .find(|line| line.starts_with("adc.s:"))
        .unwrap_or_else(|| panic!("no adc.s line in:\n{report}"));
    assert!(hot.starts_with("adc.s:42 "), "{hot}");
    let runs: u64 = hot
        .split_whitespace()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("runs");
    assert_eq!(runs % 2, 0, "two conversions, the same laps each: {hot}");
    // The stacks: a command's frame under the loop, its calls under it.
    assert!(
        folded.lines().any(|l| l.starts_with("main;/2A0;PUTHEX")),
        "{folded}"
    );
    assert!(folded.lines().any(|l| l.starts_with("IRQ")), "{folded}");
    let total: u64 = folded
        .lines()
        .map(|l| {
            l.rsplit(' ')
                .next()
                .and_then(|n| n.parse::<u64>().ok())
                .expect("a count")
        })
        .sum();
    assert!(
        report.starts_with(&format!("{total} cycles of robot time profiled")),
        "{report}"
    );
    assert!(svg.starts_with("<?xml") && svg.contains("<svg"), "an SVG");
    assert!(
        svg.contains("/2A0") && svg.contains("PUTHEX"),
        "the flame graph names the stacks"
    );
}

#[test]
fn the_patrol_operating_system_profiled() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let (report, folded, svg) = profile("patrol", out.path());
    assert!(report.contains("/2A "), "{report}");
    assert!(folded.contains("main;/2A1"), "{folded}");
    assert!(svg.contains("<svg"));
}

#[test]
fn a_workspace_is_profiled_member_by_member() {
    let output = scorpion(&example(""), &["profile"]);
    assert!(!output.status.success());
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("members run on robots of their own"),
        "{}",
        transcript(&output)
    );
}
