//! A card's `read` is called only when its answer can have changed
//! (issue 28, 4): the answer is kept until a write to the card, a
//! wake-up, or a read of a register the script lists in `VOLATILE`.
//!
//! The property: for scripts generated from fragments (reads that depend
//! on the register, `this` and the table; writes and wake-ups that change
//! them), a card served from its cache answers every read of a generated
//! sequence as the same card does with every register `VOLATILE` (every
//! read a call). Short in CI (`PROPTEST_CASES` asks for more).

use cards::ScriptCard;
use emulator::board::{Device, Scorpion};
use proptest::prelude::*;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|cases| cases.parse().ok())
        .unwrap_or(32)
}

/// What `read(reg, now)` answers: a function of the register, `this` and
/// the table, never of `now` (a register whose answer changes with robot
/// time alone must be `VOLATILE`).
const READS: &[&str] = &[
    "(reg * 37 + this.a) & 0xFF",
    "get(reg) ^ 0x5A",
    "(this.b + reg) & 0xFF",
    "if this.a > reg * 40 { 0x80 } else { get(reg) }",
    "(this.a * 3 + this.b) & 0xFF",
];

/// What `write(reg, value, now)` does.
const WRITES: &[&str] = &[
    "this.a = value;",
    "set(reg, value);",
    "this.b = (this.b + value) & 0xFF;",
    "set((reg + 1) % 4, value ^ 0xFF);",
    "wake_at(now + 30);",
];

/// What `wake(now)` does.
const WAKES: &[&str] = &[
    "this.a = (this.a + 1) & 0xFF;",
    "set(0, now & 0xFF);",
    "this.b = (this.b * 5 + 1) & 0xFF;",
    "wake_at(now + 45);",
];

/// One access by the CPU: robot time moves on by `after` first.
#[derive(Debug, Clone)]
enum Access {
    Read {
        register: u16,
        after: u64,
    },
    Write {
        register: u16,
        value: u8,
        after: u64,
    },
}

fn access() -> impl Strategy<Value = Access> {
    prop_oneof![
        3 => (0u16..4, 0u64..200).prop_map(|(register, after)| Access::Read { register, after }),
        1 => (0u16..4, any::<u8>(), 0u64..200)
            .prop_map(|(register, value, after)| Access::Write { register, value, after }),
    ]
}

fn script() -> impl Strategy<Value = String> {
    (
        prop::sample::select(READS),
        prop::collection::vec(prop::sample::select(WRITES), 1..3),
        prop::collection::vec(prop::sample::select(WAKES), 1..3),
        1u64..500,
    )
        .prop_map(|(read, writes, wakes, first)| {
            format!(
                "const SIZE = 4;\nconst BASE = 0x9000;\n\
                 fn init() {{ this.a = 0; this.b = 7; wake_at({first}); }}\n\
                 fn read(reg, now) {{ {read} }}\n\
                 fn write(reg, value, now) {{ {} }}\n\
                 fn wake(now) {{ {} wake_at(now + 100); }}\n",
                writes.concat(),
                wakes.concat()
            )
        })
}

/// The answers of `card` to `accesses`, from robot time 1 on.
fn answers(card: &mut ScriptCard, accesses: &[Access]) -> Vec<u8> {
    let mut now = 1;
    let mut answers = Vec::new();
    for access in accesses {
        match *access {
            Access::Read { register, after } => {
                now += after;
                answers.push(card.read(register, now));
            }
            Access::Write {
                register,
                value,
                after,
            } => {
                now += after;
                card.write(register, value, now);
            }
        }
    }
    answers
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn answers_served_from_the_cache_are_the_scripts(
        text in script(),
        accesses in prop::collection::vec(access(), 1..60),
    ) {
        let every_read = text.replace(
            "const BASE = 0x9000;",
            "const BASE = 0x9000;\nconst VOLATILE = [0, 1, 2, 3];",
        );
        let mut cached = ScriptCard::load("cached.rhai", &text, None).expect("loads");
        let mut called = ScriptCard::load("called.rhai", &every_read, None).expect("loads");
        let from_cache = answers(&mut cached, &accesses);
        let from_calls = answers(&mut called, &accesses);
        prop_assert!(cached.take_fault().is_none());
        prop_assert!(called.take_fault().is_none());
        prop_assert_eq!(from_cache, from_calls, "{}", text);
    }
}

