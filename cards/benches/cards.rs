//! The virtual robot's speed while a program polls a card, the card as a
//! script against the same card in Rust and against plain RAM, same
//! program, taking turns in one run.
//!
//! `cargo bench -p cards` runs `loop: BIT $8001 / JMP loop` (7 cycles an
//! access) on the Scorpion board with the rangefinder card at `$8000`:
//! (a) `examples/rangefinder/rangefinder.rhai` (STATUS is a plain register:
//! served from the card's table), (b) the same card with every register
//! read through its `read` function, whose answers the card keeps until a
//! write or wake-up (a polled status register as most cards have it),
//! (c) the same registers in Rust, (d) no card, KIM-bus RAM; and (e) the
//! script with every register `VOLATILE`, every read a call into `read`
//! (a data register that clears an interrupt), to report what one call
//! into a script costs. Each is run twice: as the robot runs it (the
//! emulator skips a loop whose reads cannot change: (a), (b) once their
//! answer is kept, and (c), whose registers say they are stable) and with
//! every instruction run (the idle skip off), where each read costs what
//! it costs. Targets: (b) at least 0.5 of the Rust card with every
//! instruction run (as run, both loops are skipped and a run takes
//! microseconds, too short to compare), and at least 200 times the real
//! robot's 1 MHz as run.
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
    // Only a write changes a register, and a read has no effect: what a
    // careful author of the card says, so the emulator may skip a loop
    // that polls it, as it does for the script's kept answers.
    fn is_stable(&self, _offset: u16) -> bool {
        true
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

/// How the rangefinder's registers are read.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reads {
    /// From the table (`PLAIN`), as the example has it.
    Plain,
    /// Through `read`, its answers kept until a write or wake-up.
    Kept,
    /// Through `read`, every read a call (`VOLATILE`).
    EveryRead,
}

fn script(reads: Reads) -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/rangefinder/rangefinder.rhai"
    );
    let text = std::fs::read_to_string(path).expect("the example card");
    let through_read = |declarations: &str| {
        text.replace("const PLAIN = [0, 1, 2, 3];", declarations)
            + "\nfn read(reg, now) { get(reg) }\n"
    };
    match reads {
        Reads::Plain => text.clone(),
        Reads::Kept => through_read("const PLAIN = [];"),
        Reads::EveryRead => through_read("const PLAIN = [];\nconst VOLATILE = [0, 1, 2, 3];"),
    }
}

/// Seconds of wall time for `CYCLES` of robot time with `card`, the idle
/// skip as `skip` says.
fn run(card: Option<Box<dyn Device>>, skip: bool) -> f64 {
    let mut robot = Scorpion::scorpion(&rom()).expect("a 4 KiB ROM");
    robot.cpu.set_idle_skip(skip);
    if let Some(card) = card {
        robot.map_kim(0x8000, 0x8003, card).expect("free");
    }
    let start = Instant::now();
    robot.run(CYCLES);
    let took = start.elapsed().as_secs_f64();
    assert!(robot.now() >= CYCLES);
    took
}

/// Robot time each run of the room covers: 20 s.
const ROOM_CYCLES: u64 = 20_000_000;

/// A room of 10 by 10 metres, a post and a floor line: the robot,
/// driving at speed 40 from the middle, meets nothing in 20 s.
const ROOM: &str = r#"
walls = [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]
[[obstacle]]
circle = { x = 200, y = 200, radius = 20 }
[[obstacle]]
polygon = [[800, 100], [900, 100], [850, 200]]
[[line]]
points = [[100, 500], [900, 500], [900, 900]]
[robot]
x = 500
y = 450
heading = 90
"#;

/// Obstacles in the crowded room.
const CROWD: usize = 10_000;

/// [`ROOM`] with [`CROWD`] posts 2 cm round, 9 cm apart, all over it but
/// for a corridor 1 m wide along the robot's way north.
fn crowded_room() -> String {
    let mut posts = String::new();
    let mut count = 0;
    'rows: for row in 0..111 {
        for column in 0..111 {
            let (x, y) = (5 + 9 * column, 5 + 9 * row);
            if (450..=550).contains(&x) {
                continue;
            }
            if count == CROWD {
                break 'rows;
            }
            posts.push_str(&format!(
                "[[obstacle]]\ncircle = {{ x = {x}, y = {y}, radius = 1 }}\n"
            ));
            count += 1;
        }
    }
    assert_eq!(count, CROWD, "the room holds the crowd");
    ROOM.replace("[robot]", &format!("{posts}[robot]"))
}

