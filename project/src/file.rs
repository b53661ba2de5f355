//! What `Scorpion.toml` and the per-user file hold, as serde reads them.
//! docs/PROJECT.md documents every key; its test deserializes the doc's
//! files and lists these structs' keys, so the two cannot drift apart.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The whole project file.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectFile {
    /// `[project]`.
    pub project: Meta,
    /// `[[image]]`, one per image.
    #[serde(rename = "image", default)]
    pub images: Vec<ImageSpec>,
    /// `[robot]`.
    #[serde(default)]
    pub robot: RobotSpec,
    /// `[tests]`.
    #[serde(default)]
    pub tests: TestsSpec,
    /// `[budgets]`: the most a robot command (`"/2A"`, from its arrival
    /// to `CMD_DONE`) or a routine (its label, from its entry to its
    /// `RTS`) may cost, in cycles, anywhere in the tests.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub budgets: BTreeMap<String, u64>,
}

/// A workspace's file: `[workspace]` only.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceFile {
    /// `[workspace]`.
    pub workspace: WorkspaceSpec,
}

/// `[workspace]`: projects that `scorpion test` and `build` run together,
/// in one process (as cargo's workspaces).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceSpec {
    /// The members' directories, relative to the workspace, in the order
    /// they run.
    pub members: Vec<String>,
}

/// `[project]`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    /// The project's name.
    pub name: String,
}

/// One image: its sources and how to link them.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImageSpec {
    /// The image's name: `target/scorpion/NAME.elf`, the snapshots'
    /// prefix; a plain file name (checked when the file is read).
    pub name: String,
    /// The sources, in link order, relative to the project; at least one.
    pub sources: Vec<String>,
    /// A built-in target (`scorpion-ext`, `scorpion-os`), a layout file
    /// (`FILE.toml`) or an ld65 configuration (`FILE.cfg`).
    #[serde(default = "default_target")]
    pub target: String,
    /// Include directories, relative to the project.
    #[serde(default)]
    pub include: Vec<String>,
    /// `-D` definitions, each within [`assembler::DEFINE_VALUES`].
    #[serde(default)]
    pub defines: BTreeMap<String, i64>,
}

fn default_target() -> String {
    "scorpion-ext".to_owned()
}

/// `[robot]`: the virtual robot's set-up and the real one's line.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// The serial port (`--port`, `SCORPION_PORT` and the per-user file
    /// come first, so a shared project need not carry one person's device).
    pub port: Option<String>,
    /// The baud rate (`--baud`, `SCORPION_BAUD` and the per-user file come
    /// first).
    pub baud: Option<u32>,
    /// Card scripts, `FILE[@ADDR]`, relative to the project.
    #[serde(default)]
    pub cards: Vec<String>,
    /// The surroundings script, relative to the project.
    pub world: Option<String>,
    /// A ROM profile (the ROM's linked ELF) the images link against and
    /// the virtual robot runs, instead of the reference ROM.
    pub rom: Option<String>,
}

/// `[tests]`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TestsSpec {
    /// Transcript files (`.expect`), relative to the project; default:
    /// every `tests/*.expect`.
    #[serde(default)]
    pub transcripts: Vec<String>,
    /// List the built-in `scorpion.inc` where the sources include it, in
    /// the listing snapshots and `target/scorpion/NAME.lst` (off: the
    /// snapshots show the project's own code, and a new ROM, whose
    /// identity the include's text names, fails none of them).
    #[serde(default)]
    pub builtin_listing: bool,
}

/// The per-user file (`$XDG_CONFIG_HOME/scorpion/config.toml`, else
/// `~/.config/scorpion/config.toml`): this person's robot, for every
/// project.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct UserSettings {
    /// `[robot]`.
    #[serde(default)]
    pub robot: UserRobot,
}

/// `[robot]` of the per-user file.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct UserRobot {
    /// The serial port this person's robot is on.
    pub port: Option<String>,
    /// Its baud rate.
    pub baud: Option<u32>,
}
