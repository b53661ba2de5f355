//! The hostile tester's findings on the host-side step and the stub
//! (issue 27, `hstepfix`), on the virtual Scorpion through nothing but
//! the line: a stop and a patching step with the program's decimal flag
//! set, a robot that sends garbage for ever, a step that writes into a
//! breakpoint's displaced bytes or into the stub, and what `mem` shows
//! at a stop. Each runs on a thread of its own with a deadline of wall
//! time, so a hang fails the test instead of holding it.

mod common;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use common::stub::{attach, hooked_at_0400};
use uploader::stub::{Reply, StubError};
use uploader::{Area, UploadImage};

const WAIT: Duration = Duration::from_secs(1);

/// Runs `test` on its own thread; a test still running after two
/// minutes of wall time is a hang, and fails.
fn within(test: impl FnOnce() + Send + 'static) {
    let (done, finished) = channel();
    std::thread::spawn(move || {
        test();
        let _ = done.send(());
    });
    match finished.recv_timeout(Duration::from_secs(120)) {
        Ok(()) => {}
        Err(RecvTimeoutError::Disconnected) => panic!("the test failed (its panic is above)"),
        Err(RecvTimeoutError::Timeout) => panic!("the test still runs after 120 s: a hang"),
    }
}

/// A handler at $0403 for the command letter `letter`, its body `code`
/// from $0407 (the chain slot at $0400, as the uploader leaves it).
fn handler(letter: u8, code: &[u8]) -> UploadImage {
    let mut bytes = vec![0x4C, 0x21, 0xFF, 0xC9, letter, 0xD0, 0xF9];
    bytes.extend_from_slice(code);
    bytes.resize(0x81, 0xEA);
    hooked_at_0400(bytes)
}

/// `/1U` answers 09 + 01 added in decimal, `10`:
///
/// ```text
/// $0407  SED
/// $0408  LDA #$09      ; the breakpoint (LDA and CLC displaced)
/// $040A  CLC
/// $040B  PHA           ; a push: the patching step
/// $040C  PLA
/// $040D  ADC #$01
/// $040F  CLD
/// $0410  JSR PUTHEX
/// $0413  JSR PUTEOL
/// $0416  JMP CMD_DONE
/// ```
fn decimal() -> UploadImage {
    handler(
        b'U',
        &[
            0xF8, 0xA9, 0x09, 0x18, 0x48, 0x68, 0x69, 0x01, 0xD8, 0x20, 0x03, 0xFF, 0x20, 0x09,
            0xFF, 0x4C, 0x1E, 0xFF,
        ],
    )
}

/// F1: the stub ran with the program's D flag and its sums (ADC) came
/// out decimal: every frame garbled, the monitor hung, the robot left
/// stopped. A breakpoint hit with D set, host steps, a patching step of
/// `PHA` with D set: each stop right, D in P, and D given back when the
/// robot goes on (the answer is the decimal sum).
#[test]
fn a_stop_and_a_patching_step_with_the_decimal_flag_set_are_right() {
    within(|| {
        let image = decimal();
        let mut debug = attach(&image);
        debug.set_breakpoint(0x0408, &[]).expect("set");
        let reply = debug.command(b"/1U", WAIT).expect("sent");
        let Reply::Stopped(hit) = reply else {
            panic!("no stop: {reply:?}");
        };
        assert_eq!(hit.pc, 0x0408);
        assert_eq!(hit.p & 0x08, 0x08, "D set at the stop: {hit:?}");
        for pc in [0x040A, 0x040B] {
            let Reply::Stopped(at) = debug.step(&[], false, WAIT).expect("host step") else {
                panic!("no stop");
            };
            assert_eq!(at.pc, pc);
        }
        let reply = debug.step(&[], false, WAIT).expect("PHA");
        let Reply::Stopped(pushed) = reply else {
            panic!("the patching step did not stop: {reply:?}");
        };
        assert_eq!((pushed.pc, pushed.a), (0x040C, 0x09));
        assert_eq!(pushed.s, hit.s.wrapping_sub(1), "one byte pushed");
        assert_eq!(pushed.p & 0x08, 0x08, "D still set: {pushed:?}");
        assert_eq!(
            debug
                .read(0x0100 | u16::from(pushed.s.wrapping_add(1)), 1)
                .expect("read"),
            [0x09]
        );
        debug.resume().expect("continue");
        assert_eq!(
            debug.wait_event(WAIT).expect("an answer"),
            Reply::Answer(b"10\r".to_vec()),
            "ADC decimal after the stop: D given back"
        );
        // Hit again, and straight on.
        assert!(matches!(
            debug.command(b"/1U", WAIT).expect("sent"),
            Reply::Stopped(_)
        ));
        debug.resume().expect("continue");
        assert_eq!(
            debug.wait_event(WAIT).expect("an answer"),
            Reply::Answer(b"10\r".to_vec())
        );
        debug.detach().expect("detached");
    });
}

