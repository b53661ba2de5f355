//! Where a backup's hooks lead through the file's own memory (over the
//! robot's table where the file holds part of it), told against the
//! file's table before a restore writes anything, and said by `backup` of
//! a robot in such a state ([`Disagreement`]):
//! - refused: a way into the memory of an entry the table has freed
//!   (hostile22 F4), through code no entry lists before an extension the
//!   table lists on that hook (hostile25 F2), or back to where it has been
//!   (hostile25 F5), or into a listed extension but not to its handler
//!   (hostile25 F5b). Restored, commands would run through memory the
//!   next upload may take, the middle of code, or never end. An upload's undo puts back the first
//!   two where its upload found them so.
//! - said, not refused: an extension the table lists on a hook whose way
//!   does not reach it (the hook at the ROM's target, a chain that skips
//!   it, hSkip): restored, it is listed and never runs, as `installed`
//!   shows. A robot is left so by an extension that takes a hook whole, or
//!   a way dropped by hand, and a restore puts back what was there.
//!   `backup` tells it from the file; a restore from the robot once it is
//!   done ([`unreached`]: an undo file does not hold the chain slots).
//!
//! [`steps`] lists each address a way goes through, which a backup must
//! hold or witness. Only bytes the file holds are followed; where it holds
//! no more (an undo file, memory a backup only witnesses), nothing is told
//! from the file.

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
    /// The hook's way runs into the memory of `freed`, an entry the table
    /// no longer lists.
    ThroughFreed {
        /// The hook.
        hook: HookKind,
        /// What the freed entry's bytes still say.
        freed: Installed,
        /// The way there.
        path: String,
    },
    /// The hook's way runs into code no entry lists while extensions the
    /// table lists on it are still to come (hostile25 F2: an entry
    /// zeroed; an upload only ever chains to such code last).
    Unlisted {
        /// The hook.
        hook: HookKind,
        /// The extensions listed on the hook the way has not reached.
        behind: Vec<Installed>,
        /// The way there.
        path: String,
        /// Whether that code is the hook's own target, in front of every
        /// listed extension: an owner's handler (fresh28 F1), which a
        /// restore puts back where its way goes on into them (told over
        /// the robot, [`crate::way_checked::owner_in_front`]).
        first: bool,
    },
    /// The hook's way runs into the memory of `extension`, which the
    /// table lists, but not to its handler on that hook: the middle of its
    /// code, where no chain goes (hostile25 F5b: told only once the memory
    /// was written).
    Strays {
        /// The hook.
        hook: HookKind,
        /// The extension whose memory it runs into.
        extension: Installed,
        /// The way there.
        path: String,
    },
    /// The hook's way comes back, through listed extensions' chain slots,
    /// to where it has been (hostile25 F5: told only once the memory was
    /// written).
    Loops {
        /// The hook.
        hook: HookKind,
        /// The way, the address it comes back to last.
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
            Disagreement::Unlisted {
                hook,
                behind,
                path,
                first,
            } => {
                let behind: Vec<String> = behind.iter().map(Installed::describe).collect();
                format!(
                    "{} runs {}through code no entry of the table lists ({path}), before {} the table lists on it",
                    hook.rom_symbol(),
                    if *first { "first " } else { "" },
                    behind.join(", ")
                )
            }
            Disagreement::Strays {
                hook,
                extension,
                path,
            } => format!(
                "{} runs into {} ({path}) but not to its handler on that hook",
                hook.rom_symbol(),
                extension.describe()
            ),
            Disagreement::Loops { hook, path } => format!(
                "{} comes back to where it has been ({path}), a loop the robot would run for ever {}",
                hook.rom_symbol(),
                when_run(*hook)
            ),
        }
    }

    /// Whether it is a way through memory the table does not list, which
    /// an upload may have found so (changed by hand before it) and
    /// chained in front of: its undo puts it back as found.
    #[must_use]
    pub(crate) fn made_by_hand_before(&self) -> bool {
        matches!(
            self,
            Disagreement::ThroughFreed { .. } | Disagreement::Unlisted { .. }
        )
    }

    /// Why a restore refuses it, where it does (all but
    /// [`Disagreement::NotHooked`], which is put back as it is).
    #[must_use]
    pub fn refusal(&self) -> Option<&'static str> {
        match self {
            Disagreement::NotHooked { .. } => None,
            Disagreement::Unlisted { first: true, .. } => None,
            Disagreement::ThroughFreed { .. } | Disagreement::Unlisted { .. } => {
                Some("commands would run through memory the next upload may be put in")
            }
            Disagreement::Strays { .. } => {
                Some("commands would run the middle of its code, where no chain goes")
            }
            Disagreement::Loops {
                hook: HookKind::Loop,
                ..
            } => Some("the robot would stop answering at once"),
            Disagreement::Loops { .. } => Some("no unknown command would ever end"),
        }
    }
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
    let word = |at: u16| word_at(backup, at);
    let mut found = Vec::new();
    for &(kind, target) in &backup.hooks {
        let on_hook: Vec<&Installed> = listed
            .iter()
            .filter(|entry| entry.hooks.iter().any(|hook| hook.kind == kind))
            .collect();
        let mut path: Vec<u16> = Vec::new();
        let mut at = target;
        // Whether the way was followed to its end (the ROM, an extension
        // that takes the hook whole, or code after every listed one).
        let ended = loop {
            if profile.reset_target(kind) == Some(at) || in_rom(profile, at) {
                path.push(at);
                break true;
            }
            let came_back = path.contains(&at);
            path.push(at);
            if came_back {
                found.push(Disagreement::Loops {
                    hook: kind,
                    path: path_text(&path),
                });
                break false;
            }
            let handler = listed
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .find(|hook| hook.kind == kind && hook.handler == at);
            if let Some(hook) = handler {
                match hook.chain.map(word) {
                    None => break true,
                    Some(Some(next)) => at = next,
                    Some(None) => break false,
                }
                continue;
            }
            if let Some(entry) = listed.iter().find(|entry| entry.contains(at)) {
                found.push(Disagreement::Strays {
                    hook: kind,
                    extension: entry.clone(),
                    path: path_text(&path),
                });
                break false;
            }
            if let Some(entry) = freed.iter().find(|entry| entry.contains(at)) {
                found.push(Disagreement::ThroughFreed {
                    hook: kind,
                    freed: entry.clone(),
                    path: path_text(&path),
                });
                break false;
            }
            let behind: Vec<Installed> = on_hook
                .iter()
                .filter(|entry| !reached(entry, kind, &path))
                .map(|entry| (*entry).clone())
                .collect();
            if !behind.is_empty() {
                found.push(Disagreement::Unlisted {
                    hook: kind,
                    behind,
                    first: path.len() == 1,
                    path: path_text(&path),
                });
                break false;
            }
            // An owner's code after every listed extension: an upload
            // chains to whatever a hook led to.
            break true;
        };
        if ended {
            found.extend(not_hooked(&listed, kind, &path));
        }
    }
    found
}

