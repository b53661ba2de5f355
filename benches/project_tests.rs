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

/// Robot seconds the run's `transcripts:` line reports.
fn robot_seconds(stdout: &str) -> f64 {
    stdout
        .lines()
        .find_map(|line| line.strip_prefix("transcripts: "))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|number| number.parse().ok())
        .unwrap_or(0.0)
}

fn main() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let projects = ["rangefinder", "adc", "checksum", "patrol"];
    let mut best = vec![f64::MAX; projects.len()];
    let mut robot = vec![0.0; projects.len()];
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
            robot[index] = robot_seconds(&stdout);
        }
    }
    println!("scorpion test on the example projects (best of {ROUNDS}, a fresh process each)");
    println!(
        "  {:<12} {:>12} {:>10} {:>10}",
        "project", "robot time", "wall", "x robot"
    );
    for ((project, wall), robot) in projects.iter().zip(&best).zip(&robot) {
        println!(
            "  {project:<12} {robot:>10.3} s {wall:>8.3} s {:>10.0}",
            robot / wall
        );
    }
    let wall: f64 = best.iter().sum();
    let robot: f64 = robot.iter().sum();
    let ratio = robot / wall;
    println!(
        "  {:<12} {robot:>10.3} s {wall:>8.3} s {ratio:>10.0}",
        "suite"
    );
    println!(
        "  goals: 1000x the robot ({ratio:.0}x: {}), under a second ({wall:.3} s: {})",
        if ratio >= 1000.0 { "met" } else { "MISSED" },
        if wall < 1.0 { "met" } else { "MISSED" }
    );
}
