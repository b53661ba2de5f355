//! The examples in `examples/`, built with our own assembler and linker
//! against the reference ROM, written into the virtual Scorpion with `/9W`
//! commands over the emulated serial line, hooked in, and used: a new
//! command for a KIM-bus card, a second extension chained behind it, and an
//! operating system that takes over the control loop. Transcripts are insta
//! snapshots.

mod rom_support;

use std::any::Any;

use emulator::board::{Device, Motor};
use rom_support::{Session, build, examples_dir, upload};
use romlib::symbols::BUSY;

/// A model of the ultrasonic rangefinder card of `examples/rangefinder`:
/// four registers, a measurement that takes as long as the echo's round
/// trip (58 us per centimetre), 25 ms and "no echo" beyond 4 m.
#[derive(Debug, Default)]
struct RangeCard {
    /// The obstacle's distance in centimetres, `None` for open space.
    obstacle: Option<u16>,
    /// When the running measurement ends, and its result.
    done_at: Option<(u64, Option<u16>)>,
    range: u16,
    no_echo: bool,
    pings: u32,
}

const ROUND_TRIP_CYCLES_PER_CM: u64 = 58;
const MAX_RANGE_CM: u16 = 400;
const NO_ECHO_CYCLES: u64 = 25_000;

impl RangeCard {
    fn finish(&mut self, cycle: u64) {
        if let Some((at, result)) = self.done_at {
            if cycle >= at {
                self.done_at = None;
                self.range = result.unwrap_or(0);
                self.no_echo = result.is_none();
            }
        }
    }
}

