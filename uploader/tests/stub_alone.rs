//! A step the host cannot do for the robot (a store to a card's register,
//! a push) where the next instruction cannot take a breakpoint's `JSR`
//! (fresh14 F7: `sta ADC_CONTROL`, then `ldx #0` before a loop's line):
//! the robot runs the instruction alone in a trampoline of the stub and
//! stops right after it, nothing patched into the program.

mod common;

use common::stub::{attach, hooked_at_0400};
use std::time::Duration;
use uploader::UploadImage;
use uploader::stub::{Registers, Reply};

const WAIT: Duration = Duration::from_secs(1);

/// `/1Q` starts the "card" at $9000 (KIM bus beyond the image: the host
/// does not write there for the robot), waits, and answers `Q`:
///
/// ```text
/// $0400  JMP chain
/// $0403  CMP #'Q'
/// $0405  BNE $0400
/// $0407  LDA #$85
/// $0409  PHA
/// $040A  PLA
/// $040B  STA $9000      ; the card's control register
/// $040E  LDX #3
/// $0410  DEX            ; a loop's line: no JSR may cover it
/// $0411  BNE $0410
/// $0413  LDA #'Q'
/// $0415  JSR PUTCH
/// $0418  JSR PUTEOL
/// $041B  JMP CMD_DONE
/// ```
fn card_handler() -> UploadImage {
    hooked_at_0400(vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, 0x85, 0x48, 0x68, 0x8D, 0x00, 0x90, 0xA2,
        0x03, 0xCA, 0xD0, 0xFD, 0xA9, b'Q', 0x20, 0x00, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ])
}

const ENTRIES: [u16; 3] = [0x0400, 0x0403, 0x0410];

fn step(
    debug: &mut uploader::stub::RobotDebug<uploader::transport::VirtualTransport>,
) -> Registers {
    match debug.step(&ENTRIES, false, WAIT).expect("a step") {
        Reply::Stopped(registers) => registers,
        other => panic!("the step did not stop: {other:?}"),
    }
}

#[test]
fn a_store_to_a_cards_register_before_a_loops_line_is_stepped_alone() {
    let image = card_handler();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0407, &ENTRIES).expect("set");
    debug
        .write_verified(0x9000, &[0x00])
        .expect("the card's register");
    let Reply::Stopped(at) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    assert_eq!(at.pc, 0x0407);
    assert_eq!(step(&mut debug).pc, 0x0409, "LDA #$85");
    let code_before = debug.read(0x0400, 0x1E).expect("read");
    // A push runs alone, onto the robot's own stack.
    let pushed = step(&mut debug);
    assert_eq!((pushed.pc, pushed.s), (0x040A, at.s.wrapping_sub(1)));
    let top = 0x0100 | u16::from(at.s);
    assert_eq!(debug.read(top, 1).expect("the stack"), [0x85]);
    let pulled = step(&mut debug);
    assert_eq!((pulled.pc, pulled.s, pulled.a), (0x040B, at.s, 0x85));
    let stored = step(&mut debug);
    assert_eq!(
        (stored.pc, stored.a, stored.s),
        (0x040E, 0x85, at.s),
        "STA $9000 ran and stopped after it: {stored:?}"
    );
    assert_eq!(
        debug.read(0x9000, 1).expect("read"),
        [0x85],
        "the card got it"
    );
    // Nothing was patched into the program for it.
    assert_eq!(debug.read(0x0400, 0x1E).expect("read"), code_before);
    // The registers a person sets at such a stop are the ones it goes on with.
    debug
        .set_registers(Registers { a: 0x01, ..stored })
        .expect("set A");
    assert_eq!(step(&mut debug).pc, 0x0410, "LDX #3");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"Q\r".to_vec())
    );
    debug.remove_breakpoint(0x0407).expect("removed");
    assert_eq!(debug.compare_with_image().expect("read"), None);
}

/// hostile15 F6: a session that died (`kill -9`) with the robot stopped
/// after a step run alone left it stopped at the trampoline's `JSR`, which
/// the next session could neither show nor let go on (`continue` stopped
/// there again). The trampoline's `JMP` after the `JSR` names the program's
/// next instruction: the next session shows the stop there and goes on.
#[test]
fn a_session_that_died_after_a_step_alone_is_found_at_the_programs_next_instruction() {
    let image = card_handler();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0407, &ENTRIES).expect("set");
    let Reply::Stopped(_) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    step(&mut debug);
    assert_eq!(step(&mut debug).pc, 0x040A, "PHA, alone");
    let client = debug.abandon();
    let mut again =
        uploader::stub::RobotDebug::attach(client, &uploader::RomProfile::reference(), image)
            .expect("attaches again");
    let found = again.recovery().stopped.expect("found stopped");
    assert_eq!(found.pc, 0x040A, "at the program's PLA: {found:?}");
    assert_eq!(again.stopped().map(|r| r.pc), Some(0x040A));
    again.resume().expect("continue");
    assert_eq!(
        again.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"Q\r".to_vec())
    );
    again.detach().expect("detached");
}

/// hostile15 F5: with all eight trampolines holding breakpoints, a step
/// that would run alone is refused, and now says how to free one.
#[test]
fn a_step_with_every_trampoline_taken_says_to_delete_a_breakpoint() {
    let areas = card_handler().areas().to_vec();
    let mut bytes = areas[0].bytes.clone();
    bytes.resize(0x60, 0xEA);
    let image = hooked_at_0400(bytes);
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0409, &ENTRIES).expect("on the PHA");
    for at in (0x0420..0x0440).step_by(4).take(7) {
        debug.set_breakpoint(at, &ENTRIES).expect("on the NOPs");
    }
    let Reply::Stopped(at) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    assert_eq!(at.pc, 0x0409);
    match debug.step(&ENTRIES, false, WAIT) {
        Err(uploader::stub::StubError::Refused { reason, .. }) => {
            assert!(reason.contains("delete one"), "{reason}");
        }
        other => panic!("not refused: {other:?}"),
    }
    debug.remove_breakpoint(0x0438).expect("one freed");
    assert_eq!(step(&mut debug).pc, 0x040A, "PHA, alone");
}
