//! The one reader of every file a user names: sources and their
//! `.include`/`.incbin`, card and world scripts, ROM profiles, transcripts,
//! `.calls` files, layouts and ld65 configurations, `Scorpion.toml`, and the
//! images and objects `link`, `upload` and `disasm` read.
//!
//! A name can point at anything: `/dev/zero` never ends, a FIFO blocks its
//! reader until someone writes, a directory is not text. [`read`] looks at
//! the metadata *before* opening (opening a FIFO blocks), refuses anything
//! but a regular file, refuses a file over the [`Limit`] its kind states,
//! and reads at most that limit even if the file grows meanwhile, so no
//! name makes a tool hang or exhaust memory. Its [`Error`] names the file,
//! what it is and the limit.
//!
//! Files a tool writes go through [`check_writable`] (before the tool
//! does its work: a FIFO would block the write at the end, a device eat
//! it) and [`write`] (a temporary file in the same directory, renamed over
//! the target, so an interrupted write leaves the old file whole).

use std::fs::File;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

mod limit;

pub use limit::{BACKUP, BINARY, Limit, RAW_IMAGE, SOURCE, TEXT};

/// Why a file was not read.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// Nothing is at the path (or a directory on the way is missing).
    #[error("{}: no such file", path.display())]
    #[diagnostic(code(hostfs::not_found))]
    NotFound {
        /// The path as given.
        path: PathBuf,
    },

    /// The path names a directory, a device, a FIFO or a socket.
    #[error("{}: {what}, not a regular file", path.display())]
    #[diagnostic(
        code(hostfs::not_a_file),
        help(
            "name a regular file: a device or a pipe could block or never end, so it is not read"
        )
    )]
    NotAFile {
        /// The path as given.
        path: PathBuf,
        /// What it is instead ("a FIFO (named pipe)", "a character device").
        what: &'static str,
    },

    /// The file is larger than its kind allows.
    #[error("{}: {}", path.display(), too_large_text(*size, *limit, what))]
    #[diagnostic(
        code(hostfs::too_large),
        help("{what} is never this large; check that the path names the file you meant")
    )]
    TooLarge {
        /// The path as given.
        path: PathBuf,
        /// Its size (what its metadata says, or what was read before the
        /// limit was passed).
        size: u64,
        /// The limit in bytes.
        limit: u64,
        /// The kind of file the limit is for ("a text file").
        what: &'static str,
    },

    /// The file is not UTF-8 text where text was asked for.
    #[error("{}: not UTF-8 text (byte {offset} is not)", path.display())]
    #[diagnostic(
        code(hostfs::not_text),
        help("save the file as UTF-8 (ASCII is UTF-8)")
    )]
    NotText {
        /// The path as given.
        path: PathBuf,
        /// The offset of the first byte that is not UTF-8.
        offset: usize,
    },

    /// A path to write names a directory, a device, a FIFO or a socket.
    #[error("{}: {what}, not a regular file; nothing was written to it", path.display())]
    #[diagnostic(
        code(hostfs::not_writable),
        help(
            "give the path of a regular file (it is created or replaced): a pipe would block the write, a device eat it"
        )
    )]
    NotWritable {
        /// The path as given.
        path: PathBuf,
        /// What it is instead.
        what: &'static str,
    },

    /// Writing failed (a missing directory, permissions, a full disk).
    // The cause is in the message and is not the error's `source`: a
    // source would be printed a second time under it.
    #[error("{}: cannot write it: {cause}", path.display())]
    #[diagnostic(code(hostfs::write))]
    Write {
        /// The path as given.
        path: PathBuf,
        /// What the system said.
        cause: io::Error,
    },

    /// The system refused (permissions, an I/O error).
    #[error("{}: cannot read it: {cause}", path.display())]
    #[diagnostic(code(hostfs::io))]
    Io {
        /// The path as given.
        path: PathBuf,
        /// What the system said.
        cause: io::Error,
    },
}

