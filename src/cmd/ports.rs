//! `scorpion ports`: list the serial ports a robot could be on; and the one
//! place the CLI turns a `--port` value into a transport.

use std::process::ExitCode;

use miette::IntoDiagnostic;
use romlib::VirtualScorpion;
use uploader::Transport;
use uploader::transport::{SerialTransport, VirtualTransport, list_ports};

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

/// The line to a robot, for every command that talks to one.
#[derive(Debug, clap::Args)]
pub(crate) struct Line {
    /// The serial port the robot is on (`scorpion ports` lists them), or
    /// `emu` for the virtual Scorpion in this process.
    #[arg(long)]
    pub(crate) port: String,
    /// The line's baud rate (the robot's).
    #[arg(long, default_value_t = DEFAULT_BAUD)]
    pub(crate) baud: u32,
    /// The virtual Scorpion's cards and surroundings (with `--port emu`,
    /// and for `upload`'s rehearsal).
    #[command(flatten)]
    pub(crate) rig: crate::cmd::rig::Rig,
}

impl Line {
    /// Whether `--port` names the virtual Scorpion in this process.
    pub(crate) fn is_emulated(&self) -> bool {
        self.port == EMU
    }

    /// Opens the line: see [`open`].
    pub(crate) fn open(&self) -> miette::Result<Box<dyn Transport>> {
        open(&self.port, self.baud, &self.rig)
    }
}

/// The default baud rate: the board's as shipped (docs/PROTOCOL.md section 3).
pub(crate) const DEFAULT_BAUD: u32 = platform::line::DEFAULT_BAUD;

/// The `--port` value that names the in-process virtual Scorpion.
pub(crate) const EMU: &str = "emu";

/// A fresh virtual Scorpion whose DIP switches and host line are at `baud`,
/// with the cards and surroundings of `rig`, running the ROM profile `rom`
/// (its name and linked image) or the reference ROM.
pub(crate) fn virtual_robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
    rig: &crate::cmd::rig::Rig,
) -> miette::Result<VirtualScorpion> {
    let mut robot = match rom {
        Some((name, image)) => VirtualScorpion::with_rom(name, image)?,
        None => VirtualScorpion::new(),
    };
    // A fresh robot runs at the reference rate already: no second boot.
    if robot.host_baud() != baud && !robot.set_baud(baud) {
        miette::bail!(
            help = "the 6551 runs at 50 to 19200 baud; the reference ROM's rate is 9600",
            "the Scorpion's 6551 has no {baud} baud rate"
        );
    }
    // What their scripts print is shown by `scorpion sim` only.
    let _printed = rig.apply(&mut robot)?;
    Ok(robot)
}

/// [`virtual_robot`] without the cards' and surroundings' scripts.
pub(crate) fn bare_robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
) -> miette::Result<VirtualScorpion> {
    virtual_robot(baud, rom, &crate::cmd::rig::Rig::default())
}

/// Opens `--port`: a serial device path, or `emu` for a fresh virtual
/// Scorpion in this process (the transport's clock is then its emulated
/// time) with the cards and surroundings of `rig`.
pub(crate) fn open(
    port: &str,
    baud: u32,
    rig: &crate::cmd::rig::Rig,
) -> miette::Result<Box<dyn Transport>> {
    if port == EMU {
        return Ok(Box::new(VirtualTransport::new(virtual_robot(
            baud, None, rig,
        )?)));
    }
    if !rig.is_empty() {
        miette::bail!(
            help = "cards and surroundings are scripts the virtual Scorpion runs: use them with `--port emu`, or with `upload`, whose rehearsal on the virtual Scorpion comes first",
            "--card and --world do not apply to the robot on {port}"
        );
    }
    Ok(Box::new(SerialTransport::open(port, baud)?))
}
