//! Deciding about snapshots: what a run does with one that differs
//! ([`Mode`]), the three decisions about one pending snapshot (accept,
//! reject, skip), and the pending snapshots of a project for a front end
//! that reviews them on its own (an editor, `cargo insta review` does the
//! same with the same files).

use std::path::{Path, PathBuf};

use miette::{Context, IntoDiagnostic};

use super::snapshot;
use crate::Project;

/// What a run does with a snapshot that differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Fail, leaving the new text pending.
    #[default]
    Fail,
    /// Take it.
    Accept,
    /// Fail, deleting the pending text.
    Reject,
    /// Ask [`Progress::review`](super::Progress::review).
    Review,
}

/// What to do with one new, changed or stale snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// Take the new text (delete a stale snapshot).
    Accept,
    /// Keep the accepted text, delete the pending one.
    Reject,
    /// Leave the new text pending.
    Skip,
}

/// Deletes `path` if it is there.
pub(crate) fn remove(path: &Path) -> miette::Result<()> {
    match std::fs::remove_file(path) {
        Err(error) if error.kind() != std::io::ErrorKind::NotFound => Err(error)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot delete {}", path.display())),
        _ => Ok(()),
    }
}

fn write_file(path: &Path, text: &str) -> miette::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).into_diagnostic()?;
    }
    std::fs::write(path, text)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}

/// Carries out `decision` about the snapshot accepted at `accepted`
/// whose new file text (as [`snapshot::render`] writes it) is `rendered`:
/// accept writes it there and deletes the pending file, reject deletes the
/// pending file, skip writes the new text to the pending file.
///
/// # Errors
/// A file that cannot be written or deleted.
pub fn decide(decision: Decision, accepted: &Path, rendered: &str) -> miette::Result<()> {
    let pending = snapshot::pending_path(accepted);
    match decision {
        Decision::Accept => {
            write_file(accepted, rendered)?;
            remove(&pending)
        }
        Decision::Reject => remove(&pending),
        Decision::Skip => write_file(&pending, rendered),
    }
}

/// A snapshot's new text left for review beside the accepted one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pending {
    /// The accepted snapshot's file (`NAME.snap`), which may not exist yet.
    pub accepted: PathBuf,
    /// The pending file (`NAME.snap.new`).
    pub pending: PathBuf,
}

impl Pending {
    /// The diff from the accepted text to the pending one (`None`: the
    /// same), or the pending text whole if none was accepted.
    ///
    /// # Errors
    /// The pending file cannot be read.
    pub fn diff(&self) -> miette::Result<Option<String>> {
        let new = hostfs::read_text(&self.pending, hostfs::TEXT)
            .wrap_err_with(|| format!("cannot read {}", self.pending.display()))?;
        let new = snapshot::content(&new).unwrap_or(&new).to_owned();
        Ok(match snapshot::compare(&self.accepted, &new) {
            snapshot::Compared::Same => None,
            snapshot::Compared::New => Some(new),
            snapshot::Compared::Changed(diff) => Some(diff),
        })
    }

    /// Takes the pending text: it becomes the accepted snapshot.
    ///
    /// # Errors
    /// The file cannot be moved.
    pub fn accept(&self) -> miette::Result<()> {
        std::fs::rename(&self.pending, &self.accepted)
            .into_diagnostic()
            .wrap_err_with(|| {
                format!(
                    "cannot move {} to {}",
                    self.pending.display(),
                    self.accepted.display()
                )
            })
    }

    /// Deletes the pending text; the accepted snapshot stays as it was.
    ///
    /// # Errors
    /// The file cannot be deleted.
    pub fn reject(&self) -> miette::Result<()> {
        remove(&self.pending)
    }
}

/// The pending snapshots of `project` (`tests/snapshots/*.snap.new`), by
/// name.
pub fn pending(project: &Project) -> Vec<Pending> {
    let dir = project.root.join("tests").join("snapshots");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut found: Vec<Pending> = entries
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "new"))
        .filter_map(|pending| {
            let accepted = snapshot::accepted_path(&pending)?;
            accepted
                .extension()
                .is_some_and(|ext| ext == "snap")
                .then_some(Pending { accepted, pending })
        })
        .collect();
    found.sort_by(|a, b| a.pending.cmp(&b.pending));
    found
}
