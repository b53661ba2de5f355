//! Cards and surroundings as scripts (issue 13): the examples' card scripts
//! on the virtual Scorpion with the examples' extensions, an interrupt from
//! a script card reaching the CPU, and a bumper that a surroundings script
//! closes while the robot runs.

mod rom_support;

use cards::{ScriptCard, ScriptWorld};
use emulator::board::{Motor, Scorpion};
use rom_support::{Session, build, examples_dir, upload};
use romlib::symbols::IOBYTE;

fn script(path: &str) -> String {
    std::fs::read_to_string(examples_dir().join(path)).expect("the example's script")
}

/// A session with the card script `text` mapped where it says.
fn with_card(name: &str, text: &str) -> Session {
    let mut s = Session::new();
    let card = ScriptCard::load(name, text, None).expect("the card loads");
    let (start, end) = card.window();
    s.robot
        .map_card(start, end, Box::new(card))
        .expect("its window is free KIM-bus space");
    s
}

#[test]
fn the_rangefinder_answers_the_distance_its_card_script_sets() {
    let text = script("rangefinder/rangefinder.rhai");
    let mut s = with_card("rangefinder.rhai", &text);
    upload(
        &mut s,
        &build(
            &[examples_dir().join("rangefinder/rangefinder.s")],
            "scorpion-ext",
        ),
    );
    assert_eq!(s.ask("/1U"), "U0123\r", "the script's obstacle");

    // Another obstacle, set in the script: another answer, after the echo's
    // flight time (58 us a centimetre there and back).
    let far = text.replace("this.obstacle = 123;", "this.obstacle = 350;");
    let mut s = with_card("rangefinder.rhai", &far);
    upload(
        &mut s,
        &build(
            &[examples_dir().join("rangefinder/rangefinder.s")],
            "scorpion-ext",
        ),
    );
    let before = s.robot.cycles();
    assert_eq!(s.ask("/1U"), "U0350\r");
    let took = s.robot.cycles() - before;
    assert!(
        took > 350 * 58,
        "the answer waited for the echo: {took} cycles"
    );

    // Open space: no echo within 4 m.
    let open = text.replace("this.obstacle = 123;", "this.obstacle = 0;");
    let mut s = with_card("rangefinder.rhai", &open);
    upload(
        &mut s,
        &build(
            &[examples_dir().join("rangefinder/rangefinder.s")],
            "scorpion-ext",
        ),
    );
    assert_eq!(s.ask("/1U"), "U----\r");
}

#[test]
fn the_adc_extension_reads_the_channels_of_its_card_script() {
    let mut s = with_card("adc.rhai", &script("adc/adc.rhai"));
    upload(
        &mut s,
        &build(&[examples_dir().join("adc/adc.s")], "scorpion-ext"),
    );
    assert_eq!(s.ask("/2A0"), "AC0\r", "192 on channel 0");
    assert_eq!(s.ask("/2A1"), "A57\r", "87 on channel 1");
    // Not a channel: not the extension's; the ROM ignores it, and the
    // extension still answers after it.
    assert_eq!(s.send("/2A9"), None);
    assert_eq!(s.ask("/2A0"), "AC0\r");
}

/// A 4 KiB ROM: reset code at $F000, the IRQ handler at $F800.
fn rom(program: &[u8], handler: &[u8]) -> Vec<u8> {
    let mut rom = vec![0xEA; 0x1000];
    rom[..program.len()].copy_from_slice(program);
    rom[0x800..0x800 + handler.len()].copy_from_slice(handler);
    rom[0xFFC..].copy_from_slice(&[0x00, 0xF0, 0x00, 0xF8]);
    rom
}

#[test]
fn the_adc_cards_interrupt_reaches_the_cpu() {
    // Start a conversion of channel 1 with its interrupt on, then spin; the
    // handler reads DATA (which releases /IRQ) into $10 and counts in $11.
    let program = [
        0x58, // CLI
        0xA9, 0xC1, 0x8D, 0x00, 0x90, // LDA #$C1 / STA $9000
        0x4C, 0x06, 0xF0, // JMP *
    ];
    let handler = [
        0xAD, 0x02, 0x90, // LDA $9002
        0x85, 0x10, // STA $10
        0xE6, 0x11, // INC $11
        0x40, // RTI
    ];
    let mut robot = Scorpion::scorpion(&rom(&program, &handler)).expect("a 4 KiB ROM");
    let card = ScriptCard::load("adc.rhai", &script("adc/adc.rhai"), None).expect("loads");
    robot.map_kim(0x9000, 0x9002, Box::new(card)).expect("free");
    robot.run(90);
    let memory = |robot: &Scorpion, at: usize| robot.board().memory()[at];
    assert_eq!(memory(&robot, 0x11), 0, "not before the conversion ends");
    robot.run(300);
    assert_eq!(
        memory(&robot, 0x11),
        1,
        "one interrupt, 100 us after the start"
    );
    assert_eq!(memory(&robot, 0x10), 87, "channel 1's reading");
    robot.run(10_000);
    assert_eq!(memory(&robot, 0x11), 1, "reading DATA released /IRQ");
}

