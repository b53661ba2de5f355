//! hostile26 F4, hostile28 F1, F2: a robot whose `HOOK_LOOP` runs code no
//! entry of the table lists (an owner's, by hand), just where the stub
//! would go. The stub was written over it with the ROM's commands while
//! the loop ran it, and the robot jammed; a margin around what one run on
//! the host touched missed the branches it did not take. Attaching is
//! refused before anything is written, and the robot runs on.

mod common;

use common::stub::{handler, robot};
use isa::objfmt::HookKind;
use uploader::RomProfile;
use uploader::stub::{RobotDebug, StubError, StubPlan};

#[test]
fn attaching_to_a_robot_whose_hook_runs_unlisted_code_is_refused_untouched() {
    let profile = RomProfile::reference();
    let image = handler();
    // Where the stub goes on a robot with nothing else: beside the image
    // and the RAM loader an upload of it uses.
    let loader = uploader::loader_plan(&profile, &image, (9600, uploader::FAST_BAUD))
        .expect("links")
        .expect("room for the loader");
    let taken = [
        loader.code.address..=loader.code.address + loader.code.bytes.len() as u16 - 1,
        u16::from(*loader.zero_page.start())..=u16::from(*loader.zero_page.end()),
    ];
    let alone =
        StubPlan::place_beside(&profile, &image, profile.hook_unknown, &taken).expect("links");
    // `INC counter; JMP chain` in the middle of that place, on HOOK_LOOP,
    // listed by no entry.
    let code = alone.address + 0x40;
    // Its counter outside that place: a read of the place that finds its
    // bytes changing refuses too, as memory in use.
    let counter = alone.address - 0x10;
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
    let ram = |transport: &uploader::transport::VirtualTransport| {
        let memory = transport.robot().robot().board().memory();
        // The hooks, user RAM and the table (the ROM's own RAM changes
        // with every command).
        let mut ram = [&memory[0x0200..0x0206], &memory[0x0400..0x1000]].concat();
        ram[6 + usize::from(counter) - 0x0400] = 0;
        ram
    };
    let before = ram(&transport);
    let count = |transport: &uploader::transport::VirtualTransport| {
        transport.robot().robot().board().memory()[usize::from(counter)]
    };
    let first = count(&transport);
    let client = uploader::client(&mut transport, &profile);
    let Err(error) = RobotDebug::attach(client, &profile, image) else {
        panic!("attached over code HOOK_LOOP runs");
    };
    let said = error.to_string();
    assert!(
        matches!(error, StubError::Refused { .. })
            && said.contains(&format!("HOOK_LOOP (${code:04X}) runs code at ${code:04X}")),
        "{said}"
    );
    assert!(ram(&transport) == before, "user RAM changed");
    // The robot runs on: its loop still counts.
    let mut client = uploader::client(&mut transport, &profile);
    client.probe().expect("the robot answers");
    drop(client);
    assert_ne!(count(&transport), first, "HOOK_LOOP's code still runs");
}
