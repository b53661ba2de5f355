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
/// too few free entries for them all. Reads the table only.
///
/// # Errors
/// [`Error::ImageInTheWay`], [`Error::ProjectTableFull`], and the line's.
pub fn refuse_what_cannot_go_in<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    images: &[(&str, &UploadImage)],
) -> Result<()> {
    let mut holding = crate::table::read_installed(client, profile)?;
    let free = profile
        .table
        .map(|(_, entries)| entries.saturating_sub(holding.iter().map(Installed::entries).sum()));
    let mut needed = 0;
    for &(name, image) in images {
        let extents = image.extents();
        if holding
            .iter()
            .any(|old| old.id == image.id() && old.extents == extents)
        {
            continue;
        }
        if let Some(overlap) = holding.iter().find_map(|old| old.overlap(extents)) {
            return Err(Error::ImageInTheWay {
                image: name.to_owned(),
                source: overlap,
            });
        }
        let entry = Installed::new(image.id(), extents.to_vec(), image.hooks());
        needed += entry.entries();
        // Held once checked: the images after it must not overlap it.
        holding.push(entry);
    }
    match free {
        Some(free) if needed > free => Err(Error::ProjectTableFull { needed, free }),
        _ => Ok(()),
    }
}
