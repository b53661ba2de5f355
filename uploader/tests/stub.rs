//! The debug stub (`uploader/stub/stub.s`) on the virtual Scorpion,
//! driven through nothing but the line: attached beside a handler, a
//! breakpoint hit inside it by its command, the registers read, a byte
//! changed, a step, continue and the command answered with the changed
//! byte, the breakpoint removed and the code compared with the image, the
//! hook given back at detach. And the refusals (the ROM, a jump target
//! covered).

mod common;

use common::stub::{attach, handler};

use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use std::time::Duration;
use uploader::stub::{Reply, StubError};

const WAIT: Duration = Duration::from_secs(1);

#[test]
fn a_breakpoint_in_a_handler_stops_it_and_it_goes_on_changed() {
    let image = handler();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x040C, &[]).expect("set");
    // The patch is a JSR into the stub's entry.
    let entry = debug.stub().entry.to_le_bytes();
    assert_eq!(
        debug.read(0x040C, 3).expect("read"),
        [0x20, entry[0], entry[1]]
    );
    let reply = debug.command(b"/1Q", WAIT).expect("sent");
    let Reply::Stopped(registers) = reply else {
        panic!("no stop: {reply:?}");
    };
    assert_eq!((registers.pc, registers.a, registers.x), (0x040C, b'Q', 1));
    assert_eq!(debug.read(0x0480, 1).expect("read"), [0x42]);
    debug.write_verified(0x0480, &[0x99]).expect("write");
    // A command sent while stopped is refused, not lost.
    assert!(matches!(
        debug.command(b"/1X", WAIT),
        Err(StubError::Refused { .. })
    ));
    // One step: LDA $0480 runs, it stops before JSR PUTHEX.
    let Reply::Stopped(after) = debug.step(&[], false, WAIT).expect("step") else {
        panic!("the step did not stop");
    };
    assert_eq!((after.pc, after.a), (0x040F, 0x99));
    // The step's temporary breakpoint is gone.
    assert_eq!(debug.read(0x040F, 3).expect("read"), [0x20, 0x03, 0xFF]);
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"Q99\r".to_vec())
    );
    // It stops again at the next command; removed, it does not.
    assert!(matches!(
        debug.command(b"/1Q", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    debug.remove_breakpoint(0x040C).expect("removed");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"Q99\r".to_vec())
    );
    // The code as the image has it, but for the byte changed (data).
    assert_eq!(
        debug.compare_with_image().expect("read"),
        Some((0x0480, 0x42, 0x99))
    );
    let stub = debug.stub().clone();
    let client = debug.detach().expect("detached");
    let robot = client.into_transport().into_robot();
    let memory = robot.robot().board().memory();
    let hook = usize::from(HOOK_UNKNOWN);
    assert_eq!(
        memory[hook + 1..hook + 3],
        [0x03, 0x04],
        "the hook is given back"
    );
    assert_eq!(stub.previous, 0x0403);
    assert_eq!(&memory[0x0400..0x0480], &image.areas()[0].bytes[..0x80]);
}

#[test]
fn registers_changed_at_a_stop_are_the_ones_it_goes_on_with() {
    let image = handler();
    let mut debug = attach(&image);
    // At $0407 (LDA #'Q', JSR PUTCH displaced together): set A... then
    // LDA overwrites it; so stop at $040F and change A before PUTHEX.
    debug.set_breakpoint(0x040F, &[]).expect("set");
    let Reply::Stopped(mut registers) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    assert_eq!(registers.a, 0x42);
    registers.a = 0x5A;
    debug.set_registers(registers).expect("set A");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"Q5A\r".to_vec())
    );
}

#[test]
fn breakpoints_the_robot_cannot_take_are_refused_with_the_reason() {
    let image = handler();
    let mut debug = attach(&image);
    let refused = |result: Result<(), StubError>| match result {
        Err(StubError::Refused { reason, .. }) => reason,
        other => panic!("not refused: {other:?}"),
    };
    let rom = refused(debug.set_breakpoint(BAD_COMMAND, &[]));
    assert!(rom.contains("ROM"), "{rom}");
    // $0407 LDA #'Q' (two bytes) displaces JSR PUTCH at $0409 too: refused
    // when a label or a line starts there.
    let covered = refused(debug.set_breakpoint(0x0407, &[0x0409]));
    assert!(covered.contains("$0409"), "{covered}");
    debug.set_breakpoint(0x0407, &[]).expect("no label inside");
    let overlap = refused(debug.set_breakpoint(0x0409, &[]));
    assert!(overlap.contains("$0407"), "{overlap}");
    // One address, one breakpoint: the second would displace the first's JSR.
    let twice = refused(debug.set_breakpoint(0x0407, &[]));
    assert!(twice.contains("already"), "{twice}");
    // Nothing half-written: the code is the image's but for the patch.
    let stub = debug.stub().entry.to_le_bytes();
    assert_eq!(
        debug.read(0x0403, 9).expect("read"),
        [0xC9, b'Q', 0xD0, 0xF9, 0x20, stub[0], stub[1], 0x00, 0xFF]
    );
    // And it stops there, and the displaced pair runs from the trampoline.
    let Reply::Stopped(registers) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    assert_eq!(registers.pc, 0x0407);
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"Q42\r".to_vec())
    );
}

