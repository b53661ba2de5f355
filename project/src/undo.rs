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
/// The finished undo file an upload found, kept on disk until the upload
/// has finished (hostile14 F2: an upload that changed nothing, killed
/// before it knew, had written its own over it): after an undo of an
/// upload that did not finish, it is the undo file again.
pub const BEFORE: &str = ".before";

/// How many earlier uploads' undo files are kept beside the last one's
/// (`X.undo.1` the upload before it, `X.undo.2` the one before that...):
/// each `--undo` goes back one upload (fresh19 F1: an upload replaced the
/// undo file of the one before it, and only the last could be undone).
pub const EARLIER: usize = 16;

/// The undo file of the `n`th upload before the one `path` undoes.
#[must_use]
pub fn earlier(path: &Path, n: usize) -> PathBuf {
    marked(path, &format!(".{n}"))
}

/// Which undo file [`further_back`] made the undo file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FurtherBack {
    /// The one an upload that did not finish found ([`BEFORE`]).
    Unfinished,
    /// The earlier upload's ([`earlier`]), with this many more kept.
    Earlier(usize),
}

/// After a successful undo of the file at `path` (marked used): an undo
/// file that goes further back ([`BEFORE`], left by an upload that did
/// not finish, or else the earlier upload's) becomes the undo file.
/// Returns which, if there was one.
pub fn further_back(path: &Path) -> Option<FurtherBack> {
    if path.exists() {
        return None;
    }
    let before = marked(path, BEFORE);
    if before.is_file() && std::fs::rename(&before, path).is_ok() {
        return Some(FurtherBack::Unfinished);
    }
    // A gap (a file taken away by hand, one that could not be written)
    // is stepped over (hostile20 F3).
    let mut kept = (1..=EARLIER + 1)
        .map(|n| earlier(path, n))
        .filter(|file| file.is_file());
    let first = kept.next()?;
    std::fs::rename(first, path).ok()?;
    let mut more = 0;
    for file in kept {
        if std::fs::rename(&file, earlier(path, more + 1)).is_ok() {
            more += 1;
        }
    }
    Some(FurtherBack::Earlier(more))
}

/// Keeps `older`, the undo file of the upload before the one whose file
/// replaces it, as [`earlier`]`(path, 1)`, each one kept there moved one
/// further back (the oldest beyond [`EARLIER`] dropped).
fn keep_earlier(path: &Path, older: &[u8]) -> Result<(), hostfs::Error> {
    let _ = std::fs::remove_file(earlier(path, EARLIER));
    for n in (1..EARLIER).rev() {
        if earlier(path, n).is_file() {
            let _ = std::fs::rename(earlier(path, n), earlier(path, n + 1));
        }
    }
    hostfs::write(earlier(path, 1), older)
}

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
    /// Why the undo file of the upload before could not be kept one back
    /// ([`earlier`]), if it could not: it is lost (hostile20 F2).
    pub history_failed: Option<hostfs::Error>,
    /// Whether it was written (said if the upload is interrupted).
    pub kept: Arc<AtomicBool>,
    /// The finished undo file the upload found there, read before its
    /// first keep (`None` until then): put back if the upload changes
    /// nothing, since it goes further back than this upload's.
    older: Option<Option<Vec<u8>>>,
    /// Whether the last upload changed nothing and the undo file it found
    /// was kept (see [`uploader::Keep::finished_unchanged`]).
    pub kept_older: bool,
    /// Why the undo file an upload that changed nothing found could not
    /// be kept (damaged: it is replaced by this upload's).
    pub older_damaged: Option<String>,
    /// Whether an upload through this keeper finished already (a project's
    /// images, one after the other): the file found by the next is that
    /// one's, which the next one's goes further back from, changed or not.
    wrote: bool,
    /// The finished undo file found before this keeper's first upload:
    /// it goes one back ([`earlier`]) once the run changes the robot.
    found: Option<Vec<u8>>,
    /// What this keeper's uploads kept, the first one's going further back
    /// with each later one's: the undo of this run alone.
    run: Option<uploader::Backup>,
    /// Whether the file holds [`UndoFile::found`] going further back with
    /// this run (every upload of it so far changed nothing): once one
    /// changes the robot, the file becomes [`UndoFile::run`] (recheck20 F1:
    /// a run whose first image was unchanged undid the upload before it
    /// too).
    merged: bool,
}

