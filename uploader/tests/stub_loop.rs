//! Breakpoints in code the robot runs on its own: a `HOOK_LOOP` handler,
//! run on every pass of the control loop, as an OS in RAM has (fresh10
//! F21). The loop reaches a breakpoint's `JSR` while the host is still
//! reading the patch back, or reading memory, with the ROM's commands:
//! the stub's stop frame comes among their answers. It must be taken for
//! the stop it is (the breakpoint kept, the stop told), not for line
//! noise (the breakpoint forgotten, the robot left stopped).

mod common;

use common::stub::robot;
use isa::objfmt::{HookKind, HookRecord};
use romlib::protocol::{Answer, Command};
use romlib::symbols::{HOOK_LOOP, HOOK_UNKNOWN};
use std::time::Duration;
use uploader::stub::{Reply, RobotDebug};
use uploader::transport::VirtualTransport;
use uploader::{Area, RomProfile, UploadImage};

const WAIT: Duration = Duration::from_secs(1);

/// Where the loop's handler counts its passes.
const PASSES: u16 = 0x04F0;

/// The `/1Q` handler of `common::stub::handler`, and a loop handler that
/// counts the passes:
///
/// ```text
/// $0420  INC $04F0      ; HOOK_LOOP's handler (outside the image)
/// $0423  JMP chain      ; its chain slot, $0424
/// ```
fn looping() -> UploadImage {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, b'Q', 0x20, 0x00, 0xFF, 0xAD, 0x80, 0x04,
        0x20, 0x03, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x20, 0xEA);
    bytes.extend([0xEE, 0xF0, 0x04, 0x4C, 0x24, 0xFF]);
    bytes.resize(0x81, 0x00);
    bytes[0x80] = 0x42;
    UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes,
        }],
        vec![
            HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0403,
                chain: Some(0x0401),
            },
            HookRecord {
                kind: HookKind::Loop,
                handler: 0x0420,
                chain: Some(0x0424),
            },
        ],
    )
    .expect("an image")
}

fn attach(image: &UploadImage) -> RobotDebug<VirtualTransport> {
    let mut transport = robot(image);
    transport
        .robot_mut()
        .install_hook(HookKind::Loop, 0x0420, Some(0x0424))
        .expect("HOOK_LOOP is a JMP");
    let profile = RomProfile::reference();
    let client = uploader::client(transport, &profile);
    RobotDebug::attach(client, &profile, image.clone()).expect("attaches")
}

fn stop_at(reply: Option<Reply>, pc: u16) {
    match reply {
        Some(Reply::Stopped(registers)) => assert_eq!(registers.pc, pc, "{registers:?}"),
        other => panic!("no stop at ${pc:04X} told: {other:?}"),
    }
}

#[test]
fn a_breakpoint_the_loop_hits_while_it_is_set_is_kept_and_its_stop_told() {
    let image = looping();
    let mut debug = attach(&image);
    debug
        .set_breakpoint(0x0420, &[0x0403, 0x0420])
        .expect("the breakpoint is set, though the loop hit it at once");
    assert!(
        debug.stopped().is_some(),
        "the robot is stopped in the stub"
    );
    assert_eq!(debug.breakpoints().collect::<Vec<_>>(), [0x0420]);
    // Told once: to the front end that asks, then no more.
    stop_at(debug.poll(WAIT).expect("the line"), 0x0420);
    assert_eq!(debug.take_unasked(), None);
    let entry = debug.stub().entry.to_le_bytes();
    assert_eq!(
        debug.read(0x0420, 3).expect("read through the stub"),
        [0x20, entry[0], entry[1]]
    );
    // Every pass stops there again.
    debug.resume().expect("continue");
    stop_at(Some(debug.wait_event(WAIT).expect("a stop")), 0x0420);
    let before = debug.read(PASSES, 1).expect("read")[0];
    debug.resume().expect("continue");
    stop_at(Some(debug.wait_event(WAIT).expect("a stop")), 0x0420);
    assert_eq!(
        debug.read(PASSES, 1).expect("read")[0],
        before.wrapping_add(1),
        "one pass between two stops"
    );
    debug.remove_breakpoint(0x0420).expect("removed");
    debug.resume().expect("continue");
    assert_eq!(debug.wait_event(WAIT).expect("the line"), Reply::Silent);
    assert_eq!(debug.compare_with_image().expect("read"), None);
    let client = debug.detach().expect("detached");
    let robot = client.into_transport().into_robot();
    let memory = robot.robot().board().memory();
    let hook = |at: u16| [memory[usize::from(at) + 1], memory[usize::from(at) + 2]];
    assert_eq!(hook(HOOK_UNKNOWN), [0x03, 0x04], "HOOK_UNKNOWN given back");
    assert_eq!(hook(HOOK_LOOP), [0x20, 0x04], "HOOK_LOOP untouched");
}

#[test]
fn memory_read_while_the_loop_stops_is_read_through_the_stub() {
    let image = looping();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0420, &[]).expect("set");
    stop_at(debug.poll(WAIT).expect("the line"), 0x0420);
    debug.resume().expect("continue");
    // The robot stops again at once: the read meets the stop frame.
    let code = debug.read(0x0400, 0x30).expect("read");
    assert_eq!(code[..0x20], image.areas()[0].bytes[..0x20]);
    assert!(debug.stopped().is_some());
    stop_at(debug.take_unasked().map(Reply::Stopped), 0x0420);
}

#[test]
fn a_detach_while_the_loop_keeps_stopping_takes_every_breakpoint_out() {
    let image = looping();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0420, &[]).expect("set");
    stop_at(debug.poll(WAIT).expect("the line"), 0x0420);
    // Let go running: the removal meets the next stop on its way.
    debug.resume().expect("continue");
    let client = debug.detach().expect("detached");
    let mut robot = client.into_transport().into_robot();
    let passes = robot.robot().board().memory()[usize::from(PASSES)];
    assert_eq!(
        robot.robot().board().memory()[0x0400..0x0481],
        image.areas()[0].bytes[..],
        "the code is the image's again"
    );
    // The robot runs its loop, and answers.
    let ask = Command::parse(b"/1Q").expect("a command");
    assert_eq!(
        robot.ask_extension(&ask).expect("answered"),
        Answer::Text("Q42".into())
    );
    assert_ne!(
        robot.robot().board().memory()[usize::from(PASSES)],
        passes,
        "the loop runs"
    );
}
