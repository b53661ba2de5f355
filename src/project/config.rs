//! `Scorpion.toml`, read with serde and toml; an error names the file, the
//! line and column, and shows the key.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use miette::{NamedSource, SourceSpan};
use serde::Deserialize;

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ProjectFile {
    /// `[project]`.
    pub(crate) project: Meta,
    /// `[[image]]`, one per image.
    #[serde(rename = "image", default)]
    pub(crate) images: Vec<ImageSpec>,
    /// `[robot]`.
    #[serde(default)]
    pub(crate) robot: RobotSpec,
    /// `[tests]`.
    #[serde(default)]
    pub(crate) tests: TestsSpec,
}

/// A workspace's file: `[workspace]` only.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct WorkspaceFile {
    workspace: WorkspaceSpec,
}

/// `[workspace]`: projects that `scorpion test` and `build` run together,
/// in one process (as cargo's workspaces).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct WorkspaceSpec {
    /// The members' directories, relative to the workspace, in the order
    /// they run.
    members: Vec<String>,
}

/// `[project]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Meta {
    /// The project's name.
    pub(crate) name: String,
}

/// One image: its sources and how to link them.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ImageSpec {
    /// The image's name: `target/scorpion/NAME.elf`, the snapshots' prefix.
    pub(crate) name: String,
    /// The sources, in link order, relative to the project.
    pub(crate) sources: Vec<String>,
    /// A built-in target (`scorpion-ext`, `scorpion-os`), a layout file
    /// (`FILE.toml`) or an ld65 configuration (`FILE.cfg`).
    #[serde(default = "default_target")]
    pub(crate) target: String,
    /// Include directories, relative to the project.
    #[serde(default)]
    pub(crate) include: Vec<String>,
    /// `-D` definitions.
    #[serde(default)]
    pub(crate) defines: BTreeMap<String, i64>,
}

fn default_target() -> String {
    "scorpion-ext".to_owned()
}

/// `[robot]`: the virtual robot's set-up and the real one's line.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RobotSpec {
    /// The serial port (`SCORPION_PORT` overrides it, so a shared project
    /// need not carry one person's device).
    pub(crate) port: Option<String>,
    /// The baud rate (`SCORPION_BAUD` overrides it).
    pub(crate) baud: Option<u32>,
    /// Card scripts, `FILE[@ADDR]`, relative to the project.
    #[serde(default)]
    pub(crate) cards: Vec<String>,
    /// The surroundings script.
    pub(crate) world: Option<String>,
    /// A ROM profile (the ROM's linked ELF) the images link against and
    /// the virtual robot runs, instead of the reference ROM.
    pub(crate) rom: Option<String>,
}

/// `[tests]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TestsSpec {
    /// Transcript files (`.expect`), relative to the project; default:
    /// every `tests/*.expect`.
    #[serde(default)]
    pub(crate) transcripts: Vec<String>,
    /// List the built-in `scorpion.inc` where the sources include it, in
    /// the listing snapshots and `target/scorpion/NAME.lst` (off: the
    /// snapshots show the project's own code, and a new ROM, whose
    /// identity the include's text names, fails none of them).
    #[serde(default)]
    pub(crate) builtin_listing: bool,
}

/// The per-user file (`$XDG_CONFIG_HOME/scorpion/config.toml`, else
/// `~/.config/scorpion/config.toml`): this person's robot, for every
/// project.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct UserSettings {
    #[serde(default)]
    robot: UserRobot,
}

/// `[robot]` of the per-user file.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct UserRobot {
    port: Option<String>,
    baud: Option<u32>,
}

/// The per-user file's path.
pub(crate) fn user_file() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".config")))?;
    Some(base.join("scorpion").join("config.toml"))
}

/// The per-user settings, if the file exists; an error in it at its
/// line.
fn user_settings() -> miette::Result<Option<UserSettings>> {
    let Some(path) = user_file() else {
        return Ok(None);
    };
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(None);
    };
    let name = path.display().to_string();
    toml::from_str(&text).map(Some).map_err(|error| {
        located(
            &name,
            &text,
            &error,
            "the per-user file holds [robot] port and baud",
        )
        .into()
    })
}

fn located(name: &str, text: &str, error: &toml::de::Error, help: &str) -> ProjectError {
    let span = error.span().unwrap_or(0..0);
    let (line, column) = line_col(text, span.start);
    ProjectError {
        file: name.to_owned(),
        line,
        column,
        message: error.message().to_owned(),
        source_code: NamedSource::new(name, text.to_owned()),
        at: SourceSpan::from((span.start, span.len())),
        help: Some(help.to_owned()),
    }
}

