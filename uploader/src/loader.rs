//! The RAM loader, after esptool's stub: a small 6502 program
//! (`uploader/loader/loader.s`), assembled by our assembler when this
//! crate is built and linked here, at an address the image leaves free,
//! against the ROM profile's services. Two parts, one piece of code:
//!
//! - `rate` (15 bytes, first): `/1F` toggles the 6551 between the base
//!   rate and 19200 baud; every other command is dropped. Written alone
//!   at the base rate, verified, hooked: the rest goes in at 19200.
//! - `frames`: `/1L` frames that carry up to 255 bytes at about one
//!   character a byte (the ROM's `/9W` needs 5.5); every other command
//!   falls into `rate`, whose `/1F` takes the line back at the end.
//!
//! The rate is switched by code the uploader verified, never by writing
//! the 6551's control register with the ROM's `/7W`: line noise can change
//! the digits of a `/7W`, and a control value it makes up (another word
//! length, the external receiver clock, a write to the 6551's reset
//! register beside it) leaves a robot that no host can reach until its
//! reset button is pressed.
//!
//! This module links the loader, finds it room (RAM and eight bytes of
//! user zero page for its state), encodes frames and estimates whether it
//! pays for itself; `session` runs it.

use std::time::Duration;

use isa::objfmt::HookKind;
use linker::{Image, ImageSymbol};
use platform::{acia, map};

use romlib::installed::Installed;

use crate::client::Client;
use crate::image::{Area, RomProfile, Services, UploadImage};
use crate::transport::Transport;
use crate::transport::char_time;
use crate::{Error, Result};

/// `loader/loader.s`, assembled to take its data through `CHKCH`.
const LOADER_OBJECT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/loader.o"));

/// `loader/loader.s`, assembled to take its data straight from the ROM's
/// receive ring.
const LOADER_RING_OBJECT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/loader_ring.o"));

/// The fastest rate of the 6551's internal generator: what the loader
/// switches the line to.
pub const FAST_BAUD: u32 = 19200;

/// The most data bytes the uploader puts in one frame (`loader.s` takes up
/// to 255). The upload sends one frame per `/7R` span of the verification
/// (up to 99 bytes), so a frame and the read that checks it travel
/// together, and the next frame fits the ROM's receive ring beside the
/// answer being sent (two frames a span would not: the window of
/// characters ahead of an answer would hold them back). At 128, a frame's
/// 137 bytes leave at least 127 of the 256 keys free of a slash.
pub const FRAME_MAX: usize = 128;

/// Characters a frame adds to its data: `/1L`, the key, three header
/// bytes and two check bytes.
pub(crate) const FRAME_OVERHEAD: usize = 3 + 1 + 3 + 2;

/// The slash that starts every command.
const SLASH: u8 = b'/';

/// The user zero page the loader keeps its state in (`LZP` in
/// `loader.s`): the key, two sums, the five header bytes.
pub(crate) const ZERO_PAGE_LEN: u8 = 8;

/// The 6551's control register (`ACIA_CTRL` in the ROM's `hardware.inc`).
pub(crate) const ACIA_CONTROL: u16 = map::ACIA + acia::reg::CONTROL;

/// What `rate` XORs the 6551's control register with: the baud codes of
/// the two rates XORed, so the framing bits stay as they are; 0 (no
/// change) when either is not a rate of the 6551.
pub(crate) fn rate_toggle((base, fast): (u32, u32)) -> u8 {
    acia::baud_code(base)
        .zip(acia::baud_code(fast))
        .map_or(0, |(base, fast)| base ^ fast)
}

/// The loader, linked and placed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Loader {
    /// Its bytes: one area, `rate` first.
    pub(crate) image: UploadImage,
    /// `rate`'s address: where `HOOK_UNKNOWN` points while the line is
    /// switched.
    pub(crate) rate: u16,
    /// `frames`' address: where `HOOK_UNKNOWN` points while `sums` goes in.
    pub(crate) frames: u16,
    /// `sums`' address: where `HOOK_UNKNOWN` points once the whole loader
    /// is in (it falls into `frames`, which falls into `rate`).
    pub(crate) sums: u16,
    /// The first of its zero-page bytes.
    pub(crate) zero_page: u8,
}