#[test]
fn a_bumper_the_surroundings_close_at_half_a_second_makes_patrol_back_away() {
    let world = ScriptWorld::load(
        "obstacle.rhai",
        "fn init() { wake_at(ms(500)); }\nfn wake(now) { bumpers(0x10); }\n",
    )
    .expect("loads");
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(world));
    // Loaded as an upload leaves it, at once: the run starts near 0 s.
    let patrol = build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os");
    s.robot.load_image(&patrol).expect("patrol loads");
    s.send("/2A1");
    let start = s.robot.cycles();
    let io = |s: &Session| s.robot.robot().board().memory()[usize::from(IOBYTE)];
    // Robot time is counted from power-up: the bumper closes at 0.5 s.
    s.robot.run_until(490_000).expect("runs");
    assert!(start < 100_000, "patrolling from {start} cycles");
    assert_eq!(io(&s) & 0x80, 0, "no bumper yet at 0.49 s");
    let cruised = s.position(Motor::Left);
    assert!(cruised > 0, "cruising: {cruised}");
    s.robot.run_until(510_000).expect("runs");
    assert_eq!(io(&s) & 0x80, 0x80, "the ROM set Master I/O bit 7 at 0.5 s");
    let hit = s.position(Motor::Left);
    s.robot.run_until(600_000).expect("runs");
    let backing = s.position(Motor::Left);
    assert!(backing < hit, "patrol backs away: {hit} then {backing}");
}

/// The surroundings example of docs/CARDS.md, run as written: a wall 500
/// steps ahead of patrol's cruise.
#[test]
fn the_docs_wall_closes_the_bumper_where_the_robot_meets_it() {
    let docs =
        std::fs::read_to_string(examples_dir().join("../docs/CARDS.md")).expect("docs/CARDS.md");
    let start = docs.find("```rhai\n").expect("the example") + 8;
    let end = start + docs[start..].find("```").expect("its end");
    let world = ScriptWorld::load("wall.rhai", &docs[start..end]).expect("the example loads");
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(world));
    let patrol = build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os");
    s.robot.load_image(&patrol).expect("patrol loads");
    s.send("/2A1");
    let io = |s: &Session| s.robot.robot().board().memory()[usize::from(IOBYTE)];
    let mut met = None;
    for _ in 0..400 {
        s.robot.run_for(10_000).expect("runs");
        if io(&s) & 0x80 != 0 {
            met = Some(s.position(Motor::Left));
            break;
        }
    }
    let met = met.expect("the robot met the wall within 4 s");
    assert!(
        (500..520).contains(&met),
        "the bumper closed at {met} steps"
    );
}

/// Surroundings that change the robot's inputs at irregular times and
/// print what they see.
const RESTLESS_WORLD: &str = r#"
fn init() { this.n = 0; wake_at(ms(1)); }
fn wake(now) {
    this.n += 1;
    bumpers(if this.n % 3 == 0 { 0x10 } else { 0 });
    tracker(this.n % 2 == 0, true);
    print(`${now} ${left_position()} ${right_position()}`);
    wake_at(now + 137 * (this.n % 5 + 1));
}
"#;

/// The robot after every instruction: registers, cycle, the zero page.
type Trace = Vec<(emulator::Cpu, u64, [u8; 256])>;

/// A project with a card and surroundings, run: the robot's state at
/// every instruction of 0.2 s between two questions, the answers, and
/// what the surroundings printed.
fn rigged_run() -> (Trace, Vec<String>, Vec<String>) {
    let mut s = with_card("rangefinder.rhai", &script("rangefinder/rangefinder.rhai"));
    let world = ScriptWorld::load("restless.rhai", RESTLESS_WORLD).expect("loads");
    let printed = world.printed();
    s.robot.set_surroundings(Box::new(world));
    upload(
        &mut s,
        &build(
            &[examples_dir().join("rangefinder/rangefinder.s")],
            "scorpion-ext",
        ),
    );
    let mut answers = vec![s.ask("/1U")];
    let mut trace = Trace::new();
    let until = s.robot.cycles() + 200_000;
    s.robot
        .run_until_with(until, |robot, to| {
            while robot.now() < to {
                let _ = robot.step();
                let mut zero_page = [0; 256];
                zero_page.copy_from_slice(&robot.board().memory()[..256]);
                trace.push((robot.cpu.clone(), robot.now(), zero_page));
            }
            emulator::Stop::Limit
        })
        .expect("runs");
    answers.push(s.ask("/1U"));
    (trace, answers, printed.take())
}

/// Issue 23: nothing a script does depends on the host (its clock, its
/// randomness, its speed): the same project run twice is the same robot
/// at every instruction, which step back in the debugger rests on.
#[test]
fn a_project_with_scripts_runs_the_same_twice_instruction_for_instruction() {
    let (first, first_answers, first_printed) = rigged_run();
    let (second, second_answers, second_printed) = rigged_run();
    assert_eq!(first_answers, ["U0123\r", "U0123\r"]);
    assert_eq!(first_answers, second_answers);
    assert!(
        first_printed.len() > 50,
        "the world woke: {first_printed:?}"
    );
    assert_eq!(first_printed, second_printed);
    assert!(first.len() > 10_000, "{} instructions", first.len());
    assert_eq!(first.len(), second.len());
    let differs = first.iter().zip(&second).position(|(a, b)| a != b);
    assert_eq!(differs, None, "the runs part at that instruction");
}
