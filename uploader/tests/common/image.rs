//! The extension image the upload tests, the benchmark and the trace
//! example share (the latter two include this file by `#[path]`), so that
//! the benchmark's figure and the tests are about the same kind of image.

use isa::objfmt::{HookKind, HookRecord};
use uploader::{Area, UploadImage};

/// An extension of `len` bytes at $0400 that is real code: `$0400: JMP
/// chain` (the chain slot is its operand, $0401), `$0403: JMP $0400` (the
/// handler owns nothing and falls through), then pseudo-random bytes
/// (incompressible; over 2 KiB, every value present). `seed` varies them.
pub(crate) fn extension(len: usize, seed: u32) -> UploadImage {
    let mut bytes: Vec<u8> = (0..len as u32)
        .map(|i| (i ^ seed).wrapping_mul(2_246_822_519).to_le_bytes()[2])
        .collect();
    bytes[..6].copy_from_slice(&[0x4C, 0x00, 0x00, 0x4C, 0x00, 0x04]);
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
    .expect("a valid image")
}

/// `image` with the byte at `offset` of its first area changed: the
/// one-byte change of issue 27.
pub(crate) fn one_byte_changed(image: &UploadImage, offset: usize) -> UploadImage {
    let mut areas = image.areas().to_vec();
    areas[0].bytes[offset] ^= 0x5A;
    UploadImage::new(areas, image.hooks().to_vec()).expect("an image")
}