/// Each address every hook's way goes through (with the way to it), as
/// far as `backup` holds it (listed extensions' chain slots, and `JMP`s in code it holds), the
/// ROM left out: the code a restore of it hooks, every byte of which it
/// must hold or witness (hostile26 F1, F2: a way on into memory outside
/// the file, into code no entry lists, was checked at its first step
/// only).
#[must_use]
pub(crate) fn steps(profile: &RomProfile, backup: &Backup) -> Vec<(HookKind, Vec<u16>)> {
    let listed = crate::backup::backup_table(profile, backup);
    let word = |at: u16| word_at(backup, at);
    let mut steps = Vec::new();
    for &(kind, target) in &backup.hooks {
        let mut path: Vec<u16> = Vec::new();
        let mut at = target;
        while profile.reset_target(kind) != Some(at)
            && !in_rom(profile, at)
            && !path.contains(&at)
            && path.len() < 16
        {
            path.push(at);
            steps.push((kind, path.clone()));
            let slot = listed
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .find(|hook| hook.kind == kind && hook.handler == at)
                .map(|hook| hook.chain);
            let next = match slot {
                Some(Some(slot)) => word(slot),
                Some(None) => None,
                None if backup.byte_at(u32::from(at)) == Some(crate::hooks::JMP) => {
                    word(at.wrapping_add(1))
                }
                None => None,
            };
            match next {
                Some(next) => at = next,
                None => break,
            }
        }
    }
    steps
}

/// When the robot runs `kind`'s way (recheck25 R7: a loop on HOOK_LOOP
/// stops it at once, not at an unknown command).
fn when_run(kind: HookKind) -> &'static str {
    match kind {
        HookKind::Unknown => "at its next unknown command",
        HookKind::Loop => "as soon as its control loop runs it",
    }
}

/// Whether `path` goes through `entry`'s `kind` handler.
fn reached(entry: &Installed, kind: HookKind, path: &[u16]) -> bool {
    entry
        .hooks
        .iter()
        .any(|hook| hook.kind == kind && path.contains(&hook.handler))
}

