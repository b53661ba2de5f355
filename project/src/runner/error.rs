//! The runner's one error type: what stops a build or a test run, with the
//! place it happened (the file, the image, the card, the snapshot) kept as
//! fields a caller can act on, and the lower crates' diagnostics (their
//! codes, spans, snippets and help) passed through so they render as they
//! would alone.
//!
//! Two kinds of variants: a lower crate's error said as it is
//! (transparent), and a lower error said with what the runner was doing
//! (`cannot read tests/probe.expect`): the runner's message first, then
//! the lower error as its cause, with the lower error's code, help and
//! snippets, as `miette`'s `wrap_err` shows them (the CLI's output did not
//! change when the runner stopped returning `miette::Report`s; for the
//! same reason the messages that had no code before have none now).

use std::fmt;
use std::path::PathBuf;

use miette::{Diagnostic, LabeledSpan, Severity, SourceCode};

use super::memory::OutsideMemory;

/// A result of the runner.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that stops a build of a project's image or a run of its
/// tests. A test that fails is in the run's report, not an error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The project or its configuration (a member of a workspace, a
    /// setting, a port, the ROM profile named in `Scorpion.toml`).
    #[error(transparent)]
    Project(#[from] crate::Error),

    /// An image's source does not assemble (a file missing, a mistake at
    /// its `file:line:col`).
    #[error(transparent)]
    Assemble(#[from] assembler::Error),

    /// An image does not link, or its layout or the ROM profile's image
    /// is not what it must be.
    #[error(transparent)]
    Link(#[from] linker::Error),

    /// The virtual Scorpion refused something (a ROM profile, an image).
    #[error(transparent)]
    Robot(#[from] romlib::Error),

    /// The line to the robot or the upload failed.
    #[error(transparent)]
    Upload(#[from] uploader::Error),

    /// A card's or the world's script does not load.
    #[error(transparent)]
    Script(#[from] cards::ScriptError),

    /// A project's layout puts an area outside the memory an upload may
    /// write.
    #[error(transparent)]
    LayoutOutsideRam(Box<OutsideMemory>),

    /// A layout file (`target = "FILE.toml"` or `"FILE.cfg"`) of an image
    /// cannot be read.
    #[error(transparent)]
    LayoutUnreadable(Box<LayoutUnreadable>),

    /// A line of a transcript that is not a command or `COMMAND => ANSWER`.
    #[error(transparent)]
    BadTranscript(Box<BadTranscript>),

    /// The line's rate is not one the Scorpion's 6551 has.
    #[error(transparent)]
    Baud(Box<Baud>),

    /// `--port` given to a workspace.
    #[error(transparent)]
    WorkspacePort(Box<WorkspacePort>),

    /// `--path` given where a project whose transcripts run has no room
    /// (no world file) to draw its robot in.
    #[error(transparent)]
    PathWithoutRoom(Box<PathWithoutRoom>),

    /// A directory of the project that cannot be made.
    #[error("cannot create {}: {error}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },

    /// A file of the project's `target/scorpion/` (the image, its listing
    /// or map) that cannot be written.
    #[error("cannot write {}: {error}", path.display())]
    WriteTarget {
        /// The file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },

    /// A snapshot that cannot be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },

    /// A snapshot that cannot be deleted.
    #[error("cannot delete {}", path.display())]
    Delete {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },

    /// A pending snapshot that cannot be moved over the accepted one.
    #[error("cannot move {} to {}", from.display(), to.display())]
    Move {
        /// The pending snapshot.
        from: PathBuf,
        /// The accepted one.
        to: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },

    /// A file the runner reads (a transcript, a `.calls` file, a pending
    /// snapshot) that cannot be read: missing, not a regular file, too
    /// large.
    #[error("cannot read {shown}")]
    Read {
        /// The file as shown to the user (relative to the project).
        shown: String,
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: hostfs::Error,
    },

    /// A card's script, a world script or a world file that cannot be
    /// read.
    #[error("cannot read the {what} {}", path.display())]
    ScriptUnreadable {
        /// What it is: "script", "world script", "world file".
        what: &'static str,
        /// The script, as given.
        path: PathBuf,
        /// Why.
        #[source]
        source: hostfs::Error,
    },

    /// The ROM profile the configuration names cannot be read.
    #[error("cannot read the ROM profile {} ({origin})", path.display())]
    RomUnreadable {
        /// The profile's file.
        path: PathBuf,
        /// Where the setting came from.
        origin: String,
        /// Why.
        #[source]
        source: hostfs::Error,
    },

    /// A transcript the uploader cannot take.
    #[error("in {shown}")]
    Transcript {
        /// The transcript as shown to the user.
        shown: String,
        /// Why.
        #[source]
        source: Box<uploader::Error>,
    },

    /// A card that does not fit the KIM bus where its script puts it.
    #[error("cannot put the card {card} at ${start:04X}-${end:04X}")]
    CardPlacement {
        /// The card's script, as given.
        card: String,
        /// The first address of its window.
        start: u16,
        /// The last.
        end: u16,
        /// Why.
        #[source]
        source: romlib::Error,
    },

    /// An image the virtual Scorpion cannot load.
    #[error("cannot load {image}")]
    Load {
        /// The image's name in the project.
        image: String,
        /// Why.
        #[source]
        source: romlib::Error,
    },

    /// The port a file or the environment named could not be opened
    /// (fresh19 F7: a stale one is otherwise a mystery).
    #[error("the port {port} is from the {origin}")]
    PortOpen {
        /// The port.
        port: String,
        /// Where it came from.
        origin: crate::resolve::Origin,
        /// Why it did not open.
        #[source]
        source: Box<uploader::Error>,
    },

    /// A `--port` value that is no device's name did not open: a bare
    /// `--port` took the word after it (`test --port robo`, a filter).
    #[error("--port took `{port}` as the robot's serial port; {hint}", hint = crate::BARE_PORT)]
    PortTaken {
        /// The value.
        port: String,
        /// Why it did not open.
        #[source]
        source: Box<uploader::Error>,
    },

    /// An image the robot did not take.
    #[error("cannot upload {image}")]
    UploadImage {
        /// The image's name in the project.
        image: String,
        /// Why.
        #[source]
        source: Box<uploader::Error>,
    },

    /// What the front end's [`Progress::review`](super::Progress::review)
    /// said stops the run (an answer that could not be read).
    #[error(transparent)]
    Review(FrontEnd),
}

impl From<Box<OutsideMemory>> for Error {
    fn from(outside: Box<OutsideMemory>) -> Error {
        Error::LayoutOutsideRam(outside)
    }
}

impl Error {
    /// What this error shows besides its message: the lower error's
    /// diagnostic (the whole of it for a transparent variant, all but its
    /// message for one said with the runner's message), if any.
    fn lower(&self) -> Option<&dyn Diagnostic> {
        Some(match self {
            Error::Project(e) => e,
            Error::Assemble(e) => e,
            Error::Link(e) => e,
            Error::Robot(e) => e,
            Error::Upload(e) => e,
            Error::Script(e) => e,
            Error::LayoutOutsideRam(e) => &**e,
            Error::LayoutUnreadable(e) => &**e,
            Error::BadTranscript(e) => &**e,
            Error::Baud(e) => &**e,
            Error::WorkspacePort(e) => &**e,
            Error::PathWithoutRoom(e) => &**e,
            Error::Review(e) => e,
            Error::Read { source, .. }
            | Error::ScriptUnreadable { source, .. }
            | Error::RomUnreadable { source, .. } => source,
            Error::Transcript { source, .. }
            | Error::UploadImage { source, .. }
            | Error::PortOpen { source, .. }
            | Error::PortTaken { source, .. } => &**source,
            Error::CardPlacement { source, .. } | Error::Load { source, .. } => source,
            Error::CreateDir { .. }
            | Error::WriteTarget { .. }
            | Error::Write { .. }
            | Error::Delete { .. }
            | Error::Move { .. } => return None,
        })
    }

    /// Whether the variant is the lower error itself, its message and
    /// causes included.
    fn transparent(&self) -> bool {
        matches!(
            self,
            Error::Project(_)
                | Error::Assemble(_)
                | Error::Link(_)
                | Error::Robot(_)
                | Error::Upload(_)
                | Error::Script(_)
                | Error::LayoutOutsideRam(_)
                | Error::LayoutUnreadable(_)
                | Error::BadTranscript(_)
                | Error::Baud(_)
                | Error::WorkspacePort(_)
                | Error::PathWithoutRoom(_)
                | Error::Review(_)
        )
    }
}

// By hand rather than derived: a variant with the runner's message keeps
// the lower error's code, help and snippets, which the derive gives only
// to a variant that is the lower error whole.
impl Diagnostic for Error {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        // fresh21 F6: one code and help for a ROM profile that cannot be
        // read, whichever command meets it (the file's own said nothing).
        if let Error::RomUnreadable { .. } = self {
            return Some(Box::new("scorpion::project::rom_unreadable"));
        }
        self.lower().and_then(Diagnostic::code)
    }

    fn severity(&self) -> Option<Severity> {
        self.lower().and_then(Diagnostic::severity)
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        if let Error::RomUnreadable { .. } = self {
            return Some(Box::new(crate::error::ROM_PROFILE_HELP));
        }
        self.lower().and_then(Diagnostic::help)
    }

    fn url<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.lower().and_then(Diagnostic::url)
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.lower().and_then(Diagnostic::source_code)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.lower().and_then(Diagnostic::labels)
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn Diagnostic> + 'a>> {
        self.lower().and_then(Diagnostic::related)
    }

    fn diagnostic_source(&self) -> Option<&dyn Diagnostic> {
        if self.transparent() {
            self.lower().and_then(Diagnostic::diagnostic_source)
        } else {
            None
        }
    }
}

/// A layout file of an image that cannot be read.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("image {image}: cannot read the {kind} {layout}: {error}")]
pub struct LayoutUnreadable {
    /// The image's name.
    pub image: String,
    /// The layout as `target` names it, relative to the project.
    pub layout: String,
    /// `layout` (a `.toml` file) or `ld65 configuration` (a `.cfg`).
    pub kind: &'static str,
    /// Why.
    pub error: hostfs::Error,
}

/// A line of a transcript that cannot be read as one.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{shown}:{line}: {reason}")]
#[diagnostic(
    code(uploader::bad_expectations),
    help("each line is `COMMAND` or `COMMAND => ANSWER`; `#` starts a comment")
)]
pub struct BadTranscript {
    /// The transcript as shown to the user.
    pub shown: String,
    /// The line, from 1.
    pub line: usize,
    /// What is wrong with it.
    pub reason: String,
}

/// A line's rate the Scorpion's 6551 does not have.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("the Scorpion's 6551 has no {baud} baud rate")]
#[diagnostic(help("the 6551 runs at 50 to 19200 baud; the reference ROM's rate is 9600"))]
pub struct Baud {
    /// The rate asked for.
    pub baud: u32,
}

/// `--port` given where a workspace, not a project, is found.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error(
    "--port tests one project on the robot, and {} here is a workspace",
    crate::FILE
)]
#[diagnostic(help(
    "a workspace's members may not fit on one robot together: run `scorpion test --port` in each member's directory"
))]
pub struct WorkspacePort {
    /// The workspace's directory.
    pub root: PathBuf,
}