impl UndoFile {
    /// An undo file to be written at `path`.
    #[must_use]
    pub fn new(path: PathBuf) -> UndoFile {
        UndoFile {
            path,
            failed: None,
            history_failed: None,
            kept: Arc::default(),
            older: None,
            kept_older: false,
            older_damaged: None,
            wrote: false,
            found: None,
            run: None,
            merged: false,
        }
    }

    /// Whether it was written.
    #[must_use]
    pub fn written(&self) -> bool {
        self.kept.load(Ordering::Relaxed)
    }

    /// This run's undo with `kept`, the last upload's, going further back
    /// (kept for the next).
    fn run_with(&mut self, kept: &uploader::Backup) -> uploader::Backup {
        let run = match self.run.take() {
            Some(run) => run.going_further_back(kept),
            None => kept.clone(),
        };
        self.run = Some(run.clone());
        run
    }

    /// Whether the upload under way kept what it overwrote and has not
    /// finished (the file is marked [`UPLOADING`]): only then is its undo
    /// the way back from it. A refusal before anything was kept, after an
    /// earlier image of the same run, leaves no such mark (fresh21 F4: the
    /// advice then undid an upload from before the run).
    #[must_use]
    pub fn uploading(&self) -> bool {
        self.written() && marked(&self.path, UPLOADING).exists()
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
            let older = std::fs::read(&self.path).ok().filter(|_| finished);
            // On disk too, until this upload has finished: killed before
            // it knew whether it changed anything, its own file would be
            // the only one left.
            let _ = std::fs::remove_file(marked(&self.path, BEFORE));
            if let Some(older) = &older
                && let Err(error) = hostfs::write(marked(&self.path, BEFORE), older)
            {
                self.failed = Some(error);
            }
            if !self.wrote {
                self.found.clone_from(&older);
            }
            self.older = Some(older);
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

    fn failed(&self) -> Option<String> {
        self.failed.as_ref().map(ToString::to_string)
    }

    fn finished(&mut self, kept: &uploader::Backup) {
        // hostile14 F6: the second image of a run wrote its own file over
        // the first's, and the undo left the first installed. An upload
        // after another through this keeper keeps both.
        let run = self.run_with(kept);
        if !self.wrote || self.merged {
            // The run changes the robot: the file found before it goes
            // one back.
            if let Some(found) = &self.found
                && let Err(error) = keep_earlier(&self.path, found)
            {
                self.history_failed = Some(error);
            }
        }
        self.keep(&run);
        self.merged = false;
        self.wrote = true;
        self.older = None;
        self.kept_older = false;
        let _ = std::fs::remove_file(marked(&self.path, BEFORE));
    }

    /// fresh13 F1: an upload that changed nothing (`test --port` again,
    /// the same image uploaded again) keeps the undo file it found, so
    /// that `--undo` still goes back to the robot as it was before the
    /// upload that put the image there, not to "installed".
    /// What the RAM loader went over this time, which the older file may
    /// not hold, is added to it.
    fn finished_unchanged(
        &mut self,
        kept: &uploader::Backup,
        own: &uploader::Backup,
        loader_went_over: &[uploader::Area],
    ) {
        let run = self.run_with(kept);
        if self.wrote && !self.merged {
            // An earlier upload of the run changed the robot: the file is
            // the run's.
            self.keep(&run);
            self.older = None;
            let _ = std::fs::remove_file(marked(&self.path, BEFORE));
            return;
        }
        let name = self.path.display().to_string();
        // hostile14 F1: where this upload's loader went over bytes the
        // older file holds (put there since that upload), the older file
        // would lose them: this upload's file is kept, as for a change.
        let found = self.older.take().flatten();
        let older = found
            .as_ref()
            .and_then(|older| match uploader::Backup::decode(&name, older) {
                Ok(older) => Some(older),
                Err(error) => {
                    // hostile14 F5: said, not replaced without a word.
                    self.older_damaged = Some(error.to_string());
                    None
                }
            })
            .filter(|older| {
                let over = loader_went_over.iter().any(|area| {
                    (0..area.bytes.len())
                        .any(|i| older.byte_at(u32::from(area.address) + i as u32).is_some())
                });
                // Kept as a change's would be: one back.
                if over
                    && let Some(found) = &self.found
                    && let Err(error) = keep_earlier(&self.path, found)
                {
                    self.history_failed = Some(error);
                }
                !over
            });
        match older {
            Some(older) => {
                let both = older.going_further_back(own);
                match hostfs::write(&self.path, &both.encode()) {
                    // fresh19 F8: a run's later image found the file its
                    // first image wrote: no older upload's unless the
                    // first kept one.
                    Ok(()) => {
                        self.kept_older = !self.wrote || self.kept_older;
                        self.merged = true;
                    }
                    Err(error) => self.failed = Some(error),
                }
            }
            None => {
                self.merged = false;
                self.keep(&run);
            }
        }
        self.wrote = true;
        self.older = None;
        let _ = std::fs::remove_file(marked(&self.path, BEFORE));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use uploader::{Area, Backup, Keep};

    fn backup(byte: u8) -> Backup {
        Backup {
            areas: vec![Area {
                address: 0x0400,
                bytes: vec![byte; 4],
            }],
            ..Backup::default()
        }
    }

    fn held(path: &Path) -> Backup {
        Backup::decode("undo", &std::fs::read(path).expect("the undo file")).expect("decodes")
    }

    /// hostile14 F2: an upload killed before it knew it changed nothing
    /// had written its own undo file over the one it found, the only
    /// record of the robot before the upload that put the image there.
    /// That one waits beside it, and after the undo of the killed upload
    /// it is the undo file again.
    #[test]
    fn the_undo_file_an_unfinished_upload_found_is_the_next_undo() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        hostfs::write(&path, &backup(1).encode()).expect("the older file");
        let mut undo = UndoFile::new(path.clone());
        undo.keep(&backup(2));
        assert_eq!(
            held(&path),
            backup(2),
            "this upload's, written before any change"
        );
        assert_eq!(
            held(&marked(&path, BEFORE)),
            backup(1),
            "the one found, beside it"
        );
        // Killed here. The undo of this upload marks its file used.
        drop(undo);
        std::fs::rename(&path, marked(&path, UNDONE)).expect("marked used");
        assert_eq!(further_back(&path), Some(FurtherBack::Unfinished));
        assert_eq!(
            held(&path),
            backup(1),
            "the older file is the undo file again"
        );
        assert!(!marked(&path, BEFORE).exists());
        assert_eq!(further_back(&path), None, "there is one now");
    }

    /// hostile14 F6: a project's second image wrote its upload's undo file
    /// over the first's; the undo left the first installed. Through one
    /// keeper, the second's goes further back from the first's.
    #[test]
    fn the_images_of_one_run_keep_one_undo_of_them_all() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        hostfs::write(&path, &backup(7).encode()).expect("an older run's file");
        let second = Backup {
            areas: vec![
                Area {
                    address: 0x0400,
                    bytes: vec![2; 4],
                },
                Area {
                    address: 0x0500,
                    bytes: vec![3; 2],
                },
            ],
            ..Backup::default()
        };
        let mut undo = UndoFile::new(path.clone());
        undo.keep(&backup(1));
        undo.finished(&backup(1));
        undo.finished_upload();
        assert_eq!(
            held(&path),
            backup(1),
            "a change: the older run's file replaced"
        );
        assert_eq!(held(&earlier(&path, 1)), backup(7), "and kept one back");
        undo.keep(&second);
        undo.finished(&second);
        undo.finished_upload();
        assert_eq!(
            held(&path),
            backup(1).going_further_back(&second),
            "the first image's bytes as it found them, the second's beside"
        );
    }

