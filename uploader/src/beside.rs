//! Whether the RAM loader may go in beside the extensions a robot has
//! installed: every hook, and every chain behind it, must lead to the ROM's
//! reset target or into memory an entry of the table of installed extensions names
//! (code nothing names could be where the loader lands), and the loader
//! must meet none of those extensions' memory. Then an upload compares by
//! checksums and writes only what differs, extensions installed or not.

use isa::objfmt::HookKind;
use romlib::installed::{Installed, extent_text};

use crate::Result;
use crate::client::Client;
use crate::hooks::read_word;
use crate::image::RomProfile;
use crate::loader::Loader;
use crate::transport::Transport;

/// How many handlers a walk follows down one chain: chains are a few
/// extensions long, and a damaged one must not loop.
const LONGEST_CHAIN: usize = 16;

/// Why `loader` may not go in beside what `hooks` lead to, given the
/// extensions that stay installed (`others`); `None` when it may. Reads
/// the chain slots it follows.
///
/// # Errors
/// A line error.
pub(crate) fn refusal<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    hooks: &[(HookKind, u16)],
    others: &[Installed],
    loader: &Loader,
) -> Result<Option<String>> {
    for other in others {
        if let Some(extent) = other.extents.iter().find(|extent| loader.meets(extent)) {
            return Ok(Some(format!(
                "it would land on the installed extension {:06X} at {}",
                other.id,
                extent_text(extent)
            )));
        }
    }
    for &(kind, first) in hooks {
        let mut target = first;
        let mut ended = false;
        for _ in 0..LONGEST_CHAIN {
            // Code elsewhere in the ROM (an operating system's, say) is
            // taken as unknown too: what RAM it uses, no table says.
            if profile.reset_target(kind) == Some(target) {
                ended = true;
                break;
            }
            let Some(owner) = others.iter().find(|other| other.contains(target)) else {
                return Ok(Some(format!(
                    "{} leads to ${target:04X}, code no entry of the table of installed extensions names (its extent is unknown): the loader could overwrite it",
                    kind.rom_symbol()
                )));
            };
            let slot = owner
                .hooks
                .iter()
                .find(|hook| hook.kind == kind)
                .and_then(|hook| hook.chain);
            match slot {
                Some(slot) => match read_word(client, slot)? {
                    Some(next) => target = next,
                    None => {
                        ended = true;
                        break;
                    }
                },
                // Its extension does not fall through.
                None => {
                    ended = true;
                    break;
                }
            }
        }
        if !ended {
            return Ok(Some(format!(
                "{}'s chain is more than {LONGEST_CHAIN} handlers long (a loop?)",
                kind.rom_symbol()
            )));
        }
    }
    Ok(None)
}
