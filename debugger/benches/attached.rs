//! The robot's speed with the debugger attached, as a ratio to the plain
//! run (the virtual Scorpion on its own), in the same process, taking
//! turns: the patrol operating system cruising (the motors' 1 kHz tick
//! interrupting, its loop passing through `HOOK_LOOP`), two seconds of
//! robot time per run.
//!
//! - attached, history on, nothing set: the debugger's run with its
//!   history of the host's actions (the only history it keeps);
//! - three breakpoints set (never hit);
//! - a watchpoint on a card's registers (never touched);
//! - and the cost of a step back: re-running from power-up, per second of
//!   robot time re-run.
//!
//! Goal: with history on, at least a third of the plain run's speed.
//! `cargo bench -p debugger`.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use debugger::{Breakpoint, Debugger, Watch, WatchKind};
use romlib::VirtualScorpion;

const ROBOT_CYCLES: u64 = 2_000_000;
const TRIES: usize = 5;

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
    let started = Instant::now();
    let cycles = run();
    #[allow(clippy::cast_precision_loss, reason = "a rate")]
    let rate = cycles as f64 / started.elapsed().as_secs_f64();
    rate
}

fn main() {
    let image = patrol();
    let names = [
        "plain run (the virtual Scorpion alone)",
        "attached, history on, nothing set",
        "three breakpoints (never hit)",
        "a watchpoint on $8000-$8003 (never hit)",
    ];
    let mut best = [0.0f64; 4];
    let mut back = f64::MAX;
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
        let mut d = debugger(&image, |_| {});
        d.run(ROBOT_CYCLES).expect("runs");
        let ran = d.robot().cycles();
        let started = Instant::now();
        d.back(1).expect("goes back");
        #[allow(clippy::cast_precision_loss, reason = "a rate")]
        let seconds_per_robot_second = started.elapsed().as_secs_f64() / (ran as f64 / 1e6);
        back = back.min(seconds_per_robot_second);
    }
    println!("the patrol OS cruising, {ROBOT_CYCLES} robot cycles a run, best of {TRIES}");
    for (name, speed) in names.iter().zip(best) {
        println!(
            "  {name:<42} {:>9.1} M cycles/s  {:>5.2} of the plain run",
            speed / 1e6,
            speed / best[0]
        );
    }
    println!(
        "  a step back (a re-run from power-up):      {:.1} ms per second of robot time run so far",
        back * 1e3
    );
    let history = best[1] / best[0];
    println!(
        "  goal: history on keeps at least a third of the speed ({history:.2}: {})",
        if history >= 1.0 / 3.0 {
            "met"
        } else {
            "MISSED"
        }
    );
    println!(
        "  history's memory: what the host did (a few bytes per command) and nothing per instruction"
    );
}
