//! The virtual robot's speed while a program polls a card, the card as a
//! script against the same card in Rust and against plain RAM, same
//! program, taking turns in one run.
//!
//! `cargo bench -p cards` runs `loop: BIT $8001 / JMP loop` (7 cycles an
//! access) on the Scorpion board with the rangefinder card at `$8000`:
//! (a) `examples/rangefinder/rangefinder.rhai` (STATUS is a plain register:
//! served from the card's table), (b) the same registers in Rust, (c) no
//! card, KIM-bus RAM; and (d) the script with every register read through
//! its `read` function, to report what one call into a script costs.
//! Targets: (a) at least 0.5 of (b), and at least 200 times the real
//! robot's 1 MHz.
//!
//! Then the bound on hostile scripts (docs/CARDS.md): a card that spends
//! all its share of robot time, (e) in calls (woken as often as
//! `CALL_COST` lets it, doing nothing) and (f) in operations (woken every
//! millisecond, a loop of nine tenths of what a millisecond earns), each
//! as host time per robot time: how many times slower than the real robot
//! the worst script can make the virtual one. It also prints what one call
//! and one operation cost the host, which `CALL_COST` is set against.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::any::Any;
use std::time::Instant;

use cards::ScriptCard;
use emulator::board::{Device, Scorpion};

/// Robot time each run covers: 20 s of the 1 MHz CPU.
const CYCLES: u64 = 20_000_000;
/// Cycles per access of the polling loop (BIT abs 4 + JMP 3).
const CYCLES_PER_ACCESS: u64 = 7;
const ROUNDS: usize = 5;

/// The rangefinder's registers, in Rust: what a reader of `Device` writes.
#[derive(Debug, Default)]
struct RustRanger {
    registers: [u8; 4],
}

impl Device for RustRanger {
    fn read(&mut self, offset: u16, _cycle: u64) -> u8 {
        self.registers[usize::from(offset & 3)]
    }
    fn write(&mut self, offset: u16, value: u8, _cycle: u64) {
        self.registers[usize::from(offset & 3)] = value;
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

fn rom() -> Vec<u8> {
    let mut rom = vec![0xEA; 0x1000];
    // loop: BIT $8001 / JMP loop
    rom[..6].copy_from_slice(&[0x2C, 0x01, 0x80, 0x4C, 0x00, 0xF0]);
    rom[0xFFC..].copy_from_slice(&[0x00, 0xF0, 0x00, 0xF0]);
    rom
}

fn script(all_through_read: bool) -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/rangefinder/rangefinder.rhai"
    );
    let text = std::fs::read_to_string(path).expect("the example card");
    if all_through_read {
        text.replace("const PLAIN = [0, 1, 2, 3];", "const PLAIN = [];")
            + "\nfn read(reg, now) { get(reg) }\n"
    } else {
        text
    }
}

/// Seconds of wall time for `CYCLES` of robot time with `card`.
fn run(card: Option<Box<dyn Device>>) -> f64 {
    let mut robot = Scorpion::scorpion(&rom()).expect("a 4 KiB ROM");
    if let Some(card) = card {
        robot.map_kim(0x8000, 0x8003, card).expect("free");
    }
    let start = Instant::now();
    robot.run(CYCLES);
    let took = start.elapsed().as_secs_f64();
    assert!(robot.now() >= CYCLES);
    took
}

/// Robot time each hostile run covers: 2 s.
const HOSTILE_CYCLES: u64 = 2_000_000;

/// Rounds of a plain loop one call can take within its operation budget
/// (found by halving, on `init`'s full budget): operations per round.
fn operations_per_round() -> f64 {
    let fits = |rounds: u64| {
        let text = format!(
            "const SIZE = 4;\nconst BASE = 0x8000;\nfn init() {{ let x = 0; for i in 0..{rounds} {{ x += i; }} }}\n"
        );
        ScriptCard::load("probe.rhai", &text, None).is_ok()
    };
    let (mut low, mut high) = (1u64, cards::OPERATION_BUDGET);
    while low + 1 < high {
        let middle = u64::midpoint(low, high);
        if fits(middle) {
            low = middle;
        } else {
            high = middle;
        }
    }
    cards::OPERATION_BUDGET as f64 / low as f64
}

/// A card woken every `interval` microseconds, running `rounds` rounds of
/// a plain loop each time.
fn hostile(interval: u64, rounds: u64) -> ScriptCard {
    let text = format!(
        "const SIZE = 4;\nconst BASE = 0x8000;\nfn init() {{ wake_at(1); }}\nfn wake(now) {{ let x = 0; for i in 0..{rounds} {{ x += i; }} wake_at(now + {interval}); }}\n"
    );
    ScriptCard::load("hostile.rhai", &text, None).expect("loads")
}