/// What the robot's table lists on a hook whose chain, as the robot holds
/// it now, does not lead to it: as `installed` marks it "not hooked".
///
/// # Errors
/// The line's.
pub(crate) fn unreached<T: crate::transport::Transport>(
    client: &mut crate::client::Client<T>,
    profile: &RomProfile,
) -> crate::Result<Vec<Disagreement>> {
    let everyone = crate::table::read_installed(client, profile)?;
    let mut found = Vec::new();
    if everyone.is_empty() {
        return Ok(found);
    }
    for kind in HookKind::ALL {
        let listed_on = everyone
            .iter()
            .any(|entry| entry.hooks.iter().any(|hook| hook.kind == kind));
        if !listed_on {
            continue;
        }
        let path = crate::table::chain_of(client, profile, &everyone, kind)?;
        // A chain that ends at code no entry lists may go on through it
        // (recheck25 R2: said "never runs" of one that answered).
        let ends = path
            .last()
            .is_none_or(|&at| profile.reset_target(kind) == Some(at) || in_rom(profile, at));
        let whole = path.last().is_some_and(|&at| {
            everyone
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .any(|hook| hook.kind == kind && hook.handler == at && hook.chain.is_none())
        });
        if ends || whole {
            found.extend(not_hooked(&everyone, kind, &path));
        }
    }
    Ok(found)
}

/// Each of `listed` with a `kind` handler that `path` (a hook's way) does
/// not go through.
fn not_hooked(listed: &[Installed], kind: HookKind, path: &[u16]) -> Vec<Disagreement> {
    listed
        .iter()
        .filter(|entry| {
            entry
                .hooks
                .iter()
                .any(|hook| hook.kind == kind && !path.contains(&hook.handler))
        })
        .map(|entry| Disagreement::NotHooked {
            hook: kind,
            extension: entry.clone(),
            path: path_text(path),
        })
        .collect()
}

/// The little-endian word `backup` holds at `at`, if it holds both bytes.
fn word_at(backup: &Backup, at: u16) -> Option<u16> {
    let low = backup.byte_at(u32::from(at))?;
    let high = backup.byte_at(u32::from(at) + 1)?;
    Some(u16::from_le_bytes([low, high]))
}

/// `$0800 -> $F0A2`.
pub(crate) fn path_text(path: &[u16]) -> String {
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

/// `backup` as a restore of it would leave the robot, as far as its ways
/// go: the robot's table under the file's where the file does not hold it
/// whole, and the robot's bytes where a way goes on through memory the
/// file does not hold (a listed extension's chain slot, the `JMP` at a
/// step), the file's own bytes first. Read once the file's witnesses are
/// checked, so the robot's bytes at a witnessed step are the file's.
/// Then [`steps`] and [`disagreements`] follow a way past what the file
/// holds (N1: the code a backup only witnesses went on, by its `JMP`, into
/// memory nothing checked; hostile26 F1b, an undo file's chain slots).
///
/// # Errors
/// The line's.
pub(crate) fn over_robot<T: crate::transport::Transport>(
    client: &mut crate::client::Client<T>,
    profile: &RomProfile,
    backup: &Backup,
) -> crate::Result<Backup> {
    let mut seen = backup.clone();
    if let Some((at, len)) = crate::backup::table_range(profile) {
        let whole = (0..len).all(|i| backup.byte_at(u32::from(at) + i as u32).is_some());
        if !whole {
            seen.areas.push(crate::image::Area {
                address: at,
                bytes: client.read_memory(at, len)?,
            });
        }
    }
    let readable = |at: u16| profile.writable.iter().any(|range| range.contains(&at));
    for _ in 0..MOST_READS {
        let listed = crate::backup::backup_table(profile, &seen);
        let mut wanted = std::collections::BTreeSet::new();
        for (kind, way) in steps(profile, &seen) {
            let at = way[way.len() - 1];
            let slot = listed
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .find(|hook| hook.kind == kind && hook.handler == at)
                .map(|hook| hook.chain);
            let bytes: Vec<u16> = match slot {
                Some(Some(slot)) => vec![slot, slot.wrapping_add(1)],
                Some(None) => Vec::new(),
                None => (0..3).map(|i| at.wrapping_add(i)).collect(),
            };
            wanted.extend(
                bytes
                    .into_iter()
                    .filter(|&at| readable(at) && seen.byte_at(u32::from(at)).is_none()),
            );
        }
        if wanted.is_empty() {
            break;
        }
        let mut runs: Vec<(u16, usize)> = Vec::new();
        for at in wanted {
            match runs.last_mut() {
                Some((start, len)) if u32::from(*start) + *len as u32 == u32::from(at) => {
                    *len += 1;
                }
                _ => runs.push((at, 1)),
            }
        }
        for (at, len) in runs {
            seen.areas.push(crate::image::Area {
                address: at,
                bytes: client.read_memory(at, len)?,
            });
        }
    }
    Ok(seen)
}

/// Rounds of reads [`over_robot`] makes, each a step further down the
/// ways: as many as [`steps`] follows.
const MOST_READS: usize = 16;
