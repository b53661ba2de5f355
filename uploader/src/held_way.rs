//! Where a backup's hooks lead through the file's own memory, told
//! against the file's own table before a restore writes anything (and
//! said by `backup` of a robot in such a state). Two disagreements are
//! possible where the file holds the table's flags whole:
//! - the way runs, past a listed extension's chain slot, into the memory
//!   of an entry the table frees (hostile22 F4): restored, commands would
//!   run through code the next upload may be put over. Refused.
//! - an extension the table lists on a hook is not on that hook's way (the
//!   hook at the ROM's target, or a chain that skips it, hSkip): restored,
//!   it is listed and never runs, as `installed` then shows. Said, not
//!   refused: a robot is left so by an extension that takes a hook whole,
//!   or a way dropped by hand, and a restore puts back what was there.
//!
//! Only bytes the file holds are followed; where it holds no more (an undo
//! file, memory a backup only witnesses), nothing is told.

use isa::objfmt::HookKind;
use romlib::installed::{ENTRY_LEN, Installed, entry_address, in_use};

use crate::backup::{Backup, in_rom};
use crate::image::RomProfile;

/// Where a hook's way, followed through a file, disagrees with the file's
/// table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Disagreement {
    /// The table lists `extension` on `hook`, and the hook's way does not
    /// lead to it.
    NotHooked {
        /// The hook.
        hook: HookKind,
        /// The extension listed on it.
        extension: Installed,
        /// The way the hook goes, `$0800 -> $F0A2`.
        path: String,
    },
    /// The hook's way runs, past a listed extension, into the memory of
    /// `freed`, an entry the table no longer lists.
    ThroughFreed {
        /// The hook.
        hook: HookKind,
        /// What the freed entry's bytes still say.
        freed: Installed,
        /// The way there.
        path: String,
    },
}

impl Disagreement {
    /// What it is, for a message.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Disagreement::NotHooked {
                hook,
                extension,
                path,
            } => format!(
                "the table lists {} on {}, but {} does not lead to it ({path})",
                extension.describe(),
                hook.rom_symbol(),
                hook.rom_symbol()
            ),
            Disagreement::ThroughFreed { hook, freed, path } => format!(
                "{} runs through {} ({path}), an entry the table has freed",
                hook.rom_symbol(),
                freed.describe()
            ),
        }
    }
}

/// How a way followed through the file ended.
enum End {
    /// At the ROM (its target or elsewhere in it).
    Rom,
    /// At an extension that takes the hook whole (no chain slot).
    Whole,
    /// At code no entry lists, past a listed extension when `past`.
    Unlisted { past: bool },
    /// Where the file holds no more, or back where it has been (the
    /// robot-side check after the memory tells loops).
    Unknown,
}

/// The disagreements between `backup`'s hooks and its table (none where
/// the profile keeps no table or the file does not hold its flags whole).
#[must_use]
pub(crate) fn disagreements(profile: &RomProfile, backup: &Backup) -> Vec<Disagreement> {
    let Some((table, entries)) = profile.table else {
        return Vec::new();
    };
    let flags: Option<Vec<u8>> = (0..entries)
        .map(|slot| backup.byte_at(u32::from(table) + slot as u32))
        .collect();
    let Some(flags) = flags else {
        return Vec::new();
    };
    let listed = crate::backup::backup_table(profile, backup);
    let freed = freed_entries(backup, (table, entries), &flags);
    let word = |at: u16| {
        let low = backup.byte_at(u32::from(at))?;
        let high = backup.byte_at(u32::from(at) + 1)?;
        Some(u16::from_le_bytes([low, high]))
    };
    let mut found = Vec::new();
    for &(kind, target) in &backup.hooks {
        let mut path: Vec<u16> = Vec::new();
        let mut at = target;
        let end = loop {
            if profile.reset_target(kind) == Some(at) || in_rom(profile, at) {
                path.push(at);
                break End::Rom;
            }
            if path.contains(&at) || path.len() > listed.len() {
                break End::Unknown;
            }
            path.push(at);
            let handler = listed
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .find(|hook| hook.kind == kind && hook.handler == at);
            match handler {
                Some(hook) => match hook.chain {
                    None => break End::Whole,
                    Some(slot) => match word(slot) {
                        Some(next) => at = next,
                        None => break End::Unknown,
                    },
                },
                None => {
                    break End::Unlisted {
                        past: path.len() > 1,
                    };
                }
            }
        };
        let shown = path_text(&path);
        // Inside a listed extension but not at its handler is the
        // robot-side check's (a way that strays).
        let unowned = !listed.iter().any(|entry| entry.contains(at));
        if let End::Unlisted { past: true } = end
            && unowned
            && let Some(entry) = freed.iter().find(|entry| entry.contains(at))
        {
            found.push(Disagreement::ThroughFreed {
                hook: kind,
                freed: entry.clone(),
                path: shown,
            });
            continue;
        }
        if matches!(end, End::Rom | End::Unlisted { .. }) {
            for entry in &listed {
                let skipped = entry
                    .hooks
                    .iter()
                    .any(|hook| hook.kind == kind && !path.contains(&hook.handler));
                if skipped {
                    found.push(Disagreement::NotHooked {
                        hook: kind,
                        extension: entry.clone(),
                        path: shown.clone(),
                    });
                }
            }
        }
    }
    found
}

/// `$0800 -> $F0A2`.
fn path_text(path: &[u16]) -> String {
    path.iter()
        .map(|at| format!("${at:04X}"))
        .collect::<Vec<_>>()
        .join(" -> ")
}

/// What the table's free entries still hold (a loader frees an entry by
/// its flags alone): each one whose extent the file holds and reads as
/// one, and its hooks where their handlers lie in it.
fn freed_entries(backup: &Backup, (table, entries): (u16, usize), flags: &[u8]) -> Vec<Installed> {
    let mut freed = Vec::new();
    for (slot, &flag) in flags.iter().enumerate() {
        if in_use(flag) {
            continue;
        }
        let at = entry_address(table, entries, slot);
        let bytes: Option<Vec<u8>> = (0..ENTRY_LEN)
            .map(|i| backup.byte_at(u32::from(at) + i as u32))
            .collect();
        let Some(bytes) = bytes else {
            continue;
        };
        let word = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]);
        let (first, last) = (word(3), word(5));
        if last < first || (first == 0 && last == 0) {
            continue;
        }
        let id = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], 0]);
        freed.push(Installed {
            id,
            extents: vec![first..=last],
            hooks: Vec::new(),
            slot,
        });
    }
    freed
}
