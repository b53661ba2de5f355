//! A Scorpion project: one `Scorpion.toml` that holds what the commands
//! otherwise take as options (the images, the virtual robot's cards and
//! surroundings, the robot's port and baud rate), found in the current
//! directory or above, as cargo finds `Cargo.toml`.
//!
//! - [`config`]: the file, with errors at its line and key, and the
//!   per-user settings (`SCORPION_PORT`, `SCORPION_BAUD`).
//! - [`build`]: an image built in memory, with its listing, map, symbols
//!   and bytes.
//! - [`snapshot`]: insta-format snapshot files and their diffs.
//! - [`calls`]: routine-level tests (`tests/*.calls`).
//! - [`transcript`]: transcripts read and their mismatches said as
//!   failures, all of them, at their `file:line`.
//!
//! Nothing here prints: `scorpion build`, `test` and `new` do.

pub(crate) mod build;
pub(crate) mod calls;
pub(crate) mod config;
pub(crate) mod snapshot;
pub(crate) mod transcript;

pub(crate) use config::Project;

/// The project file's name.
pub(crate) const FILE: &str = "Scorpion.toml";
