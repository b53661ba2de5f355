//! Attaching to a robot that is not as the image says (issue 27's hostile
//! findings F3, F4, F6): a robot holding other code is refused before
//! anything is written; a session whose process was killed (the stub
//! hooked, a `JSR` left in the code, the robot stopped in the stub) is
//! cleaned up by the next one, which says so; a chain slot's bytes are the
//! robot's, not the image's.

mod common;

use common::stub::{attach, handler, robot};
use romlib::symbols::HOOK_UNKNOWN;
use std::time::Duration;
use uploader::stub::{Reply, RobotDebug, StubError};
use uploader::transport::VirtualTransport;
use uploader::{Client, RomProfile, UploadImage};

const WAIT: Duration = Duration::from_secs(1);

/// `LDA $0480`, where the breakpoints go.
const AT: u16 = 0x040C;

fn reattach(client: Client<VirtualTransport>, image: &UploadImage) -> RobotDebug<VirtualTransport> {
    RobotDebug::attach(client, &RomProfile::reference(), image.clone()).expect("attaches again")
}

/// The robot's memory once `debug` has detached.
fn detached_memory(debug: RobotDebug<VirtualTransport>) -> Vec<u8> {
    let client = debug.detach().expect("detached");
    let robot = client.into_transport().into_robot();
    robot.robot().board().memory().to_vec()
}

#[test]
fn a_robot_holding_other_code_is_refused_naming_the_first_difference() {
    let image = handler();
    // The robot runs a build whose `LDA $0480` reads $0481.
    let mut other = image.areas()[0].bytes.clone();
    other[0x0D] = 0x81;
    let on_robot = UploadImage::new(
        vec![uploader::Area {
            address: 0x0400,
            bytes: other,
        }],
        image.hooks().to_vec(),
    )
    .expect("an image");
    let profile = RomProfile::reference();
    let client = uploader::client(robot(&on_robot), &profile);
    match RobotDebug::attach(client, &profile, image) {
        Err(StubError::NotTheImage {
            address,
            expected,
            found,
        }) => {
            assert_eq!(address, 0x040D);
            assert!(expected.starts_with("80 04"), "{expected}");
            assert!(found.starts_with("81 04"), "{found}");
        }
        other => panic!("not refused: {other:?}"),
    }
}

#[test]
fn a_session_killed_while_the_robot_runs_is_cleaned_up_by_the_next() {
    let image = handler();
    let mut first = attach(&image);
    first.set_breakpoint(AT, &[]).expect("set");
    let client = first.abandon();
    let mut second = reattach(client, &image);
    let recovery = second.recovery().clone();
    assert!(recovery.hooked, "{recovery:?}");
    assert_eq!(recovery.removed, [AT]);
    assert_eq!(recovery.stopped, None);
    assert!(second.recovery().describe().contains("$040C"));
    assert_eq!(second.compare_with_image().expect("read"), None);
    // The command runs through, no stop.
    assert_eq!(
        second.command(b"/1Q", WAIT).expect("sent"),
        Reply::Answer(b"Q42\r".to_vec())
    );
    let memory = detached_memory(second);
    assert_eq!(&memory[0x0400..0x0481], &image.areas()[0].bytes[..]);
    let hook = usize::from(HOOK_UNKNOWN);
    assert_eq!(
        memory[hook + 1..hook + 3],
        [0x03, 0x04],
        "the hook given back"
    );
}

#[test]
fn a_jsr_into_a_stub_no_longer_hooked_is_taken_out() {
    let image = handler();
    let mut first = attach(&image);
    first.set_breakpoint(AT, &[]).expect("set");
    let mut client = first.abandon();
    // What an older second session did: the hook given back, the JSR left.
    client
        .transport()
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(HOOK_UNKNOWN + 1, &[0x03, 0x04])
        .expect("RAM");
    let mut second = reattach(client, &image);
    assert!(!second.recovery().hooked);
    assert_eq!(second.recovery().removed, [AT]);
    assert_eq!(second.stub().previous, 0x0403);
    assert_eq!(
        second.command(b"/1Q", WAIT).expect("sent"),
        Reply::Answer(b"Q42\r".to_vec())
    );
    let memory = detached_memory(second);
    assert_eq!(&memory[0x0400..0x0481], &image.areas()[0].bytes[..]);
}