/// Where the RAM loader goes for an upload, and what it is: for tests
/// and tools that check the robot's memory afterwards.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoaderPlan {
    /// The loader (`loader/loader.s`) as linked: `rate`, then `frames`.
    /// No byte of it changes while it runs.
    pub code: Area,
    /// `rate`'s address (`HOOK_UNKNOWN`'s target while the line switches).
    pub rate_handler: u16,
    /// `frames`' address (`HOOK_UNKNOWN`'s target while `sums` goes in).
    pub frames_handler: u16,
    /// `sums`' address (`HOOK_UNKNOWN`'s target once the loader is in:
    /// `/9K` checksums, anything else falls into `frames`).
    pub sums_handler: u16,
    /// The user zero page it keeps its state in (eight bytes).
    pub zero_page: std::ops::RangeInclusive<u8>,
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
    Ok(Loader::place(profile, image, rates)?.map(|loader| loader.plan()))
}

/// Whether `target` (a hook's) is the RAM loader where an upload leaves
/// it, at the top of user RAM: an upload that did not finish (killed, its
/// line cut) leaves it hooked in place of the ROM's target. Its place when
/// it is (the bytes there read and compared with the loader's).
///
/// # Errors
/// The line's errors.
pub fn loader_left_at<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    target: u16,
) -> Result<Option<std::ops::RangeInclusive<u16>>> {
    // An image at the start of user RAM leaves the loader its usual place.
    let start = *profile.user_ram.start();
    let probe = UploadImage::new(
        vec![Area {
            address: start,
            bytes: vec![0],
        }],
        Vec::new(),
    )?;
    // Linked for a line raised to the fast rate, or kept at its own (a
    // pseudo-terminal, `--fast-baud 0`): the switch's bytes differ.
    let baud = client.transport().baud();
    let mut held: Option<Vec<u8>> = None;
    for rates in [(baud, FAST_BAUD), (baud, baud)] {
        let Some(plan) = loader_plan(profile, &probe, rates)? else {
            continue;
        };
        if ![plan.rate_handler, plan.frames_handler, plan.sums_handler].contains(&target) {
            continue;
        }
        let code = &plan.code;
        let from = usize::from(target - code.address);
        let expected = &code.bytes[from..code.bytes.len().min(from + 8)];
        if held.is_none() {
            held = Some(client.read_memory(target, expected.len())?);
        }
        if held.as_deref() == Some(expected) {
            return Ok(Some(
                code.address..=code.address + (code.bytes.len() as u16 - 1),
            ));
        }
    }
    Ok(None)
}

impl Loader {
    /// Where it goes and what it is, as tools see it.
    pub(crate) fn plan(&self) -> LoaderPlan {
        LoaderPlan {
            code: self.image.areas()[0].clone(),
            rate_handler: self.rate,
            frames_handler: self.frames,
            sums_handler: self.sums,
            zero_page: self.zero_page..=self.zero_page + (ZERO_PAGE_LEN - 1),
        }
    }

    /// Links the loader for `profile` and a line at `rates`, in RAM and
    /// zero page the image leaves free: `None` when there is no room or
    /// the ROM lacks the services.
    ///
    /// # Errors
    /// [`Error::LoaderLink`] if the object does not link (a defect of this
    /// crate, since it is built with it).
    pub(crate) fn place(
        profile: &RomProfile,
        image: &UploadImage,
        rates: (u32, u32),
    ) -> Result<Option<Loader>> {
        let Some(services) = profile.loader_services else {
            return Ok(None);
        };
        let Some(zero_page) = free_zero_page(profile, image) else {
            return Ok(None);
        };
        let object = if services.ring.is_some() {
            LOADER_RING_OBJECT
        } else {
            LOADER_OBJECT
        };
        let symbols = Symbols {
            services,
            zero_page,
            toggle: rate_toggle(rates),
        };
        // The size does not depend on the address: link once to learn it.
        let start = *profile.user_ram.start();
        let len = link(object, start, &symbols)?.0.len();
        let Some(address) = free_space(profile, image, len) else {
            return Ok(None);
        };
        let (image, linked) = link(object, address, &symbols)?;
        let label = |name: &str| {
            linked
                .symbol(name)
                .and_then(|at| u16::try_from(at).ok())
                .ok_or_else(|| Error::LoaderLink {
                    address,
                    message: format!("the loader has no `{name}`"),
                })
        };
        let (rate, frames, sums) = (label("rate")?, label("frames")?, label("sums")?);
        let hooked = image
            .hooks()
            .iter()
            .any(|record| record.kind == HookKind::Unknown && record.handler == sums);
        let ordered = rate == address && rate < frames && frames < sums && image.contains(sums);
        if !(ordered && hooked) {
            return Err(Error::LoaderLink {
                address,
                message: "`rate`, `frames` and `sums` must come in that order and `sums` take HOOK_UNKNOWN".into(),
            });
        }
        Ok(Some(Loader {
            image,
            rate,
            frames,
            sums,
            zero_page,
        }))
    }