    /// hostile14 F5: a damaged undo file found by an upload that changed
    /// nothing was replaced without a word; it is said.
    #[test]
    fn a_damaged_undo_file_found_is_said_when_replaced() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        let mut damaged = backup(1).encode();
        damaged.truncate(damaged.len() / 2);
        hostfs::write(&path, &damaged).expect("the older file");
        let mut undo = UndoFile::new(path.clone());
        undo.keep(&backup(2));
        undo.finished_unchanged(&backup(2), &backup(2), &[]);
        assert_eq!(held(&path), backup(2));
        assert!(!undo.kept_older);
        assert!(undo.older_damaged.is_some());
    }

    /// A finished upload leaves nothing beside its file: a change keeps
    /// its own, no change the older one with what the loader went over
    /// (where the older holds nothing), and the older one's own bytes
    /// where the loader went over bytes it holds is a change after all.
    #[test]
    fn a_finished_upload_leaves_one_undo_file() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        for (unchanged, over, kept) in [
            (false, 0x0000, backup(2)),
            (true, 0x0800, backup(1)),
            (true, 0x0401, backup(2)),
        ] {
            hostfs::write(&path, &backup(1).encode()).expect("the older file");
            let mut undo = UndoFile::new(path.clone());
            undo.keep(&backup(2));
            let over = [Area {
                address: over,
                bytes: vec![9],
            }];
            if unchanged {
                undo.finished_unchanged(&backup(2), &backup(2), &over);
            } else {
                undo.finished(&backup(2));
            }
            assert_eq!(
                held(&path),
                kept,
                "unchanged {unchanged}, loader over {:04X}",
                over[0].address
            );
            assert_eq!(undo.kept_older, kept == backup(1));
            assert!(!marked(&path, BEFORE).exists());
            undo.finished_upload();
        }
    }

    /// fresh19 F1: each upload that changes the robot keeps the file it
    /// found one back, and each undo brings the one before back, to
    /// [`EARLIER`] of them.
    #[test]
    fn each_upload_keeps_the_last_ones_file_one_back() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        for n in 1..=EARLIER as u8 + 3 {
            let mut undo = UndoFile::new(path.clone());
            undo.keep(&backup(n));
            undo.finished(&backup(n));
            undo.finished_upload();
        }
        let last = EARLIER as u8 + 3;
        assert_eq!(held(&path), backup(last));
        assert!(!earlier(&path, EARLIER + 1).exists(), "the oldest dropped");
        for n in (3..=last).rev() {
            assert_eq!(held(&path), backup(n));
            std::fs::rename(&path, marked(&path, UNDONE)).expect("undone");
            let back = further_back(&path);
            if n > 3 {
                let more = usize::from(n) - 4;
                assert_eq!(back, Some(FurtherBack::Earlier(more)), "{n}");
            } else {
                assert_eq!(back, None, "no more");
            }
        }
    }

    /// fresh19 F8: a run of two images that changed nothing, with no undo
    /// file before it: the second found the first's and said the file
    /// "still puts back what it held before the upload that put it there".
    #[test]
    fn a_run_with_no_older_file_does_not_say_it_kept_one() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        let mut undo = UndoFile::new(path.clone());
        for n in [1, 2] {
            undo.keep(&backup(n));
            undo.finished_unchanged(&backup(n), &backup(n), &[]);
            undo.finished_upload();
            assert!(!undo.kept_older, "image {n}");
        }
    }

    /// recheck20 F1: a run whose first image changed nothing (merged with
    /// the file found, the last upload's) and whose second changed the
    /// robot kept one file for both, and its undo undid the last upload
    /// too. The run's file is the run's alone; the one found goes one back.
    #[test]
    fn a_run_that_changes_after_an_unchanged_image_keeps_the_last_uploads_file_one_back() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        hostfs::write(&path, &backup(7).encode()).expect("the last upload's file");
        let second = Backup {
            areas: vec![Area {
                address: 0x0600,
                bytes: vec![3; 2],
            }],
            ..Backup::default()
        };
        let mut undo = UndoFile::new(path.clone());
        undo.keep(&backup(1));
        undo.finished_unchanged(&backup(1), &backup(1), &[]);
        undo.finished_upload();
        assert!(undo.kept_older);
        undo.keep(&second);
        undo.finished(&second);
        undo.finished_upload();
        assert!(!undo.kept_older);
        assert_eq!(
            held(&path),
            backup(1).going_further_back(&second),
            "the run's"
        );
        assert_eq!(
            held(&earlier(&path, 1)),
            backup(7),
            "the last upload's, one back"
        );
    }

    /// hostile20 F3: a gap in the history (NAME.1 taken away, a directory
    /// there) stopped the undo with "none is left" while older files lay
    /// there: the next one is taken.
    #[test]
    fn a_gap_in_the_history_is_stepped_over() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("last.undo");
        hostfs::write(earlier(&path, 2), &backup(2).encode()).expect("written");
        hostfs::write(earlier(&path, 4), &backup(4).encode()).expect("written");
        std::fs::create_dir(earlier(&path, 3)).expect("a directory in the way");
        assert_eq!(further_back(&path), Some(FurtherBack::Earlier(1)));
        assert_eq!(held(&path), backup(2));
        assert_eq!(held(&earlier(&path, 1)), backup(4));
    }
}