#[test]
fn a_robot_left_stopped_in_the_stub_is_found_stopped_and_goes_on() {
    let image = handler();
    let mut first = attach(&image);
    first.set_breakpoint(AT, &[]).expect("set");
    let Reply::Stopped(registers) = first.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    let client = first.abandon();
    let mut second = reattach(client, &image);
    assert_eq!(second.recovery().stopped, Some(registers));
    assert_eq!(second.stopped(), Some(registers));
    assert_eq!(second.recovery().removed, [AT]);
    // The image's bytes are back under the stop: it goes on through them.
    assert_eq!(second.read(AT, 3).expect("read"), [0xAD, 0x80, 0x04]);
    second.resume().expect("continue");
    // The `Q` went out before the stop, to the killed session.
    assert_eq!(
        second.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"42\r".to_vec())
    );
    let memory = detached_memory(second);
    assert_eq!(&memory[0x0400..0x0481], &image.areas()[0].bytes[..]);
    let hook = usize::from(HOOK_UNKNOWN);
    assert_eq!(memory[hook + 1..hook + 3], [0x03, 0x04]);
}

#[test]
fn a_breakpoint_on_a_chain_slot_jmp_displaces_and_restores_the_robots_bytes() {
    let image = handler();
    let profile = RomProfile::reference();
    let mut transport = robot(&image);
    // The uploader chained the handler to another extension's, here
    // CMD_DONE's address standing for it: the image says $FF21.
    let chained = [0x1E, 0xFF];
    transport
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(0x0401, &chained)
        .expect("RAM");
    let client = uploader::client(transport, &profile);
    let mut debug = RobotDebug::attach(client, &profile, image.clone()).expect("attaches");
    debug.set_breakpoint(0x0400, &[]).expect("set");
    let trampoline = debug.stub().trampoline(0);
    assert_eq!(
        debug.read(trampoline, 3).expect("read"),
        [0x4C, chained[0], chained[1]],
        "the trampoline runs the robot's JMP"
    );
    debug.remove_breakpoint(0x0400).expect("removed");
    assert_eq!(
        debug.read(0x0400, 3).expect("read"),
        [0x4C, chained[0], chained[1]]
    );
    assert_eq!(debug.compare_with_image().expect("read"), None);
}

/// Two extensions installed: `handler()` at $0400 (`/1Q`) and one at
/// $0800 answering `/1H` with `H24`.
fn two_installed() -> (UploadImage, UploadImage, Client<VirtualTransport>) {
    let first = handler();
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'H', 0xD0, 0xF9, 0xA9, b'H', 0x20, 0x00, 0xFF, 0xAD, 0x80, 0x08,
        0x20, 0x03, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x81, 0xEA);
    bytes[0x80] = 0x24;
    let second = UploadImage::new(
        vec![uploader::Area {
            address: 0x0800,
            bytes,
        }],
        vec![isa::objfmt::HookRecord {
            kind: isa::objfmt::HookKind::Unknown,
            handler: 0x0803,
            chain: Some(0x0801),
        }],
    )
    .expect("an image");
    let profile = RomProfile::reference();
    let options = uploader::UploadOptions {
        loader: uploader::LoaderChoice::Never,
        ..uploader::UploadOptions::default()
    };
    let mut client = uploader::client(
        VirtualTransport::new(romlib::VirtualScorpion::new()),
        &profile,
    );
    for image in [&first, &second] {
        uploader::upload(&mut client, image, &options, &mut uploader::NoProgress)
            .expect("installed");
    }
    (first, second, client)
}

