//! The one resolution of a command's configuration: each setting from the
//! first of the command line's flags, the environment (`SCORPION_PORT`,
//! `SCORPION_BAUD`), the per-user file (`$XDG_CONFIG_HOME/scorpion/
//! config.toml`), the project (`Scorpion.toml` here or above), and the
//! default, with where it came from.
//!
//! Which sources carry which setting (docs/PROJECT.md has the table):
//! the robot's line (`port`, `baud`) is a person's, so every source may
//! carry it; the virtual robot's parts (`cards`, `world`, `rom`) belong
//! to the project, and a flag replaces the project's, each key by itself.

use std::fmt;
use std::path::{Path, PathBuf};

use cards::CardArg;
use serde::Deserialize;

use crate::error::{Error, Located};
use crate::file::UserSettings;
use crate::project::{Project, shown};
use crate::spans::RobotSpans;

/// The environment variables the resolution reads (docs/PROJECT.md lists
/// each; its test checks that).
pub const VARIABLES: [&str; 4] = ["SCORPION_PORT", "SCORPION_BAUD", "XDG_CONFIG_HOME", "HOME"];

/// The port that names the virtual Scorpion in the command's own process.
pub const EMU: &str = "emu";

/// Where a setting came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// A command-line flag (`--port`).
    Flag(&'static str),
    /// An environment variable.
    Env(&'static str),
    /// The per-user file, at a line.
    UserFile {
        /// The file, as shown.
        path: String,
        /// The line, from 1.
        line: usize,
    },
    /// The project's file, at a line.
    Project {
        /// The file, as shown.
        path: String,
        /// The line, from 1.
        line: usize,
    },
    /// Nothing said it: the default.
    Default,
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Origin::Flag(flag) => write!(f, "flag {flag}"),
            Origin::Env(name) => write!(f, "environment {name}"),
            Origin::UserFile { path, line } => write!(f, "user file {path}:{line}"),
            Origin::Project { path, line } => write!(f, "project {path}:{line}"),
            Origin::Default => f.write_str("default"),
        }
    }
}

/// How to give the configured port where a bare `--port` took the word
/// after it for its value.
pub const BARE_PORT: &str =
    "for the configured port, put a bare --port after the command's arguments (or before `--`)";

/// Whether `port` looks like a serial device's name (a path under `/dev`,
/// a Windows `COMn`), not like a command, an address, a filter or a file
/// that followed a bare `--port`.
#[must_use]
pub fn device_like(port: &str) -> bool {
    port.starts_with("/dev/")
        || port
            .strip_prefix("COM")
            .is_some_and(|number| !number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()))
}

/// A setting and where it came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sourced<T> {
    /// The value.
    pub value: T,
    /// Its source.
    pub origin: Origin,
}

/// What the command line said (nothing: `None`, empty).
#[derive(Debug, Clone, Default)]
pub struct Flags {
    /// `--port`.
    pub port: Option<String>,
    /// `--baud`.
    pub baud: Option<u32>,
    /// `--card`, in order.
    pub cards: Vec<CardArg>,
    /// `--world`.
    pub world: Option<PathBuf>,
    /// `--rom`.
    pub rom: Option<PathBuf>,
}

/// What the environment says: its variables, and where the per-user file
/// is. Tests and front ends may make one; commands take the process's.
#[derive(Debug, Clone, Default)]
pub struct Environment {
    /// `SCORPION_PORT`.
    pub port: Option<String>,
    /// `SCORPION_BAUD`, as written.
    pub baud: Option<String>,
    /// The per-user file's path (whether or not it exists).
    pub user_file: Option<PathBuf>,
}

