//! What an undo checks before it writes anything, beyond what every
//! restore checks: that the uploads its file undoes are the last ones on
//! each hook ([`refuse_later_uploads`]) and in the table of installed
//! extensions ([`refuse_later_entries`]), so that an undo never unhooks or
//! unlists what a later upload put in.

use isa::objfmt::HookKind;

use crate::backup::{Backup, in_rom};
use crate::client::Client;
use crate::image::{Area, RomProfile};
use crate::transport::Transport;
use crate::{Error, Result};

/// An undo puts a hook back where it was before the upload it undoes: so
/// the hook must lead now to that upload's image (memory the file puts
/// back), to where the file puts it anyway, or to the ROM (a reset, an
/// undo stopped half way). Anywhere else, a later upload was chained
/// ahead, and the undo would unhook it (fresh10 F20; hostile11 F2, where
/// the undo of that later upload then hooked code the first undo had
/// taken away).
pub(crate) fn refuse_later_uploads<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    profile: &RomProfile,
    (hooks, undone): (&[(HookKind, u16)], &[romlib::installed::Installed]),
) -> Result<()> {
    for &(kind, target) in &backup.hooks {
        let Some(current) = hooks
            .iter()
            .find(|(this, _)| *this == kind)
            .map(|&(_, current)| current)
        else {
            continue;
        };
        let put_back = backup.byte_at(u32::from(current)).is_some();
        if current == target
            || put_back
            || profile.reset_target(kind) == Some(current)
            || in_rom(profile, current)
        {
            continue;
        }
        // fresh14 F3: the RAM loader the upload being undone hooked (found
        // in RAM, so its file does not hold it) and left hooked, killed:
        // verified code of that upload's, which the hooks leave first.
        if crate::loader::loader_left_at(client, profile, current)?.is_some() {
            continue;
        }
        // fresh17 F6: that upload's own image, at the head of the chain,
        // whose handler it did not rewrite (an edit elsewhere, `--replace`
        // of an extension that sat behind another), so the file does not
        // hold it: its table entry, as the upload wrote it, says so.
        if undone.iter().any(|undone| {
            undone
                .hooks
                .iter()
                .any(|hook| hook.kind == kind && hook.handler == current)
        }) {
            continue;
        }
        let owner = crate::table::read_installed(client, profile)
            .ok()
            .and_then(|everyone| {
                everyone
                    .into_iter()
                    .find(|entry| entry.contains(current))
                    .map(|entry| format!(" (extension {:06X})", entry.id))
            })
            .unwrap_or_default();
        return Err(Error::UndoNotLast {
            hook: kind.rom_symbol(),
            current,
            owner,
        });
    }
    Ok(())
}

/// The installed extensions, split in two: those the uploads an undo file
/// undoes put in (each one whose table entry the file witnesses as
/// written, where the robot still holds that entry so), and the others,
/// each with its table bytes as the robot holds them.
pub(crate) type Undone = (
    Vec<romlib::installed::Installed>,
    Vec<(romlib::installed::Installed, [Area; 2])>,
);

pub(crate) fn undone_extensions<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    profile: &RomProfile,
) -> Result<Undone> {
    let mut undone = (Vec::new(), Vec::new());
    for (entry, [flags, bytes]) in crate::table::installed_bytes(client, profile)? {
        // An older file witnessed the entry among the hooks' witnesses.
        let written = backup
            .written_entries
            .iter()
            .chain(&backup.witnesses)
            .any(|witness| {
                witness.address == bytes.address
                    && usize::from(witness.len) == bytes.bytes.len()
                    && witness.sum.matches(&bytes.bytes)
            });
        if written {
            undone.0.push(entry);
        } else {
            undone.1.push((entry, [flags, bytes]));
        }
    }
    Ok(undone)
}

/// An undo puts back the table as the upload found it: every extension
/// the robot lists now, but those the undo takes out, must hold there
/// what the file puts back. Otherwise a later upload wrote that entry (a
/// `--replace` of an extension the upload being undone chained in front
/// of, whose handler stayed where it was: recheck18 F1), and the undo
/// would list the old extension over the new one's code.
///
/// A restore that stopped half way (`resume`) may have put back part of an
/// entry: one whose first byte is the file's already is let through
/// (hostile19 F8: another upload between the two halves of an undo was
/// not looked for, and the undo listed the old extension over its code).
pub(crate) fn refuse_later_entries(
    backup: &Backup,
    (profile, resume): (&RomProfile, bool),
    (undone, others): &Undone,
) -> Result<()> {
    // hostile19 F1: the file takes out what its upload put in: the table's
    // flags there are the file's, and an entry they list is the file's
    // too. A file that does not hold them (edited, or records copied from
    // another) would leave the table listing memory the undo put back.
    if let Some((table, entries)) = profile.table {
        let held = |address: u16, len: usize| {
            (0..len).all(|i| backup.byte_at(u32::from(address) + i as u32).is_some())
        };
        for entry in undone {
            let slots = entry.slot..entry.slot + entry.entries();
            let freed = slots.clone().all(|slot| {
                let flags = romlib::installed::flags_address(table, slot);
                let listed = backup
                    .byte_at(u32::from(flags))
                    .map(romlib::installed::in_use);
                let entry = romlib::installed::entry_address(table, entries, slot);
                listed.is_some_and(|listed| !listed || held(entry, romlib::installed::ENTRY_LEN))
            });
            if !freed {
                return Err(Error::BackupRefused {
                    reason: format!(
                        "the file takes out extension {:06X} (it holds the sum of its table entry as an upload wrote it) but does not put back the table there: the table would go on listing it over the memory the undo puts back; nothing was written",
                        entry.id
                    ),
                });
            }
        }
    }
    for (entry, areas) in others {
        let changed = areas.iter().any(|area| {
            area.bytes.iter().enumerate().any(|(offset, &now)| {
                let address = u32::from(area.address) + offset as u32;
                backup.byte_at(address).is_some_and(|put| put != now)
            })
        });
        let begun = || {
            let first = &areas[1];
            resume && backup.byte_at(u32::from(first.address)) == first.bytes.first().copied()
        };
        if changed && !begun() {
            return Err(Error::UndoEntryChanged {
                id: entry.id,
                at: areas[1].address,
            });
        }
    }
    Ok(())
}
