//! The robot's speed with the debugger attached, as a ratio to the plain
//! run (the virtual Scorpion on its own), in the same process, taking
//! turns: the patrol operating system cruising (the motors' 1 kHz tick
//! interrupting, its loop passing through `HOOK_LOOP`), a minute of
//! robot time per run.
//!
//! - attached, history and checkpoints on, nothing set;
//! - three breakpoints set (never hit): goal at least 0.9 of the plain run;
//! - a watchpoint on a card's registers (never touched): goal 0.8;
//! - a step back after a minute and after an hour of robot time (a re-run
//!   from the newest checkpoint before the target): goal at most 20 ms;
//! - the memory the session holds after the hour (checkpoints, history,
//!   the robot), counted by this bench's allocator.
//!
//! Times are this thread's time on a CPU (the scheduler's account), so
//! that other work on a shared machine does not count.
//!
//! `cargo bench -p debugger`.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
#![allow(
    unsafe_code,
    reason = "a counting allocator: GlobalAlloc is an unsafe trait; it only forwards to System"
)]

#[path = "common/clock.rs"]
mod clock;

use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use clock::Clock;
use debugger::{Breakpoint, Debugger, Watch, WatchKind};
use romlib::VirtualScorpion;

/// Long enough for the scheduler's account, which advances by ticks.
const ROBOT_CYCLES: u64 = 60_000_000;
const TRIES: usize = 3;
/// A second of robot time (the CPU runs at 1 MHz).
const SECOND: u64 = 1_000_000;
/// Step backs timed after each session.
const STEPS_BACK: usize = 20;

/// The system allocator, counting the bytes live.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to `System` unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(new_size, Ordering::Relaxed);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn patrol() -> linker::Image {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/patrol/patrol.s");
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly =
        assembler::assemble(&assembler::FsSource, &source, &options).expect("patrol assembles");
    romlib::link_against_rom("patrol.s", &assembly.object, "scorpion-os").expect("patrol links")
}

fn robot(image: &linker::Image) -> VirtualScorpion {
    let mut robot = VirtualScorpion::new();
    robot.load_image(image).expect("patrol loads");
    robot
}

/// A debugger on the patrol robot, cruising.
fn debugger(image: &linker::Image, setup: impl Fn(&mut Debugger)) -> Debugger {
    let loaded = image.clone();
    let make = Box::new(move || Ok(robot(&loaded)));
    let mut d = Debugger::new(make, std::slice::from_ref(image)).expect("the robot builds");
    setup(&mut d);
    d.send(b"/2A1");
    d
}

/// Robot cycles per second of one run.
fn rate(run: impl FnOnce() -> u64) -> f64 {
    let started = Clock::start();
    let cycles = run();
    #[allow(clippy::cast_precision_loss, reason = "a rate")]
    let rate = cycles as f64 / started.elapsed().as_secs_f64();
    rate
}

/// A session run for `robot_time` cycles, then stepped back one
/// instruction at a time: the mean step (the scheduler's account is too
/// coarse for one) and the slowest by the wall clock, the host time the
/// run took, and the bytes the session holds.
fn steps_back(
    image: &linker::Image,
    robot_time: u64,
) -> (Duration, Duration, Duration, usize, usize) {
    let before = LIVE.load(Ordering::Relaxed);
    let mut d = debugger(image, |_| {});
    let started = Clock::start();
    d.run(robot_time).expect("runs");
    let ran = started.elapsed();
    let held = LIVE.load(Ordering::Relaxed).saturating_sub(before);
    let checkpoints = d.checkpoints();
    let all = Clock::start();
    let slowest = (0..STEPS_BACK)
        .map(|_| {
            let started = Instant::now();
            d.back(1).expect("goes back");
            started.elapsed()
        })
        .max()
        .unwrap_or_default();
    #[allow(clippy::cast_possible_truncation, reason = "a small count")]
    let mean = all.elapsed() / STEPS_BACK as u32;
    (mean, slowest, ran, held, checkpoints)
}

fn main() {
    let image = patrol();
    let names = [
        "plain run (the virtual Scorpion alone)",
        "attached, history on, nothing set",
        "three breakpoints (never hit)",
        "a watchpoint on $8000-$8003 (never hit)",
    ];
    let goals = [None, None, Some(0.9), Some(0.8)];
    let mut best = [0.0f64; 4];
    for _ in 0..TRIES {
        best[0] = best[0].max(rate(|| {
            let mut r = robot(&image);
            r.send(b"/2A1");
            let start = r.cycles();
            r.run_for(ROBOT_CYCLES).expect("runs");
            r.cycles() - start
        }));
        best[1] = best[1].max(rate(|| {
            let mut d = debugger(&image, |_| {});
            d.run(ROBOT_CYCLES).expect("runs").cycles
        }));
        best[2] = best[2].max(rate(|| {
            let mut d = debugger(&image, |d| {
                for address in [0x0300, 0x0301, 0x0302] {
                    d.add_breakpoint(Breakpoint::At(address));
                }
            });
            d.run(ROBOT_CYCLES).expect("runs").cycles
        }));
        best[3] = best[3].max(rate(|| {
            let mut d = debugger(&image, |d| {
                d.add_watch(Watch {
                    start: 0x8000,
                    end: 0x8003,
                    kind: WatchKind::Access,
                });
            });
            d.run(ROBOT_CYCLES).expect("runs").cycles
        }));
    }
    println!("the patrol OS cruising, {ROBOT_CYCLES} robot cycles a run, best of {TRIES}");
    for ((name, speed), goal) in names.iter().zip(best).zip(goals) {
        let ratio = speed / best[0];
        let verdict = match goal {
            Some(goal) if ratio >= goal => format!("  (goal {goal}: met)"),
            Some(goal) => format!("  (goal {goal}: MISSED)"),
            None => String::new(),
        };
        println!(
            "  {name:<42} {:>9.1} M cycles/s  {ratio:>5.2} of the plain run{verdict}",
            speed / 1e6,
        );
    }
    println!(
        "step back one instruction ({STEPS_BACK} in a row; checkpoints every {} cycles, at most {} kept):",
        debugger::CHECKPOINT_EVERY,
        debugger::MAX_CHECKPOINTS
    );
    for (label, robot_time) in [("a minute", 60 * SECOND), ("an hour", 3600 * SECOND)] {
        let (mean, slowest, ran, held, checkpoints) = steps_back(&image, robot_time);
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "  after {label:<8} of robot time: {:.2} ms a step on a CPU (goal 20 ms: {}), slowest {:.2} ms \
             by the wall clock; the run took {:.1} s; the session holds {:.1} MiB ({checkpoints} checkpoints, history, the robot)",
            ms(mean),
            if ms(mean) <= 20.0 { "met" } else { "MISSED" },
            ms(slowest),
            ran.as_secs_f64(),
            held as f64 / f64::from(1 << 20),
        );
    }
}
