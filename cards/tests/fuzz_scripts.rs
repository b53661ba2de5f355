//! Card and surroundings scripts built at random from hostile fragments
//! (waking now or in the past, loops, floods of output and calls, deep
//! recursion, huge strings, the host's clock, syntax errors) and numbers
//! (zero, small, huge, negative), each run for a budget of robot time:
//! every one ends, with what it printed bounded, and a second run gives
//! the same fault, the same output and the same robot, instruction for
//! instruction (nothing in a script sees the host's clock or randomness).
//!
//! Short in CI (`PROPTEST_CASES` asks for more).

use std::sync::mpsc;
use std::time::Duration;

use cards::{MAX_PRINTED_LINES, ScriptCard, ScriptWorld};
use emulator::board::Scorpion;
use proptest::prelude::*;
use romlib::VirtualScorpion;

/// Robot time each script runs for.
const ROBOT_CYCLES: u64 = 20_000;

/// Host time a run may take before it counts as a hang.
const WATCHDOG: Duration = Duration::from_secs(120);

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|cases| cases.parse().ok())
        .unwrap_or(16)
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_owned()),
        (1_i64..100).prop_map(|n| n.to_string()),
        (100_i64..100_000).prop_map(|n| n.to_string()),
        Just("9223372036854775807".to_owned()),
        Just("-9223372036854775807".to_owned()),
        (1_i64..1000).prop_map(|n| format!("-{n}")),
    ]
}

/// A statement that may appear in any function; `$N` is a number.
const ANYWHERE: &[&str] = &[
    "print(\"x\")",
    "for i in 0..$N { print(i); }",
    "debug(`${this}`)",
    "loop { }",
    "while true { }",
    "for i in 0..$N { }",
    "this.x = $N",
    "this.x = (this.x ?? 0) + 1",
    "this.list = []; this.list.pad($N, 0)",
    "let s = \"x\"; s.pad($N, \"y\")",
    "sleep($N)",
    "timestamp()",
    "throw \"boom\"",
    "missing($N)",
    "$N / 0",
    "deep(0)",
    "wake_at($N)",
    "{",
    "}",
    ";;",
    "let n = $N; n * n",
];

/// A statement that needs `now` (in `read`, `write`, `wake`).
const WITH_NOW: &[&str] = &[
    "wake_at(now)",
    "wake_at(now + $N)",
    "wake_at(now - $N)",
    "wake_at(now + us(1))",
    "wake_at(now + ms($N))",
];

const CARD: &[&str] = &["set($N, $N)", "get($N)", "irq(true)", "irq(false)"];

const WORLD: &[&str] = &[
    "bumpers($N)",
    "for i in 0..60000 { bumpers(i); }",
    "tracker(true, false)",
    "scene($N)",
    "scene_at($N, $N, $N)",
    "left_position() + right_position()",
];

/// A body of up to four statements from `pools`, numbers filled in.
fn body(pools: Vec<&'static [&'static str]>) -> impl Strategy<Value = String> {
    let all: Vec<&'static str> = pools.into_iter().flatten().copied().collect();
    prop::collection::vec((prop::sample::select(all), number()), 0..4).prop_map(|statements| {
        statements
            .into_iter()
            .map(|(statement, n)| statement.replace("$N", &n) + ";\n")
            .collect()
    })
}

fn card_script() -> impl Strategy<Value = String> {
    (
        prop_oneof![Just("4".to_owned()), number()],
        prop_oneof![Just("0x9000".to_owned()), number()],
        body(vec![ANYWHERE, CARD]),
        body(vec![ANYWHERE, WITH_NOW, CARD]),
        body(vec![ANYWHERE, WITH_NOW, CARD]),
        body(vec![ANYWHERE, WITH_NOW, CARD]),
        number(),
    )
        .prop_map(|(size, base, init, read, write, wake, answer)| {
            format!(
                "const SIZE = {size};\nconst BASE = {base};\nfn deep(n) {{ deep(n + 1) }}\n\
                 fn init() {{\n{init}}}\nfn read(reg, now) {{\n{read}{answer}\n}}\n\
                 fn write(reg, value, now) {{\n{write}}}\nfn wake(now) {{\n{wake}}}\n"
            )
        })
}

fn world_script() -> impl Strategy<Value = String> {
    (
        body(vec![ANYWHERE, WORLD]),
        body(vec![ANYWHERE, WITH_NOW, WORLD]),
    )
        .prop_map(|(init, wake)| {
            format!(
                "fn deep(n) {{ deep(n + 1) }}\nfn init() {{\nwake_at(1);\n{init}}}\n\
                 fn wake(now) {{\n{wake}wake_at(now + 100);\n}}\n"
            )
        })
}