/// An error in the project file, at its place.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{file}:{line}:{column}: {message}")]
#[diagnostic(code(scorpion::project))]
pub(crate) struct ProjectError {
    file: String,
    line: usize,
    column: usize,
    message: String,
    #[source_code]
    source_code: NamedSource<String>,
    #[label("here")]
    at: SourceSpan,
    #[help]
    help: Option<String>,
}

/// A project: its root directory and its file.
#[derive(Debug, Clone)]
pub(crate) struct Project {
    /// The directory that holds `Scorpion.toml`.
    pub(crate) root: PathBuf,
    /// What the file says.
    pub(crate) file: ProjectFile,
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

impl Project {
    /// The project whose `Scorpion.toml` is in `dir` or the nearest
    /// directory above it; `None` if there is none.
    pub(crate) fn find(dir: &Path) -> Option<PathBuf> {
        dir.ancestors()
            .find(|d| d.join(super::FILE).is_file())
            .map(Path::to_path_buf)
    }

    /// Reads the project in `root`; a workspace there is an error that
    /// says what to do instead.
    pub(crate) fn load(root: &Path) -> miette::Result<Project> {
        match Found::load(root)? {
            Found::Project(project) => Ok(project),
            Found::Workspace(workspace) => miette::bail!(
                help = "`scorpion test` and `scorpion build` run every member from here; run the other commands in a member's directory",
                "{} is a workspace of {}, not a project",
                shown(&root.join(super::FILE)),
                workspace.member_names().join(", ")
            ),
        }
    }

    fn parse(root: &Path, name: &str, text: &str) -> miette::Result<Project> {
        let file: ProjectFile = toml::from_str(text).map_err(|error| {
            located(
                name,
                text,
                &error,
                "the keys: [project] name; [[image]] name, sources, target, include, defines; [robot] port, baud, cards, world, rom; [tests] transcripts, builtin_listing (or, for a workspace, [workspace] members alone)",
            )
        })?;
        if file.images.is_empty() {
            miette::bail!(
                help = "add an image:\n[[image]]\nname = \"myext\"\nsources = [\"src/myext.s\"]",
                "{name} has no [[image]]"
            );
        }
        Ok(Project {
            root: root.to_path_buf(),
            file,
        })
    }

    /// The project found from the current directory up, or an error that
    /// says what was looked for.
    pub(crate) fn here() -> miette::Result<Project> {
        Project::load(&here_root()?)
    }

    /// A path of the project, relative to its root.
    pub(crate) fn path(&self, relative: &str) -> PathBuf {
        self.root.join(relative)
    }

    /// Where built images go.
    pub(crate) fn target_dir(&self) -> PathBuf {
        self.root.join("target").join("scorpion")
    }

    /// The robot's port: `SCORPION_PORT`, else the user's file, else the
    /// project's.
    pub(crate) fn port(&self) -> miette::Result<Option<String>> {
        if let Some(port) = std::env::var("SCORPION_PORT")
            .ok()
            .filter(|p| !p.is_empty())
        {
            return Ok(Some(port));
        }
        Ok(user_settings()?
            .and_then(|u| u.robot.port)
            .or_else(|| self.file.robot.port.clone()))
    }

    /// The baud rate: `SCORPION_BAUD`, else the user's file, else the
    /// project's, else 9600.
    pub(crate) fn baud(&self) -> miette::Result<u32> {
        match std::env::var("SCORPION_BAUD") {
            Ok(text) if !text.is_empty() => text
                .parse()
                .map_err(|_| miette::miette!("SCORPION_BAUD={text} is not a baud rate")),
            _ => Ok(user_settings()?
                .and_then(|u| u.robot.baud)
                .or(self.file.robot.baud)
                .unwrap_or(platform::line::DEFAULT_BAUD)),
        }
    }

    /// The virtual robot's cards and surroundings, paths made absolute.
    pub(crate) fn rig(&self) -> miette::Result<crate::cmd::rig::Rig> {
        let mut cards = Vec::new();
        for card in &self.file.robot.cards {
            let arg: cards::CardArg = card
                .parse()
                .map_err(|e: String| miette::miette!("{}: [robot] cards: {e}", super::FILE))?;
            cards.push(arg);
        }
        Ok(crate::cmd::rig::Rig {
            cards,
            world: self.file.robot.world.as_ref().map(PathBuf::from),
            root: Some(self.root.clone()),
        })
    }

    /// The ROM profile's path and linked image, if the project names one.
    pub(crate) fn rom(&self) -> miette::Result<Option<(String, linker::Image)>> {
        let Some(rom) = &self.file.robot.rom else {
            return Ok(None);
        };
        let bytes = std::fs::read(self.root.join(rom))
            .map_err(|e| miette::miette!("{}: [robot] rom = \"{rom}\": {e}", super::FILE))?;
        Ok(Some((rom.clone(), linker::Image::parse(rom, &bytes)?)))
    }