/// `--path` given to the tests of a project whose robot has no room: the
/// transcripts take the world from the project (`[robot] world`), not
/// from the command line, so the project is what to change.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error(
    "--path draws each transcript's robot in its room, and the robot of {file} has none{}",
    world.as_ref().map(|w| format!(" (its world, {w}, is a script, not a world file)")).unwrap_or_default()
)]
#[diagnostic(
    code(project::path_without_room),
    help(
        "give the project a world file: `world = \"room.toml\"` under [robot] in {file} (docs/WORLD.md); `scorpion test` takes the world from the project"
    )
)]
pub struct PathWithoutRoom {
    /// The project's file, as shown to the user.
    pub file: String,
    /// The project's `[robot] world`, when it is a world script.
    pub world: Option<String>,
}

/// An error of the front end (its [`Progress`](super::Progress)), shown as
/// the front end made it.
pub struct FrontEnd(pub miette::Report);

impl fmt::Debug for FrontEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.0, f)
    }
}

impl fmt::Display for FrontEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

impl std::error::Error for FrontEnd {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

impl Diagnostic for FrontEnd {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.0.code()
    }

    fn severity(&self) -> Option<Severity> {
        self.0.severity()
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.0.help()
    }

    fn url<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.0.url()
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.0.source_code()
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.0.labels()
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn Diagnostic> + 'a>> {
        self.0.related()
    }

    fn diagnostic_source(&self) -> Option<&dyn Diagnostic> {
        self.0.diagnostic_source()
    }
}
