//! Every byte of code a file's hooks run, as a restore would leave them,
//! is one the file holds or witnesses (hostile28 F3, fresh28 F2). A way
//! that went through code on the KIM bus was followed only through chain
//! slots and a `JMP` at each step: code before the `JMP` (`INC counter;
//! JMP next`, what every loop handler looks like), or a `JMP` whose
//! operand lay past the witnessed bytes, hid the next step, which could
//! change and be restored with "verified", exit 0. The ways are followed
//! as [`crate::chain::way_code`] does (run on the host, and every arm of
//! its branches): `backup` witnesses all of it, a restore refuses what it
//! does not check.

use std::collections::{BTreeMap, BTreeSet};

use isa::objfmt::HookKind;
use romlib::installed::Installed;

use crate::backup::Backup;
use crate::client::Client;
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

/// The code one hook's way runs outside the extensions listed.
#[derive(Debug, Clone)]
pub(crate) struct WayCode {
    /// The hook.
    pub(crate) hook: HookKind,
    /// The steps the way went through.
    pub(crate) way: Vec<u16>,
    /// Every byte of code it runs that no listed extension holds.
    pub(crate) code: BTreeSet<u16>,
    /// Whether it ends where a command's way may ([`crate::chain::Noted`]).
    pub(crate) fine: bool,
    /// Where it jumps where its data says, if it does.
    pub(crate) computed: Option<u16>,
    /// Where it goes into a listed extension's code, if it does.
    pub(crate) entered: Option<u16>,
}

/// The bytes `backup` holds, as a restore would write them (the first
/// area that holds a byte, as [`Backup::byte_at`] reads it).
#[must_use]
pub(crate) fn laid(backup: &Backup) -> BTreeMap<u16, u8> {
    let mut laid = BTreeMap::new();
    for area in &backup.areas {
        for (i, &byte) in area.bytes.iter().enumerate() {
            laid.entry(area.address.wrapping_add(i as u16))
                .or_insert(byte);
        }
    }
    laid
}

/// The code each of `hooks` that goes into RAM runs, over the robot's
/// memory with `laid` over it, `everyone` the table it would list.
///
/// # Errors
/// The line's errors.
pub(crate) fn code_of<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (hooks, everyone): (&[(HookKind, u16)], &[Installed]),
    laid: &BTreeMap<u16, u8>,
) -> Result<Vec<WayCode>> {
    let mut ways = Vec::new();
    for (hook, target) in crate::chain::into_ram(profile, hooks) {
        let noted =
            crate::chain::way_code(client, profile, everyone, (hook, target), laid.clone())?;
        ways.push(WayCode {
            hook,
            way: noted.way,
            code: noted.code,
            fine: noted.fine,
            computed: noted.computed,
            entered: noted.entered,
        });
    }
    Ok(ways)
}

/// What the robot lists now, and the code its hooks run now.
///
/// # Errors
/// The line's errors.
fn ways_now<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<(Vec<Installed>, Vec<WayCode>)> {
    let listed = crate::table::read_installed(client, profile)?;
    let hooks = crate::hooks::read_hooks(client, profile)?;
    let now = code_of(client, profile, (&hooks, &listed), &BTreeMap::new())?;
    Ok((listed, now))
}

/// The first byte of `ways` in memory an extension may hold that
/// `backup` neither holds nor witnesses and `fine` does not excuse: the
/// hook, the way, the byte.
#[must_use]
pub(crate) fn first_unchecked<'a>(
    profile: &RomProfile,
    backup: &Backup,
    ways: &'a [WayCode],
    fine: &dyn Fn(u16) -> bool,
) -> Option<(&'a WayCode, u16)> {
    ways.iter().find_map(|way| {
        way.code
            .iter()
            .copied()
            .find(|&at| {
                let writable = profile.writable.iter().any(|range| range.contains(&at));
                writable
                    && backup.byte_at(u32::from(at)).is_none()
                    && !backup.witnessed(at)
                    && !fine(at)
            })
            .map(|at| (way, at))
    })
}