#[test]
fn a_breakpoint_where_no_instruction_starts_is_refused_when_the_starts_are_known() {
    let image = handler();
    let mut debug = attach(&image);
    // The handler's instructions, as a built image's line table has them.
    debug.set_instruction_starts(vec![
        0x0400, 0x0403, 0x0405, 0x0407, 0x0409, 0x040C, 0x040F, 0x0412, 0x0415,
    ]);
    // $040D is `LDA $0480`'s operand.
    match debug.set_breakpoint(0x040D, &[]) {
        Err(StubError::Refused { reason, .. }) => {
            assert!(reason.contains("no instruction"), "{reason}");
        }
        other => panic!("not refused: {other:?}"),
    }
    assert_eq!(debug.breakpoints().count(), 0);
    assert_eq!(debug.compare_with_image().expect("read"), None);
    debug
        .set_breakpoint(0x040C, &[])
        .expect("an instruction starts there");
}

/// The hostile tester's F5: a step over `JSR PUTEOL` ends the answer
/// before it stops. The stop after it is not lost: `poll` sees it, the
/// step's breakpoint is taken out at it, and a detach without it gives
/// the robot back running all the same.
#[test]
fn a_stop_after_the_answer_of_a_step_is_noticed_and_detach_lets_it_go() {
    let image = handler();
    let mut debug = attach(&image);
    debug
        .set_breakpoint(0x0412, &[])
        .expect("set at JSR PUTEOL");
    assert!(matches!(
        debug.command(b"/1Q", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    let reply = debug.step(&[], true, WAIT).expect("next");
    assert_eq!(reply, Reply::Answer(b"Q42\r".to_vec()));
    let Some(Reply::Stopped(registers)) = debug.poll(WAIT).expect("polled") else {
        panic!("the stop after the answer was not seen");
    };
    assert_eq!(registers.pc, 0x0415);
    assert_eq!(debug.stopped(), Some(registers));
    // The step's breakpoint is out; the user's stays.
    assert_eq!(debug.read(0x0415, 3).expect("read"), [0x4C, 0x1E, 0xFF]);
    assert_eq!(debug.breakpoints().collect::<Vec<_>>(), [0x0412]);
    debug.resume().expect("continue");
    assert_eq!(debug.poll(WAIT).expect("polled"), None);
    // Again, and this time nobody looks before detach.
    assert!(matches!(
        debug.command(b"/1Q", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    debug.step(&[], true, WAIT).expect("next");
    let client = debug.detach().expect("detached");
    let mut robot = client.into_transport();
    let answer = {
        use uploader::transport::Transport as _;
        robot.send(b"/1Q").expect("sent");
        let mut heard = Vec::new();
        let deadline = robot.now() + WAIT;
        while !heard.ends_with(b"\r") && robot.now() < deadline {
            let left = deadline - robot.now();
            robot.receive(&mut heard, left).expect("heard");
        }
        heard
    };
    assert_eq!(answer, b"Q42\r", "the robot runs its control loop again");
    let memory = robot.into_robot();
    let memory = memory.robot().board().memory();
    assert_eq!(&memory[0x0400..0x0481], &image.areas()[0].bytes[..]);
}

/// `/1Z` answers the digit X ends at, written to $0480 first:
///
/// ```text
/// $0400  JMP chain      ; the chain slot
/// $0403  CMP #'Z'
/// $0405  BNE $0400
/// $0407  LDX #3         ; the breakpoint: it displaces LDX and INX
/// $0409  INX
/// $040A  DEX
/// $040B  DEX
/// $040C  TXA
/// $040D  CLC
/// $040E  ADC #'0'
/// $0410  STA $0480
/// $0413  JSR PUTCH
/// $0416  JSR PUTEOL
/// $0419  JMP CMD_DONE
/// ```
fn short_instructions() -> uploader::UploadImage {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Z', 0xD0, 0xF9, 0xA2, 0x03, 0xE8, 0xCA, 0xCA, 0x8A, 0x18, 0x69,
        b'0', 0x8D, 0x80, 0x04, 0x20, 0x00, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x81, 0xEA);
    uploader::UploadImage::new(
        vec![uploader::Area {
            address: 0x0400,
            bytes,
        }],
        vec![isa::objfmt::HookRecord {
            kind: isa::objfmt::HookKind::Unknown,
            handler: 0x0403,
            chain: Some(0x0401),
        }],
    )
    .expect("an image")
}

/// Steps over one- and two-byte instructions, which a breakpoint's
/// three-byte `JSR` cannot stop before: the host does them for the robot
/// (registers and the byte written as the robot would have them), from
/// among the bytes the breakpoint displaced too, and the robot goes on
/// from there with the right answer.
#[test]
fn steps_over_short_instructions_are_done_on_the_host() {
    let image = short_instructions();
    let mut debug = attach(&image);
    debug
        .set_breakpoint(0x0407, &[])
        .expect("LDX and INX displaced");
    let Reply::Stopped(at) = debug.command(b"/1Z", WAIT).expect("sent") else {
        panic!("no stop");
    };
    assert_eq!(at.pc, 0x0407);
    let mut trace = Vec::new();
    for _ in 0..7 {
        let Reply::Stopped(after) = debug.step(&[], false, WAIT).expect("step") else {
            panic!("the step did not stop: {trace:?}");
        };
        trace.push((after.pc, after.a, after.x));
    }
    assert_eq!(
        trace,
        [
            (0x0409, b'Z', 3),
            (0x040A, b'Z', 4),
            (0x040B, b'Z', 3),
            (0x040C, b'Z', 2),
            (0x040D, 2, 2),
            (0x040E, 2, 2),
            (0x0410, b'2', 2),
        ]
    );
    let Reply::Stopped(stored) = debug.step(&[], false, WAIT).expect("STA") else {
        panic!("STA did not stop");
    };
    assert_eq!(stored.pc, 0x0413);
    assert_eq!(
        debug.read(0x0480, 1).expect("read"),
        [b'2'],
        "written for it"
    );
    // Nothing patched for those steps: the code is the image's.
    assert_eq!(
        debug.read(0x040A, 9).expect("read"),
        image.areas()[0].bytes[10..19]
    );
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"2\r".to_vec())
    );
    // Stopped again, one step leaves the PC among the displaced bytes
    // (INX at $0409): it goes on from the trampoline's copy.
    assert!(matches!(
        debug.command(b"/1Z", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    let Reply::Stopped(inside) = debug.step(&[], false, WAIT).expect("LDX") else {
        panic!("LDX did not stop");
    };
    assert_eq!((inside.pc, inside.x), (0x0409, 3));
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"2\r".to_vec())
    );
    debug.remove_breakpoint(0x0407).expect("removed");
    assert_eq!(
        debug.compare_with_image().expect("read"),
        Some((0x0480, 0xEA, b'2'))
    );
}

/// The handler with `extra` bytes of code (NOPs) after its byte at $0480.
fn longer_handler(extra: usize) -> uploader::UploadImage {
    let image = handler();
    let mut area = image.areas()[0].clone();
    area.bytes.resize(area.bytes.len() + extra, 0xEA);
    uploader::UploadImage::new(vec![area], image.hooks().to_vec()).expect("an image")
}

/// Issue 27, round 6: attach compares the robot's code with the image
/// reading each span once when it is the image's (it read every byte
/// until two answers agreed): 512 more bytes of code cost under three
/// characters a byte on the return wire (two hex digits and the
/// answers' letters), not four. Prints the robot time at 9600 baud.
#[test]
fn attach_reads_code_that_is_the_images_once() {
    let cost = |extra: usize| {
        let image = longer_handler(extra);
        let mut client = attach(&image).abandon();
        let received = client.stats().received;
        let time = uploader::transport::Transport::now(client.transport());
        (received, time)
    };
    let (short, short_time) = cost(0);
    let (long, long_time) = cost(512);
    let per_byte = (long - short) as f64 / 512.0;
    println!(
        "attach at 9600 baud: {short} characters received, {:.3} s of robot time with {} bytes of code; {long}, {:.3} s with 512 more ({per_byte:.2} characters and {:.2} ms a byte more)",
        short_time.as_secs_f64(),
        handler().len(),
        long_time.as_secs_f64(),
        (long_time - short_time).as_secs_f64() * 1000.0 / 512.0,
    );
    assert!(per_byte < 3.0, "{per_byte:.2} characters a byte");
}

/// The stub a session leaves in RAM (detached, unhooked) is found there by
/// the next attach, which then writes only its data, not its code: a
/// second session at 9600 baud starts in about half the time.
#[test]
fn a_second_attach_writes_none_of_the_stubs_code() {
    let image = handler();
    let mut first = attach(&image);
    let sent_first = first.client().stats().sent;
    let stub = first.stub().clone();
    let client = first.detach().expect("detached");
    let before = client.stats().sent;
    let profile = uploader::RomProfile::reference();
    let mut second =
        uploader::stub::RobotDebug::attach(client, &profile, image.clone()).expect("attaches");
    let sent_second = second.client().stats().sent - before;
    let code = usize::from(stub.code_end - stub.address);
    // A byte written costs a character at least (in the RAM loader's
    // frames; 5.5 with `/9W`): the code written again would send more.
    assert!(
        sent_second + code < sent_first,
        "the second attach sent {sent_second} characters, the first {sent_first} (code: {code} bytes)"
    );
    assert_eq!(second.stub(), &stub, "the same stub, in the same place");
    assert_eq!(
        second.read(stub.address, stub.bytes.len()).expect("read"),
        stub.bytes,
        "the whole stub as linked"
    );
}

/// `/1Q` calls a subroutine of the image:
///
/// ```text
/// $0403  CMP #'Q'
/// $0405  BNE $0400
/// $0407  JSR $0413      ; show: the breakpoint's JSR displaces this one
/// $040A  JSR PUTCH
/// $040D  JSR PUTEOL
/// $0410  JMP CMD_DONE
/// $0413  LDA #'T'       ; getval
/// $0415  RTS
/// ```
fn calls_a_subroutine() -> uploader::UploadImage {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0x20, 0x13, 0x04, 0x20, 0x00, 0xFF, 0x20, 0x09,
        0xFF, 0x4C, 0x1E, 0xFF, 0xA9, b'T', 0x60,
    ];
    bytes.resize(0x81, 0xEA);
    common::stub::hooked_at_0400(bytes)
}

/// fresh10 F15: a `JSR` a breakpoint displaced runs from its trampoline,
/// so the subroutine's `RTS` came back into the stub: the step out
/// stopped at an address with no name, one more step to get home. The
/// stop is where the program goes on, after its `JSR`.
#[test]
fn a_step_out_of_a_subroutine_called_at_a_breakpoint_stops_after_the_call() {
    let image = calls_a_subroutine();
    let mut debug = attach(&image);
    debug
        .set_breakpoint(0x0407, &[])
        .expect("the JSR displaced");
    let reply = debug.command(b"/1Q", WAIT).expect("sent");
    let Reply::Stopped(at) = reply else {
        panic!("no stop: {reply:?}");
    };
    assert_eq!(at.pc, 0x0407);
    let mut pcs = Vec::new();
    for _ in 0..3 {
        let Reply::Stopped(after) = debug.step(&[], false, WAIT).expect("step") else {
            panic!("the step did not stop: {pcs:04X?}");
        };
        pcs.push(after.pc);
    }
    assert_eq!(pcs, [0x0413, 0x0415, 0x040A], "in, LDA, out: {pcs:04X?}");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("an answer"),
        Reply::Answer(b"T\r".to_vec())
    );
    debug.remove_breakpoint(0x0407).expect("removed");
    assert_eq!(debug.compare_with_image().expect("read"), None);
}

/// fresh30 F5: steps from the handler into the ROM (`/1Z` is not the
/// handler's: `BNE` to the chain slot, `JMP BAD_COMMAND`, ...) run on the
/// host until one must run on the robot with its next instruction in the
/// ROM. That refusal said "it goes outside the uploaded code", which the
/// steps before it had done too; it now says what tells it apart.
#[test]
fn a_step_the_robot_must_run_in_the_rom_says_why_the_ones_before_went() {
    let image = handler();
    let mut debug = attach(&image);
    debug.set_breakpoint(0x0403, &[]).expect("set");
    assert!(matches!(
        debug.command(b"/1Z", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    let mut went = Vec::new();
    let reason = loop {
        match debug.step(&[], false, WAIT) {
            Ok(Reply::Stopped(at)) => went.push(at.pc),
            Err(StubError::Refused { reason, .. }) => break reason,
            other => panic!("after {went:04X?}: {other:?}"),
        }
        assert!(went.len() < 50, "no refusal: {went:04X?}");
    };
    assert!(
        went.iter().any(|&pc| pc >= 0xF000),
        "steps into the ROM first: {went:04X?}"
    );
    assert!(reason.contains("must run on the robot"), "{reason}");
    assert!(reason.contains("continue"), "{reason}");
    debug.resume().expect("continue");
}
