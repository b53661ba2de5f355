//! `--card FILE[@ADDR]` and `--world FILE`: what the virtual Scorpion has
//! around it besides the ROM and the images (KIM-bus cards and the
//! surroundings, as scripts), for every command that runs it; the flags of
//! the library's [`scorpion_project::runner::Rig`], which loads them.

use std::io::Write;
use std::path::PathBuf;

use cards::{CardArg, Printed};
use romlib::VirtualScorpion;

/// Cards and surroundings of the virtual Scorpion.
#[derive(Debug, Clone, Default, clap::Args)]
pub(crate) struct Rig {
    /// A KIM-bus card, a Rhai script (docs/CARDS.md), at the script's
    /// `BASE` or at ADDR (hex); repeat for more cards.
    #[arg(long = "card", value_name = "FILE[@ADDR]")]
    pub(crate) cards: Vec<CardArg>,
    /// The robot's surroundings: a Rhai script that closes bumpers and
    /// lights the phototransistors over robot time (docs/CARDS.md), or a
    /// world file (`.toml`: a room with obstacles and floor lines, the
    /// robot's pose following its motors; docs/WORLD.md).
    #[arg(long = "world", value_name = "FILE")]
    pub(crate) world: Option<PathBuf>,
    /// The directory the cards' relative paths are read from (a
    /// project's root); the paths are shown as given.
    #[arg(skip)]
    pub(crate) root: Option<PathBuf>,
    /// The directory the world's relative path is read from: each part
    /// may come from its own source (`--world` with the project's cards).
    #[arg(skip)]
    pub(crate) world_root: Option<PathBuf>,
    /// The room of a world file, once a robot has it.
    #[arg(skip)]
    pub(crate) room: scorpion_project::runner::rig::RoomSlot,
}

impl Rig {
    /// The library's rig: the same cards, world and directories.
    pub(crate) fn plain(&self) -> scorpion_project::runner::Rig {
        scorpion_project::runner::Rig {
            cards: self.cards.clone(),
            world: self.world.clone(),
            root: self.root.clone(),
            world_root: self.world_root.clone(),
            room: self.room.clone(),
        }
    }

    /// Maps the cards into `robot`'s KIM bus and gives it the
    /// surroundings, saying on stderr where each card went. Returns each
    /// script's name and what it prints.
    pub(crate) fn apply(
        &self,
        robot: &mut VirtualScorpion,
    ) -> miette::Result<Vec<(String, Printed)>> {
        self.attach(robot, &mut say_mapped)
    }

    /// [`Rig::apply`], telling `mapped` (name, first and last address)
    /// where each card went instead of saying it (the debugger builds the
    /// robot again for every step back, without a word).
    pub(crate) fn attach(
        &self,
        robot: &mut VirtualScorpion,
        mapped: &mut dyn FnMut(&str, u16, u16),
    ) -> miette::Result<Vec<(String, Printed)>> {
        Ok(self.plain().attach(robot, mapped)?)
    }
}

impl From<scorpion_project::runner::Rig> for Rig {
    fn from(rig: scorpion_project::runner::Rig) -> Rig {
        Rig {
            cards: rig.cards,
            world: rig.world,
            root: rig.root,
            world_root: rig.world_root,
            room: rig.room,
        }
    }
}

/// Says on stderr where a card went.
pub(crate) fn say_mapped(name: &str, start: u16, end: u16) {
    let _ = writeln!(std::io::stderr(), "card {name}: ${start:04X}-${end:04X}");
}

/// Shows on stderr what the scripts printed, a line each, after the
/// script's name.
pub(crate) fn show_printed(printed: &[(String, Printed)]) {
    let mut err = std::io::stderr().lock();
    for (name, lines) in printed {
        for line in lines.take() {
            let _ = writeln!(err, "{name}: {line}");
        }
    }
}

/// Where `--path FILE.svg` draws, checked before the run: the robot needs
/// a room (`room`, the rig's view of it) and FILE must be one
/// [`check_path`] takes, so that a long run does not end in "cannot
/// write".
pub(crate) fn path_picture<V>(
    path: Option<&PathBuf>,
    room: Option<V>,
) -> miette::Result<Option<(&PathBuf, V)>> {
    let Some(path) = path else {
        return Ok(None);
    };
    check_path(path)?;
    let room = room.ok_or_else(|| {
        miette::miette!(
            help = "give a world file: `--world room.toml` (docs/WORLD.md)",
            "--path draws the robot in its room, and the robot has none"
        )
    })?;
    Ok(Some((path, room)))
}

/// The pictures `--path` draws, by the extension that asks for each (any
/// case).
const PICTURE_EXTENSIONS: [&str; 2] = ["svg", "png"];

/// `--path` names a picture (`.svg` or `.png`: anything else would get an
/// SVG under a name that says otherwise) in a directory that exists (it
/// is not created: a mistyped directory would scatter pictures), and is
/// not a FIFO or a device.
pub(crate) fn check_path(path: &std::path::Path) -> miette::Result<()> {
    let picture = path.extension().is_some_and(|extension| {
        PICTURE_EXTENSIONS
            .iter()
            .any(|known| extension.eq_ignore_ascii_case(known))
    });
    if !picture {
        return Err(miette::miette!(
            help = "end the path in .svg (the picture as SVG text) or .png (rasterized)",
            "--path {}: a picture is .svg or .png",
            path.display()
        ));
    }
    let directory = path
        .parent()
        .filter(|parent| !parent.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    // An existing FIFO or device would block the write (or eat it) at
    // the end of a long run: only a regular file is replaced.
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
    {
        return Err(miette::miette!(
            help = "give the path of a file (it is created or replaced)",
            "--path {}: not a regular file",
            path.display()
        ));
    }
    if directory.is_dir() {
        Ok(())
    } else {
        Err(miette::miette!(
            help = "make the directory first, or give a path in one that exists",
            "--path {}: the directory {} does not exist",
            path.display(),
            directory.display()
        ))
    }
}

/// Writes the picture `bytes` to `path` through a temporary file in its
/// directory renamed over it: a write that fails (a full disk, a file
/// size limit) leaves what was there, not half a picture.
pub(crate) fn write_picture(path: &std::path::Path, bytes: &[u8]) -> miette::Result<()> {
    use miette::Context as _;
    hostfs::write(path, bytes)
        .wrap_err_with(|| format!("cannot write the path to {}", path.display()))
}
