//! CPU speed against the `mos6502` crate, same workloads, same process.
//!
//! `cargo bench -p emulator` runs each workload on our CPU and on mos6502's
//! and prints emulated cycles per second for both and the ratio (target: at
//! least 4x). Workloads:
//! - `sieve`: `programs/sieve.bin` (ours: primes below 8192, 20 times),
//!   run 10 times;
//! - `dormann`: Klaus Dormann's functional test from the mos6502 package
//!   (found with `cargo metadata`; skipped with a note if not found).
//!
//! Our CPU runs with `StopAtTrap` (how the programs end), and once more with
//! an empty breakpoint set, to show what an active hook costs; with no hooks
//! the loop has no hook code at all. Each emulator gets 7 tries, taking turns
//! (so that a busy machine slows them alike), and reports its best.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
#![allow(clippy::print_stderr, reason = "a benchmark reports on stdout")]

use std::hint::black_box;
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use emulator::{Breakpoints, Hooks, RamMachine, Stop, StopAtTrap};

const SIEVE: &[u8] = include_bytes!("../programs/sieve.bin");

/// One workload: a 64 KiB image, the start address, and how many runs.
struct Workload {
    name: &'static str,
    image: Vec<u8>,
    start: u16,
    runs: u32,
}

/// Tries per emulator; each reports its best. The emulators take turns, so
/// that a busy machine slows them alike.
const TRIES: usize = 7;

/// One timed pass of `workload` on our CPU with `hooks`: (cycles, seconds,
/// trap address).
fn ours<H: Hooks>(workload: &Workload, hooks: &mut H) -> (u64, f64, u16) {
    let mut cycles = 0;
    let mut trap = 0;
    let started = Instant::now();
    for _ in 0..workload.runs {
        let mut machine = RamMachine::with_image(0, &workload.image).expect("64 KiB image");
        machine.cpu.pc = workload.start;
        let stop = machine.run_with(u64::MAX, hooks);
        let Stop::Trap { pc } = stop else {
            panic!("{}: stopped with {stop:?}", workload.name)
        };
        trap = pc;
        cycles += black_box(machine.cpu.cycles());
    }
    (cycles, started.elapsed().as_secs_f64(), trap)
}

/// One timed pass of `workload` on the mos6502 crate, each run until its PC
/// reaches `trap`, which it then executes once (as our CPU does before it
/// stops): (cycles, seconds).
fn theirs(workload: &Workload, trap: u16) -> (u64, f64) {
    use mos6502::memory::Bus as _;
    let mut cycles = 0;
    let started = Instant::now();
    for _ in 0..workload.runs {
        let mut cpu = mos6502::cpu::CPU::new(
            mos6502::memory::Memory::new(),
            mos6502::instruction::Nmos6502,
        );
        cpu.memory.set_bytes(0, &workload.image);
        cpu.registers.program_counter = workload.start;
        while cpu.registers.program_counter != trap {
            cpu.single_step();
        }
        cpu.single_step();
        cycles += black_box(cpu.cycles);
    }
    (cycles, started.elapsed().as_secs_f64())
}

fn dormann_image() -> Option<Vec<u8>> {
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let output = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--manifest-path",
            manifest,
        ])
        .output()
        .ok()?;
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout).ok()?;
    let package = metadata["packages"]
        .as_array()?
        .iter()
        .find(|package| package["name"] == "mos6502")?;
    let path = PathBuf::from(package["manifest_path"].as_str()?)
        .with_file_name("tests/assets/6502_functional_test.bin");
    std::fs::read(path).ok()
}

fn main() {
    let mut sieve = vec![0u8; 0x1_0000];
    sieve[0x0400..0x0400 + SIEVE.len()].copy_from_slice(SIEVE);
    let mut workloads = vec![Workload {
        name: "sieve",
        image: sieve,
        start: 0x0400,
        runs: 10,
    }];
    match dormann_image() {
        Some(image) => workloads.push(Workload {
            name: "dormann",
            image,
            start: 0x0400,
            runs: 2,
        }),
        None => eprintln!("dormann: the mos6502 package's test binary was not found; skipped"),
    }

    println!(
        "{:<9} {:<28} {:>13} {:>9} {:>12} {:>8}",
        "workload", "emulator", "cycles", "seconds", "M cycles/s", "vs mos6502"
    );
    for workload in &workloads {
        let mut best = [f64::INFINITY; 3];
        let mut cycles = [0u64; 3];
        for _ in 0..TRIES {
            let (plain, seconds, trap) = ours(workload, &mut StopAtTrap);
            cycles[0] = plain;
            best[0] = best[0].min(seconds);
            let (hooked, seconds, _) = ours(workload, &mut (StopAtTrap, Breakpoints::new()));
            cycles[1] = hooked;
            best[1] = best[1].min(seconds);
            let (their_cycles, seconds) = theirs(workload, trap);
            cycles[2] = their_cycles;
            best[2] = best[2].min(seconds);
        }
        assert!(
            cycles[0] == cycles[2] && cycles[1] == cycles[2],
            "{}: the CPUs disagree on the cycle count: {cycles:?}",
            workload.name
        );
        let rate = |index: usize| cycles[index] as f64 / best[index] / 1e6;
        for (index, label) in [
            "scorpion emulator",
            "scorpion + empty breakpoints",
            "mos6502 0.10.1",
        ]
        .into_iter()
        .enumerate()
        {
            println!(
                "{:<9} {:<28} {:>13} {:>9.3} {:>12.1} {:>7.2}x",
                workload.name,
                label,
                cycles[index],
                best[index],
                rate(index),
                rate(index) / rate(2)
            );
        }
    }
}
