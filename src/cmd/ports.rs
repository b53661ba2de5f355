//! `scorpion ports`: list the serial ports a robot could be on; and the one
//! place the CLI turns a `--port` value into a transport.

use std::process::ExitCode;

use miette::IntoDiagnostic;
use uploader::Transport;
use uploader::transport::{SerialTransport, list_ports};

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
    Ok(ExitCode::SUCCESS)
}

/// The default baud rate: the reference ROM's (PLATFORM.md section 3).
pub(crate) const DEFAULT_BAUD: u32 = 9600;

/// Opens `--port`: a serial device path.
pub(crate) fn open(port: &str, baud: u32) -> miette::Result<Box<dyn Transport>> {
    Ok(Box::new(SerialTransport::open(port, baud)?))
}
