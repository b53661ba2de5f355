//! Issue 23's determinism property, on the virtual robot's side: a
//! project (the rangefinder extension, its card script, a surroundings
//! script that closes bumpers and moves the tracker's light over robot
//! time) driven by any sequence of commands and line noise, at any gaps,
//! run twice, gives the same robot state at every instruction: registers,
//! flags and cycle count before each instruction, then the same memory
//! and the same bytes back on the line. Step back and the rehearsals rest
//! on this.

mod rom_support;

use cards::{ScriptCard, ScriptWorld};
use emulator::{Bus, Control, Cpu, Hooks};
use proptest::prelude::*;
use rom_support::{build, examples_dir};
use romlib::VirtualScorpion;

/// The CPU's state before one instruction.
type State = (u64, u16, u8, u8, u8, u8, u8);

/// Records the state before every instruction.
#[derive(Default)]
struct Recorder(Vec<State>);

impl Hooks for Recorder {
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, _bus: &B) -> Control {
        self.0
            .push((cpu.cycles(), cpu.pc, cpu.a, cpu.x, cpu.y, cpu.s, cpu.p()));
        Control::Continue
    }
}

/// The world: its wake-ups and what it does at each come from `seed`.
fn world(seed: u32) -> String {
    format!(
        "fn init() {{ this.n = {seed}; wake_at(ms(1)); }}\n\
         fn wake(now) {{\n\
             this.n = (this.n * 1103515245 + 12345) % 2147483648;\n\
             bumpers((this.n / 65536) % 4);\n\
             tracker((this.n / 16) % 2 == 0, (this.n / 32) % 2 == 0);\n\
             wake_at(now + us(200 + this.n % 3000));\n\
         }}\n"
    )
}

/// One step of a session: bytes sent, then robot time run.
#[derive(Debug, Clone)]
struct Step {
    bytes: Vec<u8>,
    gap: u64,
}

fn steps() -> impl Strategy<Value = Vec<Step>> {
    let command = prop_oneof![
        4 => prop::sample::select(vec![
            "/1U", "/1B", "/1E", "/2E3", "/1P", "/1X", "/1T", "/8C100100", "/1M", "/3H05", "/1S",
            "/7R040002", "/1R",
        ])
        .prop_map(|c| c.as_bytes().to_vec()),
        1 => prop::collection::vec(any::<u8>(), 0..8),
    ];
    prop::collection::vec(
        (command, 0u64..30_000).prop_map(|(bytes, gap)| Step { bytes, gap }),
        1..12,
    )
}

/// Runs the project through `steps`: the state before every instruction,
/// the memory at the end and everything the robot sent.
fn run(image: &linker::Image, seed: u32, steps: &[Step]) -> (Vec<State>, Vec<u8>, Vec<u8>) {
    let mut robot = VirtualScorpion::new();
    let text = std::fs::read_to_string(examples_dir().join("rangefinder/rangefinder.rhai"))
        .expect("the example's card");
    let card = ScriptCard::load("rangefinder.rhai", &text, None).expect("the card loads");
    let (start, end) = card.window();
    robot
        .map_card(start, end, Box::new(card))
        .expect("its window is free");
    let world = ScriptWorld::load("world.rhai", &world(seed)).expect("the world loads");
    robot.set_surroundings(Box::new(world));
    robot.load_image(image).expect("the extension loads");
    let mut recorder = Recorder::default();
    let mut sent = Vec::new();
    for step in steps {
        robot.send(&step.bytes);
        let until = robot.cycles() + step.gap + 2_000;
        robot
            .run_until_with(until, |machine, to| machine.run_with(to, &mut recorder))
            .expect("the robot runs");
        sent.extend(robot.receive());
    }
    let memory = robot.robot().board().memory().to_vec();
    (recorder.0, memory, sent)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn a_project_run_twice_is_the_same_at_every_instruction(seed in any::<u32>(), steps in steps()) {
        let image = build(
            &[examples_dir().join("rangefinder/rangefinder.s")],
            "scorpion-ext",
        );
        let (first, memory, sent) = run(&image, seed, &steps);
        let (second, memory2, sent2) = run(&image, seed, &steps);
        prop_assert!(!first.is_empty());
        prop_assert_eq!(first.len(), second.len());
        if let Some(at) = first.iter().zip(&second).position(|(a, b)| a != b) {
            prop_assert!(false, "instruction {} differs: {:?} then {:?}", at, first[at], second[at]);
        }
        prop_assert!(memory == memory2, "the memory differs");
        prop_assert_eq!(sent, sent2);
    }
}