impl Environment {
    /// The process's environment. An empty variable counts as unset.
    ///
    /// # Errors
    /// [`Error::Environment`] for a `SCORPION_*` variable that is not
    /// text (UTF-8): treated as unset, a port given that way would be
    /// replaced by another without a word.
    pub fn from_process() -> Result<Environment, Error> {
        let [port, baud, xdg, home] = VARIABLES;
        let var = |name: &'static str| match std::env::var(name) {
            Ok(value) => Ok(Some(value).filter(|v| !v.is_empty())),
            Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(value)) => Err(Error::Environment {
                name,
                value: value.to_string_lossy().into_owned(),
                expected: "text (UTF-8)",
            }),
        };
        // The per-user file's directory is a path, which need not be text.
        let base = std::env::var_os(xdg)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| std::env::var_os(home).map(|h| PathBuf::from(h).join(".config")));
        Ok(Environment {
            port: var(port)?,
            baud: var(baud)?,
            user_file: base.map(|base| base.join("scorpion").join("config.toml")),
        })
    }
}

/// Every setting of a command, resolved.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The project found from the working directory up, if any.
    pub project: Option<Project>,
    /// The robot's port, if any source names one.
    pub port: Option<Sourced<String>>,
    /// The line's baud rate.
    pub baud: Sourced<u32>,
    /// The virtual robot's cards (paths relative to [`Resolved::base`]).
    pub cards: Sourced<Vec<CardArg>>,
    /// The virtual robot's surroundings script.
    pub world: Option<Sourced<PathBuf>>,
    /// The ROM profile the virtual robot runs (a path to read as it is).
    pub rom: Option<Sourced<PathBuf>>,
    /// The per-user file's path, whether or not it exists.
    pub user_file: Option<PathBuf>,
}

/// The per-user file read, with its text for lines.
struct UserFile {
    shown: String,
    text: String,
    settings: UserSettings,
}

fn user_file(path: Option<&Path>) -> crate::Result<Option<UserFile>> {
    let Some(path) = path else {
        return Ok(None);
    };
    let text = match hostfs::read_text(path, hostfs::TEXT) {
        Ok(text) => text,
        Err(error) if error.is_not_found() => return Ok(None),
        Err(error) => return Err(error.into()),
    };
    let shown = path.display().to_string();
    let settings: UserSettings = toml::from_str(&text).map_err(|error| {
        Located::toml(
            &shown,
            &text,
            &error,
            "the per-user file holds [robot] port and baud (docs/PROJECT.md)",
        )
    })?;
    Ok(Some(UserFile {
        shown,
        text,
        settings,
    }))
}

/// `[robot]` spans of a file (either kind).
fn robot_spans(text: &str) -> RobotSpans {
    #[derive(Deserialize, Default)]
    struct Outer {
        #[serde(default)]
        robot: RobotSpans,
    }
    toml::from_str::<Outer>(text).unwrap_or_default().robot
}

fn line_of(text: &str, span: Option<std::ops::Range<usize>>) -> usize {
    span.map_or(0, |span| crate::error::line_col(text, span.start).0)
}

