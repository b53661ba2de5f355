//! `scorpion config`: what a command run here would use, and where each
//! setting came from; and the CLI's side of the one resolution
//! (`scorpion-project`'s [`Resolved`]): the flags every command shares,
//! and the virtual robot and images made from what was resolved.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use scorpion_project::{Environment, Flags, Origin, Resolved};

use crate::cmd::rig::Rig;

/// Show the configuration a command run here resolves: the project, the
/// per-user file, the robot's port and baud rate, the virtual robot's
/// cards, world and ROM, each with where it came from (a flag, the
/// environment, the per-user file's or the project's line, the default).
///
/// Precedence: flags, then SCORPION_PORT and SCORPION_BAUD, then the
/// per-user file, then Scorpion.toml, then the defaults (docs/PROJECT.md).
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The serial port, as a command would be given it.
    #[arg(
        long,
        value_name = "PORT",
        num_args = 0..=1,
        default_missing_value = crate::cmd::ports::CONFIGURED,
        value_parser = crate::cmd::ports::port_value
    )]
    port: Option<String>,
    /// The baud rate, as a command would be given it.
    #[arg(long)]
    baud: Option<u32>,
    /// A ROM profile, as `sim`, `debug` would be given it.
    #[arg(long, value_name = "ELF")]
    rom: Option<PathBuf>,
    /// Cards and surroundings, as a command would be given them.
    #[command(flatten)]
    rig: Rig,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let resolved = resolve(&flags(
        args.port.as_ref(),
        args.baud,
        &args.rig,
        args.rom.as_ref(),
    ))?;
    let mut rows = resolved.rows();
    // A workspace has no robot of its own: say it is one.
    if resolved.project.is_none()
        && let Ok(scorpion_project::Found::Workspace(workspace)) = scorpion_project::Found::here()
    {
        rows[0] = (
            "project",
            "(none)".to_owned(),
            format!(
                "{} is a workspace of {}: run this in a member's directory",
                scorpion_project::shown(&workspace.root.join(scorpion_project::FILE)),
                workspace.member_names().join(", ")
            ),
        );
    }
    let width = rows.iter().map(|(key, _, _)| key.len()).max().unwrap_or(0);
    let mut out = std::io::stdout().lock();
    for (key, value, origin) in rows {
        if origin.is_empty() {
            writeln!(out, "{key:<width$}  {value}").into_diagnostic()?;
        } else {
            writeln!(out, "{key:<width$}  {value}  ({origin})").into_diagnostic()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The command line's flags, for the resolution.
pub(crate) fn flags(
    port: Option<&String>,
    baud: Option<u32>,
    rig: &Rig,
    rom: Option<&PathBuf>,
) -> Flags {
    Flags {
        // A bare `--port` (as `test --port` takes it): the configured one.
        port: crate::cmd::ports::given_port(port).cloned(),
        baud,
        cards: rig.cards.clone(),
        world: rig.world.clone(),
        rom: rom.cloned(),
    }
}

/// Resolves `flags` for a command run in the working directory.
pub(crate) fn resolve(flags: &Flags) -> miette::Result<Resolved> {
    let here = std::env::current_dir()
        .into_diagnostic()
        .wrap_err("cannot read the current directory")?;
    resolve_in(flags, &here)
}

/// Resolves `flags` for a command run in `here`.
pub(crate) fn resolve_in(flags: &Flags, here: &Path) -> miette::Result<Resolved> {
    Ok(Resolved::resolve(
        flags,
        &Environment::from_process()?,
        here,
    )?)
}

/// The virtual robot's cards and surroundings, each read from where its
/// source says.
pub(crate) fn rig(resolved: &Resolved) -> Rig {
    Rig::from(scorpion_project::runner::Rig::of(resolved))
}

/// The ROM profile the virtual robot runs: its name and linked image.
pub(crate) fn rom(resolved: &Resolved) -> miette::Result<Option<(String, linker::Image)>> {
    Ok(scorpion_project::runner::rig::rom(resolved)?)
}

/// The uploader's profile of the ROM the robot runs: the project's ROM
/// profile, or the reference ROM's.
pub(crate) fn profile(
    rom: Option<&(String, linker::Image)>,
) -> miette::Result<uploader::RomProfile> {
    Ok(match rom {
        Some((name, image)) => uploader::RomProfile::from_rom_image(name, image)?,
        None => uploader::RomProfile::reference(),
    })
}

/// The images a virtual robot starts with, and where they came from.
#[derive(Debug, Default)]
pub(crate) struct Images {
    /// Each image's name (its path, or its name in the project) and
    /// linked image, in load order.
    pub(crate) images: Vec<(String, linker::Image)>,
    /// Whether they are the project's, built (none was given).
    pub(crate) from_project: bool,
}

/// The images a virtual robot starts with: those given (`--image`), else,
/// in a project, the project's, built.
pub(crate) fn images(resolved: &Resolved, given: &[PathBuf]) -> miette::Result<Images> {
    let mut images = Vec::new();
    if !given.is_empty() {
        for path in given {
            let name = path.display().to_string();
            let bytes = hostfs::read(path, hostfs::BINARY)
                .wrap_err_with(|| format!("cannot read {name}"))?;
            images.push((name.clone(), linker::Image::parse(&name, &bytes)?));
        }
        return Ok(Images {
            images,
            from_project: false,
        });
    }
    if let Some(project) = &resolved.project {
        for spec in &project.file.images {
            let built = scorpion_project::runner::build::build(project, spec)?;
            images.push((built.name.clone(), built.linked.image));
        }
    } else if let Ok(scorpion_project::Found::Workspace(workspace)) =
        scorpion_project::Found::here()
    {
        // A workspace has no robot of its own: the robot runs bare, and
        // says so, rather than seem to have lost the members' images.
        let _ = writeln!(
            std::io::stderr(),
            "note: {} is a workspace of {}: the virtual Scorpion runs with no image (run this in a member's directory for its images, or give --image)",
            scorpion_project::shown(&workspace.root.join(scorpion_project::FILE)),
            workspace.member_names().join(", ")
        );
    }
    Ok(Images {
        from_project: resolved.project.is_some(),
        images,
    })
}

/// A note on stderr when the command line gave the virtual robot's parts
/// to a command that talks to a real robot only: they are not an error
/// (the project's are never one), but nothing used them.
pub(crate) fn note_unused_rig(resolved: &Resolved) {
    let mut unused = Vec::new();
    if matches!(resolved.cards.origin, Origin::Flag(_)) {
        unused.push("--card");
    }
    if resolved
        .world
        .as_ref()
        .is_some_and(|w| matches!(w.origin, Origin::Flag(_)))
    {
        unused.push("--world");
    }
    if unused.is_empty() || resolved.is_emulated() {
        return;
    }
    let _ = writeln!(
        std::io::stderr(),
        "note: {} {} to the virtual Scorpion (`--port emu`, `sim`, an upload's rehearsal); the robot on {} has its own",
        unused.join(" and "),
        if unused.len() == 1 {
            "belongs"
        } else {
            "belong"
        },
        resolved
            .port
            .as_ref()
            .map_or("the port", |p| p.value.as_str())
    );
}
