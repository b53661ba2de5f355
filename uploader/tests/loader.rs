//! The RAM loader's 6502 code (`loader/loader.s`, as the uploader links
//! it) running on the virtual Scorpion, fed frames by hand: a good frame
//! lands; a frame whose header is damaged writes nothing anywhere; a frame
//! that lost a data byte writes nothing outside its own range; `/1F`
//! toggles the 6551 between 9600 and 19200 baud, through `frames` or with
//! `rate` hooked alone; every other command is dropped.

mod common;

use common::{CTRL_9600, extension};
use isa::objfmt::HookKind;
use romlib::VirtualScorpion;
use romlib::protocol::{Answer, BusyByte, Command};
use uploader::{FAST_BAUD, LoaderPlan, RomProfile, loader_frame, loader_plan};

/// The loader for a 2 KiB extension at $0400, as an upload at 9600 baud
/// would place it.
fn plan() -> LoaderPlan {
    loader_plan(
        &RomProfile::reference(),
        &extension(2048, 1),
        (9600, FAST_BAUD),
    )
    .expect("links")
    .expect("room")
}

/// A robot with the loader in RAM and `frames` hooked.
fn robot_with_loader() -> (VirtualScorpion, LoaderPlan) {
    let plan = plan();
    let mut robot = VirtualScorpion::new();
    robot
        .robot_mut()
        .board_mut()
        .load(plan.code.address, &plan.code.bytes)
        .expect("RAM");
    robot
        .install_hook(HookKind::Unknown, plan.frames_handler, None)
        .expect("HOOK_UNKNOWN is a JMP");
    (robot, plan)
}

fn send(robot: &mut VirtualScorpion, bytes: &[u8]) {
    robot.send(bytes);
    robot.settle().expect("the CPU runs");
}

/// The hooks, user zero page, user RAM and the KIM-bus RAM, without the
/// loader's own bytes and state, as (address, byte).
fn ram(robot: &VirtualScorpion, plan: &LoaderPlan) -> Vec<(usize, u8)> {
    let memory = robot.robot().board().memory();
    let code =
        usize::from(plan.code.address)..usize::from(plan.code.address) + plan.code.bytes.len();
    let state = usize::from(*plan.zero_page.start())..=usize::from(*plan.zero_page.end());
    (0x0030..0x0100)
        .chain(0x0200..0x0206)
        .chain(0x0400..0xC000)
        .filter(|at| !code.contains(at) && !state.contains(at))
        .map(|at| (at, memory[at]))
        .collect()
}

#[test]
fn a_good_frame_lands() {
    let (mut robot, _) = robot_with_loader();
    let data: Vec<u8> = (0..128u8).map(|i| i.wrapping_mul(37) ^ 0x2F).collect();
    send(&mut robot, &loader_frame(0x2000, &data));
    assert_eq!(
        &robot.robot().board().memory()[0x2000..0x2080],
        data.as_slice()
    );
    // Back to back with questions, as the uploader sends them.
    let mut stream = loader_frame(0x3000, &data[..40]);
    stream.extend_from_slice(b"/7R300040");
    robot.send(&stream);
    let answer = robot.read_answer(1_000_000).expect("an answer");
    assert_eq!(
        Answer::parse(&answer).expect("parses"),
        Answer::Memory(data[..40].to_vec())
    );
}

#[test]
fn a_damaged_header_writes_nothing_anywhere() {
    let data = [0x11u8; 16];
    let good = loader_frame(0x2000, &data);
    for at in 4..9 {
        for flip in [0x01u8, 0x02, 0x10, 0x40, 0x80, 0xFF] {
            let mut bad = good.clone();
            bad[at] ^= flip;
            if bad[at] == b'/' {
                continue;
            }
            let (mut robot, plan) = robot_with_loader();
            let before = ram(&robot, &plan);
            send(&mut robot, &bad);
            assert!(
                ram(&robot, &plan) == before,
                "header byte {at} ^ ${flip:02X} wrote something"
            );
            // The loader is still there for the next frame.
            send(&mut robot, &good);
            assert_eq!(&robot.robot().board().memory()[0x2000..0x2010], &data);
        }
    }
    // A header byte lost: the data shifts into the header.
    let (mut robot, plan) = robot_with_loader();
    let before = ram(&robot, &plan);
    let mut short = good.clone();
    short.remove(6);
    send(&mut robot, &short);
    assert!(
        ram(&robot, &plan) == before,
        "a short header wrote something"
    );
}

