//! The stub's code written through the RAM loader's frames, whose sum
//! covers their address, rather than with the ROM's `/9W`, which has
//! none: on a noisy line a `/9W` whose address digits changed writes two
//! bytes elsewhere, and the stub's six hundred bytes took three hundred of
//! them (a run at one byte in a hundred lost and one flipped left the
//! table of installed extensions damaged). The loader an upload of the
//! image left in RAM is verified by a read and used; where there is none,
//! it is written first (a third as many `/9W`s as the stub), as an upload
//! would. `HOOK_UNKNOWN` goes to the loader while the frames go in, and
//! back to where it was after (read back whole).

use isa::objfmt::HookKind;
use romlib::installed::Installed;

use super::error::{StubError, StubResult};
use crate::client::Client;
use crate::hooks::read_hooks;
use crate::image::{Area, RomProfile, UploadImage};
use crate::loader::{FAST_BAUD, Loader, LoaderPlan};
use crate::progress::NoProgress;
use crate::session::Session;
use crate::transport::Transport;
use crate::upload::UploadOptions;

/// Tries at taking the loader out before it is said to stay hooked.
const REMOVE_ATTEMPTS: u32 = 3;

/// Writes `areas` through the RAM loader placed for `image` (as an upload
/// of it places it), verified by the robot's sums: where that loader went
/// (it stays there, unhooked: fresh28 F3, fresh30 F4); `None`, with
/// nothing written, when the image leaves the loader no room, the ROM lacks its
/// services, or it may not go in beside the extensions `installed` (on
/// one of them, or a hook leads to code no entry names, as an upload
/// refuses it): the caller writes with the ROM's commands then.
///
/// # Errors
/// The line's and the loader's errors, once the loader is taken out
/// (`HOOK_UNKNOWN` back where it was); [`StubError::LoaderLeft`] when it
/// could not be (seed 64 of the noisy-line runs: a frame the noise made
/// longer held the loader until the line gave up).
pub(super) fn write_summed<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (image, installed): (&UploadImage, &[Installed]),
    areas: &[Area],
) -> StubResult<Option<LoaderPlan>> {
    let base = client.transport().baud();
    // Placed and linked as an upload's, so a loader one left is found: the
    // line stays at its rate all the same (`None` for the fast one).
    let Some(loader) = Loader::place(profile, image, (base, FAST_BAUD))? else {
        return Ok(None);
    };
    let plan = loader.plan();
    // Reads only: tried again where the line went quiet a while.
    let hooks =
        crate::session::tried_quiet(crate::hooks::QUIET_LOOKS, || read_hooks(client, profile))?;
    let refused = crate::session::tried_quiet(crate::hooks::QUIET_LOOKS, || {
        crate::beside::refusal(client, profile, &hooks, installed, &loader)
    })?;
    if refused.is_some() {
        return Ok(None);
    }
    let Some(&(_, original)) = hooks.iter().find(|(kind, _)| *kind == HookKind::Unknown) else {
        return Ok(None);
    };
    let limits = UploadOptions::default().limits();
    let mut session = Session::new(loader, profile, original, (base, None), limits, true, None);
    let mut progress = NoProgress;
    let written = session
        .install(client, &mut progress, &mut |_, _| Ok(()))
        .and_then(|()| session.transfer_summed(client, areas, &mut progress));
    // The loader must not stay hooked for one look a noisy line lost.
    let taken_out =
        crate::session::tried(REMOVE_ATTEMPTS, || session.remove(client, &mut progress));
    match (written, taken_out) {
        (Ok(_), Ok(())) => Ok(Some(plan)),
        (Err(error), Ok(())) => Err(error.into()),
        (Ok(_), Err(error)) | (Err(error), Err(_)) => Err(StubError::LoaderLeft {
            source: error,
            hook: session.handler(),
        }),
    }
}