impl Device for RangeCard {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.finish(cycle);
        self.peek(offset)
    }

    fn write(&mut self, offset: u16, value: u8, cycle: u64) {
        self.finish(cycle);
        if offset == 0 && value & 1 == 1 && self.done_at.is_none() {
            self.pings += 1;
            let result = self.obstacle.filter(|&cm| cm <= MAX_RANGE_CM);
            let time = result.map_or(NO_ECHO_CYCLES, |cm| {
                u64::from(cm) * ROUND_TRIP_CYCLES_PER_CM
            });
            self.done_at = Some((cycle + time, result));
        }
    }

    fn peek(&self, offset: u16) -> u8 {
        match offset {
            1 => {
                let busy = if self.done_at.is_some() { 0x80 } else { 0 };
                busy | u8::from(self.no_echo)
            }
            2 => (self.range & 0xFF) as u8,
            3 => (self.range >> 8) as u8,
            _ => 0,
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

fn rangefinder() -> linker::Image {
    build(
        &[examples_dir().join("rangefinder/rangefinder.s")],
        "scorpion-ext",
    )
}

fn checksum() -> linker::Image {
    let layout = examples_dir().join("checksum/checksum.toml");
    build(
        &[examples_dir().join("checksum/checksum.s")],
        layout.to_str().expect("a UTF-8 path"),
    )
}

fn patrol() -> linker::Image {
    build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os")
}

/// A robot with the rangefinder card at $8000 and the obstacle at `cm`.
fn robot_with_card(cm: Option<u16>) -> (Session, emulator::board::KimSlotId) {
    let mut s = Session::new();
    let slot = s
        .robot
        .robot_mut()
        .map_kim(
            0x8000,
            0x8003,
            Box::new(RangeCard {
                obstacle: cm,
                ..RangeCard::default()
            }),
        )
        .expect("$8000 is free KIM-bus space");
    (s, slot)
}

fn set_obstacle(s: &mut Session, slot: emulator::board::KimSlotId, cm: Option<u16>) {
    s.note(&format!("obstacle at {cm:?} cm"));
    s.robot
        .robot_mut()
        .board_mut()
        .kim_device_mut::<RangeCard>(slot)
        .expect("the card is mapped")
        .obstacle = cm;
}

#[test]
fn an_extension_answers_a_new_command_from_a_kim_bus_card() {
    let (mut s, slot) = robot_with_card(Some(123));
    let image = rangefinder();
    assert_eq!(image.hooks.records.len(), 1);
    // Before the upload the ROM drops /1U like any unknown command.
    s.tell_raw(b"/1U");
    upload(&mut s, &image);
    assert_eq!(s.ask("/1U"), "U0123\r");
    set_obstacle(&mut s, slot, Some(7));
    assert_eq!(s.ask("/1U"), "U0007\r");
    set_obstacle(&mut s, slot, None);
    assert_eq!(s.ask("/1U"), "U----\r");
    set_obstacle(&mut s, slot, Some(401));
    assert_eq!(s.ask("/1U"), "U----\r", "beyond 4 m: no echo");
    let pings = s
        .robot
        .robot()
        .board()
        .kim_device::<RangeCard>(slot)
        .expect("mapped")
        .pings;
    assert_eq!(pings, 4);
    // Other unknown commands still fall through to the ROM and vanish;
    // the ROM's own commands are untouched.
    s.tell_raw(b"/2U1");
    s.tell_raw(b"/1Q");
    assert_eq!(s.ask("/1X"), "X00\r");
    // A measurement keeps the robot receiving: commands sent right behind
    // /1U are all executed.
    set_obstacle(&mut s, slot, Some(300));
    s.robot.send(b"/1U/2E3/2G1/1P");
    let first = s
        .robot
        .read_answer(romlib::sim::ANSWER_TIMEOUT)
        .expect("the range");
    let second = s
        .robot
        .read_answer(romlib::sim::ANSWER_TIMEOUT)
        .expect("the status");
    assert_eq!(String::from_utf8_lossy(&first), "U0300\r");
    assert!(String::from_utf8_lossy(&second).starts_with("PB00E3G1"));
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn a_second_extension_chains_behind_the_first() {
    let (mut s, _slot) = robot_with_card(Some(42));
    let first = rangefinder();
    let second = checksum();
    assert!(
        second.areas.iter().all(|a| a.load >= 0x0C00),
        "the second extension sits above the first"
    );
    upload(&mut s, &first);
    upload(&mut s, &second);
    // HOOK_UNKNOWN -> checksum -> rangefinder -> BAD_COMMAND.
    let hook = s.ask("/7R020102");
    let handler = second.hooks.records[0].handler;
    assert_eq!(
        hook,
        format!("R{:02X}{:02X}\r", handler & 0xFF, handler >> 8)
    );
    // The checksum of the ROM's first kilobyte, computed here too.
    let expected: u32 = romlib::ROM[..0x400].iter().map(|&b| u32::from(b)).sum();
    assert_eq!(
        s.ask("/9KF0000400"),
        format!("K{:04X}\r", expected & 0xFFFF)
    );
    // Of the first extension as it sits in RAM.
    let code = &first.areas[0];
    let sum: u32 = code.bytes.iter().map(|&b| u32::from(b)).sum();
    assert_eq!(
        s.ask(&format!("/9K{:04X}{:04X}", code.load, code.bytes.len())),
        format!("K{:04X}\r", sum & 0xFFFF)
    );
    assert_eq!(s.ask("/9K04000000"), "K0000\r", "no bytes, sum 0");
    // The first extension still answers through the chain.
    assert_eq!(s.ask("/1U"), "U0042\r");
    // Malformed and unknown commands go all the way down and vanish.
    s.tell_raw(b"/9KXYZ000000");
    s.tell_raw(b"/1Q");
    assert_eq!(s.ask("/1E"), "E0\r");
    insta::assert_snapshot!(s.transcript);
}

/// The busy byte's drive bits (left and right motor on).
const DRIVES: u8 = 0x60;

/// Runs the robot in steps of 100 cycles until neither drive is busy
/// (within a second); the motors' positions then.
fn drives_idle(s: &mut Session) -> (i64, i64) {
    for _ in 0..10_000 {
        if s.robot.robot().board().memory()[usize::from(BUSY)] & DRIVES == 0 {
            return (s.position(Motor::Left), s.position(Motor::Right));
        }
        s.robot.run_for(100).expect("the CPU does not jam");
    }
    panic!("the drives did not stop within a second");
}

#[test]
fn an_operating_system_takes_the_control_loop() {
    let s = patrol_session(true);
    insta::assert_snapshot!(s.transcript);
}

/// The patrol session again with idle-loop skipping off: the OS's loop
/// (a JSR to PENDING every pass, so it writes the stack) is skipped between
/// the motors' ticks, and the robot ends exactly as running every cycle
/// leaves it.
#[test]
fn skipping_an_operating_systems_loop_changes_nothing() {
    let skipped = patrol_session(true);
    let run = patrol_session(false);
    assert_eq!(skipped.transcript, run.transcript);
    let (a, b) = (skipped.robot.robot(), run.robot.robot());
    assert_eq!(a.cpu, b.cpu, "registers, flags and counters");
    assert_eq!(a.board().memory(), b.board().memory());
    assert_eq!(format!("{:?}", a.board()), format!("{:?}", b.board()));
    // Both booted with skipping on; only one went on with it.
    let share = (a.cpu.skipped_cycles() - b.cpu.skipped_cycles()) * 100 / a.cpu.cycles();
    assert!(share >= 20, "only {share}% of the cycles were skipped");
}

/// Installs the patrol OS, patrols, bumps into something, stops.
fn patrol_session(skip: bool) -> Session {
    let mut s = Session::new();
    s.robot.robot_mut().cpu.set_idle_skip(skip);
    let image = patrol();
    assert!(
        image
            .areas
            .iter()
            .all(|a| a.load >= 0x1000 && a.load < 0xC000),
        "the OS lives in KIM-bus RAM"
    );
    assert_eq!(image.hooks.records.len(), 2);
    upload(&mut s, &image);
    // Installed but stopped: the robot stands still and answers as before.
    s.wait_ms(100);
    assert_eq!(s.position(Motor::Left), 0);
    assert_eq!(s.ask("/1X"), "X00\r");

    s.send("/2A1");
    s.wait_ms(500);
    let cruised = s.position(Motor::Left);
    assert!(cruised > 90, "cruising forward: {cruised}");
    assert_eq!(s.position(Motor::Right), cruised);
    assert_eq!(s.ask("/1X"), "XE0\r");

    // An obstacle: the OS backs away 100 steps, turns 60 steps, cruises on.
    s.bumpers(0b0001_0000);
    s.wait_ms(100);
    let backing = s.position(Motor::Left);
    assert!(backing < cruised, "backing away");
    s.bumpers(0);
    // Back 100 steps on both, then the left forward 60 and the right back
    // 60, then both cruising forward again. The drives step on their own
    // phases of the 1 kHz tick, so the turn is measured between the two
    // moments both drives are idle: when the back-away ends, and when the
    // turn does (before the next cruise step).
    let (left0, right0) = drives_idle(&mut s);
    while s.robot.robot().board().memory()[usize::from(BUSY)] & DRIVES == 0 {
        s.robot.run_for(100).expect("the CPU does not jam");
    }
    let (left, right) = drives_idle(&mut s);
    s.note(&format!(
        "the turn: left {:+}, right {:+}",
        left - left0,
        right - right0
    ));
    assert_eq!((left - left0, right - right0), (60, -60), "the turn");
    s.wait_ms(200);
    assert!(s.position(Motor::Left) > left + 30, "cruising again");
    // The ROM still answers everything while the OS runs.
    let status = s.ask("/1P");
    assert!(status.starts_with("PB00E0G0T0M"), "{status}");
    assert!(status.contains("Y00XE0"), "{status}");

    s.send("/2A0");
    let stopped = s.position(Motor::Left);
    s.wait_ms(200);
    assert_eq!(s.position(Motor::Left), stopped);
    assert_eq!(s.ask("/1X"), "X00\r");
    s
}

/// The soak of issue 11: an operating system that injects a command on
/// every pass of the control loop (`inject_soak/feeder.s`), alone and with
/// the two example extensions chained behind it (the rangefinder with its
/// card), and 10,000 host commands of every kind sent back to back at 9600
/// baud in bursts of at most 120 characters: every answer is the one a
/// model of the robot predicts, none is lost, and the injected commands
/// ran.
#[test]
fn injected_commands_never_cut_the_hosts() {
    soak(false);
}

#[test]
fn injected_commands_never_cut_the_hosts_with_extensions_chained() {
    soak(true);
}

fn soak(extensions: bool) {
    let (mut s, _) = robot_with_card(Some(42));
    let feeder = build(
        &[std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inject_soak/feeder.s")],
        "scorpion-os",
    );
    s.robot.load_image(&feeder).expect("the feeder loads");
    if extensions {
        for image in [&checksum(), &rangefinder()] {
            s.robot
                .load_image(image)
                .expect("the images do not overlap");
        }
    }
    let fed_at = u16::try_from(feeder.symbol("fed").expect("`fed`")).expect("16-bit");
    // The host's side: the commands, and the answer each must get.
    let mut rng: u64 = 0x5EED_CAFE;
    let mut next = |n: u64| {
        rng = rng
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (rng >> 33) % n
    };
    let mut eyes = 0u8;
    let mut ram = [0u8; 2];
    let mut commands: Vec<(String, Option<String>)> = Vec::new();
    for _ in 0..10_000 {
        let command = match next(9) {
            0 => {
                let busy = if eyes == 0 { 0x00 } else { 0x82 };
                ("/1X".to_string(), Some(format!("X{busy:02X}")))
            }
            1 => {
                eyes = if eyes == 0 { 3 } else { 0 };
                (format!("/2E{eyes}"), None)
            }
            2 => ("/1E".to_string(), Some(format!("E{eyes}"))),
            3 => {
                ram = [next(256) as u8, next(256) as u8];
                (format!("/9W2000{:02X}{:02X}", ram[0], ram[1]), None)
            }
            4 => (
                "/7R200002".to_string(),
                Some(format!("R{:02X}{:02X}", ram[0], ram[1])),
            ),
            5 => {
                let sum = u16::from(ram[0]) + u16::from(ram[1]);
                (
                    "/9K20000002".to_string(),
                    extensions.then(|| format!("K{sum:04X}")),
                )
            }
            6 => ("/1U".to_string(), extensions.then(|| "U0042".to_string())),
            7 => ("/1Q".to_string(), None),
            _ => ("/7R050001".to_string(), Some("R42".to_string())),
        };
        commands.push(command);
    }
    // The first /7R050001 may come before the feeder's first command ran;
    // the host's two bytes at $2000 start as the model has them.
    s.robot.send(b"/7W050042/9W20000000");
    s.robot.settle().expect("the CPU runs");
    let mut answered = 0;
    let mut burst: Vec<&(String, Option<String>)> = Vec::new();
    let mut chars = 0;
    let mut check = |s: &mut Session, burst: &mut Vec<&(String, Option<String>)>| {
        let wanted: Vec<&String> = burst.iter().filter_map(|(_, a)| a.as_ref()).collect();
        let text: String = burst.iter().map(|(c, _)| c.as_str()).collect();
        s.robot.send(text.as_bytes());
        let mut got = Vec::new();
        for expected in &wanted {
            let raw = s
                .robot
                .read_answer(romlib::sim::ANSWER_TIMEOUT)
                .unwrap_or_else(|error| panic!("`{text}`: no answer for `{expected}`: {error:?}"));
            got.push(String::from_utf8_lossy(&raw).trim_end().to_string());
        }
        let wanted: Vec<String> = wanted.into_iter().cloned().collect();
        assert_eq!(got, wanted, "after `{text}`");
        s.robot.settle().expect("the CPU runs");
        assert!(
            s.robot.receive().is_empty(),
            "an answer nobody asked for, after `{text}`"
        );
        answered += got.len();
        burst.clear();
    };
    for command in &commands {
        if chars + command.0.len() > 120 {
            check(&mut s, &mut burst);
            chars = 0;
        }
        chars += command.0.len();
        burst.push(command);
    }
    check(&mut s, &mut burst);
    let expected = commands.iter().filter(|(_, a)| a.is_some()).count();
    assert_eq!(answered, expected);
    assert_eq!(s.robot.robot().board().acia().overruns(), 0, "no byte lost");
    let memory = s.robot.robot().board().memory();
    let fed = u16::from_le_bytes([memory[usize::from(fed_at)], memory[usize::from(fed_at) + 1]]);
    assert!(fed > 1000, "the feeder fed only {fed} commands");
}
