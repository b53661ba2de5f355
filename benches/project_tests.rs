//! `scorpion test`'s speed against the robot time its transcripts stand
//! for: the four example projects, each a fresh process (build, snapshots,
//! transcripts on the virtual Scorpion), as CI runs them.
//!
//! `cargo bench -p scorpion --bench project_tests` prints each project's
//! robot time and wall time and the suite's ratio. Goals: the whole suite
//! at least 1000 times faster than the real robot, and under a second.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const ROUNDS: usize = 5;

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

fn main() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let projects = ["rangefinder", "adc", "checksum", "patrol"];
    let mut best = vec![f64::MAX; projects.len()];
    let mut robot = vec![0.0; projects.len()];
    let mut runner = vec![f64::MAX; projects.len()];
    for _ in 0..ROUNDS {
        for (index, project) in projects.iter().enumerate() {
            let start = Instant::now();
            let output = Command::new(env!("CARGO_BIN_EXE_scorpion"))
                .args(["test", "--timing"])
                .current_dir(examples.join(project))
                .env_remove("SCORPION_PORT")
                .output()
                .expect("scorpion runs");
            let wall = start.elapsed().as_secs_f64();
            let stdout = String::from_utf8_lossy(&output.stdout);
            assert!(output.status.success(), "{project}: {stdout}");
            best[index] = best[index].min(wall);
            let (robot_time, transcripts) = transcript_seconds(&stdout);
            robot[index] = robot_time;
            runner[index] = runner[index].min(transcripts);
        }
    }
    println!("scorpion test on the example projects (best of {ROUNDS}, a fresh process each)");
    println!(
        "  {:<12} {:>12} {:>14} {:>9} {:>11} {:>9}",
        "project", "robot time", "transcripts", "x robot", "whole run", "x robot"
    );
    for (((project, wall), robot), runner) in projects.iter().zip(&best).zip(&robot).zip(&runner) {
        println!(
            "  {project:<12} {robot:>10.3} s {runner:>12.6} s {:>9.0} {wall:>9.4} s {:>9.0}",
            robot / runner,
            robot / wall
        );
    }
    let wall: f64 = best.iter().sum();
    let runner: f64 = runner.iter().sum();
    let robot: f64 = robot.iter().sum();
    let ratio = robot / wall;
    let runner_ratio = robot / runner;
    println!(
        "  {:<12} {robot:>10.3} s {runner:>12.6} s {runner_ratio:>9.0} {wall:>9.4} s {ratio:>9.0}",
        "suite"
    );
    println!(
        "  (transcripts: the runner's own time for them, robots set up and images loaded; whole run: a process per project: start, build, snapshots, transcripts)"
    );
    println!(
        "  goals: 1000x the robot (transcripts {runner_ratio:.0}x: {}; whole runs {ratio:.0}x: {}), under a second ({wall:.3} s: {})",
        if runner_ratio >= 1000.0 {
            "met"
        } else {
            "MISSED"
        },
        if ratio >= 1000.0 { "met" } else { "MISSED" },
        if wall < 1.0 { "met" } else { "MISSED" }
    );
}
