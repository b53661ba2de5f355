//! The RAM loader, after esptool's stub: two small 6502 programs in
//! `uploader/loader/`, assembled by our assembler when this crate is built
//! and linked here, at an address the image leaves free, against the ROM
//! profile's services.
//!
//! - `fast.s` (15 bytes): hooked through `HOOK_UNKNOWN` after it verified,
//!   `/1F` toggles the 6551 between the base rate and 19200 baud.
//! - `frames.s`: hooked next, it takes `/1L` frames that carry up to 255
//!   bytes at about one character a byte (the ROM's `/9W` needs 5.5) and
//!   falls through to the rate switch, whose `/1F` puts the line back on
//!   the base rate at the end.
//!
//! This module links the stages, finds them room, encodes frames and
//! estimates whether the loader pays for itself; `session` runs it.

use std::time::Duration;

use isa::objfmt::HookKind;
use linker::{Image, ImageSymbol};

use crate::image::{Area, RomProfile, Services, UploadImage};
use crate::transport::char_time;
use crate::{Error, Result};

/// `loader/fast.s`, assembled.
const FAST_OBJECT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/fast.o"));

/// `loader/frames.s`, assembled.
const FRAMES_OBJECT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/frames.o"));

/// The fastest rate of the 6551's internal generator: what the loader
/// switches to.
pub const FAST_BAUD: u32 = 19200;

/// The most data bytes the uploader puts in one frame (`frames.s` takes up
/// to 255). The upload sends one frame per `/7R` span of the verification
/// (up to 99 bytes), so a frame and the read that checks it travel
/// together; at 128, a frame's 133 bytes leave most of the 256 keys free.
pub const FRAME_MAX: usize = 128;

/// Characters a frame adds to its data: `/1L`, the key, four header bytes
/// and two check bytes.
pub(crate) const FRAME_OVERHEAD: usize = 3 + 1 + 3 + 2;

/// The slash that starts every command.
const SLASH: u8 = b'/';

/// One linked stage of the loader.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Stage {
    /// Its bytes, as an image with its hook record.
    pub(crate) image: UploadImage,
    /// Where `HOOK_UNKNOWN` must point to run it.
    pub(crate) handler: u16,
    /// Its chain slot, if it falls through.
    pub(crate) chain: Option<u16>,
    /// The operands it rewrites as it runs (self-modifying code).
    pub(crate) scratch: Vec<u16>,
}

/// The 6551's control value for 8N1 at `baud` (receiver on the baud
/// generator), if it has the rate.
pub(crate) fn acia_control(baud: u32) -> Option<u8> {
    emulator::board::acia::baud_code(baud).map(|code| 0x10 | code)
}

/// What `fast.s` XORs the control register with: the base rate's value
/// XOR the fast rate's; 0 (no change) if either is no 6551 rate.
fn rate_toggle((base, fast): (u32, u32)) -> u8 {
    acia_control(base)
        .zip(acia_control(fast))
        .map_or(0, |(base, fast)| base ^ fast)
}

/// Where the RAM loader goes for an upload, and what it is: for tests
/// and tools that check the robot's memory afterwards.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoaderPlan {
    /// The rate switch (`loader/fast.s`), as linked.
    pub fast: Area,
    /// The frame handler (`loader/frames.s`), as linked (its chain slot
    /// still holds `BAD_COMMAND`).
    pub frames: Area,
    /// Where `HOOK_UNKNOWN` points while the rate switch is in.
    pub fast_handler: u16,
    /// Where `HOOK_UNKNOWN` points while the frame handler is in.
    pub frames_handler: u16,
    /// Bytes of the frame handler that differ from the linked ones while it
    /// runs: the operands it rewrites itself, and its chain slot.
    pub scratch: Vec<u16>,
}

/// The RAM loader an upload of `image` with `profile` would use, for a
/// line at `rates` (base, fast); whether it is used also depends on
/// `--loader`, the hooks and the estimate.
///
/// # Errors
/// [`Error::LoaderLink`] (a defect of this crate).
pub fn loader_plan(
    profile: &RomProfile,
    image: &UploadImage,
    rates: (u32, u32),
) -> Result<Option<LoaderPlan>> {
    Ok(Loader::place(profile, image, rates)?.map(|loader| {
        let mut scratch = loader.frames.scratch.clone();
        if let Some(slot) = loader.frames.chain {
            scratch.extend([slot, slot + 1]);
        }
        LoaderPlan {
            fast: loader.fast.image.areas()[0].clone(),
            frames: loader.frames.image.areas()[0].clone(),
            fast_handler: loader.fast.handler,
            frames_handler: loader.frames.handler,
            scratch,
        }
    }))
}