/// fresh7's F4: a session with image A killed with a breakpoint in A
/// (the robot running, then stopped at it); the next session came with
/// image B (installed beside A), cleaned up only what B's bytes showed,
/// and left A's `JSR` into the stub, where `/1Q` then stopped with no host
/// to serve it. Every breakpoint the stub's trampolines say was left is
/// taken out, in any installed extension.
#[test]
fn a_session_with_another_image_takes_out_what_the_first_left() {
    for stop in [false, true] {
        let (first, second, client) = two_installed();
        let profile = RomProfile::reference();
        let mut session = RobotDebug::attach(client, &profile, first.clone()).expect("attaches");
        session.set_breakpoint(AT, &[]).expect("set");
        if stop {
            let reply = session.command(b"/1Q", WAIT).expect("sent");
            assert!(matches!(reply, Reply::Stopped(_)), "{reply:?}");
        }
        let client = session.abandon();
        let mut other = reattach(client, &second);
        assert!(
            other.recovery().removed.contains(&AT),
            "{:?}",
            other.recovery()
        );
        if stop {
            assert!(other.stopped().is_some(), "found stopped");
            other.resume().expect("continue");
            assert_eq!(
                other.wait_event(WAIT).expect("an answer"),
                Reply::Answer(b"42\r".to_vec())
            );
        }
        assert_eq!(
            other.command(b"/1Q", WAIT).expect("sent"),
            Reply::Answer(b"Q42\r".to_vec()),
            "stopped first: {stop}"
        );
        assert_eq!(
            other.command(b"/1H", WAIT).expect("sent"),
            Reply::Answer(b"H24\r".to_vec())
        );
        let memory = detached_memory(other);
        assert_eq!(&memory[0x0400..0x0481], &first.areas()[0].bytes[..]);
    }
}

/// hostile16 F2: a session killed at a stop after a byte of the code was
/// changed (`poke` into an instruction) left a robot the next session
/// refused as "not the image", and every other command refused as stopped
/// in the stub: only a reset helped. Found stopped, the robot's code is
/// taken as it is (said), and it goes on.
#[test]
fn a_robot_found_stopped_with_its_code_changed_still_goes_on() {
    let image = handler();
    let mut debug = attach(&image);
    debug.set_breakpoint(AT, &[]).expect("set");
    let Reply::Stopped(_) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    // LDA #'Q' at $0407 made LDA #'Z' (its operand is code).
    debug.write_verified(0x0408, b"Z").expect("poked");
    let mut again = reattach(debug.abandon(), &image);
    assert_eq!(again.recovery().changed, [0x0408]);
    assert!(
        again
            .recovery()
            .describe()
            .contains("differs from the image in 1 byte ($0408;")
    );
    assert_eq!(again.stopped().map(|r| r.pc), Some(AT));
    again.resume().expect("continue");
    assert_eq!(
        again.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"42\r".to_vec()),
        "the Q went out before the stop, to the session that died; the change shows at the next command"
    );
    assert_eq!(
        again.command(b"/1Q", WAIT).expect("sent"),
        Reply::Answer(b"Z42\r".to_vec())
    );
    again.detach().expect("detached");
}

/// hostile16 F3: a session killed at a stop after a `poke` into the bytes
/// a breakpoint displaced (which the stub's trampoline runs in their
/// place) came back with the image's bytes: the clean-up undid the poke
/// without a word, where `quit` keeps it. Found stopped, the trampoline's
/// copy is what is put back, and the change is said.
#[test]
fn a_poke_into_a_breakpoints_displaced_bytes_survives_the_clean_up() {
    let image = handler();
    let mut debug = attach(&image);
    // The JSR at $0407 covers LDA #'Q' (2 bytes) and JSR PUTCH.
    debug.set_breakpoint(0x0407, &[]).expect("set");
    let Reply::Stopped(_) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    debug.write_as_program(0x0408, b"Z").expect("poked");
    let mut again = reattach(debug.abandon(), &image);
    assert_eq!(again.recovery().removed, [0x0407]);
    assert_eq!(again.recovery().changed, [0x0408]);
    assert_eq!(
        again.read(0x0407, 3).expect("read"),
        [0xA9, b'Z', 0x20],
        "the program's bytes, the poke kept"
    );
    again.resume().expect("continue");
    assert_eq!(
        again.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"Z42\r".to_vec()),
        "the stopped command goes on with the poke"
    );
    again.detach().expect("detached");
}