    /// Bytes of the loader.
    pub(crate) fn len(&self) -> usize {
        self.image.len()
    }

    /// The first address of the loader.
    pub(crate) fn address(&self) -> u16 {
        self.image.areas()[0].address
    }

    /// Whether `address` is in the loader.
    pub(crate) fn contains(&self, address: u16) -> bool {
        self.image.contains(address)
    }

    /// Whether a hook of `kind` at `target` is this loader left hooked by
    /// an upload that failed: one of its entries, and in no extension the
    /// table lists (`installed`), since the loader is never placed over
    /// one: an extension that happens to start where an entry would be
    /// is that extension.
    pub(crate) fn left_hooked(&self, kind: HookKind, target: u16, installed: &[Installed]) -> bool {
        kind == HookKind::Unknown
            && [self.sums, self.frames, self.rate].contains(&target)
            && !installed.iter().any(|other| other.contains(target))
    }

    /// Whether the loader's code or zero page meets `extent` (an installed
    /// extension's memory, which it must leave alone).
    pub(crate) fn meets(&self, extent: &std::ops::RangeInclusive<u16>) -> bool {
        let zero_page =
            u16::from(self.zero_page)..=u16::from(self.zero_page) + u16::from(ZERO_PAGE_LEN - 1);
        let code = self.address()..=(self.image.areas()[0].end() - 1) as u16;
        [zero_page, code]
            .iter()
            .any(|ours| ours.start() <= extent.end() && extent.start() <= ours.end())
    }

    /// `rate` alone: what goes in at the base rate.
    pub(crate) fn rate_part(&self) -> Result<UploadImage> {
        self.part(self.rate, self.frames)
    }

    /// `rate` and `frames`: what goes in with the ROM's commands when the
    /// line stays at one rate.
    pub(crate) fn rom_part(&self) -> Result<UploadImage> {
        self.part(self.rate, self.sums)
    }

    /// `frames` alone: what goes in with the ROM's commands at the fast
    /// rate.
    pub(crate) fn frames_part(&self) -> Result<UploadImage> {
        self.part(self.frames, self.sums)
    }

    /// `frames` and `sums`: what a loader found in RAM is verified by, at
    /// the fast rate, before `sums` is hooked.
    pub(crate) fn frames_and_sums_part(&self) -> Result<UploadImage> {
        let end = self.image.areas()[0].end();
        self.part(self.frames, end)
    }

    /// `sums` alone: what goes in through `frames`.
    pub(crate) fn sums_part(&self) -> Result<UploadImage> {
        let end = self.image.areas()[0].end();
        self.part(self.sums, end)
    }

    fn part(&self, from: u16, to: impl Into<u32>) -> Result<UploadImage> {
        let area = &self.image.areas()[0];
        let start = usize::from(from - area.address);
        let end = (to.into() - u32::from(area.address)) as usize;
        UploadImage::new(
            vec![Area {
                address: from,
                bytes: area.bytes[start..end].to_vec(),
            }],
            Vec::new(),
        )
    }
}

/// What the loader is linked against besides its own code.
struct Symbols {
    services: Services,
    zero_page: u8,
    toggle: u8,
}

