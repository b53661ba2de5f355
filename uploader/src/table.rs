//! The robot's table of installed extensions, from the host side: read
//! before an upload writes anything (an image that overlaps an installed
//! one is refused, or with `--replace` the old one is taken out of its
//! chains first), and the new image's entries written and verified after
//! its body and before its hooks, so the hook stays the last write.
//! The format is `romlib::installed`'s.

use std::ops::RangeInclusive;

use isa::objfmt::HookKind;
use romlib::installed::{self, ENTRY_LEN, Installed, TakenHook};
use romlib::protocol::{Answer, Command, ReadSpan, WordWrite};

use crate::client::Client;
use crate::hooks::{read_word, read_word_expecting, write_word_verified};
use crate::image::{Area, RomProfile, UploadImage};
use crate::transport::Transport;
use crate::{Error, Result};

/// What the table says before an upload: what is installed, and where
/// the new image's entries go.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    /// The table's address and entries.
    table: (u16, usize),
    /// The new image's entry, at its first slot.
    entry: Installed,
    /// Its flags bytes now (set, where an earlier copy of the same image
    /// left its entry).
    current_flags: Vec<Option<u8>>,
    /// The table as it was read, before anything changed it: its flags
    /// and the entries in use (what an undo puts back).
    pub(crate) found: Vec<Area>,
    /// The hooks as `prepare` left them: as found, but for those it
    /// pointed past an extension it took out (each write verified).
    pub(crate) hooks: Vec<(HookKind, u16)>,
    /// The extensions that stay installed beside the image (neither
    /// replaced nor an earlier copy of it): where the RAM loader must not
    /// go, and what a hook into them is known to be.
    pub(crate) others: Vec<Installed>,
    /// Whether the robot may hold much of the image already: the table
    /// lists an earlier copy of it, or an extension it replaces.
    pub(crate) held_maybe: bool,
    /// Whether the table lists an earlier copy of this very image (the
    /// same bytes as linked, at the same place).
    pub(crate) reused: bool,
    /// The installed extensions `replace` took out (their chains and
    /// entries), as the table described them.
    pub(crate) replaced: Vec<Installed>,
    /// Other extensions' chain slots re-pointed to take an extension out
    /// of its chain, as they were (what an undo puts back; a hook's own
    /// operand is the undo's hooks, switched last).
    pub(crate) unlinked: Vec<Area>,
    /// An earlier copy of the image behind another extension in a chain,
    /// taken out of it while the upload runs: once the image is verified,
    /// it goes back there rather than to the head of the chain (hostile14
    /// F6b: a project of two images re-chained them at every run, and no
    /// second run was ever "unchanged").
    pub(crate) relink: Vec<Relink>,
    /// Those of `others` whose flags a reset cleared while the upload ran
    /// (recheck20 F2): no longer installed, so nothing to chain to.
    pub(crate) freed: Vec<Installed>,
}

/// Where an earlier copy of the image was in a chain, behind another
/// extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Relink {
    /// The hook whose chain it is.
    pub(crate) kind: HookKind,
    /// The chain slot of the extension in front, which pointed at the
    /// image's handler.
    pub(crate) slot: u16,
    /// Where the image fell through to, what the slot holds while the
    /// upload runs: the image's own chain slot gets it.
    pub(crate) onward: u16,
}

/// Reads what the robot has installed (nothing, for a ROM without a table).
///
/// # Errors
/// The client's, or [`romlib::Error::DamagedTable`].
pub fn read_installed<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<Vec<Installed>> {
    Ok(read_table(client, profile)?.map_or_else(Vec::new, |table| table.installed))
}

/// What the robot's table holds: its flags bytes, the bytes of the
/// entries in use (read in one span, from the first in use to the last),
/// and what they say. `None` for a ROM without a table.
struct Table {
    flags: Vec<u8>,
    /// Entry bytes from the first entry in use on, with that slot.
    entries: (usize, Vec<u8>),
    installed: Vec<Installed>,
}

impl Table {
    /// Entry `slot`'s bytes, when they were read.
    fn entry(&self, slot: usize) -> Option<&[u8]> {
        let start = slot.checked_sub(self.entries.0)? * ENTRY_LEN;
        self.entries.1.get(start..start + ENTRY_LEN)
    }
}

