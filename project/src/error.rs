//! What can go wrong reading a project or resolving a configuration: each
//! error names the file and line (with the text under a label) or the
//! variable or flag that said it, and what to do instead.

use std::path::PathBuf;

use miette::{NamedSource, SourceSpan};

/// A mistake at a place in a TOML file: `file:line:column`, the line shown.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{file}:{line}:{column}: {message}")]
#[diagnostic(code(scorpion::project))]
pub struct Located {
    /// The file as the user knows it.
    pub file: String,
    /// The line, from 1.
    pub line: usize,
    /// The column, from 1.
    pub column: usize,
    /// What is wrong.
    pub message: String,
    #[source_code]
    source_code: NamedSource<String>,
    #[label("here")]
    at: SourceSpan,
    #[help]
    help: Option<String>,
}

impl Located {
    /// A mistake at byte range `span` of `text`, the file `file`.
    pub(crate) fn new(
        file: &str,
        text: &str,
        span: std::ops::Range<usize>,
        message: impl Into<String>,
        help: impl Into<String>,
    ) -> Located {
        let (line, column) = line_col(text, span.start);
        Located {
            file: file.to_owned(),
            line,
            column,
            message: message.into(),
            source_code: NamedSource::new(file, text.to_owned()),
            at: SourceSpan::from((span.start, span.len())),
            help: Some(help.into()),
        }
    }

    /// A TOML or serde error of `text`, at its place.
    pub(crate) fn toml(file: &str, text: &str, error: &toml::de::Error, help: &str) -> Located {
        Located::new(
            file,
            text,
            error.span().unwrap_or(0..0),
            error.message(),
            help,
        )
    }
}

/// The line and column (from 1) of byte `offset` of `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// The help for a ROM profile that cannot be read, wherever it is met.
pub(crate) const ROM_PROFILE_HELP: &str = "`rom` names a ROM profile (a ROM's linked image, ELF), relative to the project; `scorpion rom read -o FILE --port PORT` writes one from the robot; without `rom`, the reference ROM; `scorpion config` shows where it is looked for";

/// Everything reading a project or resolving a configuration can say.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum Error {
    /// A mistake in `Scorpion.toml` or the per-user file, at its place.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Located(Box<Located>),

    /// A file that cannot be read.
    #[error("cannot read {path}: {source}")]
    #[diagnostic(code(scorpion::project::read))]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },

    /// A file the project names that cannot be read: missing, not a
    /// regular file, or larger than its kind allows.
    #[error(transparent)]
    #[diagnostic(transparent)]
    File(#[from] hostfs::Error),

    /// No `Scorpion.toml` here or above.
    #[error("no {} in {} or any directory above it", crate::FILE, dir.display())]
    #[diagnostic(
        code(scorpion::project::none),
        help("give the files on the command line, or start a project with `scorpion new NAME`")
    )]
    NoProject {
        /// Where the search started.
        dir: PathBuf,
    },

    /// A workspace where a single project is needed.
    #[error("{file} is a workspace of {members}, not a project")]
    #[diagnostic(
        code(scorpion::project::workspace),
        help(
            "`scorpion test` and `scorpion build` run every member from here; run the other commands in a member's directory"
        )
    )]
    IsWorkspace {
        /// The workspace's file.
        file: String,
        /// Its members, listed.
        members: String,
    },

    /// A workspace member that is not a project.
    #[error("{file}: member `{member}` {why}")]
    #[diagnostic(
        code(scorpion::project::member),
        help("a member is a directory with its own Scorpion.toml (`scorpion new NAME` makes one)")
    )]
    BadMember {
        /// The workspace's file.
        file: String,
        /// The member as listed.
        member: String,
        /// What is wrong with it.
        why: String,
    },

    /// A setting whose value cannot be used, with where it came from.
    #[error("{what} = {value:?} ({origin}) is not {expected}")]
    #[diagnostic(
        code(scorpion::project::setting),
        help("`scorpion config` shows every setting and where it came from")
    )]
    Setting {
        /// The setting's name.
        what: &'static str,
        /// Its value, as given.
        value: String,
        /// Where it came from (flag, variable, file and line).
        origin: String,
        /// What it must be.
        expected: String,
    },

    /// An environment variable whose value cannot be used.
    #[error("{name}={value} is not {expected}")]
    #[diagnostic(
        code(scorpion::config::env),
        help("unset it (`unset {name}`) to use the per-user file's, the project's or the default")
    )]
    Environment {
        /// The variable.
        name: &'static str,
        /// Its value.
        value: String,
        /// What it should be.
        expected: &'static str,
    },

    /// A command that talks to a robot and no port anywhere.
    #[error("no port for the robot")]
    #[diagnostic(
        code(scorpion::config::no_port),
        help(
            "give it (`--port /dev/ttyUSB0`, or `--port emu` for the virtual Scorpion; in an editor's launch configuration, its `port`), set SCORPION_PORT, or add `port` to [robot] in {user} (yours) or Scorpion.toml (the project's)"
        )
    )]
    NoPort {
        /// The per-user file's path, as shown.
        user: String,
    },

    /// The project's ROM profile cannot be read.
    #[error("{file}: [robot] rom = \"{rom}\": cannot read the ROM profile")]
    #[diagnostic(code(scorpion::project::rom_unreadable), help("{}", ROM_PROFILE_HELP))]
    RomUnreadable {
        /// The project file.
        file: String,
        /// The profile as written.
        rom: String,
        /// Why.
        #[source]
        source: hostfs::Error,
    },

    /// The project's ROM profile is not a ROM's linked image.
    #[error("{file}: [robot] rom = \"{rom}\" is not a linked ROM image")]
    #[diagnostic(code(scorpion::project::rom))]
    Rom {
        /// The project file.
        file: String,
        /// The profile as written.
        rom: String,
        /// Why.
        #[source]
        source: Box<linker::Error>,
    },
}

impl From<Located> for Error {
    fn from(located: Located) -> Error {
        Error::Located(Box::new(located))
    }
}
