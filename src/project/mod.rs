//! A Scorpion project as the CLI runs it. The project model and the
//! resolution of every command's configuration are the `scorpion-project`
//! library's (re-exported here as [`config`]); what stays here builds,
//! snapshots and runs the project's tests.
//!
//! - [`build`]: an image built in memory, with its listing, map, symbols
//!   and bytes.
//! - [`snapshot`]: insta-format snapshot files and their diffs.
//! - [`calls`]: routine-level tests (`tests/*.calls`).
//! - [`memory`]: a project's own layout checked against the memory an
//!   upload may write.
//! - [`transcript`]: transcripts read and their mismatches said as
//!   failures, all of them, at their `file:line`.
//!
//! Nothing here prints: `scorpion build`, `test` and `new` do.

pub(crate) mod build;
pub(crate) mod calls;
pub(crate) mod memory;
pub(crate) mod snapshot;
pub(crate) mod transcript;

/// The project model and the configuration's resolution.
pub(crate) use scorpion_project as config;
pub(crate) use scorpion_project::{FILE, Project};
