//! The host's end of the virtual robot's line under `scorpion sim` (the
//! pseudo-terminal with `--pty`, stdin without): what clients write goes
//! down the 6551's line at the baud rate, and no more of it waits than a
//! real serial port holds.
//!
//! A pseudo-terminal has no baud rate: a client can write a megabyte in a
//! moment. Putting every byte on the emulated wire at once would queue it
//! all (about 48 bytes of memory each) and make every later command wait
//! behind it at the line's pace, for minutes. A real port holds a few KiB
//! (Linux's serial driver keeps a 4 KiB transmit buffer) and the line
//! carries one character at a time. So bytes wait here, at most
//! [`HOLDS`] of them, and go on the wire only as the robot's clock reaches
//! the time they would be sent; the pseudo-terminal is read as fast as
//! clients write (so the kernel holds nothing back either), and what
//! arrives while [`HOLDS`] bytes wait is dropped and counted, for the
//! simulator to say so. On the robot's side the 6551 does what it does on
//! a real line: a character that arrives while its receive register is
//! still full is lost and sets the overrun bit (see `emulator::board::acia`).

use std::collections::VecDeque;

use romlib::VirtualScorpion;

/// The bytes the host's end holds waiting for the line: a Linux serial
/// driver's transmit buffer (`UART_XMIT_SIZE`, a page). At 9600 baud the
/// line carries them in 4.3 s, so a flood delays the command after it by
/// no more than that, as on a real port.
pub(crate) const HOLDS: usize = debugger::line::HOLDS;

/// Bytes waiting for the line, and how many were dropped.
#[derive(Debug)]
pub(crate) struct HostLine {
    waiting: VecDeque<u8>,
    holds: usize,
    dropped: u64,
}

impl HostLine {
    /// An empty host end that holds up to `holds` bytes.
    pub(crate) fn new(holds: usize) -> HostLine {
        HostLine {
            waiting: VecDeque::with_capacity(holds),
            holds,
            dropped: 0,
        }
    }

    /// Takes what a client wrote: as much as there is room for waits, the
    /// rest is dropped (counted for [`HostLine::take_dropped`]).
    pub(crate) fn accept(&mut self, bytes: &[u8]) {
        let room = self.holds.saturating_sub(self.waiting.len());
        let (kept, lost) = bytes.split_at(room.min(bytes.len()));
        self.waiting.extend(kept);
        self.dropped += lost.len() as u64;
    }

    /// Puts on the wire the waiting bytes that start before robot time
    /// `until`, back to back from where the line is free: the robot then
    /// runs to `until` with only those on their way.
    pub(crate) fn feed(&mut self, robot: &mut VirtualScorpion, until: u64) {
        while !self.waiting.is_empty() && robot.robot().host_line_free_at() < until {
            let Some(byte) = self.waiting.pop_front() else {
                break;
            };
            robot.send(&[byte]);
        }
    }

    /// Bytes waiting for the line.
    #[cfg(test)]
    fn waiting(&self) -> usize {
        self.waiting.len()
    }

    /// Whether no byte waits for the line.
    pub(crate) fn is_empty(&self) -> bool {
        self.waiting.is_empty()
    }

    /// Bytes dropped since the last call, the count then reset.
    pub(crate) fn take_dropped(&mut self) -> u64 {
        std::mem::take(&mut self.dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_keeps_what_a_port_holds_and_counts_the_rest() {
        let mut line = HostLine::new(8);
        line.accept(b"/1E");
        line.accept(&[b'x'; 100]);
        assert_eq!(line.waiting(), 8);
        assert_eq!(line.take_dropped(), 95);
        assert_eq!(line.take_dropped(), 0, "reset once taken");
    }

    #[test]
    fn bytes_go_on_the_wire_only_as_the_clock_reaches_them() {
        let mut robot = VirtualScorpion::new();
        let mut line = HostLine::new(HOLDS);
        line.accept(&[b'x'; 100]);
        let now = robot.cycles();
        // 2 ms at 9600 baud: the character on the wire at `now` and the
        // one that starts 1.04 ms later; the third would start after.
        line.feed(&mut robot, now + 2000);
        assert_eq!(line.waiting(), 98);
        robot.run_until(now + 2000).expect("runs");
        line.feed(&mut robot, now + 4000);
        assert_eq!(line.waiting(), 96);
        assert!(robot.robot().host_line_free_at() < now + 5000);
    }
}
