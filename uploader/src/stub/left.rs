//! A debug stub a session left hooked (its process killed before it
//! detached), recognised at `HOOK_UNKNOWN`'s target by its code: an
//! upload, a restore or another attach that chained to it would make a
//! loop (it chains to the image it debugged, which would chain to it) or
//! keep its breakpoints' `JSR`s reachable, with no host to serve them.
//! Only `scorpion debug --port` with the image it debugged takes it out
//! safely (docs/DEBUGGING.md, "Debug on the robot").

use isa::objfmt::HookKind;

use super::link::left_pattern;
use crate::client::Client;
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

/// A debug stub found hooked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LeftStub {
    /// Where it starts.
    pub address: u16,
    /// Its handler: the hook's target.
    pub handler: u16,
    /// The end of its code (exclusive).
    pub code_end: u16,
    /// Its last byte, data included: the extent every message gives.
    pub end: u16,
    /// What it chains to.
    pub previous: u16,
}

/// Bytes at the hook's target compared first: one short question tells
/// most targets from a stub.
const FIRST_LOOK: usize = 12;

/// Bytes of the stub's code (not its chain's or zero page's) that must
/// agree before a target inside its code is looked at whole: fewer would
/// send every target whose first byte is a `JMP` to a long read.
const FEWEST_AGREEING: usize = 4;

/// Whether `target` lies in the code of a debug stub: its handler (where
/// a session hooks it), or anywhere else in its code (a hook pointed there
/// by hand or by a glitch runs the stub's instructions from the middle,
/// and chaining to it keeps the stub reachable all the same). The robot's
/// bytes are compared with the stub linked where it would start, but for
/// those that depend on its zero page and its chain: a short read at the
/// target first, the whole code only where that agrees with some place in
/// the stub's code.
///
/// # Errors
/// The line's errors.
pub fn at_target<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    target: u16,
) -> Result<Option<LeftStub>> {
    // hostile17 F2: a counter among a handler's first bytes is no stub,
    // and no failure to read.
    find(profile, target, &mut |at, len| {
        client.read_live(at, len).map(|read| Some(read.bytes))
    })
}

/// [`at_target`] in memory held elsewhere (a backup file's): `byte_at`
/// says what it holds at an address, `None` where it holds nothing (no
/// stub is found across a hole).
pub(crate) fn held_at_target(
    profile: &RomProfile,
    target: u16,
    byte_at: &dyn Fn(u16) -> Option<u8>,
) -> Option<LeftStub> {
    let mut read = |at: u16, len: usize| -> Result<Option<Vec<u8>>> {
        Ok((0..len)
            .map(|i| byte_at(at.wrapping_add(i as u16)))
            .collect())
    };
    find(profile, target, &mut read).ok().flatten()
}

/// Reads `len` bytes at an address (`None`: not known there).
type Read<'a> = dyn FnMut(u16, usize) -> Result<Option<Vec<u8>>> + 'a;

fn find(profile: &RomProfile, target: u16, read: &mut Read<'_>) -> Result<Option<LeftStub>> {
    let Some(shape) = Shape::of(profile) else {
        return Ok(None);
    };
    let look = FIRST_LOOK.min(0x1_0000 - usize::from(target));
    let Some(first) = read(target, look)? else {
        return Ok(None);
    };
    for into in shape.places_agreeing(&first) {
        let Some(address) = target.checked_sub(into as u16) else {
            continue;
        };
        let Some((pattern, handler, whole)) = left_pattern(profile, address) else {
            continue;
        };
        let seen = first.len().min(pattern.len() - into);
        if !agrees(&first[..seen], &pattern[into..into + seen]) {
            continue;
        }
        let Some(code) = read(address, pattern.len())? else {
            continue;
        };
        if !agrees(&code, &pattern) {
            continue;
        }
        // Its last instruction is `JMP PREV`.
        let previous = u16::from_le_bytes([code[code.len() - 2], code[code.len() - 1]]);
        return Ok(Some(LeftStub {
            address,
            handler,
            code_end: address.wrapping_add(pattern.len() as u16),
            end: address.wrapping_add(whole as u16).wrapping_sub(1),
            previous,
        }));
    }
    Ok(None)
}

/// Whether the robot's bytes agree with the pattern's (`None` agrees with
/// any byte).
fn agrees(found: &[u8], expected: &[Option<u8>]) -> bool {
    found.len() == expected.len()
        && found
            .iter()
            .zip(expected)
            .all(|(&byte, want)| want.is_none_or(|want| want == byte))
}

/// The stub's code wherever it is linked: the bytes that depend on where
/// it is, its zero page or its chain left open.
struct Shape {
    pattern: Vec<Option<u8>>,
    /// Where its handler lies from its start.
    handler: usize,
}

impl Shape {
    fn of(profile: &RomProfile) -> Option<Shape> {
        // Two places that differ in both bytes of every address.
        let one = *profile.user_ram.start();
        let two = one.checked_add(0x0101)?;
        let (first, handler, _) = left_pattern(profile, one)?;
        let (second, _, _) = left_pattern(profile, two)?;
        let pattern = first
            .iter()
            .zip(&second)
            .map(|(&a, &b)| if a == b { a } else { None })
            .collect();
        Some(Shape {
            pattern,
            handler: usize::from(handler - one),
        })
    }

    /// The places in the stub's code where `bytes` could start, the
    /// handler first: those whose known bytes all agree, and at least
    /// [`FEWEST_AGREEING`] of them.
    fn places_agreeing(&self, bytes: &[u8]) -> Vec<usize> {
        let others = (0..self.pattern.len()).filter(|&into| into != self.handler);
        std::iter::once(self.handler)
            .chain(others)
            .filter(|&into| {
                let seen = &self.pattern[into..self.pattern.len().min(into + bytes.len())];
                let known = seen.iter().flatten().count();
                agrees(&bytes[..seen.len()], seen) && known >= FEWEST_AGREEING
            })
            .collect()
    }
}

/// Refuses when a hook of `hooks` leads to a debug stub a session left
/// (only `HOOK_UNKNOWN` can: the stub hooks nothing else). `known` tells
/// targets that need no look (the image's own handler: an earlier copy).
/// The ROM's own target needs none either.
///
/// # Errors
/// [`Error::DebugStubHooked`] naming it; the line's errors.
pub(crate) fn refuse_hooked<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    hooks: &[(HookKind, u16)],
    known: &dyn Fn(u16) -> bool,
) -> Result<()> {
    for &(kind, target) in hooks {
        if kind != HookKind::Unknown || profile.reset_target(kind) == Some(target) || known(target)
        {
            continue;
        }
        if let Some(stub) = at_target(client, profile, target)? {
            return Err(Error::DebugStubHooked {
                port: client.transport().name(),
                hook: kind.rom_symbol(),
                stub: stub.address,
                end: stub.end,
                previous: stub.previous,
            });
        }
    }
    Ok(())
}