/// Each installed extension with its table bytes as the robot holds them:
/// its flags bytes and its entries' bytes (empty for a ROM without a
/// table).
///
/// # Errors
/// The client's, or [`romlib::Error::DamagedTable`].
pub(crate) fn installed_bytes<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<Vec<(Installed, [Area; 2])>> {
    let (Some(read), Some((address, capacity))) = (read_table(client, profile)?, profile.table)
    else {
        return Ok(Vec::new());
    };
    Ok(read
        .installed
        .iter()
        .map(|entry| {
            let slots = entry.slot..entry.slot + entry.entries();
            let entries: Vec<u8> = slots
                .clone()
                .flat_map(|slot| read.entry(slot).unwrap_or_default().iter().copied())
                .collect();
            let areas = [
                Area {
                    address: installed::flags_address(address, entry.slot),
                    bytes: read.flags[slots].to_vec(),
                },
                Area {
                    address: installed::entry_address(address, capacity, entry.slot),
                    bytes: entries,
                },
            ];
            (entry.clone(), areas)
        })
        .collect())
}

fn read_table<T: Transport>(client: &mut Client<T>, profile: &RomProfile) -> Result<Option<Table>> {
    read_table_with(profile, &mut |at, len| client.read_memory(at, len))
}

/// What the robot has installed, read with `read` (through the debug
/// stub's frames, when the robot is stopped in it).
///
/// # Errors
/// `read`'s, or [`romlib::Error::DamagedTable`].
pub(crate) fn installed_with<E: From<Error>>(
    profile: &RomProfile,
    read: &mut dyn FnMut(u16, usize) -> std::result::Result<Vec<u8>, E>,
) -> std::result::Result<Vec<Installed>, E> {
    Ok(read_table_with(profile, read)?.map_or_else(Vec::new, |table| table.installed))
}

fn read_table_with<E: From<Error>>(
    profile: &RomProfile,
    read: &mut dyn FnMut(u16, usize) -> std::result::Result<Vec<u8>, E>,
) -> std::result::Result<Option<Table>, E> {
    let Some((address, capacity)) = profile.table else {
        return Ok(None);
    };
    let flags = read(address, capacity)?;
    let used: Vec<usize> = (0..capacity)
        .filter(|&slot| installed::in_use(flags[slot]))
        .collect();
    let entries = match (used.first(), used.last()) {
        (Some(&first), Some(&last)) => {
            let at = installed::entry_address(address, capacity, first);
            (first, read(at, (last + 1 - first) * ENTRY_LEN)?)
        }
        _ => (0, Vec::new()),
    };
    let mut table = Table {
        flags,
        entries,
        installed: Vec::new(),
    };
    table.installed = installed::decode(address, &table.flags, |slot| {
        table.entry(slot).unwrap_or_default()
    })
    .map_err(|damaged| E::from(Error::Robot(damaged.into())))?;
    Ok(Some(table))
}

/// Called before each write [`prepare`] makes (it unhooks an extension it
/// replaces, or an earlier copy behind another in its chain), with the
/// table as found and the chain slot about to be re-pointed, as it was
/// (`None` for a hook's own operand or the flags): so that what an undo
/// needs is kept before the robot changes (hostile10 F5).
pub(crate) type BeforeUnhook<'a, T> =
    dyn FnMut(&mut Client<T>, &[Area], Option<Area>) -> Result<()> + 'a;

/// What the writes of [`prepare`] share: the write limit, the table as
/// found and the call before each write, and the hooks as the writes
/// leave them (each written and verified, so known without a read).
struct Unhooking<'a, 'b, T> {
    max_writes: u32,
    found: Vec<Area>,
    before: &'a mut BeforeUnhook<'b, T>,
    hooks: Vec<(HookKind, u16)>,
}

