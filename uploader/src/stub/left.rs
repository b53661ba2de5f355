//! A debug stub a session left hooked (its process killed before it
//! detached), recognised at `HOOK_UNKNOWN`'s target by its code: an
//! upload, a restore or another attach that chained to it would make a
//! loop (it chains to the image it debugged, which would chain to it) or
//! keep its breakpoints' `JSR`s reachable, with no host to serve them.
//! Only `scorpion debug --port` with the image it debugged takes it out
//! safely (docs/DEBUGGING.md, "Debug on the robot").

use isa::objfmt::HookKind;

use super::link::{handler_offset, left_pattern};
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

/// Bytes of the handler compared first: one short question tells most
/// targets from a stub.
const FIRST_LOOK: usize = 12;

/// Whether `target` is the handler of a debug stub: the robot's bytes
/// compared with the stub linked so that its handler is there, but for
/// those that depend on its zero page and its chain. A short read of the
/// handler first, the whole code only when that matches.
///
/// # Errors
/// The line's errors.
pub fn at_target<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    target: u16,
) -> Result<Option<LeftStub>> {
    let Some(offset) = handler_offset(profile) else {
        return Ok(None);
    };
    let Some(address) = target.checked_sub(offset) else {
        return Ok(None);
    };
    let Some((pattern, handler, whole)) = left_pattern(profile, address) else {
        return Ok(None);
    };
    let matches = |found: &[u8], expected: &[Option<u8>]| {
        found.len() == expected.len()
            && found
                .iter()
                .zip(expected)
                .all(|(&byte, want)| want.is_none_or(|want| want == byte))
    };
    let from = usize::from(offset);
    let first = &pattern[from..pattern.len().min(from + FIRST_LOOK)];
    if handler != target || !matches(&client.read_memory(target, first.len())?, first) {
        return Ok(None);
    }
    let code = client.read_memory(address, pattern.len())?;
    if !matches(&code, &pattern) {
        return Ok(None);
    }
    // Its last instruction is `JMP PREV`.
    let previous = u16::from_le_bytes([code[code.len() - 2], code[code.len() - 1]]);
    Ok(Some(LeftStub {
        address,
        handler,
        code_end: address.wrapping_add(pattern.len() as u16),
        end: address.wrapping_add(whole as u16).wrapping_sub(1),
        previous,
    }))
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
