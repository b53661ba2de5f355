//! A project's builds and tests, for the `scorpion` CLI and any other
//! front end: everything `scorpion build` and `scorpion test` do but the
//! printing and the questions to a terminal.
//!
//! - [`error`]: what stops a build or a run ([`Error`]), with its place.
//! - [`build`]: an image built in memory, with its listing, map, symbols
//!   and bytes (and written into the project's `target/scorpion/`).
//! - [`toolchain`]: the built-in include files and the link step every
//!   build shares with `scorpion asm` and `scorpion link`.
//! - [`memory`]: a project's own layout checked against the memory an
//!   upload may write.
//! - [`snapshot`]: insta-format snapshot files and their diffs.
//! - [`review`]: what to do with a snapshot that differs; accepting,
//!   rejecting or leaving one pending snapshot.
//! - [`transcript`]: transcripts read and their mismatches said as
//!   failures, all of them, at their `file:line`.
//! - [`room_lines`]: a transcript's lines about the robot in its room
//!   (`wait`, `pose =>`, `bumped =>`).
//! - [`calls`]: routine-level tests (`tests/*.calls`).
//! - [`rig`]: the virtual Scorpion the tests run on (ROM profile, cards,
//!   surroundings).
//! - [`report`]: each test's outcome as it comes ([`Progress`], no-op
//!   unless a front end overrides it) and the [`Report`] at the end.
//! - [`run`]: [`run_tests`], the runner itself.
//!
//! Nothing here prints or exits.

pub mod build;
pub mod calls;
pub mod error;
pub mod memory;
pub mod report;
pub mod review;
pub mod rig;
pub mod room_lines;
pub mod run;
pub mod snapshot;
pub mod toolchain;
pub mod transcript;

pub use build::{Built, SNAPSHOT_KINDS};
pub use error::{Error, Result};
pub use report::{
    Failure, MemberReport, NoProgress, Outcome, Passed, Progress, Question, Report, TestResult,
};
pub use review::{Decision, Mode, Pending};
pub use rig::{EMU, Rig};
pub use run::{Options, path_picture, run_tests};
pub use toolchain::{builtin_includes, link_objects};