/// Reads the table and decides: an installed image that overlaps `image`
/// is an error, unless it is an earlier copy of the same image (its slot
/// is reused) or `replace` is set (it is taken out of its chains and its
/// entries cleared, verified, before anything else is written). `None`
/// for a ROM that keeps no table.
pub(crate) fn prepare<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    image: &UploadImage,
    replace: bool,
    (max_writes, hooks): (u32, &[(HookKind, u16)]),
    before: &mut BeforeUnhook<'_, T>,
) -> Result<Option<Plan>> {
    let Some(table) = profile.table else {
        return Ok(None);
    };
    let id = image.id();
    let mut kept = Vec::new();
    let mut reused = None;
    let Some(mut read) = read_table(client, profile)? else {
        return Ok(None);
    };
    let mut found = vec![Area {
        address: table.0,
        bytes: read.flags.clone(),
    }];
    if !read.entries.1.is_empty() {
        found.push(Area {
            address: installed::entry_address(table.0, table.1, read.entries.0),
            bytes: read.entries.1.clone(),
        });
    }
    let mut writes = Unhooking {
        max_writes,
        found,
        before,
        hooks: hooks.to_vec(),
    };
    let in_the_way = read.installed.iter().any(|old| {
        old.overlap(image.extents()).is_some() && !(old.id == id && old.extents == image.extents())
    });
    if replace && in_the_way {
        for &(kind, target) in hooks {
            let way = (kind, target);
            if let Some(path) =
                crate::chain::unlisted_way_into(client, profile, &read.installed, way, image)?
            {
                return Err(Error::UnlistedWayIn {
                    hook: kind.rom_symbol(),
                    path: path.to_string(),
                });
            }
        }
    }
    let mut replaced = Vec::new();
    let mut known = hooks;
    let mut unlinked = Vec::new();
    let mut relink = Vec::new();
    for old in &read.installed {
        match old.overlap(image.extents()) {
            None => kept.push(old.clone()),
            Some(_) if old.id == id && old.extents == image.extents() => {
                // An earlier copy behind another extension in its chain:
                // taken out there, or the hook, pointed at it again, would
                // lead round the chain back to it for ever. (At the head,
                // the upload points the hook past it itself.)
                for hook in &old.hooks {
                    let context = (&read.installed[..], known);
                    let Some((slot, onward)) =
                        unlink(client, profile, context, *hook, &mut writes, false)?
                    else {
                        continue;
                    };
                    relink.push(Relink {
                        kind: hook.kind,
                        slot: slot.address,
                        onward,
                    });
                    unlinked.push(slot);
                }
                reused = Some(old.clone());
            }
            Some(_) if replace => {
                replaced.push(old.clone());
                for (kind, slot, onward) in
                    remove(client, profile, (&read.installed, known), old, &mut writes)?
                {
                    // recheck17 F1: the image takes its place in the chain,
                    // behind the extension in front of it, as a copy of
                    // itself would (the undo of the one in front compares
                    // the table's entries and refuses to put this one's
                    // back: recheck18 F1).
                    let takes = image.hooks().iter().any(|record| record.kind == kind);
                    if takes && !relink.iter().any(|relink: &Relink| relink.kind == kind) {
                        relink.push(Relink {
                            kind,
                            slot: slot.address,
                            onward,
                        });
                    }
                    unlinked.push(slot);
                }
                // The hooks may have moved: read from here on.
                known = &[];
                // Its flags are cleared now, verified.
                read.flags[old.slot..old.slot + old.entries()].fill(0);
            }
            Some(refusal) => return Err(Error::Robot(refusal)),
        }
    }
    let mut entry = Installed::new(id, image.extents().to_vec(), image.hooks());
    entry.slot = match &reused {
        Some(old) => old.slot,
        None => installed::free_slot(&kept, entry.entries(), table.1).ok_or_else(|| {
            Error::Robot(romlib::Error::TableFull {
                capacity: table.1,
                reason: format!(
                    "the image needs {}, one per place its memory is in",
                    installed::entries_text(entry.entries())
                ),
            })
        })?,
    };
    let current_flags: Vec<Option<u8>> = read.flags[entry.slot..entry.slot + entry.entries()]
        .iter()
        .map(|&b| Some(b))
        .collect();
    Ok(Some(Plan {
        table,
        entry,
        current_flags,
        found: writes.found,
        hooks: writes.hooks,
        held_maybe: !replaced.is_empty() || reused.is_some(),
        reused: reused.is_some(),
        replaced,
        others: kept,
        freed: Vec::new(),
        unlinked,
        relink,
    }))
}

