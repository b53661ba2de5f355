//! The in-process virtual Scorpion as a transport: the reference ROM (or
//! a ROM profile) running on the emulated board, reached through the
//! emulated 6551 at real baud timing.
//!
//! The transport's clock is emulated time (the 1 MHz CPU's cycles), so
//! every timeout the client derives from the baud rate means the same
//! here as on a serial port, and an upload's `device_time` is what the
//! same upload takes on a robot with this ROM.

use std::time::Duration;

use platform::line::CPU_HZ;
use romlib::VirtualScorpion;

use super::Transport;
use crate::{Error, Result};

/// Something to do to the robot at a given time (press its reset button,
/// scribble over its RAM): faults a line cannot inject.
type Action = Box<dyn FnOnce(&mut VirtualScorpion) + Send>;

/// The virtual Scorpion behind the [`Transport`] trait.
pub struct VirtualTransport {
    robot: VirtualScorpion,
    baud: u32,
    /// The cycle this transport was opened at: `now` counts from it.
    opened: u64,
    /// Actions and the cycle each is due, earliest last.
    actions: Vec<(u64, Action)>,
    /// A failure of the robot's run whose bytes were handed over first.
    failed: Option<Error>,
}

impl std::fmt::Debug for VirtualTransport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VirtualTransport")
            .field("robot", &self.robot)
            .field("baud", &self.baud)
            .field("actions", &self.actions.len())
            .finish_non_exhaustive()
    }
}

impl Default for VirtualTransport {
    fn default() -> Self {
        VirtualTransport::new(VirtualScorpion::new())
    }
}

impl VirtualTransport {
    /// Talks to `robot` at the rate its host line is set to (9600 baud for
    /// a fresh [`VirtualScorpion`]).
    #[must_use]
    pub fn new(robot: VirtualScorpion) -> Self {
        let baud = robot.host_baud();
        let opened = robot.cycles();
        VirtualTransport {
            robot,
            baud,
            opened,
            actions: Vec::new(),
            failed: None,
        }
    }

    /// Does `action` to the robot when the transport's clock reaches
    /// `time` (in the middle of an upload, say).
    pub fn at(
        &mut self,
        time: Duration,
        action: impl FnOnce(&mut VirtualScorpion) + Send + 'static,
    ) {
        let cycle = self.opened.saturating_add(duration_to_cycles(time));
        self.actions.push((cycle, Box::new(action)));
        self.actions
            .sort_by_key(|(cycle, _)| std::cmp::Reverse(*cycle));
    }

    /// Runs the robot to `until` or until a byte reaches the host, doing
    /// the actions that fall due on the way.
    fn run(&mut self, until: u64) -> std::result::Result<(), romlib::Error> {
        loop {
            let due = self.actions.last().map(|(cycle, _)| *cycle);
            match due {
                Some(cycle) if cycle <= until => {
                    self.robot.run_until_received(cycle)?;
                    if self.robot.cycles() < cycle {
                        // A byte arrived first.
                        return Ok(());
                    }
                    if let Some((_, action)) = self.actions.pop() {
                        action(&mut self.robot);
                    }
                }
                _ => return self.robot.run_until_received(until),
            }
        }
    }

    /// The robot.
    #[must_use]
    pub fn robot(&self) -> &VirtualScorpion {
        &self.robot
    }

    /// The robot, mutable (to press its reset button in a test, say).
    pub fn robot_mut(&mut self) -> &mut VirtualScorpion {
        &mut self.robot
    }

    /// Unwraps the robot.
    #[must_use]
    pub fn into_robot(self) -> VirtualScorpion {
        self.robot
    }
}

/// A failure of the robot's run as the line's error.
fn line_error(error: romlib::Error) -> Error {
    match error {
        romlib::Error::Jam { pc, opcode } => Error::RobotJammed { pc, opcode },
        other => Error::Robot(other),
    }
}

/// Emulated cycles to a duration.
fn cycles_to_duration(cycles: u64) -> Duration {
    Duration::from_nanos(cycles.saturating_mul(1_000_000_000 / CPU_HZ))
}

/// A duration to emulated cycles, rounded up.
fn duration_to_cycles(duration: Duration) -> u64 {
    let nanos = duration.as_nanos();
    let per_cycle = u128::from(1_000_000_000 / CPU_HZ);
    u64::try_from(nanos.div_ceil(per_cycle)).unwrap_or(u64::MAX)
}

impl Transport for VirtualTransport {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        self.robot.send(bytes);
        Ok(())
    }

    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        let deadline = self
            .robot
            .cycles()
            .saturating_add(duration_to_cycles(timeout));
        if let Some(error) = self.failed.take() {
            return Err(error);
        }
        loop {
            // The robot runs until the first byte reaches the host, which
            // looks at it at once: no slicing, so no slice to wait out.
            let ran = self.run(deadline).map_err(line_error);
            let bytes = self.robot.receive();
            if !bytes.is_empty() {
                // A failure in the same run (a card's script) is told at
                // the next read, not lost with the bytes (hostile13 F1).
                self.failed = ran.err();
                into.extend_from_slice(&bytes);
                return Ok(bytes.len());
            }
            ran?;
            if self.robot.cycles() >= deadline {
                return Ok(0);
            }
        }
    }

    fn baud(&self) -> u32 {
        self.baud
    }

    fn set_baud(&mut self, baud: u32) -> Result<()> {
        if platform::acia::baud_code(baud).is_none() {
            return Err(Error::BaudChange {
                port: self.name(),
                baud,
                message: "the 6551 has no such rate".into(),
            });
        }
        self.robot.set_host_baud(baud);
        self.baud = baud;
        Ok(())
    }

    fn now(&self) -> Duration {
        cycles_to_duration(self.robot.cycles().saturating_sub(self.opened))
    }

    fn clear_input(&mut self) -> Result<()> {
        self.robot.receive();
        Ok(())
    }

    fn name(&self) -> String {
        "the virtual Scorpion".into()
    }

    fn diagnose_silence(&mut self) -> Result<()> {
        self.robot
            .check_loop(romlib::sim::LOOP_WATCH)
            .map_err(Error::Robot)
    }
}
