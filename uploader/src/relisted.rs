//! An undo that lists again an extension the robot no longer lists
//! (hostile28 F6, F7). A reset (`/1R`) since the upload cleared the
//! table's flags and left the entries and the code in memory, where
//! anyone may have changed them; the undo marked them in use again from
//! what memory still held: a handler's tail past the 16 bytes the file
//! witnesses, changed to run memory the table calls free, or an entry
//! with a made-up id, listed as "verified". Such an extension is listed
//! again only where the file holds or witnesses its entry and every byte
//! of its memory.

use romlib::installed::{ENTRY_LEN, Installed, entry_address};

use crate::backup::Backup;
use crate::client::Client;
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

/// Before an undo writes anything: where the robot lists none of the
/// extensions the file takes out (reset since, or taken out by hand),
/// every extension the file's table (over the robot's, `seen`) lists that
/// the robot does not list now must have its entry and its memory held or
/// witnessed by the file. While the robot still lists what the undo takes
/// out, an extension listed again is one its upload replaced, whose memory
/// nothing has been given since.
///
/// # Errors
/// [`Error::UndoRelistsUnchecked`]; the line's errors.
pub(crate) fn check<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    (backup, seen): (&Backup, &Backup),
) -> Result<()> {
    let Some((table, entries)) = profile.table else {
        return Ok(());
    };
    let after = crate::backup::backup_table(profile, seen);
    let now = crate::table::read_installed(client, profile)?;
    let entry_of = |entry: &Installed| entry_address(table, entries, entry.slot);
    let taken_out_listed = backup
        .written_entries
        .iter()
        .any(|written| now.iter().any(|entry| entry_of(entry) == written.address));
    if taken_out_listed {
        return Ok(());
    }
    let checked = |at: u16| backup.byte_at(u32::from(at)).is_some() || backup.witnessed(at);
    for entry in after.iter().filter(|entry| !now.contains(entry)) {
        let first = entry_of(entry);
        let unchecked_entry = (0..ENTRY_LEN as u16)
            .map(|i| first.wrapping_add(i))
            .find(|&at| !checked(at));
        let unchecked_code = || {
            entry
                .extents
                .iter()
                .flat_map(|extent| extent.clone())
                .find(|&at| !checked(at))
        };
        let what = match (unchecked_entry, unchecked_code()) {
            (Some(at), _) => format!("its table entry (from ${at:04X})"),
            (None, Some(at)) => format!("all of its memory (from ${at:04X})"),
            (None, None) => continue,
        };
        return Err(Error::UndoRelistsUnchecked {
            extension: entry.describe(),
            what,
        });
    }
    Ok(())
}
