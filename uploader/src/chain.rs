//! Where a hook's chain leads past what the robot's table names. Whatever
//! a hook points at, an upload chains the image to it, and a debug session
//! chains its stub to it: when that code jumps back into what is written
//! now (an owner's `JMP` to an earlier copy of the image, a stub's own
//! `JMP PREV`), the robot runs in a loop at its next unknown command. A
//! target that is a `JMP abs` is followed, as are an installed extension's
//! chain slot and a debug stub's chain; other code ends the look (where it
//! goes cannot be known without running it).

use std::fmt::Write as _;

use isa::objfmt::HookKind;
use romlib::installed::Installed;

use crate::Result;
use crate::client::Client;
use crate::hooks::{JMP, read_word};
use crate::image::RomProfile;
use crate::transport::Transport;

/// Jumps followed at most: a longer run is a loop of the robot's own
/// (it already hangs there), not one through what is written now.
const MOST_STEPS: usize = 16;

/// The way a chain comes back: each address it went through, the last
/// one inside what `comes_back` named.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Path(pub(crate) Vec<u16>);

impl std::fmt::Display for Path {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut text = String::new();
        for (i, at) in self.0.iter().enumerate() {
            if i > 0 {
                text.push_str(" -> ");
            }
            let _ = write!(text, "${at:04X}");
        }
        f.write_str(&text)
    }
}

/// Follows `kind`'s chain from `target` through `JMP`s and installed
/// extensions' chain slots (`everyone`), reading only memory an extension
/// may hold; `Some` with the way when it comes to an address `inside`
/// says is written now. The ROM's own target, the ROM, and code that does
/// not jump end it (`None`).
///
/// # Errors
/// The line's errors.
pub(crate) fn comes_back<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    inside: &dyn Fn(u16) -> bool,
) -> Result<Option<Path>> {
    let mut path = Vec::new();
    let mut at = target;
    for _ in 0..MOST_STEPS {
        path.push(at);
        if inside(at) {
            return Ok(Some(Path(path)));
        }
        let readable = profile
            .writable
            .iter()
            .any(|range| range.contains(&at) && range.contains(&at.saturating_add(2)));
        if profile.reset_target(kind) == Some(at) || !readable {
            return Ok(None);
        }
        let slot = everyone
            .iter()
            .flat_map(|other| other.hooks.iter())
            .find(|hook| hook.kind == kind && hook.handler == at)
            .and_then(|hook| hook.chain);
        let next = match slot {
            Some(slot) => read_word(client, slot)?,
            None => {
                let bytes = client.read_memory(at, 3)?;
                if bytes[0] == JMP {
                    Some(u16::from_le_bytes([bytes[1], bytes[2]]))
                } else {
                    // A debug stub (hooked or left in RAM by a session)
                    // goes on where its chain does.
                    crate::stub::left::at_target(client, profile, at)?.map(|stub| stub.previous)
                }
            }
        };
        match next {
            Some(next) => at = next,
            None => return Ok(None),
        }
    }
    Ok(None)
}