/// Both stages, placed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Loader {
    /// The rate switch.
    pub(crate) fast: Stage,
    /// The frame handler.
    pub(crate) frames: Stage,
}

impl Loader {
    /// Links both stages for `profile`, in RAM the image leaves free:
    /// `None` when there is no room or the ROM lacks the services.
    ///
    /// # Errors
    /// [`Error::LoaderLink`] if the objects do not link (a defect of this
    /// crate, since they are built with it).
    pub(crate) fn place(
        profile: &RomProfile,
        image: &UploadImage,
        rates: (u32, u32),
    ) -> Result<Option<Loader>> {
        let Some(services) = profile.loader_services else {
            return Ok(None);
        };
        let toggle = rate_toggle(rates);
        let start = *profile.user_ram.start();
        // The sizes do not depend on the address: link once to learn them.
        let fast_len = link(FAST_OBJECT, "fast.s", start, profile, services, toggle)?
            .0
            .len();
        let frames_len = link(FRAMES_OBJECT, "frames.s", start, profile, services, toggle)?
            .0
            .len();
        let Some(address) = free_space(profile, image, fast_len + frames_len) else {
            return Ok(None);
        };
        let fast = stage(link(
            FAST_OBJECT,
            "fast.s",
            address,
            profile,
            services,
            toggle,
        )?)?;
        let frames = stage(link(
            FRAMES_OBJECT,
            "frames.s",
            address + fast_len as u16,
            profile,
            services,
            toggle,
        )?)?;
        Ok(Some(Loader { fast, frames }))
    }

    /// Bytes of both stages.
    pub(crate) fn len(&self) -> usize {
        self.fast.image.len() + self.frames.image.len()
    }

    /// The first address of the loader.
    pub(crate) fn address(&self) -> u16 {
        self.fast.image.areas()[0].address
    }

    /// Whether `address` is in one of the stages.
    pub(crate) fn contains(&self, address: u16) -> bool {
        self.fast.image.contains(address) || self.frames.image.contains(address)
    }
}

/// The stage's handler and chain from its one hook record, and the
/// operands it rewrites: those of the instructions labelled in
/// [`SELF_MODIFIED`].
fn stage((image, linked): (UploadImage, Image)) -> Result<Stage> {
    let mut scratch = Vec::new();
    for &(label, len) in SELF_MODIFIED {
        if let Some(at) = linked.symbol(label).and_then(|at| u16::try_from(at).ok()) {
            scratch.extend((1..=len).map(|i| at + i));
        }
    }
    let record = image
        .hooks()
        .iter()
        .find(|record| record.kind == HookKind::Unknown)
        .copied()
        .ok_or_else(|| Error::LoaderLink {
            address: image.areas()[0].address,
            message: "the stage does not take HOOK_UNKNOWN".into(),
        })?;
    Ok(Stage {
        handler: record.handler,
        chain: record.chain,
        scratch,
        image,
    })
}

/// Labels of `loader/frames.s` whose instruction operands it rewrites,
/// with the operand's length.
const SELF_MODIFIED: &[(&str, u16)] = &[
    ("key", 1),
    ("sum0", 1),
    ("sum1", 1),
    ("dest", 2),
    ("count", 1),
];

/// Links one stage at `address` against the profile's services.
fn link(
    object: &[u8],
    name: &str,
    address: u16,
    profile: &RomProfile,
    services: Services,
    toggle: u8,
) -> Result<(UploadImage, Image)> {
    let failed = |message: String| Error::LoaderLink { address, message };
    let symbol = |name: &str, value: u16| ImageSymbol {
        name: name.to_owned(),
        value: u32::from(value),
        size: 0,
        global: true,
        section: None,
    };
    // The services as a symbol file, so any ROM profile that has them will do.
    let rom = Image {
        symbols: vec![
            symbol("GETCH", services.getch),
            symbol("CHKCH", services.chkch),
            symbol("CMD_DONE", services.cmd_done),
            symbol("RATE_TOGGLE", u16::from(toggle)),
            // The chain slot's initial value: the uploader overwrites it with
            // the hook's target before the stage is hooked.
            symbol(
                "BAD_COMMAND",
                profile
                    .reset_target(HookKind::Unknown)
                    .unwrap_or(services.cmd_done),
            ),
        ],
        ..Image::default()
    };
    let target = linker::Target::builtin("flat", Some(u64::from(address)))
        .map_err(|error| failed(error.to_string()))?;
    let linked = linker::link(
        &[linker::Input {
            name,
            bytes: object,
        }],
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[linker::SymbolFile {
                name: "rom profile",
                image: &rom,
            }],
            sources: &linker::NoSources,
        },
    )
    .map_err(|error| match error {
        linker::Error::Failed { errors, .. } => failed(
            errors
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("; "),
        ),
        other => failed(other.to_string()),
    })?;
    let image = UploadImage::try_from(&linked.image)?;
    if image.areas().len() != 1 {
        return Err(failed(format!(
            "{name} links to {} areas",
            image.areas().len()
        )));
    }
    Ok((image, linked.image))
}

