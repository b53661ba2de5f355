//! The Scorpion board's cost to the CPU: emulated cycles per second of the
//! reference ROM idling on the virtual Scorpion (waiting for commands, as a
//! robot spends most of its life) against the CPU benchmark's workload (the
//! sieve of `emulator/benches/cpu.rs`) on the plain RAM machine, in the
//! same process. Target: the board keeps at least 80% of the CPU's speed.
//!
//! Every board workload is measured twice: as the robot runs by default,
//! with idle-loop skipping (the CPU advances whole iterations of a loop
//! that can only repeat itself until a device acts, exactly as if it had
//! run them: `emulator::Cpu::set_idle_skip`), and with skipping off, every
//! cycle executed, which is the board's own cost. The same idle code on the
//! plain RAM machine (skipping off) separates the board's cost from the
//! CPU's. Also printed, for information: the board with both drive motors
//! running (the 1 kHz motion tick interrupting) and while receiving a
//! steady stream of `/9W` writes at 9600 baud, with the share of their
//! cycles that skipping saved.
//!
//! `cargo bench -p romlib --bench idle`; one workload under callgrind:
//! see [`only`].
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

/// A robot past boot, idle-loop skipping as `skip` says.
fn robot(skip: bool) -> VirtualScorpion {
    let mut robot = VirtualScorpion::new();
    robot.robot_mut().cpu.set_idle_skip(skip);
    robot
}

/// The same idle code on the plain RAM machine: the ROM's memory after
/// boot copied into 64 KiB of RAM, the CPU as the board's (no interrupt
/// comes: nothing is sent and no timer runs while the ROM idles). Idle-loop
/// skipping off: this is the CPU's own speed on that code.
fn same_code_machine() -> RamMachine {
    let robot = robot(false);
    let mut plain = RamMachine::with_image(0, robot.robot().board().memory()).expect("64 KiB");
    plain.cpu = robot.robot().cpu.clone();
    plain
}

/// A robot with both drives stepping (the 1 kHz motion tick interrupting).
fn moving(skip: bool) -> VirtualScorpion {
    let mut robot = robot(skip);
    robot.send(b"/4C+50/4D-50");
    robot.settle().expect("the ROM does not jam");
    robot
}

/// Two seconds of back-to-back `/9W` at 9600 baud sent to `robot`, and the
/// two seconds run.
fn writes(robot: &mut VirtualScorpion) -> u64 {
    let burst: Vec<u8> = b"/9W10001234".repeat(174);
    robot.send(&burst);
    run(robot, 2_000_000)
}

/// `IDLE_BENCH_ONLY=<workload> [IDLE_BENCH_CYCLES=n]`: runs that one
/// workload once, untimed, and prints the cycles it ran: for
/// `valgrind --tool=callgrind --toggle-collect='emulator::cpu::Cpu::run*'`,
/// whose instruction count divided by the cycles is the host cost of an
/// emulated cycle, repeatable on a busy machine. Workloads: `sieve`,
/// `idle` (skipping off), `idle-skip`, `same-code`, `motors` (skipping
/// off), `motors-skip`, `writes` (skipping off, two seconds whatever
/// `IDLE_BENCH_CYCLES` says), `writes-skip`.
fn only(workload: &str) {
    let cycles: u64 = std::env::var("IDLE_BENCH_CYCLES")
        .ok()
        .and_then(|text| text.parse().ok())
        .unwrap_or(20_000_000);
    let with_robot = |mut robot: VirtualScorpion, work: &dyn Fn(&mut VirtualScorpion) -> u64| {
        let ran = work(&mut robot);
        (ran, robot.robot().cpu.skipped_cycles())
    };
    let (ran, skipped) = match workload {
        "sieve" => (sieve(), 0),
        "idle" => with_robot(robot(false), &|r| run(r, cycles)),
        "idle-skip" => with_robot(robot(true), &|r| run(r, cycles)),
        "motors" => with_robot(moving(false), &|r| run(r, cycles)),
        "motors-skip" => with_robot(moving(true), &|r| run(r, cycles)),
        "writes" => with_robot(robot(false), &writes),
        "writes-skip" => with_robot(robot(true), &writes),
        "same-code" => {
            let mut plain = same_code_machine();
            let start = plain.cpu.cycles();
            plain.run(start + cycles);
            (plain.cpu.cycles() - start, 0)
        }
        other => panic!("IDLE_BENCH_ONLY: no workload {other:?}"),
    };
    println!("{workload}: {ran} cycles, {skipped} of them skipped");
}