impl Plan {
    /// The entry's bytes (its flags apart), to go in with the body and be
    /// verified with it: through the RAM loader at its rate, or with `/9W`.
    pub(crate) fn entry_area(&self) -> Area {
        let (table, capacity) = self.table;
        Area {
            address: installed::entry_address(table, capacity, self.entry.slot),
            bytes: self.entry.encode(),
        }
    }

    /// Whether [`Plan::free_first`] writes anything.
    pub(crate) fn frees_first(&self) -> bool {
        !self.current_flags.iter().all(|flags| *flags == Some(0))
    }

    /// Frees the entry's slots first, where an earlier copy of the image
    /// left them flagged: the body about to rewrite them must not pass for
    /// a finished entry if the upload stops half way.
    pub(crate) fn free_first<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        max_writes: u32,
    ) -> Result<()> {
        if self.current_flags.iter().all(|flags| *flags == Some(0)) {
            return Ok(());
        }
        let at = installed::flags_address(self.table.0, self.entry.slot);
        let zeros = vec![0; self.current_flags.len()];
        write_verified(client, at, &zeros, &self.current_flags, max_writes)?;
        self.current_flags = vec![Some(0); zeros.len()];
        Ok(())
    }

    /// Sets the entry's flags, verified, once the body and the entry are:
    /// the entry counts from then on.
    pub(crate) fn write_flags<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        max_writes: u32,
    ) -> Result<()> {
        let at = installed::flags_address(self.table.0, self.entry.slot);
        let flags = self.entry.flags();
        write_verified(client, at, &flags, &self.current_flags, max_writes)?;
        self.current_flags = flags.into_iter().map(Some).collect();
        Ok(())
    }

    /// Whether the table listed no extension in use when it was read.
    pub(crate) fn lists_nothing(&self) -> bool {
        self.others.is_empty() && self.replaced.is_empty() && !self.reused
    }

    /// The flags are known to be cleared (a reset): the next write sets
    /// them again.
    pub(crate) fn forget_flags(&mut self) {
        self.current_flags = vec![None; self.current_flags.len()];
    }
}

impl Plan {
    /// Whether the entry's flags are still set, and the other extensions'
    /// too: a reset since they were written clears them all (the first
    /// byte of each is enough; one read covers them). A reset found by
    /// the others' flags alone came before the image's were written, and
    /// perhaps before its hooks chained to one of those others: those are
    /// `freed` from then on, and the caller puts the hooks in again.
    pub(crate) fn still_there<T: Transport>(&mut self, client: &mut Client<T>) -> Result<bool> {
        let ours = self.entry.slot;
        let watched: Vec<usize> = self
            .others
            .iter()
            .filter(|other| !self.freed.contains(other))
            .map(|other| other.slot)
            .chain([ours])
            .collect();
        let first = watched.iter().copied().min().unwrap_or(ours);
        let last = watched.iter().copied().max().unwrap_or(ours);
        let at = installed::flags_address(self.table.0, first);
        let count = last - first + 1;
        let wanted = self.entry.flags().first().copied();
        let fine = |read: &[u8]| {
            read.get(ours - first).copied() == wanted
                && watched.iter().all(|&slot| {
                    read.get(slot - first)
                        .is_some_and(|&flags| installed::in_use(flags))
                })
        };
        // One question where all is well (the common case: as fast as the
        // check of the image's own flags alone was); anything else is read
        // until two answers agree, as noise may have changed the first.
        let span = ReadSpan::new(at, u8::try_from(count).unwrap_or(u8::MAX))?;
        if let Ok(Answer::Memory(bytes)) = client.ask(&Command::ReadMemory(span))
            && fine(&bytes)
        {
            return Ok(true);
        }
        let read = client.read_memory(at, count)?;
        let set = |slot: usize| {
            read.get(slot - first)
                .is_some_and(|&flags| installed::in_use(flags))
        };
        if read.get(ours - first).copied() != wanted {
            return Ok(false);
        }
        let cleared: Vec<Installed> = self
            .others
            .iter()
            .filter(|other| !self.freed.contains(other) && !set(other.slot))
            .cloned()
            .collect();
        let reset = !cleared.is_empty();
        self.freed.extend(cleared);
        Ok(!reset)
    }
}

