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
}
