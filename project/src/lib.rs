//! The Scorpion project model and the one place a command's configuration
//! is resolved, for the `scorpion` CLI and any other front end (an
//! editor's extension, a build server).
//!
//! - [`file`]: what `Scorpion.toml` and the per-user file hold (serde).
//! - [`project`]: a project or workspace found from a directory up, as
//!   cargo finds `Cargo.toml`, checked where its names become paths.
//! - [`resolve`]: flags, then the environment, then the per-user file,
//!   then the project, then defaults, each value with where it came from.
//! - [`error`]: what can go wrong, located in the file that says it.
//! - [`runner`]: the project's builds and tests (snapshots, transcripts,
//!   routine calls, on the virtual Scorpion or a robot), reported as they
//!   go through a [`runner::Progress`] and at the end as a
//!   [`runner::Report`].
//! - [`template`]: a new project, as `scorpion new` makes it.
//! - [`undo`]: the undo file an upload to a robot keeps.
//!
//! Nothing here prints or exits: callers show [`Error`]s and the runner's
//! reports with miette.

pub mod error;
pub mod file;
pub mod project;
pub mod resolve;
pub mod runner;
mod spans;
pub mod template;
pub mod undo;
mod validate;

pub use error::{Error, Located};
pub use file::{
    ImageSpec, Meta, ProjectFile, RobotSpec, TestsSpec, UserRobot, UserSettings, WorkspaceFile,
};
pub use project::{Found, Project, Workspace, shown};
pub use resolve::{BARE_PORT, Environment, Flags, Origin, Resolved, Sourced, device_like};

/// The project file's name.
pub const FILE: &str = "Scorpion.toml";

/// A result of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
