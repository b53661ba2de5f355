//! hostile29 F2: the robot's sums are Fletcher-16 mod 256, under which a
//! page of one even byte (256 `NOP`s, `$EA`) sums as a page of zeros. An
//! upload of such pages onto a robot holding zeros took them for held and
//! said "verified" with 768 bytes wrong. Both sums are 16 bits now, over
//! ranges of at most `uploader::EXACT` bytes, under which only zeros sum
//! as zeros; each case here writes every byte it must.

mod common;

use common::robot;
use uploader::{Area, NoProgress, UploadImage, UploadOptions, upload};

/// `len` bytes of `fill` then an `RTS` at `base`, uploaded onto a robot
/// whose memory there holds `before`: the bytes the robot holds after.
fn uploaded(base: u16, len: usize, before: u8, fill: u8) -> (Vec<u8>, Vec<u8>) {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    let mut bytes = vec![fill; len];
    bytes.push(0x60);
    client
        .transport()
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(base, &vec![before; len + 1])
        .expect("RAM");
    let image = UploadImage::new(
        vec![Area {
            address: base,
            bytes: bytes.clone(),
        }],
        vec![],
    )
    .expect("an image");
    upload(&mut client, &image, &options, &mut NoProgress).expect("uploaded");
    let memory = client.transport().robot().robot().board().memory();
    let held = memory[usize::from(base)..usize::from(base) + bytes.len()].to_vec();
    (held, bytes)
}

#[test]
fn pages_of_one_byte_are_written_over_zeros_and_over_other_runs() {
    for (base, len) in [
        (0x0400u16, 1000usize),
        (0x1000, 1000),
        (0x1000, 600),
        (0x0500, 64),
    ] {
        for (before, fill) in [
            (0x00, 0xEA),
            (0x00, 0x10),
            (0x00, 0x80),
            (0x10, 0x20),
            (0x00, 0xFF),
        ] {
            let (held, wanted) = uploaded(base, len, before, fill);
            let wrong = held.iter().zip(&wanted).filter(|(a, b)| a != b).count();
            assert_eq!(
                wrong, 0,
                "${base:04X}, {len} x ${fill:02X} over ${before:02X}: {wrong} bytes wrong"
            );
        }
    }
}
