//! The byte pipe to a robot, behind a trait so the protocol client runs the
//! same over a serial port, the in-process virtual Scorpion, a test double,
//! or a fault-injecting wrapper around any of them.
//!
//! Time belongs to the transport: a serial port's clock is the wall clock,
//! the virtual Scorpion's is emulated time, so a timeout computed from the
//! baud rate means the same on both, and the benchmark reads device time.

mod faults;
mod observed;
mod serial;
mod sim;

use std::time::Duration;

pub use faults::{FaultConfig, FaultStats, FaultyTransport};
pub use observed::{Exchanged, Observed};
pub use serial::{PortInfo, SerialTransport, list_ports};
pub use sim::VirtualTransport;

use crate::Result;

/// A full-duplex byte line to one robot.
pub trait Transport {
    /// Queues `bytes` for sending. They leave at the line's pace; this may
    /// return before they are on the wire.
    ///
    /// # Errors
    /// An I/O error on the line.
    fn send(&mut self, bytes: &[u8]) -> Result<()>;

    /// Appends what has arrived to `into`, waiting up to `timeout` (on the
    /// transport's clock) for at least one byte. Returns how many bytes were
    /// appended: 0 means the timeout passed.
    ///
    /// # Errors
    /// An I/O error on the line.
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize>;

    /// The line's baud rate (8N1: ten bits per character).
    fn baud(&self) -> u32;

    /// Changes the host's end of the line to `baud`, after everything
    /// already sent has left at the old rate. The robot's end is the
    /// robot's business (the RAM loader reprograms its 6551).
    ///
    /// # Errors
    /// [`crate::Error::BaudChange`] if this line cannot run at `baud`.
    fn set_baud(&mut self, baud: u32) -> Result<()> {
        Err(crate::Error::BaudChange {
            port: self.name(),
            baud,
            message: "this transport has a fixed rate".into(),
        })
    }

    /// The transport's clock: time since it was opened.
    fn now(&self) -> Duration;

    /// Discards bytes received but not yet read.
    ///
    /// # Errors
    /// An I/O error on the line.
    fn clear_input(&mut self) -> Result<()>;

    /// A name for messages (`/dev/ttyUSB0`, `the virtual Scorpion`).
    fn name(&self) -> String;

    /// Says why the robot is silent where the transport can see inside it
    /// (the virtual Scorpion: a control loop that stopped, and where); a
    /// serial line cannot, and says nothing.
    ///
    /// # Errors
    /// The reason, when there is one.
    fn diagnose_silence(&mut self) -> Result<()> {
        Ok(())
    }
}

impl<T: Transport + ?Sized> Transport for &mut T {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        (**self).send(bytes)
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        (**self).receive(into, timeout)
    }
    fn baud(&self) -> u32 {
        (**self).baud()
    }
    fn set_baud(&mut self, baud: u32) -> Result<()> {
        (**self).set_baud(baud)
    }
    fn now(&self) -> Duration {
        (**self).now()
    }
    fn clear_input(&mut self) -> Result<()> {
        (**self).clear_input()
    }
    fn name(&self) -> String {
        (**self).name()
    }
    fn diagnose_silence(&mut self) -> Result<()> {
        (**self).diagnose_silence()
    }
}

impl<T: Transport + ?Sized> Transport for Box<T> {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        (**self).send(bytes)
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        (**self).receive(into, timeout)
    }
    fn baud(&self) -> u32 {
        (**self).baud()
    }
    fn set_baud(&mut self, baud: u32) -> Result<()> {
        (**self).set_baud(baud)
    }
    fn now(&self) -> Duration {
        (**self).now()
    }
    fn clear_input(&mut self) -> Result<()> {
        (**self).clear_input()
    }
    fn name(&self) -> String {
        (**self).name()
    }
    fn diagnose_silence(&mut self) -> Result<()> {
        (**self).diagnose_silence()
    }
}

/// The time `chars` characters take on a line at `baud` (8N1: ten bits each).
#[must_use]
pub fn char_time(chars: usize, baud: u32) -> Duration {
    Duration::from_nanos((chars as u64).saturating_mul(10_000_000_000) / u64::from(baud.max(1)))
}