/// Seconds of wall time for [`HOSTILE_CYCLES`] of robot time with `card`
/// polled by the ROM's loop, and the card's fault, if it was stopped.
fn run_hostile(card: ScriptCard) -> (f64, Option<String>) {
    let mut robot = Scorpion::scorpion(&rom()).expect("a 4 KiB ROM");
    robot.map_kim(0x8000, 0x8003, Box::new(card)).expect("free");
    let start = Instant::now();
    robot.run(HOSTILE_CYCLES);
    let took = start.elapsed().as_secs_f64();
    let fault = robot
        .board_mut()
        .take_device_fault()
        .map(|(_, fault)| fault.to_string());
    (took, fault)
}

fn main() {
    let kinds = [
        "script card",
        "Rust card",
        "plain RAM",
        "script, every read a call",
    ];
    let mut best = [f64::MAX; 4];
    for _ in 0..ROUNDS {
        for (index, slot) in best.iter_mut().enumerate() {
            let card: Option<Box<dyn Device>> = match index {
                0 => Some(Box::new(
                    ScriptCard::load("rangefinder.rhai", &script(false), None).expect("loads"),
                )),
                1 => Some(Box::new(RustRanger::default())),
                2 => None,
                _ => Some(Box::new(
                    ScriptCard::load("rangefinder.rhai", &script(true), None).expect("loads"),
                )),
            };
            *slot = slot.min(run(card));
        }
    }
    let speed = |seconds: f64| CYCLES as f64 / seconds;
    println!(
        "polling a card register ({} M cycles of robot time, best of {ROUNDS} rounds taken in turns)",
        CYCLES / 1_000_000
    );
    println!(
        "  {:<28} {:>12} {:>12} {:>10}",
        "card", "M cycles/s", "x robot", "x Rust"
    );
    for (kind, seconds) in kinds.iter().zip(best) {
        println!(
            "  {kind:<28} {:>12.1} {:>12.0} {:>10.2}",
            speed(seconds) / 1e6,
            speed(seconds) / 1e6,
            best[1] / seconds
        );
    }
    println!(
        "  (plain RAM: the emulator skips a loop that only reads RAM, so it runs no instruction)"
    );
    let accesses = (CYCLES / CYCLES_PER_ACCESS) as f64;
    let per_call = (best[3] - best[1]) / accesses;
    println!(
        "  one call into a script's `read`: {:.0} ns",
        per_call * 1e9
    );
    let ratio = best[1] / best[0];
    let times_robot = speed(best[0]) / 1e6;
    println!(
        "  targets: script card at least 0.5 of the Rust card ({ratio:.2}: {}), at least 200x the robot ({times_robot:.0}x: {})",
        if ratio >= 0.5 { "met" } else { "MISSED" },
        if times_robot >= 200.0 {
            "met"
        } else {
            "MISSED"
        }
    );

    // The bound: all of a script's share spent in calls, then in
    // operations.
    let per_round = operations_per_round();
    let budget = cards::OPERATIONS_PER_MICROSECOND;
    // The call and its own few operations (`wake_at`, the empty loop).
    let interval = (cards::CALL_COST + 20).div_ceil(budget);
    let rounds = (0.9 * (1000 * budget) as f64 / per_round) as u64;
    let mut calls_best = f64::MAX;
    let mut operations_best = f64::MAX;
    let mut faults = Vec::new();
    for _ in 0..ROUNDS {
        let (took, fault) = run_hostile(hostile(interval, 0));
        calls_best = calls_best.min(took);
        faults.extend(fault);
        let (took, fault) = run_hostile(hostile(1000, rounds));
        operations_best = operations_best.min(took);
        faults.extend(fault);
    }
    let robot_seconds = HOSTILE_CYCLES as f64 / 1e6;
    let rust_seconds = best[1] * HOSTILE_CYCLES as f64 / CYCLES as f64;
    let calls = (HOSTILE_CYCLES / interval) as f64;
    let operations = (HOSTILE_CYCLES / 1000) as f64 * rounds as f64 * per_round;
    let per_call = (calls_best - rust_seconds) / calls;
    let per_operation = (operations_best - rust_seconds) / operations;
    println!(
        "a script spending its whole share of robot time ({} s of robot time, best of {ROUNDS})",
        HOSTILE_CYCLES / 1_000_000
    );
    println!(
        "  (e) woken every {interval} us, nothing else:          {:>6.2} x real time",
        calls_best / robot_seconds
    );
    println!(
        "  (f) woken every 1 ms, {rounds} loop rounds ({per_round:.1} operations each): {:>6.2} x real time",
        operations_best / robot_seconds
    );
    println!(
        "  one call: {:.0} ns; one operation: {:.1} ns; a call costs the host {:.0} operations (CALL_COST {})",
        per_call * 1e9,
        per_operation * 1e9,
        per_call / per_operation,
        cards::CALL_COST
    );
    if !faults.is_empty() {
        println!(
            "  STOPPED (the bound is not what the bench assumes): {}",
            faults[0]
        );
    }
}