impl Resolved {
    /// Resolves every setting for a command run in `cwd` with `flags`.
    ///
    /// # Errors
    /// A project or per-user file that cannot be read, at its line; a
    /// variable that cannot be used; a card the project names wrongly.
    pub fn resolve(flags: &Flags, env: &Environment, cwd: &Path) -> crate::Result<Resolved> {
        let project = Project::around(cwd)?;
        let user = user_file(env.user_file.as_deref())?;
        let user_spans = user.as_ref().map(|u| robot_spans(&u.text));
        let project_spans = project.as_ref().map(|p| robot_spans(p.text()));
        let at_user = |pick: fn(&RobotSpans) -> Option<std::ops::Range<usize>>| {
            let user = user.as_ref()?;
            Some(Origin::UserFile {
                path: user.shown.clone(),
                line: line_of(&user.text, user_spans.as_ref().and_then(pick)),
            })
        };
        let at_project = |pick: fn(&RobotSpans) -> Option<std::ops::Range<usize>>| {
            let project = project.as_ref()?;
            Some(Origin::Project {
                path: project.shown().to_owned(),
                line: line_of(project.text(), project_spans.as_ref().and_then(pick)),
            })
        };
        let port_span: fn(&RobotSpans) -> Option<std::ops::Range<usize>> =
            |s| s.port.as_ref().map(toml::Spanned::span);
        let baud_span: fn(&RobotSpans) -> Option<std::ops::Range<usize>> =
            |s| s.baud.as_ref().map(toml::Spanned::span);

        let port = if let Some(port) = &flags.port {
            Some(Sourced {
                value: port.clone(),
                origin: Origin::Flag("--port"),
            })
        } else if let Some(port) = &env.port {
            Some(Sourced {
                value: port.clone(),
                origin: Origin::Env("SCORPION_PORT"),
            })
        } else if let Some(port) = user.as_ref().and_then(|u| u.settings.robot.port.clone()) {
            at_user(port_span).map(|origin| Sourced {
                value: port,
                origin,
            })
        } else if let Some(port) = project.as_ref().and_then(|p| p.file.robot.port.clone()) {
            at_project(port_span).map(|origin| Sourced {
                value: port,
                origin,
            })
        } else {
            None
        };

        let baud = if let Some(baud) = flags.baud {
            Sourced {
                value: baud,
                origin: Origin::Flag("--baud"),
            }
        } else if let Some(text) = &env.baud {
            let value = text.trim().parse().map_err(|_| Error::Environment {
                name: "SCORPION_BAUD",
                value: text.clone(),
                expected: "a baud rate (9600)",
            })?;
            Sourced {
                value,
                origin: Origin::Env("SCORPION_BAUD"),
            }
        } else if let Some((value, origin)) = user
            .as_ref()
            .and_then(|u| u.settings.robot.baud)
            .and_then(|b| Some((b, at_user(baud_span)?)))
        {
            Sourced { value, origin }
        } else if let Some((value, origin)) = project
            .as_ref()
            .and_then(|p| p.file.robot.baud)
            .and_then(|b| Some((b, at_project(baud_span)?)))
        {
            Sourced { value, origin }
        } else {
            Sourced {
                value: platform::line::DEFAULT_BAUD,
                origin: Origin::Default,
            }
        };

        // An empty port or a rate of 0 is a slip wherever it was written,
        // said where it was, not when a command first opens the line.
        if let Some(port) = port.as_ref().filter(|p| p.value.trim().is_empty()) {
            return Err(Error::Setting {
                what: "port",
                value: port.value.clone(),
                origin: port.origin.to_string(),
                expected: "a serial port (/dev/ttyUSB0) or `emu`".into(),
            });
        }
        // The robot's 6551 runs at its standard rates only: any other is
        // a slip (hostile10 F15: `--baud 1` went on to a silent line).
        if platform::acia::baud_code(baud.value).is_none() {
            return Err(Error::Setting {
                what: "baud",
                value: baud.value.to_string(),
                origin: baud.origin.to_string(),
                expected: format!(
                    "a rate the robot's 6551 runs at ({})",
                    platform::acia::rates_text()
                ),
            });
        }

        let cards = if !flags.cards.is_empty() {
            Sourced {
                value: flags.cards.clone(),
                origin: Origin::Flag("--card"),
            }
        } else if let Some(project) = project.as_ref().filter(|p| !p.file.robot.cards.is_empty()) {
            let mut cards = Vec::new();
            for card in &project.file.robot.cards {
                let arg: CardArg = card.parse().map_err(|why: String| {
                    let span = project_spans
                        .as_ref()
                        .and_then(|s| s.cards.as_ref().map(toml::Spanned::span))
                        .unwrap_or(0..0);
                    Located::new(
                        project.shown(),
                        project.text(),
                        span,
                        format!("[robot] cards: `{card}`: {why}"),
                        "a card is FILE or FILE@ADDR (hex), relative to the project",
                    )
                })?;
                cards.push(arg);
            }
            Sourced {
                value: cards,
                origin: at_project(|s| s.cards.as_ref().map(toml::Spanned::span))
                    .unwrap_or(Origin::Default),
            }
        } else {
            Sourced {
                value: Vec::new(),
                origin: Origin::Default,
            }
        };

        let world = if let Some(world) = &flags.world {
            Some(Sourced {
                value: world.clone(),
                origin: Origin::Flag("--world"),
            })
        } else {
            project.as_ref().and_then(|p| {
                let world = p.file.robot.world.as_ref()?;
                Some(Sourced {
                    value: PathBuf::from(world),
                    origin: at_project(|s| s.world.as_ref().map(toml::Spanned::span))?,
                })
            })
        };

        let rom = if let Some(rom) = &flags.rom {
            Some(Sourced {
                value: rom.clone(),
                origin: Origin::Flag("--rom"),
            })
        } else {
            project.as_ref().and_then(|p| {
                let rom = p.file.robot.rom.as_ref()?;
                Some(Sourced {
                    value: p.root.join(rom),
                    origin: at_project(|s| s.rom.as_ref().map(toml::Spanned::span))?,
                })
            })
        };

        Ok(Resolved {
            project,
            port,
            baud,
            cards,
            world,
            rom,
            user_file: env.user_file.clone(),
        })
    }