/// Writes `wanted` at `at` where it differs from `now` (`None`: not
/// known), two bytes a `/9W` (the last odd byte with `/7W`), then reads the
/// range back and writes again what differs, `max_writes` times at most.
fn write_verified<T: Transport>(
    client: &mut Client<T>,
    at: u16,
    wanted: &[u8],
    now: &[Option<u8>],
    max_writes: u32,
) -> Result<()> {
    let mut now = now.to_vec();
    for _ in 0..max_writes {
        for (index, pair) in wanted.chunks(2).enumerate() {
            let offset = index * 2;
            let known = &now[offset..offset + pair.len()];
            if known.iter().zip(pair).all(|(n, w)| *n == Some(*w)) {
                continue;
            }
            let address = at + offset as u16;
            let command = match pair {
                [low, high] => Command::WriteWord(WordWrite::new(address, [*low, *high])?),
                _ => Command::WriteByte {
                    address,
                    value: pair[0],
                },
            };
            client.send(&command)?;
        }
        let Some(read) = differs(client, at, wanted)? else {
            return Ok(());
        };
        now = read.into_iter().map(Some).collect();
    }
    let (offset, expected, found) = wanted
        .iter()
        .zip(&now)
        .enumerate()
        .find(|(_, (w, n))| Some(**w) != **n)
        .map_or((0, 0, 0), |(i, (w, n))| (i, *w, n.unwrap_or(0)));
    Err(Error::VerifyFailed {
        address: at + offset as u16,
        expected,
        found,
        attempts: max_writes,
    })
}

/// `None` if memory at `at` holds `wanted`: one `/7R` whose answer shows
/// exactly those bytes settles it (noise does not forge the bytes asked
/// for); else what it holds, read until two answers agree.
fn differs<T: Transport>(
    client: &mut Client<T>,
    at: u16,
    wanted: &[u8],
) -> Result<Option<Vec<u8>>> {
    let count = u8::try_from(wanted.len()).unwrap_or(u8::MAX);
    if let Ok(Answer::Memory(bytes)) = client.ask(&Command::ReadMemory(ReadSpan::new(at, count)?))
        && bytes == wanted
    {
        return Ok(None);
    }
    let read = client.read_memory(at, wanted.len())?;
    Ok((read != wanted).then_some(read))
}

/// Takes `old` out of every chain it is in (the pointer that jumps to its
/// handler, the hook or another extension's chain slot, re-pointed at
/// where `old` fell through, verified), then clears its entries. Returns
/// the chain slots it re-pointed, as they were, each with its hook and
/// where it points now.
///
/// # Errors
/// The client's, [`Error::VerifyFailed`].
fn remove<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (everyone, hooks): (&[Installed], &[(HookKind, u16)]),
    old: &Installed,
    writes: &mut Unhooking<'_, '_, T>,
) -> Result<Vec<(HookKind, Area, u16)>> {
    let Some((table, _)) = profile.table else {
        return Ok(Vec::new());
    };
    let mut slots = Vec::new();
    for hook in &old.hooks {
        if let Some((slot, onward)) =
            unlink(client, profile, (everyone, hooks), *hook, writes, true)?
        {
            slots.push((hook.kind, slot, onward));
        }
    }
    // Clearing its flags bytes frees its entries.
    let now: Vec<Option<u8>> = old.flags().into_iter().map(Some).collect();
    let freed = vec![0u8; now.len()];
    let at = installed::flags_address(table, old.slot);
    (writes.before)(client, &writes.found, None)?;
    write_verified(client, at, &freed, &now, writes.max_writes)?;
    Ok(slots)
}

