//! `scorpion ports`: list the serial ports a robot could be on; and the one
//! place the CLI turns a `--port` value into a transport.

use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use romlib::VirtualScorpion;
use uploader::transport::{SerialTransport, VirtualTransport, list_ports};
use uploader::{RomProfile, Transport};

/// List the serial ports of this machine.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {}

pub(crate) fn run(_args: &Args) -> miette::Result<ExitCode> {
    let ports = list_ports()?;
    let mut out = std::io::stdout().lock();
    use std::io::Write;
    if ports.is_empty() {
        writeln!(out, "no serial ports found").into_diagnostic()?;
    }
    for port in ports {
        writeln!(out, "{}\t{}", port.path, port.description).into_diagnostic()?;
    }
    writeln!(
        out,
        "{EMU}\tthe virtual Scorpion in this process (the reference ROM, emulated)"
    )
    .into_diagnostic()?;
    Ok(ExitCode::SUCCESS)
}

/// The line to a robot, for every command that talks to one. Each value
/// not given here comes from the environment, the per-user file or the
/// project (`scorpion config` shows what was resolved, and from where).
#[derive(Debug, clap::Args)]
pub(crate) struct Line {
    /// The serial port the robot is on (`scorpion ports` lists them), or
    /// `emu` for the virtual Scorpion in this process [env: SCORPION_PORT;
    /// else the per-user file's or Scorpion.toml's [robot] port]. Without
    /// a value, as `test --port`: the configured one.
    #[arg(
        long,
        value_name = "PORT",
        num_args = 0..=1,
        default_missing_value = CONFIGURED,
        value_parser = port_value
    )]
    pub(crate) port: Option<String>,
    /// The line's baud rate (the robot's) [env: SCORPION_BAUD; else the
    /// per-user file's or Scorpion.toml's [robot] baud; default 9600].
    #[arg(long)]
    pub(crate) baud: Option<u32>,
    /// The virtual Scorpion's cards and surroundings (with `--port emu`,
    /// and for `upload`'s rehearsal; else the project's [robot] cards and
    /// world). A real robot has its own: they never stop work on one.
    #[command(flatten)]
    pub(crate) rig: crate::cmd::rig::Rig,
}

impl Line {
    /// Resolves these flags with the environment, the per-user file and
    /// the project.
    pub(crate) fn resolve(&self) -> miette::Result<scorpion_project::Resolved> {
        crate::cmd::config::resolve(&crate::cmd::config::flags(
            self.port.as_ref(),
            self.baud,
            &self.rig,
            None,
        ))
    }
}

/// Opens the line to the robot `resolved` names: a serial port, or `emu`
/// for a fresh virtual Scorpion with the resolved cards, surroundings and
/// ROM profile, and `images` loaded as an upload leaves them.
pub(crate) fn open_resolved(
    resolved: &scorpion_project::Resolved,
    images: &[(String, linker::Image)],
) -> miette::Result<Box<dyn Transport>> {
    let port = resolved.port()?;
    if port.value == EMU {
        let rom = crate::cmd::config::rom(resolved)?;
        let (mut robot, shown) = virtual_robot(
            resolved.baud.value,
            rom.as_ref(),
            &crate::cmd::config::rig(resolved),
        )?;
        for (name, image) in images {
            robot
                .load_image(image)
                .wrap_err_with(|| format!("cannot load {name}"))?;
        }
        return Ok(Box::new(Showing::new(VirtualTransport::new(robot), shown)));
    }
    // A port that came from a file or the environment is named with
    // where it came from: a stale one is otherwise a mystery.
    let origin = &port.origin;
    let opened = SerialTransport::open(&port.value, resolved.baud.value);
    match origin {
        // fresh21 F1: `ask --port /1X` takes `/1X` as the port; one that
        // is no device path is said to be --port's value, with the way to
        // give the configured port before the arguments.
        scorpion_project::Origin::Flag(_)
            if opened.is_err() && !scorpion_project::device_like(&port.value) =>
        {
            Ok(Box::new(
                opened.map_err(miette::Report::new).wrap_err_with(|| {
                    format!(
                        "--port took `{}` as the robot's serial port; {}",
                        port.value,
                        scorpion_project::BARE_PORT
                    )
                })?,
            ))
        }
        scorpion_project::Origin::Flag(_) => Ok(Box::new(opened?)),
        _ => Ok(Box::new(
            opened
                .map_err(miette::Report::new)
                .wrap_err_with(|| origin_of(resolved).unwrap_or_default())?,
        )),
    }
}

/// The value a bare `--port` seems to have taken from the arguments that
/// follow it (one that is no device's name), if any.
pub(crate) fn swallowed(args: impl Iterator<Item = String>) -> Option<String> {
    let args: Vec<String> = args.collect();
    args.windows(2)
        .find(|pair| {
            pair[0] == "--port"
                && !pair[1].starts_with('-')
                && !scorpion_project::device_like(&pair[1])
        })
        .map(|pair| pair[1].clone())
}

/// The robot `line` names, probed, for commands that only look at it
/// (`read`, `installed`): on `emu` the project's images installed as an
/// upload leaves them (else nothing would be there to look at), on a real
/// port the robot as it is (a note if cards or a world would go unused).
pub(crate) fn probed(
    line: &Line,
) -> miette::Result<(uploader::Client<Box<dyn Transport>>, RomProfile)> {
    probed_with(line, false)
}