    /// The transcript files.
    pub(crate) fn transcripts(&self) -> Vec<PathBuf> {
        if !self.file.tests.transcripts.is_empty() {
            return self
                .file
                .tests
                .transcripts
                .iter()
                .map(|t| self.root.join(t))
                .collect();
        }
        self.test_files("expect")
    }

    /// The files `tests/*.EXT`, in name order.
    pub(crate) fn test_files(&self, ext: &str) -> Vec<PathBuf> {
        let mut found: Vec<PathBuf> = std::fs::read_dir(self.root.join("tests"))
            .into_iter()
            .flatten()
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == ext))
            .collect();
        found.sort();
        found
    }

    /// Where image `image`'s snapshot of `kind` lives.
    pub(crate) fn snapshot_path(&self, image: &str, kind: &str) -> PathBuf {
        self.root
            .join("tests")
            .join("snapshots")
            .join(format!("{image}__{kind}.snap"))
    }
}

/// A file's path as the user knows it: relative to where they are.
fn shown(path: &Path) -> String {
    std::env::current_dir()
        .ok()
        .and_then(|cwd| path.strip_prefix(cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf())
        .display()
        .to_string()
}

/// The directory of the `Scorpion.toml` found from the current directory
/// up, or an error that says what was looked for.
fn here_root() -> miette::Result<PathBuf> {
    let cwd = std::env::current_dir()
        .map_err(|e| miette::miette!("cannot read the current directory: {e}"))?;
    Project::find(&cwd).ok_or_else(|| {
        miette::miette!(
            help =
                "give the files on the command line, or start a project with `scorpion new NAME`",
            "no {} in {} or any directory above it",
            super::FILE,
            cwd.display()
        )
    })
}

/// Projects run together: a `Scorpion.toml` with `[workspace] members`.
#[derive(Debug, Clone)]
pub(crate) struct Workspace {
    /// The directory that holds the workspace's file.
    pub(crate) root: PathBuf,
    /// The members' directories, as the file lists them.
    members: Vec<String>,
}

impl Workspace {
    /// The members' names, as the file gives them.
    pub(crate) fn member_names(&self) -> Vec<String> {
        self.members.clone()
    }

    /// Every member, read in order: (its name, the project).
    pub(crate) fn projects(&self) -> miette::Result<Vec<(String, Project)>> {
        self.members
            .iter()
            .map(|member| {
                let root = self.root.join(member);
                match Found::load(&root) {
                    Ok(Found::Project(project)) => Ok((member.clone(), project)),
                    Ok(Found::Workspace(_)) => miette::bail!(
                        "{}: member `{member}` is a workspace itself; list its members instead",
                        shown(&self.root.join(super::FILE))
                    ),
                    Err(error) if !root.join(super::FILE).is_file() => miette::bail!(
                        help = "a member is a directory with its own Scorpion.toml (`scorpion new NAME` makes one)",
                        "{}: member `{member}` has no {}: {error}",
                        shown(&self.root.join(super::FILE)),
                        super::FILE
                    ),
                    Err(error) => Err(error),
                }
            })
            .collect()
    }
}

/// What a `Scorpion.toml` holds: a project, or a workspace of them.
#[derive(Debug, Clone)]
pub(crate) enum Found {
    Project(Project),
    Workspace(Workspace),
}

impl Found {
    /// The file found from the current directory up.
    pub(crate) fn here() -> miette::Result<Found> {
        Found::load(&here_root()?)
    }

    /// The file in `root`.
    pub(crate) fn load(root: &Path) -> miette::Result<Found> {
        let path = root.join(super::FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| miette::miette!("cannot read {}: {e}", path.display()))?;
        let name = shown(&path);
        let is_workspace = text
            .parse::<toml::Table>()
            .is_ok_and(|table| table.contains_key("workspace"));
        if !is_workspace {
            return Project::parse(root, &name, &text).map(Found::Project);
        }
        let file: WorkspaceFile = toml::from_str(&text).map_err(|error| {
            located(
                &name,
                &text,
                &error,
                "a workspace's file holds [workspace] members = [\"dir\", ...] and nothing else",
            )
        })?;
        if file.workspace.members.is_empty() {
            miette::bail!(
                help = "list the projects' directories: members = [\"myext\", \"myos\"]",
                "{name}: the workspace has no members"
            );
        }
        Ok(Found::Workspace(Workspace {
            root: root.to_path_buf(),
            members: file.workspace.members,
        }))
    }
}
