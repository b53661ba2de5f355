//! The stub (`uploader/stub/stub.s`), assembled when this crate is built
//! and linked at attach time where the image leaves room, against the ROM
//! profile's services and the hook's target it chains to.

use std::ops::RangeInclusive;

use linker::{Image, ImageSymbol};

use super::error::{StubError, StubResult};
use crate::image::{RomProfile, UploadImage};

/// `stub/stub.s`, assembled.
const STUB_OBJECT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/stub.o"));

/// The stub, linked and placed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StubPlan {
    /// Where it starts.
    pub address: u16,
    /// Its bytes: code, then the data the host reads and writes.
    pub bytes: Vec<u8>,
    /// What a breakpoint's `JSR` calls.
    pub entry: u16,
    /// `HOOK_UNKNOWN`'s target while attached (`/1@`, then the chain).
    pub handler: u16,
    /// The hook's target before: where `handler` chains.
    pub previous: u16,
    /// The end of the code (the data follows).
    pub code_end: u16,
    /// The stop frame's block: `S`, PC low, high, A, X, Y, P, S.
    pub regs: u16,
    /// The program's two bytes of `zero_page`, kept there at a stop
    /// (the stub points with them meanwhile) and given back when it goes on.
    pub saved_zp: u16,
    /// The staged patch: address low, high, three bytes.
    pub stage: u16,
    /// The trampolines: eight of [`TRAMPOLINE_LEN`] bytes.
    pub tramps: u16,
    /// The two bytes of user zero page it points with (kept at a stop).
    pub zero_page: u8,
}

/// Bytes of one trampoline: up to five displaced bytes, three more for
/// each of at most two branches relocated, and a `JMP` (13 at most).
pub const TRAMPOLINE_LEN: u16 = 16;

/// Trampolines the stub holds: breakpoints at once, step's included.
pub const TRAMPOLINES: usize = 8;

impl StubPlan {
    /// Links the stub for `profile` where `image` leaves room, chaining to
    /// `previous` (`HOOK_UNKNOWN`'s target now).
    ///
    /// # Errors
    /// [`StubError::NoRoom`], or [`StubError::Link`] (a defect of this
    /// crate).
    pub fn place(profile: &RomProfile, image: &UploadImage, previous: u16) -> StubResult<StubPlan> {
        Self::place_beside(profile, image, previous, &[])
    }

    /// [`StubPlan::place`], where none of `taken` lies either (the
    /// extensions the robot's table names, the RAM loader's memory): a
    /// stub written over them would break what they hold.
    ///
    /// # Errors
    /// As [`StubPlan::place`]; [`StubError::NoRoom`] names `taken`.
    pub fn place_beside(
        profile: &RomProfile,
        image: &UploadImage,
        previous: u16,
        taken: &[RangeInclusive<u16>],
    ) -> StubResult<StubPlan> {
        let no_room = |len: usize| StubError::NoRoom {
            len,
            taken: taken_text(image, taken),
        };
        let services = profile.loader_services.ok_or_else(|| StubError::Refused {
            what: "the debug stub".into(),
            reason: "the ROM profile lacks GETCH, PUTCH or CMD_DONE".into(),
        })?;
        let zero_page = free_zero_page(profile, image, taken).ok_or_else(|| no_room(2))?;
        let start = *profile.user_ram.start();
        let len = link(start, services, zero_page, previous)?.0.len();
        let address = free_space(profile, image, taken, len).ok_or_else(|| no_room(len))?;
        let (bytes, linked) = link(address, services, zero_page, previous)?;
        let label = |name: &str| {
            linked
                .symbol(name)
                .and_then(|at| u16::try_from(at).ok())
                .ok_or_else(|| StubError::Link {
                    address,
                    message: format!("the stub has no `{name}`"),
                })
        };
        Ok(StubPlan {
            address,
            bytes,
            entry: label("entry")?,
            handler: label("handler")?,
            previous,
            code_end: label("code_end")?,
            regs: label("regs")?,
            saved_zp: label("saved_zp")?,
            stage: label("stage")?,
            tramps: label("tramps")?,
            zero_page,
        })
    }

    /// The address of trampoline `slot`.
    #[must_use]
    pub fn trampoline(&self, slot: usize) -> u16 {
        self.tramps + slot as u16 * TRAMPOLINE_LEN
    }

    /// Whether `address` is in the stub.
    #[must_use]
    pub fn contains(&self, address: u16) -> bool {
        (u32::from(self.address)..u32::from(self.address) + self.bytes.len() as u32)
            .contains(&u32::from(address))
    }
}

