//! Whether an upload left the robot as it found it: the same image,
//! installed as it was, its hooks where they were (fresh13 F1: a second
//! `scorpion test --port` of an unchanged project kept a new undo file of
//! "installed", and `--undo` no longer went back to the robot as it was
//! before the first). Then what an earlier upload kept still undoes this
//! one, and [`crate::Keep::finished_unchanged`] lets its keeper keep that.
//!
//! Decided on the robot, not guessed: a cheap look at what was kept
//! (every kept byte the image loads must be the image's, no other
//! extension's chain slot re-pointed) and only then the hooks and the kept
//! bytes read back. An
//! upload that wrote anything new never pays for the read.

use crate::backup::Backup;
use crate::client::Client;
use crate::hooks::read_hooks;
use crate::image::{Area, RomProfile, UploadImage};
use crate::transport::Transport;

/// What the loader owns, which an upload through it always changes (its
/// state in the zero page) or finds as it left it (its code): neither is
/// the robot's own memory, so neither counts.
pub(crate) type LoaderOwns<'a> = &'a dyn Fn(u16) -> bool;

/// Whether the robot, after the upload of `image` (its chain slots filled
/// and its table entry added, as written), holds what `kept` says it held
/// before: every kept byte and every hook. `unlinked`: whether the upload
/// re-pointed another extension's chain slot (a change in itself). The
/// loader's bytes are not compared: it may have been written over the
/// robot's memory this time, which `kept` holds as it was, and a keeper
/// that goes back further keeps that too. A line that fails the reads
/// answers "changed": the new undo file is then kept, which is always
/// right.
///
/// `again`: the robot had this very image installed before. Its data
/// (what it loads outside its code: a counter its control loop keeps)
/// was the program's to change, and the upload put it back as built
/// (fresh17 F1: a project with a pass counter was "changed" at every
/// `test --port`, and its undo went back one run only): that is no
/// change to what is installed, and an older undo file puts back what
/// was there before the first upload of the image anyway.
pub(crate) fn left_as_found<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (kept, image): (&Backup, &UploadImage),
    (unlinked, again): (bool, bool),
    loader_owns: LoaderOwns<'_>,
) -> bool {
    if unlinked {
        return false;
    }
    let its_data = |address: u16| {
        again
            && !image.is_code(address)
            && image
                .extents()
                .iter()
                .any(|extent| extent.contains(&address))
    };
    // The robot's own bytes that were kept, in runs, with what they held.
    let mut runs: Vec<(u16, Vec<Option<u8>>)> = Vec::new();
    for area in &kept.areas {
        for (offset, &byte) in area.bytes.iter().enumerate() {
            let address = area.address.wrapping_add(offset as u16);
            if loader_owns(address) || its_data(address) {
                continue;
            }
            if image.byte(address).is_some_and(|loaded| loaded != byte) {
                // The upload wrote something else there.
                return false;
            }
            match runs.last_mut() {
                Some((start, bytes))
                    if u32::from(*start) + bytes.len() as u32 == u32::from(address) =>
                {
                    bytes.push(Some(byte));
                }
                _ => runs.push((address, vec![Some(byte)])),
            }
        }
    }
    holds(client, profile, kept, &runs).unwrap_or(false)
}

/// Whether the robot's hooks are `kept`'s and `runs` hold their bytes.
fn holds<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    kept: &Backup,
    runs: &[(u16, Vec<Option<u8>>)],
) -> crate::Result<bool> {
    let mut hooks = read_hooks(client, profile)?;
    let mut before = kept.hooks.clone();
    hooks.sort_unstable();
    before.sort_unstable();
    if hooks != before {
        return Ok(false);
    }
    for (address, expected) in runs {
        let found = client.read_expecting(*address, expected)?;
        if found
            .iter()
            .zip(expected)
            .any(|(got, want)| Some(*got) != *want)
        {
            return Ok(false);
        }
    }
    Ok(true)
}

/// What `kept` held where the RAM loader's code is now and held other
/// bytes before this upload: what the loader went over this time (not
/// where an earlier upload left it). A keeper going further back
/// ([`crate::Keep::finished_unchanged`]) must not lose it to an older
/// file's bytes there (hostile14 F1: data written by hand where an
/// earlier upload's loader had been).
pub(crate) fn loader_went_over(kept: &Backup, code_byte: &dyn Fn(u16) -> Option<u8>) -> Vec<Area> {
    let mut over: Vec<Area> = Vec::new();
    for area in &kept.areas {
        for (offset, &byte) in area.bytes.iter().enumerate() {
            let address = area.address.wrapping_add(offset as u16);
            if code_byte(address).is_none_or(|code| code == byte) {
                continue;
            }
            crate::delta::push(&mut over, address, &[byte]);
        }
    }
    over
}

/// What `kept` holds of the upload's own memory: without the table and
/// without the memory of the extensions that stay installed beside the
/// image (a chain slot taken past an earlier copy of it and pointed at it
/// again). The upload left both as it found them; a keeper going further
/// back ([`crate::Keep::finished_unchanged`]) must not add them to an older
/// file as this upload found them (recheck17 F2: after the undo of an
/// extension installed in front since, the older file put its chain slot
/// and its table entry back into freed memory).
pub(crate) fn own_memory(
    kept: &Backup,
    profile: &RomProfile,
    others: &[romlib::installed::Installed],
) -> Backup {
    let table = crate::backup::table_range(profile);
    let mut own: Vec<Area> = Vec::new();
    for area in &kept.areas {
        for (offset, &byte) in area.bytes.iter().enumerate() {
            let address = area.address.wrapping_add(offset as u16);
            if crate::backup::within(table, address)
                || others.iter().any(|other| other.contains(address))
            {
                continue;
            }
            crate::delta::push(&mut own, address, &[byte]);
        }
    }
    Backup {
        areas: own,
        ..kept.clone()
    }
}
