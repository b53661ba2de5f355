//! Step back rests on determinism: the robot built again and run with the
//! host's actions replayed must be the robot that was there. A property:
//! random host actions and runs (commands, bumpers, steps, runs of robot
//! time) on a handler that talks to a card with state of its own; then,
//! at random points of that history, a step back must give exactly the
//! state seen there (registers, cycle, every byte of memory), and a
//! second debugger doing the same actions must see the same states.

mod build;

use std::any::Any;
use std::collections::BTreeMap;

use debugger::Debugger;
use emulator::board::Device;
use proptest::prelude::*;
use romlib::VirtualScorpion;

/// `/1Q` reads the card (whose value goes up by one at each read) and
/// answers `Q` and the value; any other command goes on to the ROM.
const SOURCE: &str = "
        .include \"scorpion.inc\"
CARD    = $8000
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cmp #'Q'
        bne not_mine
        lda CARD
        pha
        lda #'Q'
        jsr PUTCH
        pla
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

/// A card whose register counts its reads.
#[derive(Debug, Default)]
struct Counter(u8);

impl Device for Counter {
    fn read(&mut self, _offset: u16, _cycle: u64) -> u8 {
        self.0 = self.0.wrapping_add(1);
        self.0
    }
    fn write(&mut self, _offset: u16, value: u8, _cycle: u64) {
        self.0 = value;
    }
    fn peek(&self, _offset: u16) -> u8 {
        self.0
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

fn image() -> linker::Image {
    build::extension("q.s", SOURCE)
}

fn debugger(image: &linker::Image) -> Debugger {
    let loaded = image.clone();
    let make = Box::new(move || {
        let mut robot = VirtualScorpion::new();
        robot.map_card(0x8000, 0x8000, Box::new(Counter::default()))?;
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    Debugger::new(make, std::slice::from_ref(image)).expect("the robot builds")
}

/// Something done to the robot.
#[derive(Debug, Clone)]
enum Action {
    Send(&'static str),
    Bumpers(u8),
    Step(u64),
    Run(u64),
}

fn action() -> impl Strategy<Value = Action> {
    prop_oneof![
        prop::sample::select(vec!["/1Q", "/1X", "/2Q", "/3A", "/1Q/1Q"]).prop_map(Action::Send),
        any::<u8>().prop_map(Action::Bumpers),
        (1u64..400).prop_map(Action::Step),
        (1u64..40_000).prop_map(Action::Run),
    ]
}

/// Everything that makes the robot's state: registers, cycle, memory.
#[derive(Debug, Clone, PartialEq, Eq)]
struct State {
    instructions: u64,
    cycle: u64,
    registers: [u16; 6],
    memory: Vec<u8>,
}

fn state(d: &Debugger) -> State {
    let cpu = d.cpu();
    let bus = &d.robot().robot().bus;
    State {
        instructions: cpu.instructions(),
        cycle: d.robot().cycles(),
        registers: [
            cpu.pc,
            u16::from(cpu.a),
            u16::from(cpu.x),
            u16::from(cpu.y),
            u16::from(cpu.s),
            u16::from(cpu.p()),
        ],
        memory: (0..=u16::MAX)
            .map(|at| emulator::Bus::peek(bus, at))
            .collect(),
    }
}

/// The actions done on `d`, the state after each.
fn play(d: &mut Debugger, actions: &[Action]) -> Vec<State> {
    let mut states = vec![state(d)];
    for action in actions {
        match action {
            Action::Send(text) => d.send(text.as_bytes()),
            Action::Bumpers(closed) => d.set_bumpers(*closed),
            Action::Step(n) => {
                d.step(*n).expect("steps");
            }
            Action::Run(cycles) => {
                d.run(*cycles).expect("runs");
            }
        }
        states.push(state(d));
    }
    states
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn a_step_back_is_the_state_that_was_there(
        actions in prop::collection::vec(action(), 1..14),
        picks in prop::collection::vec(any::<prop::sample::Index>(), 1..4),
    ) {
        let image = image();
        let mut d = debugger(&image);
        let states = play(&mut d, &actions);
        // Run twice, the same states.
        let mut again = debugger(&image);
        prop_assert!(play(&mut again, &actions) == states, "a second run differs");
        // Back to random points of the history, latest first (a step back
        // goes back). At an instruction count where the host did several
        // things, going back lands after all of them: the last state there.
        let latest: BTreeMap<u64, &State> = states.iter().map(|s| (s.instructions, s)).collect();
        let latest: Vec<&State> = latest.into_values().collect();
        let mut targets: Vec<&State> = picks.iter().map(|pick| *pick.get(&latest)).collect();
        targets.sort_by_key(|s| std::cmp::Reverse(s.instructions));
        for target in targets {
            let now = d.cpu().instructions();
            d.back(now - target.instructions).expect("goes back");
            let there = state(&d);
            prop_assert!(
                there == *target,
                "back to instruction {}: cycle {} (not {}), registers {:04X?} (not {:04X?})",
                target.instructions, there.cycle, target.cycle, there.registers, target.registers
            );
        }
    }
}
