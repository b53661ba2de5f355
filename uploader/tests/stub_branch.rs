//! A breakpoint whose `JSR` displaces a branch (fresh10 F4, fresh14 F7:
//! `break handler` in the `scorpion new` template, `cmp #'A'` before
//! `bne`, were refused). In the trampoline the branch becomes its
//! opposite over a `JMP` to its target, so both ways go where the program
//! goes; a loop's head stops at every pass.

mod common;

use common::stub::{attach, handler, hooked_at_0400};
use std::time::Duration;
use uploader::stub::{Reply, StubError};

const WAIT: Duration = Duration::from_secs(1);

type Debug = uploader::stub::RobotDebug<uploader::transport::VirtualTransport>;

fn stopped_at(debug: &mut Debug, command: &[u8]) -> u16 {
    match debug.command(command, WAIT).expect("sent") {
        Reply::Stopped(registers) => registers.pc,
        other => panic!("no stop for {}: {other:?}", command.escape_ascii()),
    }
}

fn answer(debug: &mut Debug) -> Reply {
    debug.resume().expect("continue");
    debug.wait_event(WAIT).expect("an answer")
}

#[test]
fn a_breakpoint_on_a_compare_and_its_branch_goes_both_ways() {
    let image = handler();
    let mut debug = attach(&image);
    // The robot's answers without a breakpoint.
    let answers: Vec<Reply> = [&b"/1Q"[..], b"/1Z"]
        .iter()
        .map(|command| debug.command(command, WAIT).expect("sent"))
        .collect();
    // The reference ROM answers nothing to a command nobody handles.
    assert_eq!(answers, [Reply::Answer(b"Q42\r".to_vec()), Reply::Silent]);
    // $0403 CMP #'Q', $0405 BNE $0400: both under the JSR.
    debug
        .set_breakpoint(0x0403, &[])
        .expect("a branch is relocated");
    let tramp = debug.stub().trampoline(0);
    assert_eq!(
        debug.read(tramp, 10).expect("read"),
        [0xC9, b'Q', 0xF0, 0x03, 0x4C, 0x00, 0x04, 0x4C, 0x07, 0x04],
        "CMP, BEQ over JMP $0400, JMP $0407"
    );
    // Not taken: /1Q goes on to its answer.
    assert_eq!(stopped_at(&mut debug, b"/1Q"), 0x0403);
    assert_eq!(answer(&mut debug), answers[0]);
    // Taken: another letter goes down the chain to the ROM, as before.
    assert_eq!(stopped_at(&mut debug, b"/1Z"), 0x0403);
    assert_eq!(answer(&mut debug), answers[1]);
    // Stepped through: the host does CMP and BNE, the robot goes on from
    // the trampoline's copy of what comes after.
    assert_eq!(stopped_at(&mut debug, b"/1Q"), 0x0403);
    for to in [0x0405, 0x0407, 0x0409] {
        let Reply::Stopped(at) = debug.step(&[], false, WAIT).expect("step") else {
            panic!("no stop");
        };
        assert_eq!(at.pc, to);
    }
    assert_eq!(answer(&mut debug), answers[0]);
    debug.remove_breakpoint(0x0403).expect("removed");
    assert_eq!(debug.compare_with_image().expect("read"), None);
    debug.detach().expect("detached");
}

/// `/1L` counts X down from 3 in a loop and answers `L`:
///
/// ```text
/// $0407  LDX #3
/// $0409  DEX          ; the loop's head: DEX and BNE under the JSR
/// $040A  BNE $0409
/// $040C  LDA #'L'
/// $040E  JSR PUTCH
/// $0411  JSR PUTEOL
/// $0414  JMP CMD_DONE
/// ```
#[test]
fn a_breakpoint_at_a_loops_head_stops_at_every_pass() {
    let image = hooked_at_0400(vec![
        0x4C, 0x21, 0xFF, 0xC9, b'L', 0xD0, 0xF9, 0xA2, 0x03, 0xCA, 0xD0, 0xFD, 0xA9, b'L', 0x20,
        0x00, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ]);
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0409, &[0x0409]).expect("set");
    assert_eq!(stopped_at(&mut debug, b"/1L"), 0x0409);
    for x in [2, 1] {
        debug.resume().expect("continue");
        let Reply::Stopped(at) = debug.wait_event(WAIT).expect("the next pass") else {
            panic!("no stop at the next pass");
        };
        assert_eq!((at.pc, at.x), (0x0409, x));
    }
    assert_eq!(answer(&mut debug), Reply::Answer(b"L\r".to_vec()));
}

/// A branch into the bytes the `JSR` would cover is refused: it would land
/// inside the `JSR`.
#[test]
fn a_branch_into_the_covered_bytes_is_refused() {
    // $0407 BCC $040A (into the LDA's operand), $0409 LDA #0.
    let image = hooked_at_0400(vec![
        0x4C, 0x21, 0xFF, 0xC9, b'B', 0xD0, 0xF9, 0x90, 0x01, 0xA9, 0x00, 0x4C, 0x1E, 0xFF,
    ]);
    let mut debug = attach(&image);
    match debug.set_breakpoint(0x0407, &[]) {
        Err(StubError::Refused { reason, .. }) => {
            assert!(reason.contains("$040A"), "{reason}");
            assert!(reason.contains("branch"), "{reason}");
        }
        other => panic!("not refused: {other:?}"),
    }
    assert_eq!(debug.compare_with_image().expect("read"), None);
}
