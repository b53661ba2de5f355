//! The Scorpion board's cost to the CPU: emulated cycles per second of the
//! reference ROM idling on the virtual Scorpion (waiting for commands, as a
//! robot spends most of its life) against the CPU benchmark's workload (the
//! sieve of `emulator/benches/cpu.rs`) on the plain RAM machine, in the
//! same process. Target: the board keeps at least 80% of the CPU's speed.
//!
//! Also printed, for information: the board with both drive motors running
//! (the 1 kHz motion tick interrupting) and while receiving a steady stream
//! of `/9W` writes at 9600 baud.
//!
//! `cargo bench -p romlib --bench idle`
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::hint::black_box;
use std::time::Instant;

use emulator::{RamMachine, Stop, StopAtTrap};
use romlib::VirtualScorpion;

const SIEVE: &[u8] = include_bytes!("../../emulator/programs/sieve.bin");
const TRIES: usize = 5;

/// Cycles per second of `run` (which returns the cycles it ran), once.
fn once(run: &mut dyn FnMut() -> u64) -> f64 {
    let started = Instant::now();
    let cycles = run();
    #[allow(clippy::cast_precision_loss, reason = "a rate")]
    let rate = cycles as f64 / started.elapsed().as_secs_f64();
    rate
}

/// Best of `TRIES` rounds; each round runs every workload once, in turn,
/// so that a busy machine slows them alike and the ratios stay fair.
fn rates(workloads: &mut [&mut dyn FnMut() -> u64]) -> Vec<f64> {
    let mut best = vec![0.0f64; workloads.len()];
    for _ in 0..TRIES {
        for (index, workload) in workloads.iter_mut().enumerate() {
            best[index] = best[index].max(once(*workload));
        }
    }
    best
}

fn sieve() -> u64 {
    let mut total = 0;
    for _ in 0..10 {
        let mut machine = RamMachine::with_image(0x0400, SIEVE).expect("the sieve fits");
        machine.cpu.pc = 0x0400;
        let stop = machine.run_with(u64::MAX, &mut StopAtTrap);
        assert!(
            matches!(stop, Stop::Trap { .. }),
            "the sieve ends at its trap"
        );
        total += black_box(machine.cpu.cycles());
    }
    total
}

/// Runs `robot` for `cycles` more cycles; returns them.
fn run(robot: &mut VirtualScorpion, cycles: u64) -> u64 {
    let start = robot.cycles();
    robot.run_for(cycles).expect("the ROM does not jam");
    black_box(robot.cycles() - start)
}

fn main() {
    let mut idle_robot = VirtualScorpion::new();
    // The same idle code on the plain RAM machine: the ROM's memory after
    // boot copied into 64 KiB of RAM (no interrupt comes: nothing is sent
    // and no timer runs while the ROM idles).
    let mut plain = RamMachine::with_image(0, idle_robot.robot().board().memory()).expect("64 KiB");
    plain.cpu = idle_robot.robot().cpu.clone();
    let mut moving = VirtualScorpion::new();
    moving.send(b"/4C+50/4D-50");
    moving.settle().expect("the ROM does not jam");
    let mut writing = VirtualScorpion::new();
    let mut cpu = sieve;
    let mut idle = || run(&mut idle_robot, 50_000_000);
    let mut same_code = || {
        let start = plain.cpu.cycles();
        plain.run(start + 50_000_000);
        black_box(plain.cpu.cycles() - start)
    };
    let mut motors = || run(&mut moving, 20_000_000);
    let mut writes = || {
        // Two seconds of back-to-back /9W at 9600 baud.
        let burst: Vec<u8> = b"/9W10001234".repeat(174);
        writing.send(&burst);
        run(&mut writing, 2_000_000)
    };
    let measured = rates(&mut [
        &mut cpu,
        &mut idle,
        &mut same_code,
        &mut motors,
        &mut writes,
    ]);
    let [cpu, idle, same_code, motors, writes] = measured[..] else {
        unreachable!("five workloads")
    };
    let mega = |rate: f64| rate / 1e6;
    println!(
        "CPU benchmark (sieve, RAM machine): {:8.1} M cycles/s",
        mega(cpu)
    );
    println!(
        "board, ROM idle:                    {:8.1} M cycles/s  {:.2} of the CPU benchmark (target >= 0.80)",
        mega(idle),
        idle / cpu
    );
    println!(
        "same idle code, RAM machine:        {:8.1} M cycles/s  the board keeps {:.2} of it",
        mega(same_code),
        idle / same_code
    );
    println!(
        "board, both drives stepping:        {:8.1} M cycles/s  {:.2}",
        mega(motors),
        motors / cpu
    );
    println!(
        "board, receiving /9W at 9600 baud:  {:8.1} M cycles/s  {:.2}",
        mega(writes),
        writes / cpu
    );
}
