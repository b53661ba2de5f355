//! The robot's speed with profiling on and with coverage on, each as a
//! ratio to the plain run (the virtual Scorpion on its own), in the same
//! process, taking turns: the patrol operating system cruising (the
//! motors' 1 kHz tick interrupting, its loop passing through `HOOK_LOOP`)
//! with a host asking `/1P` every 10 ms, a minute of robot time per run.
//!
//! - profiling: the profiler's hooks on every run, then the profile made
//!   (routines, stacks, the flame graph's folded text);
//! - coverage: the counts without the call stack (as `scorpion test
//!   --coverage` counts), then the line and branch coverage of the
//!   patrol source and its LCOV text.
//!
//! Goal for both: at least 0.5 of the plain run.
//!
//! Times are this thread's time on a CPU (the scheduler's account), so
//! that other work on a shared machine does not count.
//!
//! `cargo bench -p scorpion-profile`.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

#[path = "../../debugger/benches/common/clock.rs"]
mod clock;

use std::collections::BTreeMap;
use std::path::Path;

use clock::Clock;
use romlib::VirtualScorpion;
use scorpion_profile::coverage::Coverage;
use scorpion_profile::lines::LineTable;
use scorpion_profile::{Profiler, Recorder};

/// Long enough for the scheduler's account, which advances by ticks.
const ROBOT_CYCLES: u64 = 60_000_000;
/// The host asks every 10 ms of robot time.
const ASK_EVERY: u64 = 10_000;
const TRIES: usize = 3;

fn patrol_source() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/patrol/patrol.s")
}

fn patrol() -> linker::Image {
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&assembler::FsSource, &patrol_source(), &options)
        .expect("patrol assembles");
    romlib::link_against_rom("patrol.s", &assembly.object, "scorpion-os").expect("patrol links")
}

fn robot(image: &linker::Image) -> VirtualScorpion {
    let mut robot = VirtualScorpion::new();
    robot.load_image(image).expect("patrol loads");
    robot.send(b"/2A1");
    robot
}

/// The host's minute: `/1P` every [`ASK_EVERY`] cycles.
fn minute(robot: &mut VirtualScorpion) -> u64 {
    let start = robot.cycles();
    while robot.cycles() - start < ROBOT_CYCLES {
        robot.receive();
        robot.send(b"/1P");
        robot.run_for(ASK_EVERY).expect("runs");
    }
    robot.cycles() - start
}

/// Robot cycles per second of one run.
fn rate(run: impl FnOnce() -> u64) -> f64 {
    let started = Clock::start();
    let cycles = run();
    #[allow(clippy::cast_precision_loss, reason = "a rate")]
    let rate = cycles as f64 / started.elapsed().as_secs_f64();
    rate
}

fn main() {
    let image = patrol();
    let read = |file: &str| std::fs::read_to_string(patrol_source().with_file_name(file)).ok();
    let mut best = [0.0f64; 3];
    let mut folded = 0;
    let mut lines = (0, 0);
    for _ in 0..TRIES {
        best[0] = best[0].max(rate(|| {
            let mut r = robot(&image);
            minute(&mut r)
        }));
        best[1] = best[1].max(rate(|| {
            let mut r = robot(&image);
            let recorder = Recorder::attach(&mut r);
            let cycles = minute(&mut r);
            let profile = recorder.finish(&mut r);
            folded = profile.folded().len();
            cycles
        }));
        best[2] = best[2].max(rate(|| {
            let mut r = robot(&image);
            // As `scorpion test --coverage` counts: no call stack.
            let profiler = Profiler::for_robot(&r).coverage_only();
            let recorder = Recorder::attach_profiler(&mut r, profiler);
            let cycles = minute(&mut r);
            let profile = recorder.finish(&mut r);
            let table = LineTable::new(&[&image], &read);
            let coverage = Coverage::new(&profile, &table, &|_| true);
            lines = coverage.line_counts();
            let _ = coverage.lcov("patrol", &|file| file.to_owned());
            cycles
        }));
    }
    println!("patrol cruising, /1P every 10 ms, a minute of robot time, best of {TRIES}:");
    println!(
        "  plain run (the virtual Scorpion alone): {:>8.1} robot seconds per second",
        best[0] / 1e6
    );
    for (index, name) in [(1, "profiling on"), (2, "coverage on")] {
        let ratio = best[index] / best[0];
        println!(
            "  {name:<38} {:>8.1} robot seconds per second, {ratio:.2} of the plain run (goal >= 0.5){}",
            best[index] / 1e6,
            if ratio >= 0.5 { "" } else { "  BELOW GOAL" }
        );
    }
    println!(
        "  (profile's folded stacks: {folded} bytes; patrol.s lines run: {} of {})",
        lines.1, lines.0
    );
}
