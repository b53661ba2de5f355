//! Whether a set of images (a project's) goes in whole beside what the
//! robot holds, told before any of them is sent: one refused after the
//! ones before it went in leaves the robot half way (hostile22 F7,
//! recheck23 F3, F5; `test --port` as `upload`, recheck24).

use romlib::installed::Installed;

use crate::client::Client;
use crate::image::{RomProfile, UploadImage};
use crate::transport::Transport;
use crate::{Error, Result};

/// Refuses `images` (each with its name, in the order they go in) where
/// one overlaps an extension the robot's table lists (other than an
/// earlier copy of itself) or an image before it, or where the table has
/// too few free entries for them all. With `replace`, what an image
/// overlaps is taken out for it, and its entries count as free (fresh25
/// F1: the count was skipped, and a full table took the first image, then
/// refused the next). Reads the table only.
///
/// # Errors
/// [`Error::ImageInTheWay`], [`Error::ProjectTableFull`], and the line's.
pub fn refuse_what_cannot_go_in<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    images: &[(&str, &UploadImage)],
    replace: bool,
) -> Result<()> {
    let mut listed = crate::table::read_installed(client, profile)?;
    let everyone = listed.clone();
    // The hooks, read once.
    let mut hooks: Option<Vec<(isa::objfmt::HookKind, u16)>> = None;
    let entries = |held: &[Installed]| held.iter().map(Installed::entries).sum::<usize>();
    let in_use = entries(&listed);
    // The images checked so far: the ones after must not overlap them,
    // `replace` or not (a layout of the project's own).
    let mut ours: Vec<Installed> = Vec::new();
    let mut needed = 0;
    for &(name, image) in images {
        let extents = image.extents();
        if listed
            .iter()
            .any(|old| old.id == image.id() && old.extents == extents)
        {
            continue;
        }
        let in_the_way = |held: &[Installed]| held.iter().find_map(|old| old.overlap(extents));
        // recheck25 R1, recheck26 N3: a way into it through code no entry
        // lists is refused by its own upload once the images before it
        // went in (a replacement, or memory the table calls free): refused
        // here, before any is sent.
        let hooks = match &hooks {
            Some(hooks) => hooks,
            None => hooks.insert(crate::hooks::read_hooks(client, profile)?),
        };
        for &(kind, target) in hooks.iter() {
            // recheck27: a hook into this image's place, at code no entry
            // lists, is one the images before it chain to as they go in:
            // it comes back into this one (alone, the upload re-points
            // the hook itself).
            let listed_handler = everyone
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .any(|hook| hook.kind == kind && hook.handler == target);
            let chained_before = ours
                .iter()
                .any(|earlier| earlier.hooks.iter().any(|hook| hook.kind == kind));
            if image.contains(target) && !listed_handler && chained_before {
                return Err(Error::UnlistedWayIn {
                    hook: kind.rom_symbol(),
                    path: format!("${target:04X}"),
                });
            }
            let way = (kind, target);
            if let Some(path) =
                crate::chain::unlisted_way_into(client, profile, &everyone, way, image)?
            {
                return Err(Error::UnlistedWayIn {
                    hook: kind.rom_symbol(),
                    path: path.to_string(),
                });
            }
        }
        if replace && in_the_way(&ours).is_none() {
            listed.retain(|old| old.overlap(extents).is_none());
        }
        if let Some(overlap) = in_the_way(&ours).or_else(|| in_the_way(&listed)) {
            return Err(Error::ImageInTheWay {
                image: name.to_owned(),
                source: overlap,
            });
        }
        let entry = Installed::new(image.id(), extents.to_vec(), image.hooks());
        needed += entry.entries();
        ours.push(entry);
    }
    // What `replace` takes out was in use before: counted free.
    let taken_out = in_use - entries(&listed);
    match profile.table {
        Some((_, capacity)) => {
            // What `replace` takes out was in use before: counted free.
            let free = (capacity + taken_out).saturating_sub(in_use);
            if needed > free {
                return Err(Error::ProjectTableFull { needed, free });
            }
            Ok(())
        }
        None => Ok(()),
    }
}
