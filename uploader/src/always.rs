//! `--loader always` refused before anything on the robot changes: the
//! hooks as they will be once an overlapping extension is replaced and
//! an earlier copy of the image disarmed, predicted from reads alone, must
//! lead to the ROM or to extensions the table names, whose memory the
//! loader leaves alone (`beside`), and the loader must have a place.
//! Without this, the upload unhooked the old extension first and refused
//! after.

use isa::objfmt::HookKind;
use romlib::installed::Installed;

use crate::client::Client;
use crate::hooks::read_word;
use crate::image::{RomProfile, UploadImage};
use crate::loader::Loader;
use crate::transport::Transport;
use crate::{Error, Result};

/// How many handlers a prediction follows down one chain: chains are a
/// few extensions long, and a damaged one must not loop.
const LONGEST_CHAIN: usize = 16;

/// Refuses, with the reason the upload would give later, an upload
/// through the loader that could not use it; reads only.
///
/// # Errors
/// [`Error::LoaderUnavailable`]; a line error.
pub(crate) fn check<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    image: &UploadImage,
    hooks_now: &[(HookKind, u16)],
    replace: bool,
    leftover: Option<&Loader>,
) -> Result<()> {
    let refuse = |reason: String| Err(Error::LoaderUnavailable { reason });
    if leftover.is_none() {
        return refuse(
            "the image leaves no room for it in user RAM or user zero page, or the ROM lacks GETCH, CHKCH or CMD_DONE; nothing was changed".into(),
        );
    }
    let at_reset = |kind: HookKind, target: u16| profile.reset_target(kind) == Some(target);
    if hooks_now
        .iter()
        .all(|&(kind, target)| at_reset(kind, target))
    {
        return Ok(());
    }
    let installed = crate::table::read_installed(client, profile)?;
    let replaced: Vec<Installed> = if replace {
        installed
            .iter()
            .filter(|old| old.overlap(image.extents()).is_some())
            .cloned()
            .collect()
    } else {
        Vec::new()
    };
    // What stays installed beside the image.
    let others: Vec<Installed> = installed
        .into_iter()
        .filter(|old| old.overlap(image.extents()).is_none())
        .collect();
    let mut predicted = Vec::new();
    for &(kind, first) in hooks_now {
        let mut target = first;
        for _ in 0..LONGEST_CHAIN {
            if at_reset(kind, target) {
                break;
            }
            let is_loader =
                leftover.is_some_and(|loader| loader.left_hooked(kind, target, &others));
            let next = if is_loader {
                profile.reset_target(kind)
            } else if image.contains(target) {
                // An earlier copy: disarmed to where it fell through.
                let slot = image
                    .hooks()
                    .iter()
                    .find(|record| record.kind == kind)
                    .and_then(|record| record.chain);
                match slot {
                    Some(slot) => read_word(client, slot)?
                        .filter(|&to| !image.contains(to))
                        .or(profile.reset_target(kind)),
                    None => profile.reset_target(kind),
                }
            } else if let Some(old) = replaced.iter().find(|old| old.contains(target)) {
                match old.hooks.iter().find(|hook| hook.kind == kind) {
                    Some(hook) => match hook.chain {
                        Some(slot) => read_word(client, slot)?,
                        None => profile.reset_target(kind),
                    },
                    None => break,
                }
            } else if let Some(other) = others.iter().find(|other| other.contains(target)) {
                // An extension that stays, in front of an earlier copy of
                // the image: the chain goes on through it.
                match other
                    .hooks
                    .iter()
                    .find(|hook| hook.kind == kind)
                    .and_then(|hook| hook.chain)
                {
                    Some(slot) => read_word(client, slot)?,
                    None => break,
                }
            } else {
                break;
            };
            match next {
                Some(next) => target = next,
                None => break,
            }
        }
        predicted.push((kind, target));
    }
    match leftover {
        Some(loader) => match crate::beside::refusal(client, profile, &predicted, &others, loader)?
        {
            Some(reason) => refuse(format!("{reason}; nothing was changed")),
            None => Ok(()),
        },
        None => Ok(()),
    }
}
