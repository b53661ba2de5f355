//! Code a hook leads to that no entry of the table lists (an owner's, put
//! there by hand; an extension whose entry was freed), which runs on every
//! pass of the control loop or at every unknown command. Written over
//! while it ran, it jammed the robot (hostile26 F4). Its extent no look can
//! tell: a margin around what one run on the host touches missed a branch
//! it did not take (hostile28 F1: a command's body; F2: a jump far away
//! every 256th pass, the robot killed). So attaching refuses a robot whose
//! hooks run such code in RAM, before anything is written.

use std::collections::BTreeSet;

use romlib::installed::Installed;

use super::error::{StubError, StubResult};
use crate::client::Client;
use crate::hooks::read_hooks;
use crate::image::{RomProfile, UploadImage};
use crate::transport::Transport;

/// Refuses attaching where a hook's way runs code in RAM that neither
/// `installed` nor `image` holds, nor `stub` (where this image's stub
/// goes: a hook into the middle of a stub a session left there is that
/// stub, which attaching recognises, hostile10 F11), naming the hook and
/// the first address.
///
/// # Errors
/// [`StubError::Refused`]; the line's errors.
pub(super) fn refuse<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    installed: &[Installed],
    image: &UploadImage,
    stub: &dyn Fn(u16) -> bool,
) -> StubResult<()> {
    // Only reads: tried again where the line went quiet (fresh15 F5's
    // quiet line, which every other look of an attach survives).
    let found = crate::session::tried_quiet(crate::hooks::QUIET_LOOKS, || {
        for (kind, target) in read_hooks(client, profile)? {
            if profile.reset_target(kind) == Some(target) {
                continue;
            }
            let mut touched: BTreeSet<u16> =
                crate::chain::unlisted_touched(client, profile, installed, (kind, target))?;
            touched.retain(|&at| !image.contains(at) && !stub(at));
            if let Some(&first) = touched.first() {
                return Ok(Some((kind, target, first)));
            }
        }
        Ok(None)
    })?;
    match found {
        None => Ok(()),
        Some((kind, target, first)) => Err(StubError::Refused {
            what: "attaching".into(),
            reason: format!(
                "{} (${target:04X}) runs code at ${first:04X} that no entry of the table of installed extensions lists: how far it reaches no look can tell, and the stub could be written over it while it runs; upload that code as an extension (`scorpion upload`), or put the hook back at the ROM's target (`/1R` resets both hooks), and attach again",
                kind.rom_symbol()
            ),
        }),
    }
}