    /// The directory a setting's relative paths are read from: the
    /// project's root for the project's settings, else the working
    /// directory (`None`).
    #[must_use]
    pub fn base(&self, origin: &Origin) -> Option<&Path> {
        match origin {
            Origin::Project { .. } => self.project.as_ref().map(|p| p.root.as_path()),
            _ => None,
        }
    }

    /// The robot's port, for a command that needs one.
    ///
    /// # Errors
    /// [`Error::NoPort`], saying every place one may be given.
    pub fn port(&self) -> crate::Result<&Sourced<String>> {
        self.port.as_ref().ok_or_else(|| Error::NoPort {
            user: self.user_file.as_ref().map_or_else(
                || "~/.config/scorpion/config.toml".to_owned(),
                |path| path.display().to_string(),
            ),
        })
    }

    /// Whether the port (if any) names the virtual Scorpion.
    #[must_use]
    pub fn is_emulated(&self) -> bool {
        self.port.as_ref().is_some_and(|p| p.value == EMU)
    }

    /// Every setting as `(key, value, origin)`, for `scorpion config`.
    #[must_use]
    pub fn rows(&self) -> Vec<(&'static str, String, String)> {
        let mut rows = vec![(
            "project",
            self.project
                .as_ref()
                .map_or_else(|| "(none)".to_owned(), |p| p.shown().to_owned()),
            if self.project.is_some() {
                "found from the working directory up".to_owned()
            } else {
                "no Scorpion.toml here or above".to_owned()
            },
        )];
        rows.push((
            "user file",
            self.user_file.as_ref().map_or_else(
                || "(none: neither XDG_CONFIG_HOME nor HOME is set)".to_owned(),
                |p| p.display().to_string(),
            ),
            match &self.user_file {
                Some(path) if path.is_file() => "read".to_owned(),
                Some(_) => "absent".to_owned(),
                None => String::new(),
            },
        ));
        rows.push(match &self.port {
            Some(port) => ("port", port.value.clone(), port.origin.to_string()),
            None => ("port", "(none)".to_owned(), Origin::Default.to_string()),
        });
        rows.push((
            "baud",
            self.baud.value.to_string(),
            self.baud.origin.to_string(),
        ));
        let cards: Vec<String> = self
            .cards
            .value
            .iter()
            .map(|card| match card.base {
                Some(base) => format!("{}@{base:04X}", card.path.display()),
                None => card.path.display().to_string(),
            })
            .collect();
        rows.push((
            "cards",
            if cards.is_empty() {
                "(none)".to_owned()
            } else {
                cards.join(", ")
            },
            self.cards.origin.to_string(),
        ));
        let path_row = |key, value: &Option<Sourced<PathBuf>>, none: &str| match value {
            Some(v) => (key, shown(&v.value), v.origin.to_string()),
            None => (key, none.to_owned(), Origin::Default.to_string()),
        };
        rows.push(path_row("world", &self.world, "(none)"));
        rows.push(path_row("rom", &self.rom, "(the reference ROM)"));
        rows
    }
}
