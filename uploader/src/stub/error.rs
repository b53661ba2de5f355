//! What can go wrong while a debugger is attached to a robot through the
//! stub: the line's errors, a garbled frame, a refused breakpoint.

use std::time::Duration;

/// A failure of the debugger on the robot.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum StubError {
    /// The line or the ROM's commands failed.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Line(#[from] crate::Error),

    /// Writing the stub through the RAM loader failed (the line), and the
    /// loader could not be taken out of `HOOK_UNKNOWN` after: the robot
    /// drops unknown commands until it is.
    #[error(
        "writing the debug stub through the RAM loader failed ({source}), and the loader stays hooked on HOOK_UNKNOWN (${hook:04X}): the robot drops the extensions' commands until it is taken out"
    )]
    #[diagnostic(
        code(uploader::stub::loader_left),
        help(
            "nothing unverified is hooked; `scorpion upload` of the image finds the loader and takes it out (or reset the robot, which unhooks everything), then attach again; on a line this noisy, shorten or fix the cable first"
        )
    )]
    LoaderLeft {
        /// Why the write failed.
        source: crate::Error,
        /// Where `HOOK_UNKNOWN` is.
        hook: u16,
    },

    /// The stub does not link (a defect of this crate).
    #[error("the debug stub does not link at ${address:04X}: {message}")]
    #[diagnostic(code(uploader::stub::link))]
    Link {
        /// Where it was linked.
        address: u16,
        /// The linker's complaint.
        message: String,
    },

    /// No room for the stub beside the image and what the robot holds.
    #[error(
        "no room for the debug stub ({len} bytes) in user RAM or two bytes of user zero page: taken are {taken}"
    )]
    #[diagnostic(
        code(uploader::stub::no_room),
        help(
            "the stub goes where neither the image, nor an extension the robot's table names, nor the RAM loader lies, in user RAM ($0400-$0F3F); make the image smaller, or take an extension out"
        )
    )]
    NoRoom {
        /// The stub's size.
        len: usize,
        /// The ranges it had to leave (the image's, the installed
        /// extensions', the loader's), as `$0400-$0452, ...`.
        taken: String,
    },

    /// A reply from the stub that is not what was asked for.
    #[error("a garbled reply from the stub to {asked}: expected {expected}, found {found}")]
    #[diagnostic(
        code(uploader::stub::garbled),
        help(
            "the line is noisy or the robot is not running the stub (a reset?); `detach` and attach again"
        )
    )]
    Garbled {
        /// The request.
        asked: String,
        /// What should have come.
        expected: String,
        /// What came (escaped).
        found: String,
    },

    /// Nothing came back in time.
    #[error("no reply from the stub to {asked} within {}", crate::human_duration(*waited))]
    #[diagnostic(
        code(uploader::stub::timeout),
        help("the robot may have been reset (its hooks go back to the ROM) or the line is down")
    )]
    Timeout {
        /// The request.
        asked: String,
        /// How long the host waited.
        waited: Duration,
    },

    /// Memory that does not hold what was written to it.
    #[error("${address:04X} holds {found} after the write of {expected}")]
    #[diagnostic(
        code(uploader::stub::verify),
        help("the memory there is not RAM, or the line is very noisy")
    )]
    Verify {
        /// The first address that differs.
        address: u16,
        /// The bytes written (hex).
        expected: String,
        /// The bytes read back (hex).
        found: String,
    },

    /// The robot's code is not the image's: attaching would patch
    /// instructions that are not there.
    #[error(
        "the robot does not hold the image: ${address:04X} holds {found}, the image has {expected}"
    )]
    #[diagnostic(
        code(uploader::stub::not_the_image),
        help(
            "upload the image first (`scorpion upload --replace` in its project, or `scorpion upload ELF --port PORT --replace`), or give `debug` the image the robot runs; nothing was written"
        )
    )]
    NotTheImage {
        /// The first address that differs.
        address: u16,
        /// The image's bytes there (hex).
        expected: String,
        /// The robot's (hex).
        found: String,
    },

    /// A signal (Ctrl-C, a `kill`) came while the host waited for the
    /// robot.
    #[error("interrupted while waiting for {waiting}")]
    #[diagnostic(
        code(uploader::stub::interrupted),
        help(
            "the session ends as `quit` does: the breakpoints are taken out and the hook given back, if the robot still answers"
        )
    )]
    Interrupted {
        /// What was waited for.
        waiting: String,
    },

    /// What the robot cannot do, and why.
    #[error("{what} is refused on the robot: {reason}")]
    #[diagnostic(code(uploader::stub::refused))]
    Refused {
        /// What was asked.
        what: String,
        /// Why not.
        reason: String,
    },
}

/// Results of the debugger on the robot.
pub type StubResult<T> = std::result::Result<T, StubError>;

/// `bytes` as spaced hex, for messages.
#[must_use]
pub fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}
