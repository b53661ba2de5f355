//! What the upload tests share: extension images that are real code, an
//! upload run against the virtual Scorpion, and the one invariant every
//! case checks in the emulated RAM afterwards.
#![allow(
    dead_code,
    unreachable_pub,
    unused_imports,
    reason = "each test file uses a part"
)]

mod image;
pub(crate) mod stub;

/// hostile30's 1022-byte extension at $0400 (`image::extension`): long
/// enough for the loader's sums, and for ranges of every kind.
pub(crate) fn extension_big() -> uploader::UploadImage {
    image::extension(1022, 7)
}

/// An extension of 64 bytes at `base`: its handler at `base + 3` jumps
/// to its chain slot's `JMP` at `base` (it falls through).
pub(crate) fn extension_at(base: u16) -> uploader::UploadImage {
    let [lo, hi] = base.to_le_bytes();
    let mut bytes = vec![0x4C, 0x00, 0x00, 0x4C, lo, hi];
    bytes.resize(64, 0xEA);
    uploader::UploadImage::new(
        vec![uploader::Area {
            address: base,
            bytes,
        }],
        vec![isa::objfmt::HookRecord {
            kind: isa::objfmt::HookKind::Unknown,
            handler: base + 3,
            chain: Some(base + 1),
        }],
    )
    .expect("an image")
}

pub(crate) use image::{extension, one_byte_changed};

use romlib::VirtualScorpion;
use romlib::symbols::{BAD_COMMAND, HOOK_LOOP, HOOK_UNKNOWN, ROM_LOOP};
use uploader::transport::{Transport, VirtualTransport};
use uploader::{
    LoaderChoice, LoaderPlan, NoProgress, RomProfile, UploadImage, UploadOptions, UploadReport,
    loader_plan, upload,
};

/// Keeps what an upload overwrote (the last file it handed over), for
/// the tests that undo it, and whether the upload said it changed nothing.
#[derive(Default)]
pub(crate) struct Kept(pub(crate) Option<uploader::Backup>, pub(crate) bool);

impl uploader::Keep for Kept {
    fn keep(&mut self, overwritten: &uploader::Backup) {
        self.0 = Some(overwritten.clone());
    }

    fn finished_unchanged(
        &mut self,
        kept: &uploader::Backup,
        _own: &uploader::Backup,
        _over: &[uploader::Area],
    ) {
        self.keep(kept);
        self.1 = true;
    }
}

/// The step between the places a sweep test puts its fault: `usual`, or
/// `SCORPION_FAULT_STEP` where set (`1`: every byte, for a long run by
/// hand; CI keeps the usual steps).
pub(crate) fn fault_step(usual: usize) -> usize {
    std::env::var("SCORPION_FAULT_STEP")
        .ok()
        .and_then(|step| step.parse().ok())
        .filter(|&step| step > 0)
        .unwrap_or(usual)
}

/// The 8N1 control value for 9600 baud (emulator::board::acia).
pub const CTRL_9600: u8 = 0x1E;

/// Options for one of the two paths.
pub fn options(loader: LoaderChoice) -> UploadOptions {
    UploadOptions {
        loader,
        ..UploadOptions::default()
    }
}

/// Uploads `image` over `transport` with the default client pacing.
pub fn run<T: Transport>(
    transport: T,
    image: &UploadImage,
    options: &UploadOptions,
) -> (uploader::Result<UploadReport>, T) {
    let mut client = uploader::client(transport, &options.profile);
    let result = upload(&mut client, image, options, &mut NoProgress);
    (result, client.into_transport())
}

/// A fresh virtual Scorpion behind a transport.
pub fn robot() -> VirtualTransport {
    VirtualTransport::new(VirtualScorpion::new())
}

/// The opcode at `hook` and its operand.
pub fn target(memory: &[u8], hook: u16) -> (u8, u16) {
    let at = usize::from(hook);
    (
        memory[at],
        u16::from_le_bytes([memory[at + 1], memory[at + 2]]),
    )
}