/// A card whose `read` prints each time it runs: how many calls a run of
/// reads made.
const COUNTED: &str = r#"
const SIZE = 2;
const BASE = 0x9000;
fn init() { this.level = 1; wake_at(1000); }
fn read(reg, now) { print("read"); this.level + reg }
fn write(reg, value, now) { this.level = value; }
fn wake(now) { this.level += 10; }
"#;

fn calls(card: &ScriptCard) -> usize {
    card.printed().take().len()
}

#[test]
fn a_polled_register_calls_read_once() {
    let mut card = ScriptCard::load("counted.rhai", COUNTED, None).expect("loads");
    for now in 1..500 {
        assert_eq!(card.read(1, now), 2);
    }
    assert_eq!(calls(&card), 1, "one call, then the cache");
}

#[test]
fn a_write_forgets_the_answers() {
    let mut card = ScriptCard::load("counted.rhai", COUNTED, None).expect("loads");
    assert_eq!(card.read(0, 10), 1);
    assert_eq!(card.read(1, 11), 2);
    card.write(1, 40, 12);
    assert_eq!(
        card.read(0, 13),
        40,
        "register 0 was not written, but read 40"
    );
    assert_eq!(card.read(1, 14), 41);
    assert_eq!(calls(&card), 4);
}

#[test]
fn a_wake_up_forgets_the_answers() {
    let mut card = ScriptCard::load("counted.rhai", COUNTED, None).expect("loads");
    assert_eq!(card.read(0, 999), 1);
    assert_eq!(card.read(0, 1000), 11, "woken at 1000, before the read");
    assert_eq!(card.read(0, 1001), 11);
    assert_eq!(calls(&card), 2);
}

#[test]
fn a_volatile_register_calls_read_every_time_and_forgets_the_others() {
    // A data register that counts its reads (as one that clears an
    // interrupt would), and a status that shows the count.
    let text = "const SIZE = 2;\nconst BASE = 0x9000;\nconst VOLATILE = [0];\n\
                fn init() { this.reads = 0; }\n\
                fn read(reg, now) { if reg == 0 { this.reads += 1; 0 } else { this.reads } }\n";
    let mut card = ScriptCard::load("fifo.rhai", text, None).expect("loads");
    assert_eq!(card.read(1, 1), 0);
    for now in 2..6 {
        let _ = card.read(0, now);
    }
    assert_eq!(card.read(1, 6), 4, "the status after four data reads");
    assert!(card.take_fault().is_none());
}

#[test]
fn a_volatile_list_names_registers_of_the_card() {
    let text =
        "const SIZE = 2;\nconst BASE = 0x9000;\nconst VOLATILE = [2];\nfn read(reg, now) { 0 }\n";
    let error = ScriptCard::load("wrong.rhai", text, None).expect_err("refused");
    assert!(
        error
            .to_string()
            .contains("`VOLATILE` lists 2, not a register of 0 to 1"),
        "{error}"
    );
}

/// A program that polls a register the card answers through `read` runs
/// as if every read called it: it sees the change a wake-up makes at the
/// same cycle, the emulator skipping the loop while the answer holds.
#[test]
fn a_polling_program_sees_a_wake_up_at_the_same_cycle() {
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\n\
                fn init() { this.ready = false; wake_at(5000); }\n\
                fn read(reg, now) { if this.ready { 0x80 } else { 0 } }\n\
                fn wake(now) { this.ready = true; }\n";
    let every_read = text.replace(
        "const BASE = 0x9000;",
        "const BASE = 0x9000;\nconst VOLATILE = [0];",
    );
    // How many times the program counted past the loop by cycle
    // 20,000: a change seen a cycle later or earlier changes the count.
    let run = |text: &str| {
        let card = ScriptCard::load("ready.rhai", text, None).expect("loads");
        let mut rom = vec![0xEA; 0x1000];
        // loop: BIT $9000 / BPL loop / count: INC $00 / JMP count
        rom[..10].copy_from_slice(&[0x2C, 0x00, 0x90, 0x10, 0xFB, 0xE6, 0x00, 0x4C, 0x05, 0xF0]);
        rom[0xFFC..].copy_from_slice(&[0x00, 0xF0, 0x00, 0xF0]);
        let mut robot = Scorpion::scorpion(&rom).expect("a 4 KiB ROM");
        robot
            .map_kim(0x9000, 0x9000, Box::new(card))
            .expect("a free window");
        robot.run(5_000 + 8 * 100);
        let counted = emulator::Bus::peek(robot.board(), 0);
        (counted, robot.cpu.pc)
    };
    let cached = run(text);
    assert!((90..=100).contains(&cached.0), "{cached:?}");
    assert_eq!(cached, run(&every_read));
}
