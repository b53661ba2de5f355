//! What a person at a stop on the robot may change (fresh10 F16, F17;
//! hostile11 F1; fresh11 F1): writes go to RAM the program owns, not the
//! I/O page, the ROM, the KIM bus beyond the image, the hooks or the
//! table; the PC only to an instruction the host knows; never the decimal
//! flag on. Each refusal writes nothing, and the robot goes on as it was.
//! And a store into the image's own memory on the KIM bus is RAM: a step
//! over it is done on the host, as one into the board's RAM is.

mod common;

use common::stub::{attach, handler};
use isa::objfmt::{HookKind, HookRecord};
use romlib::VirtualScorpion;
use romlib::installed::TABLE;
use romlib::symbols::{HOOK_LOOP, HOOK_UNKNOWN};
use std::time::Duration;
use uploader::stub::{Registers, Reply, RobotDebug, StubError};
use uploader::transport::VirtualTransport;
use uploader::{Area, RomProfile, UploadImage};

const WAIT: Duration = Duration::from_secs(1);

fn stopped_at_show() -> (UploadImage, RobotDebug<VirtualTransport>, Registers) {
    let mut image = handler();
    // As a build's sections say: code to $0417, then data ($0480).
    image.set_code(vec![0x0400..=0x0417]);
    let mut debug = attach(&image);
    // The labels count as starts: the chain slot's ($0401) and `value`'s.
    debug.set_instruction_starts(vec![
        0x0400, 0x0401, 0x0403, 0x0405, 0x0407, 0x0409, 0x040C, 0x040F, 0x0412, 0x0415, 0x0480,
    ]);
    debug.set_breakpoint(0x040C, &[]).expect("set");
    let Reply::Stopped(registers) = debug.command(b"/1Q", WAIT).expect("sent") else {
        panic!("no stop");
    };
    (image, debug, registers)
}

fn refused<T>(result: Result<T, StubError>, why: &str) {
    match result {
        Err(StubError::Refused { reason, .. }) => {
            assert!(reason.contains(why), "`{why}` not in: {reason}");
        }
        Err(other) => panic!("not a refusal ({why}): {other:?}"),
        Ok(_) => panic!("accepted ({why})"),
    }
}

#[test]
fn writes_outside_the_programs_ram_are_refused_before_anything_is_sent() {
    let (_, mut debug, _) = stopped_at_show();
    let before = debug.read(HOOK_UNKNOWN - 2, 5).expect("read");
    for (at, why) in [
        (0xC002, "the I/O page"),
        (0xC000, "the I/O page"),
        (0xF000, "the ROM"),
        (0x9000, "KIM bus outside the image"),
        (HOOK_UNKNOWN, "HOOK_UNKNOWN's JMP"),
        (HOOK_UNKNOWN + 2, "HOOK_UNKNOWN's JMP"),
        (HOOK_LOOP + 1, "HOOK_LOOP's JMP"),
        (TABLE, "table of installed extensions"),
        // hostile11 F6: the image's chain slot, and the ROM's own RAM (its
        // receive ring's head, its buffer, the stack).
        (0x0401, "chain slot of the image's HOOK_UNKNOWN handler"),
        (0x0402, "chain slot"),
        (0x0000, "RAM the ROM leaves to extensions"),
        (0x0300, "RAM the ROM leaves to extensions"),
        (0x01F0, "RAM the ROM leaves to extensions"),
    ] {
        refused(debug.write_as_program(at, &[0x00]), why);
    }
    // A run that ends in the hook is refused whole.
    refused(
        debug.write_as_program(HOOK_UNKNOWN - 2, &[1, 2, 3]),
        "$01FE is the ROM's own RAM",
    );
    refused(
        debug.write_as_program(0x0F3E, &[1, 2, 3, 4]),
        "$0F40 is the ROM's own RAM",
    );
    assert_eq!(debug.read(HOOK_UNKNOWN - 2, 5).expect("read"), before);
    // The program's RAM: the ROM's user RAM, and the image's data.
    debug.write_as_program(0x0600, &[0x12]).expect("user RAM");
    debug
        .write_as_program(0x0480, &[0x77])
        .expect("the image's");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"Q77\r".to_vec())
    );
}