/// `/1J` sends `$F0` (a frame's start) for ever: what a stub gone wrong
/// looks like from the host.
fn garbage() -> UploadImage {
    // $0407 LDA #$F0; JSR PUTCH; JMP $0407
    handler(b'J', &[0xA9, 0xF0, 0x20, 0x00, 0xFF, 0x4C, 0x07, 0x04])
}

/// F2: a wait for the robot that hears only garbled frames answered
/// each with a slash (the stub's "send the stop again") for ever: it
/// gives up, saying what it heard.
#[test]
fn a_robot_that_sends_garbage_for_ever_does_not_hold_the_host() {
    within(|| {
        let image = garbage();
        let mut debug = attach(&image);
        match debug.command(b"/1J", WAIT) {
            Err(StubError::Garbled { found, .. }) => {
                assert!(found.contains("garbled frame F0"), "{found}");
            }
            other => panic!("not given up: {other:?}"),
        }
    });
}

/// F2: a signal's flag ends a wait for the robot at once (the monitor
/// then detaches as `quit` does).
#[test]
fn the_interrupt_flag_ends_a_wait_for_the_robot() {
    within(|| {
        let image = garbage();
        let mut debug = attach(&image);
        let flag = Arc::new(AtomicBool::new(true));
        debug.set_interrupt(Arc::clone(&flag));
        let before = uploader::transport::Transport::now(debug.client().transport());
        match debug.command(b"/1J", Duration::from_secs(60)) {
            Err(StubError::Interrupted { .. }) => {}
            other => panic!("not interrupted: {other:?}"),
        }
        let after = uploader::transport::Transport::now(debug.client().transport());
        assert!(
            after - before < Duration::from_secs(1),
            "{:?}",
            after - before
        );
    });
}

/// `/1N` answers the immediate of `LDX #` at $040E, which the handler
/// writes itself (self-modifying code):
///
/// ```text
/// $0407  LDA #$07
/// $0409  STA $040F     ; into LDX's operand
/// $040C  NOP
/// $040D  NOP
/// $040E  LDX #$00      ; a breakpoint (LDX and TXA displaced)
/// $0410  TXA
/// $0411  JSR PUTHEX
/// $0414  JSR PUTEOL
/// $0417  JMP CMD_DONE
/// ```
fn self_modifying(store: u8) -> UploadImage {
    handler(
        b'N',
        &[
            0xA9, store, 0x8D, 0x0F, 0x04, 0xEA, 0xEA, 0xA2, 0x00, 0x8A, 0x20, 0x03, 0xFF, 0x20,
            0x09, 0xFF, 0x4C, 0x1E, 0xFF,
        ],
    )
}