/// [`probed`], for `rom read`, which makes the ROM profile a project
/// names: one that cannot be read is no reason to refuse (fresh21 F6), and
/// the robot is read with the reference ROM's pacing, said on stderr.
pub(crate) fn probed_for_rom(
    line: &Line,
) -> miette::Result<(uploader::Client<Box<dyn Transport>>, RomProfile)> {
    probed_with(line, true)
}

fn probed_with(
    line: &Line,
    reference_if_unreadable: bool,
) -> miette::Result<(uploader::Client<Box<dyn Transport>>, RomProfile)> {
    let resolved = line.resolve()?;
    let rom = match crate::cmd::config::rom(&resolved) {
        Err(error) if reference_if_unreadable => {
            crate::cmd::say_err(&format!(
                "note: {error}: the robot is read as the reference ROM's is\n"
            ));
            None
        }
        rom => rom?,
    };
    let images = if resolved.port()?.value == EMU {
        crate::cmd::config::images(&resolved, &[])?.images
    } else {
        crate::cmd::config::note_unused_rig(&resolved);
        Vec::new()
    };
    let transport = open_resolved(&resolved, &images)?;
    let profile = crate::cmd::config::profile(rom.as_ref())?;
    let mut client = uploader::client(transport, &profile);
    client.probe().map_err(|error| traced(error, &resolved))?;
    Ok((client, profile))
}

/// `error`, with where the port came from when it is a robot that does not
/// answer on a port a file or the environment named (fresh21 F7: a stale
/// setting whose device now belongs to something else only timed out).
pub(crate) fn traced(
    error: uploader::Error,
    resolved: &scorpion_project::Resolved,
) -> miette::Report {
    traced_report(miette::Report::new(error), resolved)
}

/// [`traced`] for an error already said as a report (an undo refused, a
/// command's answer), whose cause is a robot that does not answer.
pub(crate) fn traced_report(
    report: miette::Report,
    resolved: &scorpion_project::Resolved,
) -> miette::Report {
    let silent = report.chain().any(|cause| {
        let line = cause.downcast_ref::<uploader::Error>().or_else(|| {
            match cause.downcast_ref::<uploader::stub::StubError>() {
                Some(uploader::stub::StubError::Line(error)) => Some(error),
                _ => None,
            }
        });
        matches!(line, Some(uploader::Error::NoAnswer { .. }))
    });
    match origin_of(resolved) {
        Some(origin) if silent => report.wrap_err(origin),
        _ => report,
    }
}

/// `the port /dev/pts/8 is from the environment SCORPION_PORT`, where the
/// port came from a file or the environment (not from `--port PORT`).
pub(crate) fn origin_of(resolved: &scorpion_project::Resolved) -> Option<String> {
    resolved
        .port
        .as_ref()
        .filter(|port| !matches!(port.origin, scorpion_project::Origin::Flag(_)))
        .map(|port| format!("the port {} is from the {}", port.value, port.origin))
}

/// What a bare `--port` stands for: the port the environment, the per-user
/// file or the project names.
pub(crate) const CONFIGURED: &str = "(configured)";

/// A `--port` value: an empty one is refused (hostile21 F13: a script's
/// `--port "$ROBOT"` with `ROBOT` unset talked to the configured robot).
pub(crate) fn port_value(value: &str) -> Result<String, String> {
    if value.is_empty() {
        Err("an empty port: give one, or write --port alone (after the command's arguments) for the configured one".to_owned())
    } else {
        Ok(value.to_owned())
    }
}

/// `--port`'s value as the resolution takes it: `None` for a bare one.
pub(crate) fn given_port(port: Option<&String>) -> Option<&String> {
    port.filter(|port| port.as_str() != CONFIGURED)
}

/// The `--port` value that names the in-process virtual Scorpion.
pub(crate) const EMU: &str = scorpion_project::runner::EMU;

/// A fresh virtual Scorpion whose DIP switches and host line are at `baud`,
/// with the cards and surroundings of `rig` (where each card went said on
/// stderr), running the ROM profile `rom` (its name and linked image) or
/// the reference ROM; and what its scripts print, to be shown while it
/// runs.
pub(crate) fn virtual_robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
    rig: &crate::cmd::rig::Rig,
) -> miette::Result<(VirtualScorpion, Shown)> {
    let (robot, printed) = scorpion_project::runner::rig::virtual_robot(
        baud,
        rom,
        &rig.plain(),
        &mut crate::cmd::rig::say_mapped,
    )?;
    Ok((robot, Shown(printed)))
}

/// [`virtual_robot`] without the cards' and surroundings' scripts.
pub(crate) fn bare_robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
) -> miette::Result<VirtualScorpion> {
    virtual_robot(baud, rom, &crate::cmd::rig::Rig::default()).map(|(robot, _)| robot)
}

/// What the virtual robot's scripts print, shown on stderr (`NAME: line`,
/// as `scorpion sim` shows it) when asked and when dropped, so that no
/// command that runs the scripts keeps their output to itself.
pub(crate) struct Shown(pub(crate) Vec<(String, cards::Printed)>);

impl Shown {
    /// Shows what the scripts printed since the last look.
    pub(crate) fn show(&self) {
        crate::cmd::rig::show_printed(&self.0);
    }
}

impl Drop for Shown {
    fn drop(&mut self) {
        self.show();
    }
}

/// A line to the virtual robot that shows what its scripts print after
/// every exchange on it.
pub(crate) type Showing<T> = uploader::transport::Observed<T, Shown>;

impl uploader::transport::Exchanged for Shown {
    fn exchanged(&mut self) {
        self.show();
    }
}