/// Before a restore writes anything: every byte of code `backup`'s hooks
/// run, over the robot as `seen` (the file over the robot's table and
/// ways, its witnesses checked) says, is held or witnessed by the file.
/// An undo file's may also be code of an extension the robot lists now,
/// or code the robot's own hooks run now (recheck25 R6: an upload chained
/// in front of an owner's code; its undo puts that way back); and code no
/// entry lists that it puts in must be such code too.
///
/// # Errors
/// [`Error::UnwitnessedStep`] for a backup, [`Error::UndoStepUnlisted`]
/// and [`Error::UndoAddsCode`] for an undo file; the line's errors.
pub(crate) fn check_restore<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (backup, seen): (&Backup, &Backup),
    undo: bool,
) -> Result<()> {
    let everyone = crate::backup::backup_table(profile, seen);
    let ways = code_of(client, profile, (&backup.hooks, &everyone), &laid(backup))?;
    if !undo {
        if let Some(error) = owner_in_front(&everyone, &ways) {
            return Err(error);
        }
        if let Some(error) = computed_outside(profile, backup, &ways) {
            return Err(error);
        }
        return match first_unchecked(profile, backup, &ways, &|_| false) {
            Some((way, at)) => Err(unchecked_error(way, at, false)),
            None => Ok(()),
        };
    }
    let put_in = |at: u16| backup.byte_at(u32::from(at)).is_some();
    let nothing_to_ask = first_unchecked(profile, backup, &ways, &|_| false).is_none()
        && !ways.iter().any(|way| way.code.iter().any(|&at| put_in(at)));
    if nothing_to_ask {
        return Ok(());
    }
    let (listed, now) = ways_now(client, profile)?;
    let run_now = |at: u16| {
        listed.iter().any(|entry| entry.contains(at))
            || now.iter().any(|way| way.code.contains(&at))
    };
    if let Some((way, at)) = first_unchecked(profile, backup, &ways, &run_now) {
        return Err(unchecked_error(way, at, true));
    }
    // hostile28 F5: code no entry lists that the file puts in itself. An
    // upload chains in front of such code where it finds a hook running
    // it, and overwrites none of it; its undo finds it run still.
    let added = ways.iter().find_map(|way| {
        way.code
            .iter()
            .copied()
            .find(|&at| put_in(at) && !run_now(at))
            .map(|at| (way, at))
    });
    match added {
        Some((way, at)) => Err(Error::UndoAddsCode {
            hook: way.hook.rom_symbol(),
            target: at,
            path: crate::held_way::path_text(&way.way),
        }),
        None => Ok(()),
    }
}

/// fresh28 F1: a hook at code no entry lists, while the table lists
/// extensions on that hook, is an owner's handler in front of them (a
/// backup of a robot an owner set up so could not be restored) only where
/// its way goes on into a listed extension's handler on that hook and
/// ends where a command's way may. Anything else is refused as before
/// (hostile22 F10: a copy of an extension in the RAM loader's place whose
/// way led nowhere).
#[must_use]
pub(crate) fn owner_in_front(everyone: &[Installed], ways: &[WayCode]) -> Option<Error> {
    ways.iter().find_map(|way| {
        let on_hook = |at: u16| {
            everyone
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .any(|hook| hook.kind == way.hook && hook.handler == at)
        };
        let any_on_hook = everyone
            .iter()
            .flat_map(|entry| entry.hooks.iter())
            .any(|hook| hook.kind == way.hook);
        let target = *way.way.first()?;
        if !any_on_hook || on_hook(target) || everyone.iter().any(|e| e.contains(target)) {
            return None;
        }
        if way.fine && way.way.iter().any(|&at| on_hook(at)) {
            return None;
        }
        let hook = way.hook.rom_symbol();
        // hostile30 F8: a way that runs an extension's code from its
        // middle says so, not that it never reaches the extension.
        let inside = way.entered.and_then(|at| {
            let entry = everyone.iter().find(|entry| entry.contains(at))?;
            let handler = entry.hooks.iter().find(|h| h.kind == way.hook)?.handler;
            Some(format!(
                "goes into extension {:06X} at ${at:04X}, not at its {hook} handler ${handler:04X}",
                entry.id
            ))
        });
        let how = match inside {
            Some(inside) if way.fine => inside,
            _ if way.fine => "does not go on into them".to_owned(),
            _ => "does not end where a command's way may (a loop, code that stops the CPU, or memory no code may be in)".to_owned(),
        };
        Some(Error::BackupRefused {
            reason: format!(
                "the file points {hook} at ${target:04X}, code no extension its table lists, while its table lists extensions on {hook}, and that code's way ({}) {how}; nothing was written",
                crate::held_way::path_text(&way.way),
            ),
        })
    })
}

