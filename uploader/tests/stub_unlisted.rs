//! hostile26 F4: a robot whose `HOOK_LOOP` runs code no entry of the
//! table lists (an owner's, by hand), just where the stub would go on a
//! robot without it. The stub was written there with the ROM's commands
//! while the loop ran it, and the robot jammed. Attaching keeps the stub
//! clear of that code (a margin around what its way touches) and the
//! robot goes on running it.

mod common;

use common::stub::{handler, robot};
use isa::objfmt::HookKind;
use romlib::symbols::HOOK_LOOP;
use std::time::Duration;
use uploader::RomProfile;
use uploader::stub::{Reply, RobotDebug, StubPlan, unlisted::MARGIN};

const WAIT: Duration = Duration::from_secs(1);

#[test]
fn the_stub_goes_clear_of_unlisted_code_a_hook_runs() {
    let profile = RomProfile::reference();
    let image = handler();
    // Where the stub goes on a robot with nothing else.
    let alone = StubPlan::place(&profile, &image, profile.hook_unknown).expect("links");
    // `INC counter; JMP chain` in the middle of that place, on HOOK_LOOP,
    // listed by no entry.
    let code = alone.address + 0x40;
    let counter = code + 0x10;
    let [lo, hi] = counter.to_le_bytes();
    let mut transport = robot(&image);
    transport
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(code, &[0xEE, lo, hi, 0x4C, 0x00, 0x00])
        .expect("RAM");
    transport
        .robot_mut()
        .install_hook(HookKind::Loop, code, Some(code + 4))
        .expect("HOOK_LOOP is a JMP");
    let client = uploader::client(transport, &profile);
    let mut debug = RobotDebug::attach(client, &profile, image).expect("attaches");

    let stub = debug.stub().clone();
    let (start, end) = (
        u32::from(stub.address),
        u32::from(stub.address) + stub.bytes.len() as u32,
    );
    let (low, high) = (
        u32::from(code - MARGIN),
        u32::from(counter) + u32::from(MARGIN),
    );
    assert!(
        end <= low || start > high,
        "the stub at ${start:04X}-${end:04X} meets the unlisted code's ${low:04X}-${high:04X}"
    );
    // The robot runs on: the loop still counts, the image's command answers.
    let before = debug.read_live_as_program(counter, 1).expect("read").bytes[0];
    assert_eq!(
        debug.command(b"/1Q", WAIT).expect("the line"),
        Reply::Answer(b"Q42\r".to_vec())
    );
    let after = debug.read_live_as_program(counter, 1).expect("read").bytes[0];
    assert_ne!(before, after, "HOOK_LOOP's code still runs");
    let client = debug.detach().expect("detached");
    let robot = client.into_transport().into_robot();
    let memory = robot.robot().board().memory();
    assert_eq!(
        [
            memory[usize::from(HOOK_LOOP) + 1],
            memory[usize::from(HOOK_LOOP) + 2]
        ],
        code.to_le_bytes(),
        "HOOK_LOOP untouched"
    );
    assert_eq!(
        &memory[usize::from(code)..usize::from(code) + 3],
        &[0xEE, lo, hi]
    );
}