/// The invariant, checked in the emulated RAM: whatever happened, each
/// hook points at the ROM, at the RAM loader's verified code (either of
/// its two entries: every byte of the loader is as linked, since it
/// rewrites none of its own), or at the image's handler with every byte
/// of the image in place.
pub fn assert_safe(robot: &VirtualScorpion, image: &UploadImage, outcome: &str) {
    let memory = robot.robot().board().memory();
    let plan: Option<LoaderPlan> =
        loader_plan(&RomProfile::reference(), image, (9600, uploader::FAST_BAUD))
            .expect("the loader links");
    let (opcode, hook) = target(memory, HOOK_UNKNOWN);
    assert_eq!(opcode, 0x4C, "HOOK_UNKNOWN is no JMP ({outcome})");
    assert_eq!(
        target(memory, HOOK_LOOP),
        (0x4C, ROM_LOOP),
        "HOOK_LOOP ({outcome})"
    );
    let area = &image.areas()[0];
    let start = usize::from(area.address);
    let loaded = &memory[start..start + area.bytes.len()];
    if hook == 0x0403 {
        let previous = u16::from_le_bytes([loaded[1], loaded[2]]);
        assert_eq!(previous, BAD_COMMAND, "the chain slot ({outcome})");
        let mut expected = area.bytes.clone();
        expected[1..3].copy_from_slice(&previous.to_le_bytes());
        assert!(
            loaded == expected.as_slice(),
            "the hook points at code that did not verify ({outcome}): first difference at ${:04X}",
            (0..expected.len())
                .find(|&i| loaded[i] != expected[i])
                .map_or(0, |i| start + i)
        );
        return;
    }
    if hook == BAD_COMMAND {
        return;
    }
    let plan = plan.unwrap_or_else(|| panic!("HOOK_UNKNOWN points at ${hook:04X} ({outcome})"));
    let code = &plan.code;
    let start = usize::from(code.address);
    // `rate` alone may be in (hooked before `frames` went in); `frames`
    // falls into `rate`, `sums` into `frames`: with one hooked, it and
    // every part before it must be there.
    let end = if hook == plan.sums_handler {
        start + code.bytes.len()
    } else if hook == plan.frames_handler {
        usize::from(plan.sums_handler)
    } else {
        assert_eq!(
            hook, plan.rate_handler,
            "HOOK_UNKNOWN points at ${hook:04X}, neither the ROM, the loader nor the image ({outcome})"
        );
        usize::from(plan.frames_handler)
    };
    let expected = &code.bytes[..end - start];
    let found = &memory[start..end];
    assert!(
        found == expected,
        "HOOK_UNKNOWN points at ${hook:04X}, a loader that differs at ${:04X} ({outcome})",
        (0..expected.len())
            .find(|&i| found[i] != expected[i])
            .map_or(0, |i| start + i)
    );
}

/// The host and the robot's 6551 both at 9600 baud, and the robot
/// answering there: how every upload, done or failed on a working line,
/// leaves them.
pub fn assert_at_9600(transport: VirtualTransport, outcome: &str) -> VirtualScorpion {
    let mut client = uploader::client(transport, &RomProfile::reference());
    assert_eq!(client.transport().baud(), 9600, "{outcome}");
    client
        .probe()
        .unwrap_or_else(|error| panic!("the robot answers at 9600 ({outcome}): {error}"));
    let robot = client.into_transport().into_robot();
    assert_eq!(
        robot.robot().board().acia().control(),
        CTRL_9600,
        "the 6551 is back at 9600 ({outcome})"
    );
    robot
}

/// After a successful upload: the image hooked, the 6551 back at 9600
/// baud, and the robot answering there.
pub fn assert_done(transport: VirtualTransport, image: &UploadImage, outcome: &str) {
    let robot = assert_at_9600(transport, outcome);
    let memory = robot.robot().board().memory();
    assert_eq!(target(memory, HOOK_UNKNOWN), (0x4C, 0x0403), "{outcome}");
    assert_safe(&robot, image, outcome);
}