#[test]
fn a_frame_that_lost_data_stays_in_its_range() {
    let (mut robot, plan) = robot_with_loader();
    let data: Vec<u8> = (1..=64).collect();
    let mut frame = loader_frame(0x2000, &data);
    frame.remove(30);
    let mut stream = frame;
    // The next command's slash ends up as the frame's last byte.
    stream.extend_from_slice(b"/1X");
    let before = ram(&robot, &plan);
    send(&mut robot, &stream);
    let after = ram(&robot, &plan);
    let memory = robot.robot().board().memory();
    assert_ne!(&memory[0x2000..0x2040], data.as_slice());
    let outside: Vec<usize> = before
        .iter()
        .zip(&after)
        .filter(|(old, new)| old != new)
        .map(|((at, _), _)| *at)
        .filter(|at| !(0x2000..0x2040).contains(at))
        .collect();
    assert!(outside.is_empty(), "writes outside the frame: {outside:X?}");
}

#[test]
fn other_commands_are_dropped_and_f_toggles_the_line() {
    let (mut robot, plan) = robot_with_loader();
    assert_eq!(plan.rate_handler, plan.code.address, "`rate` comes first");
    // Not the loader's: dropped as BAD_COMMAND drops them; the ROM answers on.
    let before = ram(&robot, &plan);
    send(&mut robot, b"/1Q/3Qxyz/1f/2Gx");
    assert_eq!(
        robot.exchange(&Command::Busy).expect("answers"),
        Some(Answer::Busy(BusyByte(0)))
    );
    assert!(
        ram(&robot, &plan) == before,
        "a dropped command wrote something"
    );
    assert_eq!(robot.robot().board().acia().control(), CTRL_9600);
    // /1F, through `frames` into `rate`: 19200 baud, framing kept.
    send(&mut robot, b"/1F");
    assert_eq!(robot.robot().board().acia().control(), 0x1F, "19200 baud");
    robot.robot_mut().set_baud(19200);
    assert!(robot.exchange(&Command::Busy).is_ok(), "answers at 19200");
    send(&mut robot, b"/1F");
    assert_eq!(robot.robot().board().acia().control(), CTRL_9600);
    robot.robot_mut().set_baud(9600);
    assert!(
        robot.exchange(&Command::Busy).is_ok(),
        "answers at 9600 again"
    );
}

#[test]
fn rate_alone_switches_the_line_and_drops_the_rest() {
    // How an upload starts: only `rate` is in RAM (15 bytes), hooked.
    let plan = plan();
    let rate_len = usize::from(plan.frames_handler - plan.rate_handler);
    assert_eq!(rate_len, 15);
    let mut robot = VirtualScorpion::new();
    robot
        .robot_mut()
        .board_mut()
        .load(plan.code.address, &plan.code.bytes[..rate_len])
        .expect("RAM");
    robot
        .install_hook(HookKind::Unknown, plan.rate_handler, None)
        .expect("HOOK_UNKNOWN is a JMP");
    // Two stop bits stay two stop bits: only the baud code changes.
    send(&mut robot, b"/7WC0139E");
    send(&mut robot, b"/1L/1Q/1F");
    assert_eq!(robot.robot().board().acia().control(), 0x9F, "19200 baud");
    robot.robot_mut().set_baud(19200);
    assert_eq!(
        robot.exchange(&Command::Busy).expect("answers at 19200"),
        Some(Answer::Busy(BusyByte(0)))
    );
}

#[test]
fn the_loader_uses_the_boards_io_addresses() {
    // The uploader links `rate` against the 6551's control register as
    // the emulator's board map places it: it must be the ROM's.
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("parses");
    assert_eq!(rom.symbol("ACIA_CTRL"), Some(0xC013));
    let plan = plan();
    let code = &plan.code.bytes;
    assert!(
        code.windows(3).any(|w| w == [0x8D, 0x13, 0xC0]),
        "`rate` stores to $C013"
    );
}