/// F3 and F5: a step of `STA` into a breakpoint's displaced bytes (its
/// `JSR`'s operand on the robot) wrote over the `JSR` and the robot ran
/// into garbage. The host does it right: the program's byte goes to the
/// trampoline's copy, the `JSR` stays, `read_as_program` shows the
/// program's bytes, the answer is the written one, and removing the
/// breakpoint puts the program's bytes back.
#[test]
fn a_step_that_writes_into_displaced_bytes_changes_the_trampolines_copy() {
    within(|| {
        let image = self_modifying(0x07);
        let mut debug = attach(&image);
        debug.set_breakpoint(0x0409, &[]).expect("on the STA");
        debug.set_breakpoint(0x040E, &[]).expect("on the LDX");
        let entry = debug.stub().entry.to_le_bytes();
        let jsr = [0x20, entry[0], entry[1]];
        assert!(matches!(
            debug.command(b"/1N", WAIT).expect("sent"),
            Reply::Stopped(_)
        ));
        let reply = debug.step(&[], false, WAIT).expect("STA $040F");
        let Reply::Stopped(after) = reply else {
            panic!("no stop: {reply:?}");
        };
        assert_eq!(after.pc, 0x040C);
        assert_eq!(debug.read(0x040E, 3).expect("read"), jsr, "the JSR kept");
        assert_eq!(
            debug.read_as_program(0x040E, 3).expect("read"),
            [0xA2, 0x07, 0x8A],
            "the program's bytes shown"
        );
        debug.resume().expect("continue");
        let Reply::Stopped(at) = debug.wait_event(WAIT).expect("the next stop") else {
            panic!("no stop at the LDX");
        };
        assert_eq!(at.pc, 0x040E);
        debug.resume().expect("continue");
        assert_eq!(
            debug.wait_event(WAIT).expect("an answer"),
            Reply::Answer(b"07\r".to_vec())
        );
        debug.remove_breakpoint(0x040E).expect("removed");
        assert_eq!(debug.read(0x040E, 3).expect("read"), [0xA2, 0x07, 0x8A]);
        debug.detach().expect("detached");
    });
}

/// F3: a write that would turn a displaced instruction into one that
/// cannot run from the trampoline (a branch) is refused, naming the
/// address and the breakpoint, with nothing written.
#[test]
fn a_step_that_would_make_a_displaced_branch_is_refused() {
    within(|| {
        // STA $040E of $D0 (BNE) over the LDX's opcode.
        let mut image = self_modifying(0xD0);
        let area = &image.areas()[0];
        let mut bytes = area.bytes.clone();
        bytes[0x0A] = 0x0E;
        image = UploadImage::new(
            vec![Area {
                address: 0x0400,
                bytes,
            }],
            image.hooks().to_vec(),
        )
        .expect("an image");
        let mut debug = attach(&image);
        debug.set_breakpoint(0x0409, &[]).expect("on the STA");
        debug.set_breakpoint(0x040E, &[]).expect("on the LDX");
        assert!(matches!(
            debug.command(b"/1N", WAIT).expect("sent"),
            Reply::Stopped(_)
        ));
        match debug.step(&[], false, WAIT) {
            Err(StubError::Refused { reason, .. }) => {
                assert!(reason.contains("$040E"), "{reason}");
                assert!(reason.contains("branch"), "{reason}");
                assert!(reason.contains("delete"), "{reason}");
            }
            other => panic!("not refused: {other:?}"),
        }
        assert_eq!(debug.stopped().map(|r| r.pc), Some(0x0409), "not stepped");
        assert_eq!(
            debug.read_as_program(0x040E, 3).expect("read"),
            [0xA2, 0x00, 0x8A]
        );
        debug.detach().expect("detached");
    });
}

/// `/1W` stores A through the pointer at $80:
///
/// ```text
/// $0407  LDY #$00      ; the breakpoint (LDY and STA displaced)
/// $0409  STA ($80),Y
/// $040B  JSR PUTEOL
/// $040E  JMP CMD_DONE
/// ```
fn store_through_pointer() -> UploadImage {
    handler(
        b'W',
        &[0xA0, 0x00, 0x91, 0x80, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF],
    )
}

