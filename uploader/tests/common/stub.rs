//! The debug stub's tests' set-up (tests/stub.rs, stub_faults.rs,
//! stub_recovery.rs): a handler image and a robot that runs it, as an
//! upload leaves it.

use isa::objfmt::{HookKind, HookRecord};
use romlib::VirtualScorpion;
use uploader::stub::RobotDebug;
use uploader::transport::VirtualTransport;
use uploader::{Area, RomProfile, UploadImage};

/// `/1Q` answers `Q` and the byte at $0480 in hex:
///
/// ```text
/// $0400  JMP chain      ; the chain slot, $0401
/// $0403  CMP #'Q'       ; the handler
/// $0405  BNE $0400
/// $0407  LDA #'Q'
/// $0409  JSR PUTCH
/// $040C  LDA $0480
/// $040F  JSR PUTHEX
/// $0412  JSR PUTEOL
/// $0415  JMP CMD_DONE
/// $0480  .byte $42
/// ```
pub(crate) fn handler() -> UploadImage {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, b'Q', 0x20, 0x00, 0xFF, 0xAD, 0x80, 0x04,
        0x20, 0x03, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x81, 0xEA);
    bytes[0x80] = 0x42;
    hooked_at_0400(bytes)
}

/// `bytes` as one area at $0400 hooked on HOOK_UNKNOWN, the handler at
/// $0403 and the chain slot at $0401 (the `JMP` at $0400), the layout
/// every stub test's handler has.
pub(crate) fn hooked_at_0400(bytes: Vec<u8>) -> UploadImage {
    UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: 0x0403,
            chain: Some(0x0401),
        }],
    )
    .expect("an image")
}

/// A robot with the handler loaded and hooked, as an upload leaves it.
pub(crate) fn robot(image: &UploadImage) -> VirtualTransport {
    let mut robot = VirtualScorpion::new();
    let area = &image.areas()[0];
    robot
        .robot_mut()
        .board_mut()
        .load(area.address, &area.bytes)
        .expect("RAM");
    robot
        .install_hook(HookKind::Unknown, 0x0403, None)
        .expect("HOOK_UNKNOWN is a JMP");
    VirtualTransport::new(robot)
}

/// The debugger attached to a robot running `image`.
pub(crate) fn attach(image: &UploadImage) -> RobotDebug<VirtualTransport> {
    let profile = RomProfile::reference();
    let client = uploader::client(robot(image), &profile);
    RobotDebug::attach(client, &profile, image.clone()).expect("attaches")
}