/// The message of [`Error::TooLarge`]: "more than" the limit when the
/// read stopped one byte past it (a file that grew, or one whose metadata
/// says 0, as `/proc`'s do), else the size the metadata gave.
fn too_large_text(size: u64, limit: u64, what: &str) -> String {
    let limit_text = limit::bytes_text(limit);
    if size == limit.saturating_add(1) {
        format!("more than {limit_text}, the limit for {what}")
    } else {
        format!(
            "{}, over the {limit_text} limit for {what}",
            limit::bytes_text(size)
        )
    }
}

impl Error {
    /// The path the error is about.
    #[must_use]
    pub fn path(&self) -> &Path {
        match self {
            Error::NotFound { path }
            | Error::NotAFile { path, .. }
            | Error::TooLarge { path, .. }
            | Error::NotText { path, .. }
            | Error::NotWritable { path, .. }
            | Error::Write { path, .. }
            | Error::Io { path, .. } => path,
        }
    }

    /// Whether nothing is at the path: a search (`.include`'s) goes on to
    /// the next place, where any other error stops it.
    #[must_use]
    pub fn is_not_found(&self) -> bool {
        matches!(self, Error::NotFound { .. })
    }
}

impl From<Error> for io::Error {
    /// For readers behind an `io::Result` (the assembler's `FileSource`):
    /// a missing file stays [`io::ErrorKind::NotFound`], the rest keep the
    /// message that names the file and the limit.
    fn from(error: Error) -> io::Error {
        let kind = match &error {
            Error::NotFound { .. } => io::ErrorKind::NotFound,
            Error::Io { cause, .. } | Error::Write { cause, .. } => cause.kind(),
            Error::NotText { .. } => io::ErrorKind::InvalidData,
            Error::NotAFile { .. } | Error::NotWritable { .. } | Error::TooLarge { .. } => {
                io::ErrorKind::InvalidInput
            }
        };
        io::Error::new(kind, error)
    }
}

/// What a path names, when it is not a regular file.
fn not_a_file(metadata: &std::fs::Metadata) -> Option<&'static str> {
    let kind = metadata.file_type();
    if kind.is_file() {
        return None;
    }
    if kind.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if kind.is_char_device() {
            return Some("a character device");
        }
        if kind.is_block_device() {
            return Some("a block device");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a file")
}

fn io_error(path: &Path, source: io::Error) -> Error {
    if source.kind() == io::ErrorKind::NotFound {
        Error::NotFound {
            path: path.to_path_buf(),
        }
    } else {
        Error::Io {
            path: path.to_path_buf(),
            cause: source,
        }
    }
}

/// Checks that `path` names a regular file within `limit`, without opening
/// it, and returns its size.
///
/// # Errors
/// [`Error::NotFound`], [`Error::NotAFile`], [`Error::TooLarge`],
/// [`Error::Io`].
pub fn check(path: impl AsRef<Path>, limit: Limit) -> Result<u64, Error> {
    let path = path.as_ref();
    // Symbolic links are followed: what matters is what would be opened.
    let metadata = std::fs::metadata(path).map_err(|e| io_error(path, e))?;
    if let Some(what) = not_a_file(&metadata) {
        return Err(Error::NotAFile {
            path: path.to_path_buf(),
            what,
        });
    }
    if metadata.len() > limit.bytes() {
        return Err(too_large(path, metadata.len(), limit));
    }
    Ok(metadata.len())
}

fn too_large(path: &Path, size: u64, limit: Limit) -> Error {
    Error::TooLarge {
        path: path.to_path_buf(),
        size,
        limit: limit.bytes(),
        what: limit.what(),
    }
}