/// Seconds of wall time for [`ROOM_CYCLES`] of robot time of the
/// reference ROM, driving both motors at speed 40 or standing still, in
/// `world` or in no room at all.
fn run_room(world: Option<&str>, drive: bool) -> f64 {
    let mut robot = romlib::VirtualScorpion::new();
    if let Some(world) = world {
        robot.set_surroundings(Box::new(
            cards::Room::load("room.toml", world).expect("loads"),
        ));
    }
    if drive {
        robot.send(b"/2G1/4C+40/4D+40");
    }
    let start = Instant::now();
    robot.run_for(ROOM_CYCLES).expect("runs");
    start.elapsed().as_secs_f64()
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
        "(a) script card, PLAIN",
        "(b) script, `read` kept",
        "(c) Rust card",
        "(d) plain RAM",
        "(e) script, every read a call",
    ];
    let card = |index: usize| -> Option<Box<dyn Device>> {
        let load = |reads| {
            Box::new(ScriptCard::load("rangefinder.rhai", &script(reads), None).expect("loads"))
        };
        match index {
            0 => Some(load(Reads::Plain)),
            1 => Some(load(Reads::Kept)),
            2 => Some(Box::new(RustRanger::default())),
            3 => None,
            _ => Some(load(Reads::EveryRead)),
        }
    };
    // [skipping, every instruction run]
    let mut best = [[f64::MAX; 2]; 5];
    for _ in 0..ROUNDS {
        for (index, slot) in best.iter_mut().enumerate() {
            if index == 4 {
                // No register of it is stable: nothing to skip.
                let took = run(card(index), false);
                slot[0] = slot[0].min(took);
                slot[1] = slot[1].min(took);
                continue;
            }
            for (mode, skip) in [true, false].into_iter().enumerate() {
                slot[mode] = slot[mode].min(run(card(index), skip));
            }
        }
    }
    let speed = |seconds: f64| CYCLES as f64 / seconds / 1e6;
    println!(
        "polling a card register ({} M cycles of robot time, best of {ROUNDS} rounds taken in turns)",
        CYCLES / 1_000_000
    );
    println!(
        "  {:<32} {:>22} {:>22}",
        "", "as run (idle skipped)", "every instruction run"
    );
    println!(
        "  {:<32} {:>12} {:>9} {:>12} {:>9}",
        "card", "M cycles/s", "x Rust", "M cycles/s", "x Rust"
    );
    for (kind, seconds) in kinds.iter().zip(best) {
        println!(
            "  {kind:<32} {:>12.1} {:>9.2} {:>12.1} {:>9.2}",
            speed(seconds[0]),
            best[2][0] / seconds[0],
            speed(seconds[1]),
            best[2][1] / seconds[1],
        );
    }
    println!("  (M cycles/s is also how many times the real robot's speed: it runs 1 M cycles/s)");
    println!(
        "  (skipped: a loop that reads only RAM, or registers whose answer holds, runs no instruction)"
    );
    let accesses = (CYCLES / CYCLES_PER_ACCESS) as f64;
    let per_call = (best[4][1] - best[2][1]) / accesses;
    println!(
        "  one call into a script's `read` (e, less the Rust card's read): {:.0} ns",
        per_call * 1e9
    );
    let verdict = |met: bool| if met { "met" } else { "MISSED" };
    // The cost of a read against the Rust card's, every instruction run:
    // as run, both loops are skipped and a run takes microseconds, too
    // short to compare. How fast the robot runs is as it runs.
    let kept = best[2][1] / best[1][1];
    let kept_robot = speed(best[1][0]);
    println!(
        "  targets, a polled register read through `read` (b): at least 0.5 of the Rust card, every instruction run ({kept:.2}: {}); at least 200x the robot, as run ({kept_robot:.0}x: {}; every instruction run {:.0}x, the Rust card {:.0}x)",
        verdict(kept >= 0.5),
        verdict(kept_robot >= 200.0),
        speed(best[1][1]),
        speed(best[2][1])
    );
    println!(
        "  a card whose every read calls its script (e): {:.3} of the Rust card, {:.0}x the robot",
        best[2][1] / best[4][1],
        speed(best[4][1])
    );

    let (mut bare, mut roomed) = (f64::MAX, f64::MAX);
    let crowd = crowded_room();
    // Driving, then standing still: without a room, in the crowded one.
    let mut crowded = [[f64::MAX; 2]; 2];
    for _ in 0..ROUNDS {
        bare = bare.min(run_room(None, true));
        roomed = roomed.min(run_room(Some(ROOM), true));
        for (slot, drive) in crowded.iter_mut().zip([true, false]) {
            slot[0] = slot[0].min(run_room(None, drive));
            slot[1] = slot[1].min(run_room(Some(&crowd), drive));
        }
    }
    let robot_seconds = ROOM_CYCLES as f64 / 1e6;
    println!(
        "the robot in a room (a world file: walls, two obstacles, a floor line; both drives at speed 40; {} s of robot time, best of {ROUNDS})",
        ROOM_CYCLES / 1_000_000
    );
    println!(
        "  without the room {:.1} ms, with it {:.1} ms a robot second: the world costs {:.1} ms of host time per robot second ({:.0}x real time with it)",
        bare / robot_seconds * 1e3,
        roomed / robot_seconds * 1e3,
        (roomed - bare) / robot_seconds * 1e3,
        robot_seconds / roomed
    );
    println!(
        "the world's cost per robot second, {CROWD} obstacles (the same room with posts all over it but the robot's way; best of {ROUNDS}):"
    );
    for ((without, with), how) in crowded
        .iter()
        .map(|slot| (slot[0], slot[1]))
        .zip(["driving at speed 40", "standing still"])
    {
        // Standing still, the robot alone idles (its loop skipped): the
        // ratio to it says little, the world's own cost says it all.
        println!(
            "  {how:<20} without the room {:.1} ms, with it {:.1} ms a robot second: the world costs {:.1} ms per robot second; with it {:.2}x the robot's host time alone, {:.0}x real time",
            without / robot_seconds * 1e3,
            with / robot_seconds * 1e3,
            (with - without) / robot_seconds * 1e3,
            with / without,
            robot_seconds / with
        );
    }

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
    let rust_seconds = best[2][0] * HOSTILE_CYCLES as f64 / CYCLES as f64;
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