fn link(
    address: u16,
    services: crate::image::Services,
    zero_page: u8,
    previous: u16,
) -> StubResult<(Vec<u8>, Image)> {
    let failed = |message: String| StubError::Link { address, message };
    let symbol = |name: &str, value: u16| ImageSymbol {
        name: name.to_owned(),
        value: u32::from(value),
        size: 0,
        global: true,
        section: None,
    };
    let rom = Image {
        symbols: vec![
            symbol("GETCH", services.getch),
            symbol("PUTCH", services.putch),
            symbol("PUTEOL", services.puteol),
            symbol("CMD_DONE", services.cmd_done),
            symbol("PREV", previous),
            symbol("SZP", u16::from(zero_page)),
        ],
        ..Image::default()
    };
    let target = linker::Target::builtin("flat", Some(u64::from(address)))
        .map_err(|error| failed(error.to_string()))?;
    let symbols = linker::SymbolFile {
        name: "rom profile",
        image: &rom,
    };
    let linked = linker::link_one("stub.s", STUB_OBJECT, &target, symbols).map_err(|error| {
        failed(match error {
            linker::Error::Failed { errors, .. } => errors
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("; "),
            other => other.to_string(),
        })
    })?;
    let image = UploadImage::try_from(&linked.image)?;
    match image.areas() {
        [area] if area.address == address => Ok((area.bytes.clone(), linked.image)),
        areas => Err(failed(format!("it links to {} areas", areas.len()))),
    }
}

/// What a stub must not go over: the image's memory, and `taken`.
fn occupied<'a>(
    image: &'a UploadImage,
    taken: &'a [RangeInclusive<u16>],
) -> impl Iterator<Item = &'a RangeInclusive<u16>> + 'a {
    image.extents().iter().chain(taken)
}

/// The ranges a stub that found no room had to leave, for its message.
fn taken_text(image: &UploadImage, taken: &[RangeInclusive<u16>]) -> String {
    let mut ranges: Vec<&RangeInclusive<u16>> = occupied(image, taken).collect();
    ranges.sort_by_key(|range| (*range.start(), *range.end()));
    ranges.dedup();
    ranges
        .iter()
        .map(|range| romlib::installed::extent_text(range))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The highest `len` bytes of user RAM that none of the image's memory
/// (loaded, BSS, zero page) nor `taken` takes.
fn free_space(
    profile: &RomProfile,
    image: &UploadImage,
    taken: &[RangeInclusive<u16>],
    len: usize,
) -> Option<u16> {
    let first = u32::from(*profile.user_ram.start());
    let mut top = u32::from(*profile.user_ram.end()) + 1;
    let len = len as u32;
    while top >= first + len {
        let start = top - len;
        let clash = occupied(image, taken)
            .filter(|e| u32::from(*e.start()) < top && u32::from(*e.end()) >= start)
            .map(|e| u32::from(*e.start()))
            .min();
        match clash {
            None => return u16::try_from(start).ok(),
            Some(below) => top = below,
        }
    }
    None
}

/// The highest two bytes of user zero page the image's memory and
/// `taken` leave.
fn free_zero_page(
    profile: &RomProfile,
    image: &UploadImage,
    taken: &[RangeInclusive<u16>],
) -> Option<u8> {
    let zero_page = profile.user_zero_page.clone()?;
    let owned = |at: u8| occupied(image, taken).any(|e| e.contains(&u16::from(at)));
    (*zero_page.start()..*zero_page.end())
        .rev()
        .find(|&at| !owned(at) && !owned(at + 1))
}

/// The stub's code as a session would have linked it at `address` for
/// `profile`, a byte `None` where it depends on what else it was linked
/// with (its zero page, the target it chains to), and its handler's
/// address: what the robot holds at `address` when a session left its
/// stub there, and its whole length (code and data: what a session's
/// messages give as its extent). `None` when no stub links there (the
/// profile lacks the ROM's services, the address is out of reach).
pub(crate) fn left_pattern(
    profile: &RomProfile,
    address: u16,
) -> Option<(Vec<Option<u8>>, u16, usize)> {
    let services = profile.loader_services?;
    // Two links that differ in every byte of the zero page and the chain.
    let (one, linked) = link(address, services, 0x10, 0x1234).ok()?;
    let (two, _) = link(address, services, 0x2A, 0xA5C3).ok()?;
    let at = |name: &str| linked.symbol(name).and_then(|at| u16::try_from(at).ok());
    let (handler, code_end) = (at("handler")?, at("code_end")?);
    let len = usize::from(code_end.checked_sub(address)?);
    let pattern = one[..len]
        .iter()
        .zip(&two[..len])
        .map(|(&a, &b)| (a == b).then_some(a))
        .collect();
    Some((pattern, handler, one.len()))
}
