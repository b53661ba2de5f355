//! `--card FILE[@ADDR]` and `--world FILE`: what the virtual Scorpion has
//! around it besides the ROM and the images (KIM-bus cards and the
//! surroundings, as scripts), for every command that runs it.

use std::io::Write;
use std::path::{Path, PathBuf};

use cards::{CardArg, Printed, ScriptCard, ScriptWorld};
use miette::Context;
use romlib::VirtualScorpion;

/// Cards and surroundings of the virtual Scorpion.
#[derive(Debug, Clone, Default, clap::Args)]
pub(crate) struct Rig {
    /// A KIM-bus card, a Rhai script (docs/CARDS.md), at the script's
    /// `BASE` or at ADDR (hex); repeat for more cards.
    #[arg(long = "card", value_name = "FILE[@ADDR]")]
    pub(crate) cards: Vec<CardArg>,
    /// The robot's surroundings, a Rhai script that closes bumpers and
    /// lights the phototransistors over robot time (docs/CARDS.md).
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
}

fn read(root: Option<&Path>, path: &Path) -> miette::Result<String> {
    let full = root.map_or_else(|| path.to_path_buf(), |root| root.join(path));
    hostfs::read_text(&full, hostfs::TEXT)
        .wrap_err_with(|| format!("cannot read the script {}", path.display()))
}

impl Rig {
    /// Maps the cards into `robot`'s KIM bus and gives it the
    /// surroundings, saying on stderr where each card went. Returns each
    /// script's name and what it prints.
    pub(crate) fn apply(
        &self,
        robot: &mut VirtualScorpion,
    ) -> miette::Result<Vec<(String, Printed)>> {
        self.attach(robot, &mut |name, start, end| {
            let _ = writeln!(std::io::stderr(), "card {name}: ${start:04X}-${end:04X}");
        })
    }

    /// [`Rig::apply`], telling `mapped` (name, first and last address)
    /// where each card went instead of saying it (the debugger builds the
    /// robot again for every step back, without a word).
    pub(crate) fn attach(
        &self,
        robot: &mut VirtualScorpion,
        mapped: &mut dyn FnMut(&str, u16, u16),
    ) -> miette::Result<Vec<(String, Printed)>> {
        let mut printed = Vec::new();
        for card in &self.cards {
            let name = card.path.display().to_string();
            let text = read(self.root.as_deref(), &card.path)?;
            let script = ScriptCard::load(&name, &text, card.base)?;
            let (start, end) = script.window();
            printed.push((name.clone(), script.printed()));
            robot
                .map_card(start, end, Box::new(script))
                .wrap_err_with(|| {
                    format!("cannot put the card {name} at ${start:04X}-${end:04X}")
                })?;
            mapped(&name, start, end);
        }
        if let Some(path) = &self.world {
            let name = path.display().to_string();
            let text = read(self.world_root.as_deref(), path)?;
            let world = ScriptWorld::load(&name, &text)?;
            printed.push((name, world.printed()));
            robot.set_surroundings(Box::new(world));
        }
        Ok(printed)
    }
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