/// The highest `len` bytes of the profile's user RAM that the image does
/// not load.
fn free_space(profile: &RomProfile, image: &UploadImage, len: usize) -> Option<u16> {
    let ram_start = u32::from(*profile.user_ram.start());
    let ram_end = u32::from(*profile.user_ram.end()) + 1;
    let len = len as u32;
    // Gaps between the image's areas, clipped to user RAM, highest first.
    let mut top = ram_end;
    let mut areas: Vec<&Area> = image.areas().iter().collect();
    areas.sort_by_key(|area| std::cmp::Reverse(area.address));
    for area in areas
        .iter()
        .map(|area| (u32::from(area.address), area.end()))
        .chain(std::iter::once((ram_start, ram_start)))
    {
        let (start, end) = area;
        let gap_start = end.clamp(ram_start, ram_end);
        if top >= gap_start + len && top <= ram_end {
            return u16::try_from(top - len).ok();
        }
        top = top.min(start.max(ram_start));
    }
    None
}

/// A `/1L` frame for the RAM loader that writes `data` (1 to
/// [`FRAME_MAX`] bytes; more are cut) at `address`: the command, the key,
/// the encoded header with its checksum, the encoded data. No byte after
/// the command is a slash. (See `uploader/loader/frames.s`.)
#[must_use]
pub fn loader_frame(address: u16, data: &[u8]) -> Vec<u8> {
    frame(address, data)
}

/// [`loader_frame`].
pub(crate) fn frame(address: u16, data: &[u8]) -> Vec<u8> {
    let [lo, hi] = address.to_le_bytes();
    let count = data.len().clamp(1, FRAME_MAX) as u8;
    let data = &data[..usize::from(count).min(data.len())];
    // Each data byte rules out one key (byte ^ slash); a frame of at most
    // 128 bytes leaves at least 128 keys to try with the header's.
    let mut ruled_out = [false; 256];
    ruled_out[usize::from(SLASH)] = true;
    for &byte in data {
        ruled_out[usize::from(byte ^ SLASH)] = true;
    }
    for key in 0u8..=255 {
        if ruled_out[usize::from(key)] {
            continue;
        }
        // Both sums start at the key; the check bytes bring them to zero:
        // c0 = -(s0 + s1), c1 = s1.
        let (mut sum0, mut sum1) = (key, key);
        for byte in [lo, hi, count] {
            sum0 = sum0.wrapping_add(byte);
            sum1 = sum1.wrapping_add(sum0);
        }
        let header = [lo, hi, count, sum0.wrapping_add(sum1).wrapping_neg(), sum1];
        if header.iter().any(|&byte| byte ^ key == SLASH) {
            continue;
        }
        let mut out = Vec::with_capacity(FRAME_OVERHEAD + data.len());
        out.extend_from_slice(b"/1L");
        out.push(key);
        out.extend(header.iter().chain(data).map(|&byte| byte ^ key));
        return out;
    }
    // Unreachable for frames of FRAME_MAX bytes or fewer (at most 134 of
    // the 256 keys are ruled out); an empty frame writes nothing.
    Vec::new()
}

/// How long an upload of `len` bytes takes at `baud` with the ROM's
/// commands alone: 11 characters per 2 bytes, plus the `/7R` questions.
#[must_use]
pub fn rom_only_estimate(len: usize, baud: u32) -> Duration {
    let questions = len.div_ceil(99);
    char_time(len.div_ceil(2) * 11 + questions * 9, baud)
}

