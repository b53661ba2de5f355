//! The undo file every upload to a robot keeps (`scorpion upload`, and
//! `scorpion test --port`'s uploads): what the upload overwrote, written
//! as soon as it is read, marked while the upload or an undo of it has
//! not finished, so that no later upload replaces the only record of
//! what the robot held.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Marks a used undo file (`X.undo.undone`), kept rather than deleted.
pub const UNDONE: &str = ".undone";
/// Marks an undo file whose undo started and has not finished.
pub const UNDOING: &str = ".undoing";
/// Marks an undo file whose upload wrote it and has not finished.
pub const UPLOADING: &str = ".uploading";

/// The undo file at `path` marked with `mark` (one of [`UNDONE`],
/// [`UNDOING`], [`UPLOADING`]).
#[must_use]
pub fn marked(path: &Path, mark: &str) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(mark);
    PathBuf::from(name)
}

/// A project's undo file: `target/scorpion/last-upload.undo`.
#[must_use]
pub fn in_project(root: &Path) -> PathBuf {
    root.join("target")
        .join("scorpion")
        .join("last-upload.undo")
}

/// What has not finished with an undo file, so that no upload may replace
/// it: it keeps what the robot held, which nothing else does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unfinished {
    /// An undo of it started and did not finish: the robot is half way
    /// back.
    Undo,
    /// The upload that wrote it did not finish.
    Upload,
}

impl Unfinished {
    /// What it is, for a sentence about the undo file at `path`.
    #[must_use]
    pub fn said(self, path: &Path) -> String {
        match self {
            Unfinished::Undo => format!(
                "an undo of {} started and did not finish (killed, or its line failed): the robot is half way back",
                path.display()
            ),
            Unfinished::Upload => format!(
                "the last upload did not finish (killed, or its line failed): {} keeps what the robot held before it",
                path.display()
            ),
        }
    }
}

/// Whether an upload may not replace the undo file at `path` now, and
/// why. A mark whose file went since is dropped: nothing is kept.
#[must_use]
pub fn unfinished(path: &Path) -> Option<Unfinished> {
    if !path.is_file() {
        let _ = std::fs::remove_file(marked(path, UPLOADING));
        return None;
    }
    if marked(path, UNDOING).exists() {
        return Some(Unfinished::Undo);
    }
    marked(path, UPLOADING)
        .exists()
        .then_some(Unfinished::Upload)
}

/// Writes what an upload overwrote to the undo file as soon as it is
/// read, before the image's bytes go out; marks it [`UPLOADING`] until
/// [`UndoFile::finished_upload`].
#[derive(Debug)]
pub struct UndoFile {
    /// Where it is written.
    pub path: PathBuf,
    /// Why it could not be written, if it could not.
    pub failed: Option<hostfs::Error>,
    /// Whether it was written (said if the upload is interrupted).
    pub kept: Arc<AtomicBool>,
    /// The finished undo file the upload found there, read before its
    /// first keep (`None` until then): put back if the upload changes
    /// nothing, since it goes further back than this upload's.
    older: Option<Option<Vec<u8>>>,
    /// Whether the last upload changed nothing and the undo file it found
    /// was kept (see [`uploader::Keep::finished_unchanged`]).
    pub kept_older: bool,
}

impl UndoFile {
    /// An undo file to be written at `path`.
    #[must_use]
    pub fn new(path: PathBuf) -> UndoFile {
        UndoFile {
            path,
            failed: None,
            kept: Arc::default(),
            older: None,
            kept_older: false,
        }
    }

    /// Whether it was written.
    #[must_use]
    pub fn written(&self) -> bool {
        self.kept.load(Ordering::Relaxed)
    }

    /// The upload finished: the next one may replace the file.
    pub fn finished_upload(&self) {
        let _ = std::fs::remove_file(marked(&self.path, UPLOADING));
    }
}

impl uploader::Keep for UndoFile {
    fn keep(&mut self, overwritten: &uploader::Backup) {
        if self.older.is_none() {
            // A file an upload or an undo did not finish is no undo to go
            // back to (and the upload was refused before it started).
            let finished = unfinished(&self.path).is_none();
            self.older = Some(std::fs::read(&self.path).ok().filter(|_| finished));
        }
        // Marked first: an upload killed from here on has not finished,
        // and the next one must not replace what the file keeps.
        if let Err(error) = hostfs::write(marked(&self.path, UPLOADING), b"") {
            self.failed = Some(error);
            return;
        }
        // Through a temporary file: an undo file is whole or the last one.
        if let Err(error) = hostfs::write(&self.path, &overwritten.encode()) {
            self.failed = Some(error);
            return;
        }
        self.kept.store(true, Ordering::Relaxed);
    }

    fn finished(&mut self, kept: &uploader::Backup) {
        self.keep(kept);
        self.older = None;
        self.kept_older = false;
    }

    /// fresh13 F1: an upload that changed nothing (`test --port` again,
    /// the same image uploaded again) keeps the undo file it found, so
    /// that `--undo` still goes back to the robot as it was before the
    /// upload that put the image there, not to "installed".
    /// What the RAM loader went over this time, which the older file may
    /// not hold, is added to it.
    fn finished_unchanged(&mut self, kept: &uploader::Backup) {
        let name = self.path.display().to_string();
        let older = self
            .older
            .take()
            .flatten()
            .and_then(|older| uploader::Backup::decode(&name, &older).ok());
        match older {
            Some(older) => {
                let both = older.going_further_back(kept);
                match hostfs::write(&self.path, &both.encode()) {
                    Ok(()) => self.kept_older = true,
                    Err(error) => self.failed = Some(error),
                }
            }
            None => self.keep(kept),
        }
        self.older = None;
    }
}