/// Re-points whatever jumps to `hook.handler` at where that extension
/// fell through: the hook's own operand (only `at_head`), or the chain
/// slot of the extension before it. Nothing to do where it is not in the
/// chain. `hooks`: the hooks' targets as the upload read them (until two
/// answers agreed), so the chain is followed from there without reading
/// them again. Returns the chain slot it re-pointed, as it was (not the
/// hook: an undo switches hooks itself, last), and where it points now.
fn unlink<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (everyone, hooks): (&[Installed], &[(HookKind, u16)]),
    hook: TakenHook,
    writes: &mut Unhooking<'_, '_, T>,
    at_head: bool,
) -> Result<Option<(Area, u16)>> {
    let head = profile.hook_address(hook.kind) + 1;
    let from_hook = hooks
        .iter()
        .find(|(kind, _)| *kind == hook.kind)
        .map(|&(_, target)| target);
    if !at_head && from_hook == Some(hook.handler) {
        return Ok(None);
    }
    // Mostly the only extension on its hook: its slot holds the ROM's
    // target, taken at the first answer that says so.
    let after = match hook.chain {
        Some(slot) => read_word_expecting(client, slot, profile.reset_target(hook.kind))?,
        None => profile.reset_target(hook.kind),
    };
    let Some(mut after) = after else {
        return Err(Error::HookInUse {
            hook: hook.kind.rom_symbol(),
            target: hook.handler,
        });
    };
    // hostile15 F1: a way out damaged by hand (into the stack, the I/O
    // page, the middle of the ROM) is not passed on to the extension
    // before it: that one falls through to the ROM instead.
    if let Some(reset) = profile.reset_target(hook.kind)
        && after != reset
        && crate::chain::broken_way(client, profile, everyone, (hook.kind, after))?.is_some()
    {
        after = reset;
    }
    let chain = walk(
        client,
        profile,
        everyone,
        (hook.kind, from_hook),
        Some(hook.handler),
    )?;
    match chain.last() {
        Some(&(pointer, target)) if target == hook.handler && (at_head || pointer != head) => {
            let slot = (pointer != head).then(|| Area {
                address: pointer,
                bytes: target.to_le_bytes().to_vec(),
            });
            (writes.before)(client, &writes.found, slot.clone())?;
            write_word_verified(client, pointer, after.to_le_bytes(), writes.max_writes)?;
            if pointer == head {
                for (kind, target) in &mut writes.hooks {
                    if *kind == hook.kind {
                        *target = after;
                    }
                }
            }
            Ok(slot.map(|slot| (slot, after)))
        }
        _ => Ok(None),
    }
}

/// The targets of `kind`'s chain, in order, for a listing: each handler
/// the hook reaches, following the installed chain slots, up to the first
/// target that no installed extension owns (the ROM's, usually).
///
/// # Errors
/// The client's.
pub fn chain_of<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    kind: HookKind,
) -> Result<Vec<u16>> {
    let chain = walk(client, profile, everyone, (kind, None), None)?;
    Ok(chain.into_iter().map(|(_, target)| target).collect())
}

/// `kind`'s chain from `first` on, as [`chain_of`] gives it from the
/// hook: for what a debug stub left hooked chains to (fresh19 F5: the
/// extensions behind it were listed as not hooked).
///
/// # Errors
/// The client's.
pub fn chain_from<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, first): (HookKind, u16),
) -> Result<Vec<u16>> {
    let chain = walk(client, profile, everyone, (kind, Some(first)), None)?;
    Ok(chain.into_iter().map(|(_, target)| target).collect())
}

/// Follows `kind`'s chain from the hook: each pointer (the hook's operand,
/// then installed chain slots) with the target it holds, read until two
/// answers agree, up to `until` or the first target no installed
/// extension owns; at most one step per extension. `from_hook`: the
/// hook's target where it was read already (two answers agreeing).
fn walk<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, from_hook): (HookKind, Option<u16>),
    until: Option<u16>,
) -> Result<Vec<(u16, u16)>> {
    let mut steps = Vec::new();
    let mut pointer = profile.hook_address(kind) + 1;
    let mut known = from_hook;
    for _ in 0..=everyone.len() {
        let read = match known.take() {
            Some(target) => Some(target),
            None => read_word(client, pointer)?,
        };
        let Some(target) = read else {
            break;
        };
        steps.push((pointer, target));
        if Some(target) == until {
            break;
        }
        let next = everyone
            .iter()
            .flat_map(|other| other.hooks.iter())
            .find(|other| other.kind == kind && other.handler == target)
            .and_then(|other| other.chain);
        match next {
            Some(slot) => pointer = slot,
            None => break,
        }
    }
    Ok(steps)
}

/// Sorted, merged extents of loaded areas.
pub(crate) fn extents_of(areas: &[crate::image::Area]) -> Vec<RangeInclusive<u16>> {
    installed::merge(
        areas
            .iter()
            .map(|area| (u64::from(area.address), area.bytes.len() as u64)),
    )
}
