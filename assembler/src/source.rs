//! Where source and binary files come from: a trait, so that tests run with
//! no disk and the CLI can add built-in include files.
//!
//! `.include "x"` and `.incbin "x"` look for `x` in this order: as written
//! when it is absolute, next to the file that names it, in each include
//! directory of [`crate::Options`], then among the built-in files of
//! [`crate::Options`] (by exact name). The first that exists wins.

use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};

/// Reads files for the assembler.
pub trait FileSource {
    /// The bytes of the file at `path`.
    ///
    /// # Errors
    /// Any I/O error; [`io::ErrorKind::NotFound`] makes the assembler try the
    /// next place in the search order.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;
}

/// The real filesystem.
#[derive(Debug, Clone, Copy, Default)]
pub struct FsSource;

impl FileSource for FsSource {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        Ok(hostfs::read(path, hostfs::SOURCE)?)
    }
}

/// Files held in memory, for tests and for tools that generate sources.
#[derive(Debug, Clone, Default)]
pub struct MemorySource {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl MemorySource {
    /// An empty set of files.
    #[must_use]
    pub fn new() -> MemorySource {
        MemorySource::default()
    }

    /// Adds (or replaces) a file.
    pub fn insert(&mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> &mut Self {
        self.files.insert(normalize(&path.into()), bytes.into());
        self
    }

    /// Builder form of [`MemorySource::insert`].
    #[must_use]
    pub fn with(mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> Self {
        self.insert(path, bytes);
        self
    }
}

impl FileSource for MemorySource {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files
            .get(&normalize(path))
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "no such file in memory"))
    }
}

/// Drops `.` components so that `./a.inc` and `a.inc` name the same file.
fn normalize(path: &Path) -> PathBuf {
    path.components()
        .filter(|component| !matches!(component, std::path::Component::CurDir))
        .collect()
}

impl<T: FileSource + ?Sized> FileSource for &T {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        (**self).read(path)
    }
}
