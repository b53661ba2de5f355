//! The virtual Scorpion a project's tests run on: the ROM profile, the
//! line's rate, and what it has around it besides the images (KIM-bus
//! cards and the surroundings, as scripts), as the one resolution gives
//! them ([`Resolved`]).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use cards::{CardArg, Printed, Room, RoomView, ScriptCard, ScriptWorld};
use romlib::VirtualScorpion;

use super::error::{Baud, Error, Result};

use crate::{Origin, Resolved};

/// The `--port` value that names the in-process virtual Scorpion.
pub const EMU: &str = "emu";

/// Cards and surroundings of the virtual Scorpion.
#[derive(Debug, Clone, Default)]
pub struct Rig {
    /// KIM-bus cards, Rhai scripts (docs/CARDS.md), each at its script's
    /// `BASE` or the address given.
    pub cards: Vec<CardArg>,
    /// The robot's surroundings: a Rhai script that closes bumpers and
    /// lights the phototransistors over robot time (docs/CARDS.md), or a
    /// world file (`.toml`: a room, docs/WORLD.md), which may name such a
    /// script beside it.
    pub world: Option<PathBuf>,
    /// The directory the cards' relative paths are read from (a
    /// project's root); the paths are shown as given.
    pub root: Option<PathBuf>,
    /// The directory the world's relative path is read from: each part
    /// may come from its own source (`--world` with the project's cards).
    pub world_root: Option<PathBuf>,
    /// The room of the last robot given a world file, seen from the host
    /// (its pose, trail and picture: `--path FILE.svg`).
    pub room: RoomSlot,
}

/// Where the host sees the room of a world file from, once a robot has
/// it: shared by the rig's copies.
#[derive(Debug, Clone, Default)]
pub struct RoomSlot(Arc<Mutex<Option<RoomView>>>);

impl RoomSlot {
    /// The room's view, if a robot was given a world file.
    pub fn get(&self) -> Option<RoomView> {
        self.0.lock().ok().and_then(|slot| slot.clone())
    }

    fn set(&self, view: RoomView) {
        if let Ok(mut slot) = self.0.lock() {
            *slot = Some(view);
        }
    }
}

/// Whether the world at `path` is a world file (a room: `.toml`) rather
/// than a world script.
#[must_use]
pub fn is_world_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "toml")
}

/// What each script of a robot prints, by the script's name.
pub type Scripts = Vec<(String, Printed)>;

fn read(root: Option<&Path>, path: &Path, what: &'static str) -> Result<String> {
    let full = root.map_or_else(|| path.to_path_buf(), |root| root.join(path));
    hostfs::read_text(&full, hostfs::TEXT).map_err(|source| Error::ScriptUnreadable {
        what,
        path: path.to_path_buf(),
        source,
    })
}

impl Rig {
    /// The virtual robot's cards and surroundings `resolved` names, each
    /// read from where its source says.
    pub fn of(resolved: &Resolved) -> Rig {
        Rig {
            cards: resolved.cards.value.clone(),
            world: resolved.world.as_ref().map(|w| w.value.clone()),
            root: resolved.base(&resolved.cards.origin).map(Path::to_path_buf),
            world_root: resolved
                .world
                .as_ref()
                .and_then(|w| resolved.base(&w.origin))
                .map(Path::to_path_buf),
            room: RoomSlot::default(),
        }
    }

    /// Maps the cards into `robot`'s KIM bus and gives it the
    /// surroundings, telling `mapped` (name, first and last address)
    /// where each card went. Returns each script's name and what it
    /// prints.
    pub fn attach(
        &self,
        robot: &mut VirtualScorpion,
        mapped: &mut dyn FnMut(&str, u16, u16),
    ) -> Result<Scripts> {
        let mut printed = Vec::new();
        for card in &self.cards {
            let name = card.path.display().to_string();
            let text = read(self.root.as_deref(), &card.path, "script")?;
            let script = ScriptCard::load(&name, &text, card.base)?;
            let (start, end) = script.window();
            printed.push((name.clone(), script.printed()));
            robot
                .map_card(start, end, Box::new(script))
                .map_err(|source| Error::CardPlacement {
                    card: name.clone(),
                    start,
                    end,
                    source,
                })?;
            mapped(&name, start, end);
        }
        if let Some(path) = &self.world {
            let name = path.display().to_string();
            let is_file = is_world_file(path);
            let what = if is_file {
                "world file"
            } else {
                "world script"
            };
            let text = read(self.world_root.as_deref(), path, what)?;
            if is_file {
                let mut room = Room::load(&name, &text)?;
                if let Some(script) = room.script_path() {
                    // Written relative to the world file.
                    let script = path.parent().unwrap_or(Path::new("")).join(script);
                    let full = self
                        .world_root
                        .as_deref()
                        .map_or_else(|| script.clone(), |root| root.join(&script));
                    // Said at the `script` key of the world file: that is
                    // what to change.
                    let text = hostfs::read_text(&full, hostfs::TEXT).map_err(|source| {
                        cards::room::file::script_error(
                            &name,
                            &text,
                            room.layout(),
                            format!("cannot read the world script: {source}"),
                        )
                    })?;
                    let name = script.display().to_string();
                    let world = ScriptWorld::load(&name, &text)?;
                    printed.push((name, world.printed()));
                    room.add(Box::new(world));
                }
                self.room.set(room.view());
                robot.set_surroundings(Box::new(room));
            } else {
                let world = ScriptWorld::load(&name, &text)?;
                printed.push((name, world.printed()));
                robot.set_surroundings(Box::new(world));
            }
        }
        Ok(printed)
    }
}

/// A fresh virtual Scorpion whose DIP switches and host line are at `baud`,
/// with the cards and surroundings of `rig` (each card's place told to
/// `mapped`), running the ROM profile `rom` (its name and linked image) or
/// the reference ROM; and what its scripts print.
pub fn virtual_robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
    rig: &Rig,
    mapped: &mut dyn FnMut(&str, u16, u16),
) -> Result<(VirtualScorpion, Scripts)> {
    let mut robot = match rom {
        Some((name, image)) => VirtualScorpion::with_rom(name, image)?,
        None => VirtualScorpion::new(),
    };
    // A fresh robot runs at the reference rate already: no second boot.
    if robot.host_baud() != baud && !robot.set_baud(baud) {
        return Err(Error::Baud(Box::new(Baud { baud })));
    }
    let printed = rig.attach(&mut robot, mapped)?;
    Ok((robot, printed))
}

/// The ROM profile the virtual robot runs, as `resolved` names it: its
/// name and linked image (`None`: the reference ROM).
pub fn rom(resolved: &Resolved) -> Result<Option<(String, linker::Image)>> {
    let Some(rom) = &resolved.rom else {
        return Ok(None);
    };
    let bytes =
        hostfs::read(&rom.value, hostfs::BINARY).map_err(|source| Error::RomUnreadable {
            path: rom.value.clone(),
            origin: rom.origin.to_string(),
            source,
        })?;
    let name = match &rom.origin {
        // The project's profile is named as its file writes it.
        Origin::Project { .. } => resolved
            .project
            .as_ref()
            .and_then(|p| p.file.robot.rom.clone())
            .unwrap_or_else(|| rom.value.display().to_string()),
        _ => rom.value.display().to_string(),
    };
    let image = linker::Image::parse(&name, &bytes)?;
    Ok(Some((name, image)))
}
