//! A project (one `Scorpion.toml` with its images) or a workspace of them,
//! found in a directory or the nearest one above it, as cargo finds
//! `Cargo.toml`.

use std::path::{Path, PathBuf};

use crate::FILE;
use crate::error::{Error, Located};
use crate::file::{ProjectFile, WorkspaceFile};

const KEYS_HELP: &str = "the keys: [project] name; [[image]] name, sources, target, include, defines; [robot] port, baud, cards, world, rom; [tests] transcripts, builtin_listing; [budgets] \"/2A\" or a routine's label = cycles (or, for a workspace, [workspace] members alone); docs/PROJECT.md has them all";

/// A project: its root directory and its file.
#[derive(Debug, Clone)]
pub struct Project {
    /// The directory that holds `Scorpion.toml`.
    pub root: PathBuf,
    /// What the file says.
    pub file: ProjectFile,
    /// The file's text, for the lines `scorpion config` names.
    text: String,
    /// The file's path as shown to the user.
    shown: String,
}

/// A file's path as the user knows it: relative to where they are.
pub fn shown(path: &Path) -> String {
    std::env::current_dir()
        .ok()
        .and_then(|cwd| path.strip_prefix(cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf())
        .display()
        .to_string()
}

fn current_dir() -> crate::Result<PathBuf> {
    std::env::current_dir().map_err(|source| Error::Read {
        path: PathBuf::from("."),
        source,
    })
}

impl Project {
    /// The directory of the project whose `Scorpion.toml` is in `dir` or
    /// the nearest directory above it; `None` if there is none.
    #[must_use]
    pub fn find(dir: &Path) -> Option<PathBuf> {
        dir.ancestors()
            .find(|d| d.join(FILE).is_file())
            .map(Path::to_path_buf)
    }

    /// Reads the project in `root`.
    ///
    /// # Errors
    /// A workspace there ([`Error::IsWorkspace`]), or any error of
    /// [`Found::load`].
    pub fn load(root: &Path) -> crate::Result<Project> {
        match Found::load(root)? {
            Found::Project(project) => Ok(project),
            Found::Workspace(workspace) => Err(Error::IsWorkspace {
                file: shown(&root.join(FILE)),
                members: workspace.member_names().join(", "),
            }),
        }
    }

    /// The project found from the current directory up.
    ///
    /// # Errors
    /// [`Error::NoProject`] if there is none; else as [`Project::load`].
    pub fn here() -> crate::Result<Project> {
        Project::load(&here_root()?)
    }

    /// The project found from `dir` up, if there is one (a workspace is
    /// none: it has no robot of its own).
    ///
    /// # Errors
    /// A project file that cannot be read, at its place.
    pub fn around(dir: &Path) -> crate::Result<Option<Project>> {
        let Some(root) = Project::find(dir) else {
            return Ok(None);
        };
        match Found::load(&root)? {
            Found::Project(project) => Ok(Some(project)),
            Found::Workspace(_) => Ok(None),
        }
    }

    fn parse(root: &Path, name: &str, text: String) -> crate::Result<Project> {
        let file: ProjectFile =
            toml::from_str(&text).map_err(|error| Located::toml(name, &text, &error, KEYS_HELP))?;
        if file.images.is_empty() {
            let end = text.len();
            return Err(Located::new(
                name,
                &text,
                end..end,
                format!("{name} has no [[image]]"),
                "add an image:\n[[image]]\nname = \"myext\"\nsources = [\"src/myext.s\"]",
            )
            .into());
        }
        crate::validate::check(name, &text, &file)?;
        Ok(Project {
            root: root.to_path_buf(),
            file,
            text,
            shown: name.to_owned(),
        })
    }

    /// The file's text.
    #[must_use]
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The file's path as shown to the user.
    #[must_use]
    pub fn shown(&self) -> &str {
        &self.shown
    }

    /// A path of the project, relative to its root.
    #[must_use]
    pub fn path(&self, relative: &str) -> PathBuf {
        self.root.join(relative)
    }

    /// Where built images go.
    #[must_use]
    pub fn target_dir(&self) -> PathBuf {
        self.root.join("target").join("scorpion")
    }

    /// The ROM profile's path (as written) and linked image, if the
    /// project names one.
    ///
    /// # Errors
    /// A file that cannot be read or is not a linked image.
    pub fn rom(&self) -> crate::Result<Option<(String, linker::Image)>> {
        let Some(rom) = &self.file.robot.rom else {
            return Ok(None);
        };
        let path = self.root.join(rom);
        let bytes = hostfs::read(&path, hostfs::BINARY).map_err(|source| Error::RomUnreadable {
            file: self.shown.clone(),
            rom: rom.clone(),
            source,
        })?;
        let image = linker::Image::parse(rom, &bytes).map_err(|source| Error::Rom {
            file: self.shown.clone(),
            rom: rom.clone(),
            source: Box::new(source),
        })?;
        Ok(Some((rom.clone(), image)))
    }

    /// The transcript files.
    #[must_use]
    pub fn transcripts(&self) -> Vec<PathBuf> {
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
    #[must_use]
    pub fn test_files(&self, ext: &str) -> Vec<PathBuf> {
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
    #[must_use]
    pub fn snapshot_path(&self, image: &str, kind: &str) -> PathBuf {
        self.root
            .join("tests")
            .join("snapshots")
            .join(format!("{image}__{kind}.snap"))
    }
}

/// The directory of the `Scorpion.toml` found from the current directory
/// up.
fn here_root() -> crate::Result<PathBuf> {
    let cwd = current_dir()?;
    Project::find(&cwd).ok_or(Error::NoProject { dir: cwd })
}

/// Projects run together: a `Scorpion.toml` with `[workspace] members`.
#[derive(Debug, Clone)]
pub struct Workspace {
    /// The directory that holds the workspace's file.
    pub root: PathBuf,
    /// The members' directories, as the file lists them.
    members: Vec<String>,
}

impl Workspace {
    /// The members' names, as the file gives them.
    #[must_use]
    pub fn member_names(&self) -> Vec<String> {
        self.members.clone()
    }

    /// Every member, read in order: (its name, the project).
    ///
    /// # Errors
    /// A member that is not a project, or whose file is wrong.
    pub fn projects(&self) -> crate::Result<Vec<(String, Project)>> {
        let file = shown(&self.root.join(FILE));
        self.members
            .iter()
            .map(|member| {
                let root = self.root.join(member);
                match Found::load(&root) {
                    Ok(Found::Project(project)) => Ok((member.clone(), project)),
                    Ok(Found::Workspace(_)) => Err(Error::BadMember {
                        file: file.clone(),
                        member: member.clone(),
                        why: "is a workspace itself; list its members instead".to_owned(),
                    }),
                    Err(error) if !root.join(FILE).is_file() => Err(Error::BadMember {
                        file: file.clone(),
                        member: member.clone(),
                        why: format!("has no {FILE}: {error}"),
                    }),
                    Err(error) => Err(error),
                }
            })
            .collect()
    }
}

/// What a `Scorpion.toml` holds: a project, or a workspace of them.
#[derive(Debug, Clone)]
pub enum Found {
    /// A project.
    Project(Project),
    /// A workspace.
    Workspace(Workspace),
}

impl Found {
    /// The file found from the current directory up.
    ///
    /// # Errors
    /// [`Error::NoProject`], or as [`Found::load`].
    pub fn here() -> crate::Result<Found> {
        Found::load(&here_root()?)
    }

    /// The file in `root`.
    ///
    /// # Errors
    /// A file that cannot be read, or a mistake in it at its line.
    pub fn load(root: &Path) -> crate::Result<Found> {
        let path = root.join(FILE);
        let text = hostfs::read_text(&path, hostfs::TEXT)?;
        let name = shown(&path);
        let is_workspace = text
            .parse::<toml::Table>()
            .is_ok_and(|table| table.contains_key("workspace"));
        if !is_workspace {
            return Project::parse(root, &name, text).map(Found::Project);
        }
        let file: WorkspaceFile = toml::from_str(&text).map_err(|error| {
            Located::toml(
                &name,
                &text,
                &error,
                "a workspace's file holds [workspace] members = [\"dir\", ...] and nothing else",
            )
        })?;
        if file.workspace.members.is_empty() {
            let end = text.len();
            return Err(Located::new(
                &name,
                &text,
                end..end,
                "the workspace has no members",
                "list the projects' directories: members = [\"myext\", \"myos\"]",
            )
            .into());
        }
        Ok(Found::Workspace(Workspace {
            root: root.to_path_buf(),
            members: file.workspace.members,
        }))
    }
}
