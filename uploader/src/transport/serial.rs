//! A real serial port (crate `serialport`): 8N1, no flow control, opened
//! exclusively so a terminal program cannot steal answers mid-upload.
//!
//! Everything runs on the caller's thread with short read timeouts: on
//! Windows a second thread on a cloned handle stalls (serialport-rs #14).

use std::io::{ErrorKind as IoKind, Read, Write};
use std::time::{Duration, Instant};

use serialport::{ClearBuffer, DataBits, ErrorKind, FlowControl, Parity, SerialPort, StopBits};

use super::Transport;
use crate::{Error, Result};

/// A serial port opened for talking to a robot.
pub struct SerialTransport {
    port: Box<dyn SerialPort>,
    path: String,
    baud: u32,
    opened: Instant,
    buffer: Vec<u8>,
    /// A pseudo-terminal: no line rate, the far end is a program.
    pseudo: bool,
}

impl std::fmt::Debug for SerialTransport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SerialTransport")
            .field("path", &self.path)
            .field("baud", &self.baud)
            .finish_non_exhaustive()
    }
}

fn open_error(path: &str, error: serialport::Error) -> Error {
    match error.kind() {
        // serialport reports EBUSY (TIOCEXCL held elsewhere) as NoDevice.
        ErrorKind::NoDevice if error.description.to_lowercase().contains("busy") => {
            Error::PortBusy { port: path.into() }
        }
        ErrorKind::NoDevice | ErrorKind::Io(IoKind::NotFound) => {
            if std::path::Path::new(path).exists() {
                Error::PortBusy { port: path.into() }
            } else {
                Error::PortNotFound { port: path.into() }
            }
        }
        ErrorKind::Io(IoKind::WouldBlock) => Error::PortBusy { port: path.into() },
        _ if error.description.contains("lock") => Error::PortBusy { port: path.into() },
        _ => Error::Port {
            port: path.into(),
            message: error.description,
        },
    }
}

impl SerialTransport {
    /// Opens `path` at `baud`, 8N1, no flow control, exclusively.
    ///
    /// # Errors
    /// [`Error::PortBusy`], [`Error::PortNotFound`] or [`Error::Port`].
    pub fn open(path: &str, baud: u32) -> Result<Self> {
        let builder = serialport::new(path, baud)
            .data_bits(DataBits::Eight)
            .parity(Parity::None)
            .stop_bits(StopBits::One)
            .flow_control(FlowControl::None)
            .timeout(Duration::from_millis(10));
        #[cfg(unix)]
        let port: Box<dyn SerialPort> = {
            let native = builder
                .open_native()
                .map_err(|error| open_error(path, error))?;
            never_block(&native).map_err(|error| Error::Port {
                port: path.into(),
                message: format!("cannot make its reads return when nothing is there: {error}"),
            })?;
            Box::new(native)
        };
        #[cfg(not(unix))]
        let port = builder.open().map_err(|error| open_error(path, error))?;
        Ok(SerialTransport {
            port,
            path: path.into(),
            baud,
            opened: Instant::now(),
            buffer: vec![0; 4096],
            pseudo: is_pseudo_terminal(path),
        })
    }

    fn io(&self, source: std::io::Error) -> Error {
        Error::Io {
            port: self.path.clone(),
            source,
        }
    }
}

/// Makes a read return what is there, even nothing (VMIN and VTIME 0;
/// raw mode's VMIN 1 waits for a byte): another program reading the port
/// (a terminal left open, a modem manager's probe) can take the bytes a
/// poll announced, and a read that then waited would wait for ever
/// (hostile11 F3). Writes are not changed.
#[cfg(unix)]
#[allow(
    unsafe_code,
    reason = "serialport's TTYPort gives its descriptor only as a raw fd (no AsFd); it is borrowed for two termios calls while the port lives"
)]
fn never_block(port: &serialport::TTYPort) -> nix::Result<()> {
    use nix::sys::termios::{SetArg, SpecialCharacterIndices, tcgetattr, tcsetattr};
    use std::os::fd::{AsRawFd, BorrowedFd};
    // SAFETY: the descriptor is the port's, open for as long as `port`.
    let fd = unsafe { BorrowedFd::borrow_raw(port.as_raw_fd()) };
    let mut termios = tcgetattr(fd)?;
    termios.control_chars[SpecialCharacterIndices::VMIN as usize] = 0;
    termios.control_chars[SpecialCharacterIndices::VTIME as usize] = 0;
    tcsetattr(fd, SetArg::TCSANOW, &termios)
}