#[test]
fn registers_the_robot_cannot_go_on_with_are_refused() {
    let (_, mut debug, registers) = stopped_at_show();
    let stub = debug.stub().clone();
    for (pc, why) in [
        (0x3039, "where the image has no code"),
        (0xC010, "the I/O page"),
        (stub.entry, "in the debug stub"),
        (0x040D, "no instruction of the image starts at $040D"),
        // hostile12 F1: the chain slot (the operand of the JMP at $0400),
        // labelled, and the image's data.
        (0x0401, "in a chain slot"),
        (0x0480, "data of the image"),
        // fresh11 F9: the reset code, and the middle of a service's JMP;
        // hostile11 F5: a subroutine (GETHEX, PUTCH), whose RTS jammed
        // the CPU.
        (0xF000, "not one of the entries that end a handler"),
        (romlib::symbols::CMD_DONE + 1, "not one of the entries"),
        (romlib::symbols::GETHEX, "not one of the entries"),
        (romlib::symbols::PUTCH, "not one of the entries"),
    ] {
        refused(debug.set_registers(Registers { pc, ..registers }), why);
    }
    refused(
        debug.set_registers(Registers {
            p: registers.p | 0x08,
            ..registers
        }),
        "decimal flag",
    );
    assert_eq!(debug.stopped(), Some(registers), "nothing changed");
    // An instruction of the image, and one of the ROM, are taken.
    debug
        .set_registers(Registers {
            pc: 0x040F,
            a: 0x5A,
            ..registers
        })
        .expect("an instruction of the image");
    debug.resume().expect("continue");
    assert_eq!(
        debug.wait_event(WAIT).expect("the answer"),
        Reply::Answer(b"Q5A\r".to_vec())
    );
    assert!(matches!(
        debug.command(b"/1Q", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    let stopped = debug.stopped().expect("stopped");
    debug
        .set_registers(Registers {
            pc: romlib::symbols::CMD_DONE,
            ..stopped
        })
        .expect("the ROM's");
    debug.resume().expect("continue");
    assert_eq!(debug.wait_event(WAIT).expect("the line"), Reply::Silent);
    assert_eq!(
        debug.command(b"/1X", WAIT).expect("sent"),
        Reply::Answer(b"X00\r".to_vec())
    );
}

/// `/1Q` stores $55 into the image's own byte on the KIM bus:
///
/// ```text
/// $1000  JMP chain      ; the chain slot, $1001
/// $1003  CMP #'Q'
/// $1005  BNE $1000
/// $1007  LDA #$55
/// $1009  STA $1080      ; the breakpoint
/// $100C  INX            ; one byte, and a jump target after it
/// $100D  JMP CMD_DONE
/// $1080  .byte 0
/// ```
#[test]
fn a_store_into_the_images_memory_on_the_kim_bus_is_stepped_on_the_host() {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, 0x55, 0x8D, 0x80, 0x10, 0xE8, 0x4C, 0x1E,
        0xFF,
    ];
    bytes.resize(0x81, 0x00);
    let image = UploadImage::new(
        vec![Area {
            address: 0x1000,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: 0x1003,
            chain: Some(0x1001),
        }],
    )
    .expect("an image");
    let mut robot = VirtualScorpion::new();
    robot
        .robot_mut()
        .board_mut()
        .load(0x1000, &image.areas()[0].bytes)
        .expect("RAM on the KIM bus");
    robot
        .install_hook(HookKind::Unknown, 0x1003, Some(0x1001))
        .expect("HOOK_UNKNOWN is a JMP");
    let profile = RomProfile::reference();
    let client = uploader::client(VirtualTransport::new(robot), &profile);
    let mut debug = RobotDebug::attach(client, &profile, image).expect("attaches");
    let entries = [0x1003, 0x100D];
    debug.set_breakpoint(0x1009, &entries).expect("set");
    assert!(matches!(
        debug.command(b"/1Q", WAIT).expect("sent"),
        Reply::Stopped(_)
    ));
    let Reply::Stopped(after) = debug.step(&entries, false, WAIT).expect("a step") else {
        panic!("the step did not stop");
    };
    assert_eq!(after.pc, 0x100C);
    assert_eq!(debug.read_as_program(0x1080, 1).expect("read"), [0x55]);
}