/// The bytes of the regular file at `path`, at most `limit` of them.
///
/// # Errors
/// [`Error::NotFound`], [`Error::NotAFile`] (checked before opening, so a
/// FIFO never blocks), [`Error::TooLarge`] (also when the file grows past
/// the limit while it is read), [`Error::Io`].
pub fn read(path: impl AsRef<Path>, limit: Limit) -> Result<Vec<u8>, Error> {
    let path = path.as_ref();
    let size = check(path, limit)?;
    let file = File::open(path).map_err(|e| io_error(path, e))?;
    // The file may have been swapped or grown since its metadata was read:
    // what is read is bounded whatever it now is.
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    file.take(limit.bytes().saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    let read = bytes.len() as u64;
    if read > limit.bytes() {
        return Err(too_large(path, read, limit));
    }
    Ok(bytes)
}

/// The UTF-8 text of the regular file at `path`, at most `limit` bytes.
///
/// # Errors
/// As [`read`], and [`Error::NotText`] for bytes that are not UTF-8.
pub fn read_text(path: impl AsRef<Path>, limit: Limit) -> Result<String, Error> {
    let path = path.as_ref();
    let bytes = read(path, limit)?;
    String::from_utf8(bytes).map_err(|e| Error::NotText {
        path: path.to_path_buf(),
        offset: e.utf8_error().valid_up_to(),
    })
}

/// Whether `name`, a source file's name as its build gave it to the
/// assembler (relative to `root`, the project's root), is one of the
/// user's own files, which they can open: a regular file there. A
/// built-in include (`scorpion.inc`, served by the toolchain, not on
/// disk) is not, nor is a name that leaves `root` by an absolute path.
/// The debuggers, the profile and the coverage all ask this
/// (with `isa::objfmt::user_place`, which line a user is shown).
#[must_use]
pub fn is_users_source(root: &Path, name: &str) -> bool {
    let path = root.join(name);
    path.starts_with(root) && std::fs::metadata(&path).is_ok_and(|m| m.is_file())
}

/// Checks, without opening it, that `path` can be written as a regular
/// file: nothing is there yet, or a regular file is (it is replaced), in
/// a directory that exists.
///
/// # Errors
/// [`Error::NotWritable`] for a FIFO, a device, a socket or a directory;
/// [`Error::Write`] for a missing directory.
pub fn check_writable(path: impl AsRef<Path>) -> Result<(), Error> {
    let path = path.as_ref();
    match std::fs::metadata(path) {
        Ok(metadata) => match not_a_file(&metadata) {
            Some(what) => Err(Error::NotWritable {
                path: path.to_path_buf(),
                what,
            }),
            None => Ok(()),
        },
        Err(_) => {
            let directory = directory_of(path);
            if directory.is_dir() {
                Ok(())
            } else {
                Err(Error::Write {
                    path: path.to_path_buf(),
                    cause: io::Error::new(
                        io::ErrorKind::NotFound,
                        format!("the directory {} does not exist", directory.display()),
                    ),
                })
            }
        }
    }
}

fn directory_of(path: &Path) -> &Path {
    path.parent()
        .filter(|parent| !parent.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Writes `bytes` to `path` through a temporary file in its directory,
/// renamed over it: the file is whole or as it was. The file keeps the
/// permissions it had; a new one gets what the umask leaves of
/// read-write for all, as a plain create would (not the temporary
/// file's owner-only mode).
///
/// # Errors
/// As [`check_writable`] (asked again: the path may have changed since),
/// and [`Error::Write`].
pub fn write(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(), Error> {
    use std::io::Write as _;
    let path = path.as_ref();
    check_writable(path)?;
    let failed = |cause: io::Error| Error::Write {
        path: path.to_path_buf(),
        cause,
    };
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut file = builder.tempfile_in(directory_of(path)).map_err(failed)?;
    if let Ok(old) = std::fs::metadata(path) {
        file.as_file()
            .set_permissions(old.permissions())
            .map_err(failed)?;
    }
    file.write_all(bytes).map_err(failed)?;
    file.as_file().sync_all().map_err(failed)?;
    file.persist(path).map_err(|error| failed(error.error))?;
    Ok(())
}

#[cfg(test)]
mod tests;