/// hostile29 F1: a way that jumps where its data says (a jump table, a
/// pointer set on a rare path, `PHA`/`PHA`/`RTS`) may run code no run on
/// the host saw, so nothing tells which bytes a backup must witness. Where
/// all of the way's code lies in memory the file restores, its targets
/// most likely do too; where part lies outside it (the KIM bus, only
/// witnessed), a restore is refused: a handler `backup` never saw could
/// have changed.
#[must_use]
pub(crate) fn computed_outside(
    profile: &RomProfile,
    backup: &Backup,
    ways: &[WayCode],
) -> Option<Error> {
    ways.iter().find_map(|way| {
        let at = way.computed?;
        let outside = way.code.iter().copied().find(|&byte| {
            profile.writable.iter().any(|range| range.contains(&byte))
                && backup.byte_at(u32::from(byte)).is_none()
        })?;
        Some(Error::ComputedWayOutside {
            hook: way.hook.rom_symbol(),
            path: crate::held_way::path_text(&way.way),
            at,
            outside,
        })
    })
}

/// The refusal of a restore whose `way` runs the code at `at`, which
/// nothing checks.
pub(crate) fn unchecked_error(way: &WayCode, at: u16, undo: bool) -> Error {
    let hook = way.hook.rom_symbol();
    let path = crate::held_way::path_text(&way.way);
    if undo {
        Error::UndoStepUnlisted {
            hook,
            target: at,
            path,
        }
    } else {
        Error::UnwitnessedStep {
            hook,
            target: at,
            path,
        }
    }
}

/// The hooks an undo leaves as they are: each whose way, over the file's
/// bytes laid on the robot's, is the way it takes now, step for step and
/// byte for byte of code, the file writing none of it; and the code of
/// the others and of the extensions the undo lists.
#[derive(Debug)]
pub(crate) struct Unchanged {
    /// The code only hooks the undo leaves run.
    left: BTreeSet<u16>,
    /// The code hooks the undo changes run, and the memory of every
    /// extension it lists.
    changed: BTreeSet<u16>,
}

impl Unchanged {
    /// Follows `backup`'s ways as the undo would leave them and the
    /// robot's as they are.
    ///
    /// # Errors
    /// The line's errors.
    pub(crate) fn read<T: Transport>(
        client: &mut Client<T>,
        profile: &RomProfile,
        backup: &Backup,
    ) -> Result<Unchanged> {
        let seen = crate::held_way::over_robot(client, profile, backup)?;
        let after_listed = crate::backup::backup_table(profile, &seen);
        let after = code_of(
            client,
            profile,
            (&backup.hooks, &after_listed),
            &laid(backup),
        )?;
        let (_, now) = ways_now(client, profile)?;
        let mut left = BTreeSet::new();
        let mut changed: BTreeSet<u16> = after_listed
            .iter()
            .flat_map(|entry| entry.extents.iter().flat_map(Clone::clone))
            .collect();
        for way in &after {
            let same = now.iter().any(|then| {
                then.hook == way.hook && then.way == way.way && then.code == way.code && then.fine
            }) && way
                .code
                .iter()
                .all(|&at| backup.byte_at(u32::from(at)).is_none());
            if same {
                left.extend(way.code.iter().copied());
            } else {
                changed.extend(way.code.iter().copied());
            }
        }
        Ok(Unchanged { left, changed })
    }

    /// Whether `witness` covers code only hooks the undo leaves run: its
    /// change, by hand since, is not the undo's to refuse.
    #[must_use]
    pub(crate) fn only_on_unchanged(&self, witness: &crate::backup::Witness) -> bool {
        let bytes = (0..witness.len).map(|i| witness.address.wrapping_add(i));
        let mut any = false;
        for at in bytes {
            if self.changed.contains(&at) {
                return false;
            }
            any |= self.left.contains(&at);
        }
        any
    }
}