fn main() {
    if let Ok(workload) = std::env::var("IDLE_BENCH_ONLY") {
        only(&workload);
        return;
    }
    let mut idle_skip = robot(true);
    let mut idle_exact = robot(false);
    let mut plain = same_code_machine();
    let mut moving_skip = moving(true);
    let mut moving_exact = moving(false);
    let mut writing_skip = robot(true);
    let mut writing_exact = robot(false);
    let mut cpu = || sieve();
    let mut idle_on = || run(&mut idle_skip, 50_000_000);
    let mut idle_off = || run(&mut idle_exact, 50_000_000);
    let mut same_code = || {
        let start = plain.cpu.cycles();
        plain.run(start + 50_000_000);
        black_box(plain.cpu.cycles() - start)
    };
    let mut motors_on = || run(&mut moving_skip, 20_000_000);
    let mut motors_off = || run(&mut moving_exact, 20_000_000);
    let mut writes_on = || writes(&mut writing_skip);
    let mut writes_off = || writes(&mut writing_exact);
    let measured = rates(&mut [
        &mut cpu,
        &mut idle_on,
        &mut idle_off,
        &mut same_code,
        &mut motors_on,
        &mut motors_off,
        &mut writes_on,
        &mut writes_off,
    ]);
    let [
        cpu,
        idle_on,
        idle_off,
        same_code,
        motors_on,
        motors_off,
        writes_on,
        writes_off,
    ] = measured[..]
    else {
        unreachable!("eight workloads")
    };
    let mega = |rate: f64| rate / 1e6;
    let share = |robot: &VirtualScorpion| {
        let cpu = &robot.robot().cpu;
        #[allow(clippy::cast_precision_loss, reason = "a share")]
        let share = cpu.skipped_cycles() as f64 / cpu.cycles() as f64;
        share
    };
    println!(
        "CPU benchmark (sieve, RAM machine):      {:10.1} M cycles/s",
        mega(cpu)
    );
    println!(
        "board, ROM idle, idle skipping on:       {:10.1} M cycles/s  {:8.2} of the CPU benchmark (target >= 0.80)  {:.3} of its cycles skipped",
        mega(idle_on),
        idle_on / cpu,
        share(&idle_skip)
    );
    println!(
        "board, ROM idle, every cycle run:        {:10.1} M cycles/s  {:8.2} of the CPU benchmark",
        mega(idle_off),
        idle_off / cpu
    );
    println!(
        "same idle code, RAM machine, run:        {:10.1} M cycles/s  {:8.2}  (the board keeps {:.2} of it)",
        mega(same_code),
        same_code / cpu,
        idle_off / same_code
    );
    println!(
        "board, both drives stepping, skipping:   {:10.1} M cycles/s  {:8.2}  {:.3} skipped",
        mega(motors_on),
        motors_on / cpu,
        share(&moving_skip)
    );
    println!(
        "board, both drives stepping, run:        {:10.1} M cycles/s  {:8.2}",
        mega(motors_off),
        motors_off / cpu
    );
    println!(
        "board, /9W at 9600 baud, skipping:       {:10.1} M cycles/s  {:8.2}  {:.3} skipped",
        mega(writes_on),
        writes_on / cpu,
        share(&writing_skip)
    );
    println!(
        "board, /9W at 9600 baud, run:            {:10.1} M cycles/s  {:8.2}",
        mega(writes_off),
        writes_off / cpu
    );
}
