//! A card's or the surroundings' copy (for a debugger's checkpoints) goes
//! on exactly as the original would, apart from it: the script's `this`,
//! register table and wake-up are copied, not shared.

use cards::{ScriptCard, ScriptWorld};
use emulator::board::Device;
use romlib::Surroundings;

const COUNTER: &str = r"
const SIZE = 1;
const BASE = 0x9000;
// Every read counts: its effects are declared.
const VOLATILE = [0];
fn init() { this.count = 0; this.seen = []; }
fn read(reg, now) { this.count += 1; this.seen.push(now); this.count }
";

#[test]
fn a_script_cards_copy_goes_on_as_the_original_would() {
    let mut card = ScriptCard::load("counter.rhai", COUNTER, None).expect("loads");
    assert_eq!(card.read(0, 10), 1);
    assert_eq!(card.read(0, 20), 2);
    let mut copy = card.snapshot().expect("a script card can be copied");
    assert_eq!(card.read(0, 30), 3);
    assert_eq!(card.read(0, 40), 4);
    // The copy did not see the original's reads: it counts on from 2.
    assert_eq!(copy.read(0, 30), 3);
    assert_eq!(copy.read(0, 40), 4);
    assert_eq!(card.read(0, 50), 5);
}

#[test]
fn a_card_whose_state_shares_a_closures_variable_is_not_copied() {
    let text = r"
const SIZE = 1;
const BASE = 0x9000;
fn init() { let n = 0; this.bump = || { n += 1; n }; }
fn read(reg, now) { this.bump.call() }
";
    let card = ScriptCard::load("closure.rhai", text, None).expect("loads");
    assert!(card.snapshot().is_none());
}

#[test]
fn the_surroundings_copy_wakes_as_the_original_would() {
    let text = r"
fn init() { this.closed = 0; wake_at(1000); }
fn wake(now) { this.closed = (this.closed + 1) % 4; bumpers(this.closed); wake_at(now + 1000); }
";
    let mut world = ScriptWorld::load("bump.rhai", text).expect("loads");
    let mut robot = emulator::board::Scorpion::scorpion(romlib::ROM).expect("the ROM");
    // Each wake-up: when, and the board as it left it (the bumpers).
    let wake = |world: &mut dyn Surroundings, robot: &mut emulator::board::Scorpion| {
        let at = world.next_wake().expect("a wake-up");
        world.wake(at, robot).expect("wakes");
        (at, format!("{:?}", robot.board()))
    };
    let first = wake(&mut world, &mut robot);
    let mut copy = world.snapshot().expect("a script world can be copied");
    let mut robot_copy = robot.snapshot().expect("no cards");
    let original: Vec<_> = (0..3).map(|_| wake(&mut world, &mut robot)).collect();
    let copied: Vec<_> = (0..3)
        .map(|_| wake(copy.as_mut(), &mut robot_copy))
        .collect();
    assert_eq!(original, copied);
    assert_ne!(first, original[0]);
}