/// How long the same upload takes through the loader: the two stages
/// through the ROM (the second at `fast`), then the bytes in frames, where
/// the `/7R` answers (two characters a byte) on the return wire are what
/// take longest; plus the round trips of the hooks and rate switches.
#[must_use]
pub fn loader_estimate(len: usize, loader_len: usize, baud: u32, fast: u32) -> Duration {
    let fast_stage = 15;
    let install = rom_only_estimate(fast_stage, baud)
        + rom_only_estimate(loader_len.saturating_sub(fast_stage), fast);
    let questions = len.div_ceil(99);
    let out = len + len.div_ceil(99) * FRAME_OVERHEAD + questions * 9;
    let back = 2 * len + 2 * questions;
    let round_trips = char_time(200, baud) + char_time(100, fast);
    install + char_time(out.max(back), fast) + round_trips
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decodes a frame as `frames.s` does: `None` where it would write
    /// nothing.
    fn decode(frame: &[u8]) -> Option<(u16, Vec<u8>)> {
        let (command, rest) = frame.split_at(3);
        assert_eq!(command, b"/1L");
        let key = rest[0];
        let mut bytes = rest[1..].iter().map(|&b| {
            assert_ne!(b, SLASH, "no slash after the command");
            b ^ key
        });
        let (mut s0, mut s1) = (key, key);
        let mut header = [0u8; 5];
        for slot in &mut header {
            *slot = bytes.next()?;
            s0 = s0.wrapping_add(*slot);
            s1 = s1.wrapping_add(s0);
        }
        if s0 != 0 || s1 != 0 {
            return None;
        }
        let data: Vec<u8> = bytes.take(usize::from(header[2])).collect();
        Some((u16::from_le_bytes([header[0], header[1]]), data))
    }

    #[test]
    fn frames_round_trip_without_a_slash() {
        let all: Vec<u8> = (0..=255u8).collect();
        for (address, data) in [
            (0x0400u16, vec![0x2F; 5]),
            (0x2F2F, vec![0x00]),
            (0x1000, all[..128].to_vec()),
            (0x0BFF, all[0x80..].to_vec()),
        ] {
            let frame = frame(address, &data);
            assert_eq!(frame.len(), FRAME_OVERHEAD + data.len());
            assert_eq!(decode(&frame), Some((address, data)));
        }
    }

    #[test]
    fn a_damaged_header_writes_nothing() {
        let good = frame(0x0400, &[1, 2, 3, 4]);
        for at in 4..9 {
            for flip in [0x01u8, 0x10, 0x80, 0xFF] {
                let mut bad = good.clone();
                bad[at] ^= flip;
                if bad[at] == SLASH {
                    continue;
                }
                assert_eq!(decode(&bad), None, "byte {at} ^ {flip:02X}");
            }
        }
        // A lost header byte shifts the data into the header.
        let mut short = good.clone();
        short.remove(5);
        assert_eq!(decode(&short), None);
    }

    #[test]
    fn stages_link_and_fit_around_the_image() {
        let profile = RomProfile::reference();
        let image = UploadImage::new(
            vec![Area {
                address: 0x0400,
                bytes: vec![0xEA; 0x0B00],
            }],
            vec![],
        )
        .expect("an image");
        let rates = (9600, FAST_BAUD);
        let loader = Loader::place(&profile, &image, rates)
            .expect("links")
            .expect("room above $0F00");
        assert_eq!(loader.fast.image.len(), 15);
        assert_eq!(
            loader.fast.image.areas()[0].bytes[4..9],
            [0xAD, 0x13, 0xC0, 0x49, 0x01],
            "LDA ACIA_CTRL / EOR #$1E^$1F"
        );
        assert!(loader.len() < 120, "{} bytes", loader.len());
        assert_eq!(
            usize::from(loader.address()) + loader.len(),
            0x1000,
            "the top of user RAM"
        );
        assert_eq!(loader.fast.handler, loader.address());
        assert_eq!(loader.frames.handler, loader.address() + 15);
        assert!(loader.frames.chain.is_some());
        assert_eq!(loader.fast.chain, None);
        assert_eq!(
            loader.frames.scratch.len(),
            6,
            "{:?}",
            loader.frames.scratch
        );

        let full = UploadImage::new(
            vec![Area {
                address: 0x0400,
                bytes: vec![0xEA; 0x0C00],
            }],
            vec![],
        )
        .expect("an image");
        assert_eq!(Loader::place(&profile, &full, rates).expect("links"), None);

        let gapped = UploadImage::new(
            vec![
                Area {
                    address: 0x0400,
                    bytes: vec![0xEA; 0x100],
                },
                Area {
                    address: 0x0700,
                    bytes: vec![0xEA; 0x900],
                },
            ],
            vec![],
        )
        .expect("an image");
        let loader = Loader::place(&profile, &gapped, rates)
            .expect("links")
            .expect("room in the gap");
        assert!(loader.address() >= 0x0500);
        assert!(usize::from(loader.address()) + loader.len() <= 0x0700);
    }
}