/// F4: a step whose write lands in the stub was left to the robot, which
/// wrote over the stub it was stopped in. Refused, naming the address
/// and the stub; the stub's code intact, the robot goes on.
#[test]
fn a_step_that_writes_into_the_stub_is_refused() {
    within(|| {
        let image = store_through_pointer();
        let mut debug = attach(&image);
        debug.set_breakpoint(0x0407, &[]).expect("set");
        assert!(matches!(
            debug.command(b"/1W", WAIT).expect("sent"),
            Reply::Stopped(_)
        ));
        let stub = debug.stub().clone();
        let target = stub.entry + 4;
        debug
            .write_verified(0x0080, &target.to_le_bytes())
            .expect("the pointer");
        debug.step(&[], false, WAIT).expect("LDY");
        match debug.step(&[], false, WAIT) {
            Err(StubError::Refused { reason, .. }) => {
                assert!(reason.contains(&format!("${target:04X}")), "{reason}");
                assert!(reason.contains("stub"), "{reason}");
            }
            other => panic!("not refused: {other:?}"),
        }
        let code_len = usize::from(stub.code_end - stub.address);
        assert_eq!(
            debug.read(stub.address, code_len).expect("read"),
            stub.bytes[..code_len]
        );
        // Going on would run it too: refused, the robot still stopped.
        match debug.resume() {
            Err(StubError::Refused { reason, .. }) => {
                assert!(reason.contains(&format!("${target:04X}")), "{reason}");
            }
            other => panic!("not refused: {other:?}"),
        }
        assert_eq!(debug.stopped().map(|r| r.pc), Some(0x0409));
        debug
            .write_verified(0x0080, &[0x00, 0x05])
            .expect("elsewhere");
        debug.resume().expect("continue");
        assert_eq!(
            debug.wait_event(WAIT).expect("an answer"),
            Reply::Answer(b"\r".to_vec())
        );
        debug.detach().expect("detached");
    });
}

/// F4 and F5: the stub's two zero-page bytes hold its pointer at a stop;
/// the program's wait in the stub. `read_as_program` shows the program's,
/// and a step that stores there is done by the host into the stub's
/// copy, which the robot has when it goes on.
#[test]
fn the_stubs_zero_page_shows_and_takes_the_programs_bytes() {
    within(|| {
        let image = store_through_pointer();
        let mut debug = attach(&image);
        let zero_page = u16::from(debug.stub().zero_page);
        debug
            .write_verified(zero_page, &[0x5A, 0x00])
            .expect("the program's bytes, while it runs");
        debug.set_breakpoint(0x0407, &[]).expect("set");
        let Reply::Stopped(hit) = debug.command(b"/1W", WAIT).expect("sent") else {
            panic!("no stop");
        };
        assert_eq!(
            debug.read_as_program(zero_page, 2).expect("read"),
            [0x5A, 0x00],
            "the program's, not the stub's pointer"
        );
        debug
            .write_verified(0x0080, &zero_page.to_le_bytes())
            .expect("the pointer");
        debug.step(&[], false, WAIT).expect("LDY");
        let reply = debug.step(&[], false, WAIT).expect("STA ($80),Y");
        assert!(matches!(reply, Reply::Stopped(_)), "{reply:?}");
        assert_eq!(
            debug.read_as_program(zero_page, 2).expect("read"),
            [hit.a, 0x00]
        );
        debug.resume().expect("continue");
        assert_eq!(
            debug.wait_event(WAIT).expect("an answer"),
            Reply::Answer(b"\r".to_vec())
        );
        assert_eq!(
            debug.read(zero_page, 2).expect("read while it runs"),
            [hit.a, 0x00]
        );
        debug.detach().expect("detached");
    });
}

/// fresh10 F4: a refused breakpoint advised "the instruction after it",
/// which was refused in turn. The refusal now names the nearest
/// instruction that takes one.
#[test]
fn the_nearest_place_that_takes_a_breakpoint_is_found() {
    use uploader::stub::patch::{nearest, plan};
    let image = common::stub::handler();
    // $0403 CMP #'Q', $0405 BNE: refused where a line starts at the BNE.
    assert!(plan(0x0403, &image, &[0x0405]).is_err());
    // $0405 BNE and $0407 LDA #'Q': four bytes, the branch relocated.
    assert_eq!(nearest(0x0403, &image, &[0x0405]), Some(0x0405));
    // With a line starting at $0407 too, the JSR at $0405 would cover it.
    assert_eq!(nearest(0x0403, &image, &[0x0405, 0x0407]), Some(0x0407));
    assert!(plan(0x0407, &image, &[0x0405, 0x0407]).is_ok());
}
