//! The images `scorpion upload` put into a robot, as linked, kept beside
//! the undo file (`NAME.images/ID.image`, in the backup file format): the
//! next upload hands them to the uploader (`UploadOptions::previous`),
//! which writes every range where the earlier version the robot's table
//! lists in the image's place differs from the new one, whatever the
//! robot's checksums say (hostile31 F1: an edit that only moves bytes
//! about balances them). A file lost or damaged costs only that: the sums
//! decide alone, as without it.

use std::path::{Path, PathBuf};

use uploader::{Backup, UploadImage};

/// How many images are kept: the newest.
const KEPT: usize = 8;

/// The directory beside the undo file `undo`.
fn directory(undo: &Path) -> PathBuf {
    let mut name = undo.as_os_str().to_owned();
    name.push(".images");
    PathBuf::from(name)
}

/// The images kept beside `undo` that read back whole.
pub(crate) fn read(undo: &Path) -> Vec<UploadImage> {
    let Ok(entries) = std::fs::read_dir(directory(undo)) else {
        return Vec::new();
    };
    entries
        .filter_map(Result::ok)
        .filter(|entry| entry.path().extension().is_some_and(|ext| ext == "image"))
        .filter_map(|entry| {
            let bytes = hostfs::read(entry.path(), hostfs::BACKUP).ok()?;
            let file = Backup::decode(&entry.path().display().to_string(), &bytes).ok()?;
            UploadImage::new(file.areas, Vec::new()).ok()
        })
        .collect()
}

/// Keeps `image` beside `undo`, and the newest [`KEPT`] with it; a
/// failure is said, not fatal (the next upload trusts the sums alone).
pub(crate) fn record(undo: &Path, image: &UploadImage) {
    let dir = directory(undo);
    let file = Backup {
        areas: image.areas().to_vec(),
        ..Backup::default()
    };
    let path = dir.join(format!("{:06X}.image", image.id()));
    let written = std::fs::create_dir_all(&dir)
        .map_err(|error| error.to_string())
        .and_then(|()| hostfs::write(&path, &file.encode()).map_err(|error| error.to_string()));
    if let Err(error) = written {
        crate::cmd::say_err(&format!(
            "warning: the image was not kept in {} ({error}): the next upload of an edit of it trusts the robot's checksums alone\n",
            dir.display()
        ));
        return;
    }
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let mut kept: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|entry| entry.path().extension().is_some_and(|ext| ext == "image"))
        .filter_map(|entry| Some((entry.metadata().ok()?.modified().ok()?, entry.path())))
        .collect();
    kept.sort();
    let extra = kept.len().saturating_sub(KEPT);
    for (_, old) in kept.into_iter().take(extra) {
        let _ = std::fs::remove_file(old);
    }
}