/// What a run comes to: the failure, what was printed, and the robot's
/// state after every instruction (registers, cycles, the zero page).
#[derive(Debug, PartialEq)]
struct Outcome {
    fault: Option<String>,
    printed: Vec<String>,
    trace: Vec<(emulator::Cpu, u64, [u8; 256])>,
}

/// A 4 KiB ROM that writes and reads the card at `$9000-$9003` in a loop.
fn rom() -> Vec<u8> {
    let mut rom = vec![0xEA; 0x1000];
    // loop: LDA $9000 / STA $10 / INC $9001 / LDA $9003 / JMP loop
    rom[..15].copy_from_slice(&[
        0xAD, 0x00, 0x90, 0x85, 0x10, 0xEE, 0x01, 0x90, 0xAD, 0x03, 0x90, 0x4C, 0x00, 0xF0, 0xEA,
    ]);
    rom[0xFFC..].copy_from_slice(&[0x00, 0xF0, 0x00, 0xF0]);
    rom
}

fn zero_page(memory: &[u8]) -> [u8; 256] {
    let mut page = [0; 256];
    page.copy_from_slice(&memory[..256]);
    page
}

fn run_card(text: &str) -> Outcome {
    let card = match ScriptCard::load("fuzz.rhai", text, None) {
        Ok(card) => card,
        Err(error) => {
            return Outcome {
                fault: Some(error.to_string()),
                printed: Vec::new(),
                trace: Vec::new(),
            };
        }
    };
    let printed = card.printed();
    let (start, end) = card.window();
    let mut robot = Scorpion::scorpion(&rom()).expect("a 4 KiB ROM");
    robot
        .map_kim(start, end, Box::new(card))
        .expect("a window on the KIM bus");
    let mut trace = Vec::new();
    while robot.now() < ROBOT_CYCLES {
        let _ = robot.step();
        trace.push((
            robot.cpu.clone(),
            robot.now(),
            zero_page(robot.board().memory()),
        ));
    }
    let fault = robot
        .board_mut()
        .take_device_fault()
        .map(|(_, fault)| fault.to_string());
    Outcome {
        fault,
        printed: printed.take(),
        trace,
    }
}

fn run_world(text: &str) -> Outcome {
    let world = match ScriptWorld::load("fuzz.rhai", text) {
        Ok(world) => world,
        Err(error) => {
            return Outcome {
                fault: Some(error.to_string()),
                printed: Vec::new(),
                trace: Vec::new(),
            };
        }
    };
    let printed = world.printed();
    let mut robot = VirtualScorpion::new();
    robot.set_surroundings(Box::new(world));
    let mut trace = Vec::new();
    let until = robot.cycles() + ROBOT_CYCLES;
    let fault = robot
        .run_until_with(until, |robot, to| {
            while robot.now() < to {
                let _ = robot.step();
                trace.push((
                    robot.cpu.clone(),
                    robot.now(),
                    zero_page(robot.board().memory()),
                ));
            }
            emulator::Stop::Limit
        })
        .err()
        .map(|error| error.to_string());
    Outcome {
        fault,
        printed: printed.take(),
        trace,
    }
}

/// Runs `run(text)` twice under the watchdog.
fn twice(text: String, run: fn(&str) -> Outcome) -> Result<(Outcome, Outcome), TestCaseError> {
    let (done, outcome) = mpsc::channel();
    std::thread::spawn(move || {
        let first = run(&text);
        let second = run(&text);
        let _ = done.send((first, second));
    });
    outcome
        .recv_timeout(WATCHDOG)
        .map_err(|why| TestCaseError::fail(format!("no end: {why}")))
}

fn check(first: &Outcome, second: &Outcome) -> Result<(), TestCaseError> {
    prop_assert!(first.printed.len() <= MAX_PRINTED_LINES + 1);
    prop_assert_eq!(&first.fault, &second.fault);
    prop_assert_eq!(&first.printed, &second.printed);
    prop_assert!(first.trace == second.trace, "the robot differs");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn any_card_script_ends_bounded_and_the_same_each_time(text in card_script()) {
        let (first, second) = twice(text, run_card)?;
        check(&first, &second)?;
    }

    #[test]
    fn any_world_script_ends_bounded_and_the_same_each_time(text in world_script()) {
        let (first, second) = twice(text, run_world)?;
        check(&first, &second)?;
    }
}
