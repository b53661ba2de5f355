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
    let robot = s.robot.robot_mut();
    let first = robot
        .read_answer(romlib::sim::ANSWER_TIMEOUT)
        .expect("the range");
    let second = robot
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

#[test]
fn an_operating_system_takes_the_control_loop() {
    let mut s = Session::new();
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
    s.wait_ms(1500);
    let (left, right) = (s.position(Motor::Left), s.position(Motor::Right));
    s.note(&format!("left {left}, right {right} after the manoeuvre"));
    // Back 100 steps on both, then the left forward 60 and the right back
    // 60, then both cruising forward again: the difference is the turn.
    assert_eq!(left - right, 120, "left {left}, right {right}");
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
    insta::assert_snapshot!(s.transcript);
}
