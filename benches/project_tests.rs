//! `scorpion test`'s speed against the robot time its transcripts stand
//! for, on the example projects as CI runs them: each project alone (a
//! fresh process each: build, snapshots, transcripts), and the whole suite
//! as the examples' workspace runs it (`scorpion test` in `examples/`: one
//! process for the four).
//!
//! `cargo bench -p scorpion --bench project_tests` prints each project's
//! robot time and wall time and the suite's ratios. Goals: the suite's
//! transcripts at least 1000 times faster than the real robot, and the
//! whole suite under a second. "Transcripts" is the runner's own time for
//! them, robots set up and images loaded; "whole run" is the process from
//! start to exit, building and snapshots included, for which the robot has
//! no counterpart (it is shown against the same robot time all the same).
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const ROUNDS: usize = 7;

/// Robot seconds and the runner's wall seconds that the run's
/// `transcripts:` line reports.
fn transcript_seconds(stdout: &str) -> (f64, f64) {
    let words: Vec<&str> = stdout
        .lines()
        .find_map(|line| line.strip_prefix("transcripts: "))
        .map(|rest| rest.split_whitespace().collect())
        .unwrap_or_default();
    let number = |index: usize| words.get(index).and_then(|w| w.parse().ok()).unwrap_or(0.0);
    // "R s of robot time in W s (...)"
    (number(0), number(6))
}

/// Best of [`ROUNDS`] runs of `scorpion test --timing` in `dir`: (robot
/// seconds, transcripts' seconds, whole process seconds).
fn measure(dir: &Path) -> (f64, f64, f64) {
    let mut best = (0.0, f64::MAX, f64::MAX);
    for _ in 0..ROUNDS {
        let start = Instant::now();
        let output = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["test", "--timing"])
            .current_dir(dir)
            .env_remove("SCORPION_PORT")
            .output()
            .expect("scorpion runs");
        let wall = start.elapsed().as_secs_f64();
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{}: {stdout}", dir.display());
        let (robot, transcripts) = transcript_seconds(&stdout);
        assert!(robot > 0.0, "no transcripts: line in {stdout}");
        best = (robot, best.1.min(transcripts), best.2.min(wall));
    }
    best
}

fn row(name: &str, (robot, transcripts, wall): (f64, f64, f64)) {
    println!(
        "  {name:<12} {robot:>10.3} s {transcripts:>12.6} s {:>9.0} {wall:>9.4} s {:>9.0}",
        robot / transcripts,
        robot / wall
    );
}

fn main() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    println!("scorpion test on the example projects (best of {ROUNDS})");
    println!(
        "  {:<12} {:>12} {:>14} {:>9} {:>11} {:>9}",
        "project", "robot time", "transcripts", "x robot", "whole run", "x robot"
    );
    for project in ["rangefinder", "adc", "checksum", "patrol"] {
        row(project, measure(&examples.join(project)));
    }
    let suite = measure(&examples);
    row("suite", suite);
    let (robot, transcripts, wall) = suite;
    println!(
        "  (each project: a process of its own; suite: the examples' workspace, one process for all four)"
    );
    let verdict = |met: bool| if met { "met" } else { "MISSED" };
    println!(
        "  goals: the suite's transcripts 1000x the robot ({:.0}x: {}), the whole suite under a second ({wall:.4} s: {}); whole run {:.0}x the robot (for information)",
        robot / transcripts,
        verdict(robot / transcripts >= 1000.0),
        verdict(wall < 1.0),
        robot / wall
    );
}
