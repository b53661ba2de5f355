//! The RAM loader's 6502 code (`loader/fast.s`, `loader/frames.s`, as the
//! uploader links them) running on the virtual Scorpion, fed frames by
//! hand: a good frame lands; a frame whose header is damaged writes
//! nothing anywhere; a frame that lost a data byte writes nothing outside
//! its own range; `/1F` toggles the 6551 between 9600 and 19200 baud; and
//! commands that are not the loader's fall through to the ROM.

mod common;

use common::{CTRL_9600, extension};
use isa::objfmt::HookKind;
use romlib::VirtualScorpion;
use romlib::protocol::{Answer, Command};
use uploader::{FAST_BAUD, LoaderPlan, RomProfile, loader_frame, loader_plan};

/// A robot with both stages in RAM and the frame stage hooked, falling
/// through to the rate switch.
fn robot_with_loader() -> (VirtualScorpion, LoaderPlan) {
    let plan = loader_plan(
        &RomProfile::reference(),
        &extension(2048, 1),
        (9600, FAST_BAUD),
    )
    .expect("links")
    .expect("room");
    let mut robot = VirtualScorpion::new();
    let board = robot.robot_mut().board_mut();
    board
        .load(plan.fast.address, &plan.fast.bytes)
        .expect("RAM");
    board
        .load(plan.frames.address, &plan.frames.bytes)
        .expect("RAM");
    let chain = plan.scratch[plan.scratch.len() - 2];
    board
        .load(chain, &plan.fast_handler.to_le_bytes())
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

/// The hooks, user RAM and the KIM-bus RAM, without the loader's own
/// bytes, as (address, byte).
fn ram(robot: &VirtualScorpion, plan: &LoaderPlan) -> Vec<(usize, u8)> {
    let memory = robot.robot().board().memory();
    let loader = usize::from(plan.fast.address)..usize::from(plan.frames.address) + 256;
    (0x0200..0x0206)
        .chain(0x0400..0xC000)
        .filter(|at| !loader.contains(at))
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
    let answer = robot.robot_mut().read_answer(1_000_000).expect("an answer");
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
fn f_toggles_the_line_and_other_commands_fall_through() {
    let (mut robot, _) = robot_with_loader();
    // Not the loader's: dropped as BAD_COMMAND would; the ROM answers on.
    send(&mut robot, b"/1Q/3Qxyz");
    assert_eq!(
        robot.exchange(&Command::Busy).expect("answers"),
        Some(Answer::Busy(romlib::protocol::BusyByte(0)))
    );
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
fn the_loader_uses_the_boards_io_addresses() {
    // fast.s and frames.s name the 6551's control register themselves (the
    // ROM does not export it): it must be the ROM's.
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("parses");
    assert_eq!(rom.symbol("ACIA_CTRL"), Some(0xC013));
}