impl Transport for SerialTransport {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        self.port.write_all(bytes).map_err(|error| self.io(error))
    }

    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        // A zero timeout would block forever on some platforms: poll briefly.
        let timeout = timeout.max(Duration::from_millis(1));
        // Not "cannot open": the port was open; now it is gone (a closed
        // pty, an adapter unplugged).
        self.port
            .set_timeout(timeout)
            .map_err(|error| self.io(std::io::Error::other(error.description)))?;
        match self.port.read(&mut self.buffer) {
            Ok(count) => {
                into.extend_from_slice(&self.buffer[..count]);
                Ok(count)
            }
            Err(error) if matches!(error.kind(), IoKind::TimedOut | IoKind::WouldBlock) => Ok(0),
            Err(error) if error.kind() == IoKind::Interrupted => Ok(0),
            Err(error) => Err(self.io(error)),
        }
    }

    fn baud(&self) -> u32 {
        self.baud
    }

    fn set_baud(&mut self, baud: u32) -> Result<()> {
        if self.pseudo && baud != self.baud {
            // Nothing to gain, and the program at the far end (`scorpion
            // sim --pty`) keeps the pace it was started with.
            return Err(Error::BaudChange {
                port: self.path.clone(),
                baud,
                message: "a pseudo-terminal has no line rate to raise".into(),
            });
        }
        // Characters still in the output buffer must leave at the old rate.
        self.port.flush().map_err(|error| self.io(error))?;
        self.port
            .set_baud_rate(baud)
            .map_err(|error| Error::BaudChange {
                port: self.path.clone(),
                baud,
                message: error.description,
            })?;
        self.baud = baud;
        Ok(())
    }

    fn now(&self) -> Duration {
        self.opened.elapsed()
    }

    fn clear_input(&mut self) -> Result<()> {
        self.port
            .clear(ClearBuffer::Input)
            .map_err(|error| Error::Port {
                port: self.path.clone(),
                message: error.description,
            })
    }

    fn name(&self) -> String {
        self.path.clone()
    }
}

/// Whether `path` names a pseudo-terminal's slave (Linux `/dev/pts/N`,
/// macOS `/dev/ttysNNN`).
fn is_pseudo_terminal(path: &str) -> bool {
    path.starts_with("/dev/pts/")
        || path
            .strip_prefix("/dev/ttys")
            .is_some_and(|rest| !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit()))
}

/// One serial port of this machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PortInfo {
    /// The path to pass as `--port`.
    pub path: String,
    /// What kind of port, with USB vendor, product and serial number when known.
    pub description: String,
}

/// The serial ports of this machine.
///
/// # Errors
/// [`Error::Port`] if the operating system cannot enumerate them.
pub fn list_ports() -> Result<Vec<PortInfo>> {
    let ports = serialport::available_ports().map_err(|error| Error::Port {
        port: "(enumeration)".into(),
        message: error.description,
    })?;
    Ok(ports
        .into_iter()
        .map(|port| PortInfo {
            description: match port.port_type {
                serialport::SerialPortType::UsbPort(usb) => {
                    let mut text = format!("USB {:04x}:{:04x}", usb.vid, usb.pid);
                    for part in [usb.manufacturer, usb.product, usb.serial_number]
                        .into_iter()
                        .flatten()
                    {
                        text.push(' ');
                        text.push_str(&part);
                    }
                    text
                }
                serialport::SerialPortType::PciPort => "PCI".into(),
                serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
                serialport::SerialPortType::Unknown => "serial".into(),
            },
            path: port.port_name,
        })
        .collect())
}