/// Links the loader at `address` against the profile's services.
fn link(object: &[u8], address: u16, symbols: &Symbols) -> Result<(UploadImage, Image)> {
    let failed = |message: String| Error::LoaderLink { address, message };
    let symbol = |name: &str, value: u16| ImageSymbol {
        name: name.to_owned(),
        value: u32::from(value),
        size: 0,
        global: true,
        section: None,
    };
    let services = symbols.services;
    // The services as a symbol file, so any ROM profile that has them will do.
    let mut list = vec![
        symbol("GETCH", services.getch),
        symbol("CHKCH", services.chkch),
        symbol("CMD_DONE", services.cmd_done),
        symbol("GETHEX", services.gethex),
        symbol("PUTCH", services.putch),
        symbol("PUTHEX", services.puthex),
        symbol("PUTEOL", services.puteol),
        symbol("ACIA_CTRL", ACIA_CONTROL),
        symbol("RATE_TOGGLE", u16::from(symbols.toggle)),
        symbol("LZP", u16::from(symbols.zero_page)),
    ];
    if let Some(ring) = services.ring {
        list.extend([
            symbol("RXBUF", ring.buffer),
            symbol("RXHEAD", u16::from(ring.head)),
            symbol("RXTAIL", u16::from(ring.tail)),
        ]);
    }
    let name = "loader.s";
    let rom = Image {
        symbols: list,
        ..Image::default()
    };
    let target = linker::Target::builtin("flat", Some(u64::from(address)))
        .map_err(|error| failed(error.to_string()))?;
    let symbols = linker::SymbolFile {
        name: "rom profile",
        image: &rom,
    };
    let linked = linker::link_one(name, object, &target, symbols).map_err(|error| match error {
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

/// The highest eight bytes of the profile's user zero page that the image
/// does not load.
fn free_zero_page(profile: &RomProfile, image: &UploadImage) -> Option<u8> {
    let zero_page = profile.user_zero_page.clone()?;
    let (first, last) = (*zero_page.start(), *zero_page.end());
    let mut base = last.checked_sub(ZERO_PAGE_LEN - 1)?;
    while base >= first {
        let clash = (0..ZERO_PAGE_LEN)
            .rev()
            .find(|&i| image.contains(u16::from(base + i)));
        match clash {
            None => return Some(base),
            // Below the loaded byte that clashed.
            Some(i) => base = (base + i).checked_sub(ZERO_PAGE_LEN)?,
        }
    }
    None
}

/// A `/1L` frame for the RAM loader that writes `data` (1 to
/// [`FRAME_MAX`] bytes; more are cut) at `address`: the command, the key,
/// the encoded header with its checksum, the encoded data last byte
/// first. No byte after the command is a slash. (See
/// `uploader/loader/loader.s`.)
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
    // 128 bytes leaves at least 127 keys to try with the header's.
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
        for byte in [hi, lo, count] {
            sum0 = sum0.wrapping_add(byte);
            sum1 = sum1.wrapping_add(sum0);
        }
        let header = [hi, lo, count, sum0.wrapping_add(sum1).wrapping_neg(), sum1];
        if header.iter().any(|&byte| byte ^ key == SLASH) {
            continue;
        }
        let mut out = Vec::with_capacity(FRAME_OVERHEAD + data.len());
        out.extend_from_slice(b"/1L");
        out.push(key);
        out.extend(
            header
                .iter()
                .chain(data.iter().rev())
                .map(|&byte| byte ^ key),
        );
        return out;
    }
    // Only if every key left makes a header byte a slash (each does with
    // a chance of about 5 in 256): an empty frame, which the caller splits.
    Vec::new()
}

/// How long an upload of `len` bytes takes at `baud` with the ROM's
/// commands alone: 11 characters per 2 bytes, plus the `/7R` questions.
#[must_use]
pub fn rom_only_estimate(len: usize, baud: u32) -> Duration {
    let questions = len.div_ceil(99);
    char_time(len.div_ceil(2) * 11 + questions * 9, baud)
}

/// How long the same upload takes through a loader of `loader_len` bytes,
/// the line at `fast` for the transfer: `rate` (15 bytes) through the ROM
/// at `baud`, the rest at `fast`, then the bytes in frames, where the `/7R`
/// answers (two characters a byte) on the return wire take longest; plus
/// the round trips of the hooks and the rate switches.
#[must_use]
pub fn loader_estimate(len: usize, loader_len: usize, baud: u32, fast: u32) -> Duration {
    let rate_part = 15;
    let install = rom_only_estimate(rate_part, baud)
        + rom_only_estimate(loader_len.saturating_sub(rate_part), fast);
    let questions = len.div_ceil(99);
    let out = len + len.div_ceil(99) * FRAME_OVERHEAD + questions * 9;
    let back = 2 * len + 2 * questions;
    let round_trips = char_time(120, baud) + char_time(60, fast);
    install + char_time(out.max(back), fast) + round_trips
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decodes a frame as `loader.s` does: `None` where it would write
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
        let mut data: Vec<u8> = bytes.take(usize::from(header[2])).collect();
        data.reverse();
        Some((u16::from_le_bytes([header[1], header[0]]), data))
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
    fn the_toggle_keeps_the_framing_bits() {
        assert_eq!(ACIA_CONTROL, 0xC013);
        assert_eq!(rate_toggle((9600, FAST_BAUD)), 0x0E ^ 0x0F);
        assert_eq!(rate_toggle((4800, FAST_BAUD)), 0x0C ^ 0x0F);
        assert_eq!(rate_toggle((9600, 12345)), 0);
    }

    #[test]
    fn the_loader_links_and_fits_around_the_image() {
        let profile = RomProfile::reference();
        let rates = (9600, FAST_BAUD);
        let image = UploadImage::new(
            vec![Area {
                address: 0x0400,
                bytes: vec![0xEA; 0x0A00],
            }],
            vec![],
        )
        .expect("an image");
        let loader = Loader::place(&profile, &image, rates)
            .expect("links")
            .expect("room above $0E00");
        assert!(loader.len() < 200, "{} bytes", loader.len());
        let through_rom = loader.rom_part().expect("a part").len();
        assert!(through_rom < 80, "{through_rom} bytes through the ROM");
        assert_eq!(
            usize::from(loader.address()) + loader.len(),
            usize::from(romlib::symbols::USER_RAM_END) + 1,
            "the top of user RAM"
        );
        assert_eq!(loader.rate, loader.address());
        assert_eq!(usize::from(loader.frames - loader.rate), 15, "rate's size");
        let rate = loader.rate_part().expect("a part");
        let frames = loader.frames_part().expect("a part");
        let sums = loader.sums_part().expect("a part");
        assert_eq!(rate.len() + frames.len() + sums.len(), loader.len());
        assert_eq!(frames.areas()[0].address, loader.frames);
        assert_eq!(sums.areas()[0].address, loader.sums);
        assert_eq!(loader.zero_page, 0xF8, "the top of user zero page");

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

    #[test]
    fn the_loaders_zero_page_avoids_the_image() {
        let profile = RomProfile::reference();
        let zero_page = |areas: Vec<(u16, usize)>| {
            let image = UploadImage::new(
                areas
                    .into_iter()
                    .map(|(address, len)| Area {
                        address,
                        bytes: vec![0; len],
                    })
                    .collect(),
                vec![],
            )
            .expect("an image");
            free_zero_page(&profile, &image)
        };
        assert_eq!(zero_page(vec![(0x0400, 1)]), Some(0xF8));
        assert_eq!(zero_page(vec![(0x00FF, 1)]), Some(0xF7));
        assert_eq!(zero_page(vec![(0x00FB, 1), (0x0400, 1)]), Some(0xF3));
        assert_eq!(zero_page(vec![(0x00F3, 1), (0x0400, 1)]), Some(0xF8));
        assert_eq!(zero_page(vec![(0x00F2, 0x0E)]), Some(0xEA));
        assert_eq!(
            zero_page(vec![(0x0037, 0xC9)]),
            None,
            "$30-$36 is too small"
        );
        assert_eq!(zero_page(vec![(0x0038, 0xC8)]), Some(0x30));
    }
}
