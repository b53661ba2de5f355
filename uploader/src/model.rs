//! A test double: a robot modelled at the protocol level in simulated time,
//! so the upload algorithm can be tested before (and beside) the emulated
//! one. Both wires carry characters at the baud rate; the robot parses
//! commands as PLATFORM.md says (resync on `/`), answers `/1X` and `/7R`,
//! obeys `/7W`, `/9W` and `/1R`. Optionally it stops reading its input
//! while it sends an answer and has a small receive buffer, as a simple
//! ROM would, so flow control is tested for real.

use std::collections::VecDeque;
use std::time::Duration;

use romlib::protocol::{Answer, BusyByte, Command};

use crate::Result;
use crate::transport::{Transport, char_time};

/// The reset targets of the model's hooks.
pub(crate) const RESET_UNKNOWN: u16 = 0xF123;
pub(crate) const RESET_LOOP: u16 = 0xF045;

#[derive(Debug)]
pub(crate) struct ModelRobot {
    pub(crate) memory: Vec<u8>,
    baud: u32,
    now: Duration,
    host_free: Duration,
    robot_free: Duration,
    to_robot: VecDeque<(Duration, u8)>,
    to_host: VecDeque<(Duration, u8)>,
    pending: VecDeque<(Duration, u8)>,
    busy_until: Duration,
    command: Option<Vec<u8>>,
    /// Stop reading input while answering (a polled transmitter).
    pub(crate) sync_tx: bool,
    /// Receive buffer size; bytes beyond it are lost (overrun).
    pub(crate) rx_capacity: usize,
    /// `/1R` also clears user RAM.
    pub(crate) reset_clears: bool,
    pub(crate) overruns: usize,
    pub(crate) resets: usize,
    /// Addresses written, in order (to check hooks are written last).
    pub(crate) writes: Vec<(Duration, u16)>,
}

impl ModelRobot {
    pub(crate) fn new(baud: u32) -> Self {
        let mut robot = ModelRobot {
            memory: vec![0; 0x1_0000],
            baud,
            now: Duration::ZERO,
            host_free: Duration::ZERO,
            robot_free: Duration::ZERO,
            to_robot: VecDeque::new(),
            to_host: VecDeque::new(),
            pending: VecDeque::new(),
            busy_until: Duration::ZERO,
            command: None,
            sync_tx: false,
            rx_capacity: 256,
            reset_clears: false,
            overruns: 0,
            resets: 0,
            writes: Vec::new(),
        };
        // User RAM holds power-up garbage.
        for (i, byte) in robot.memory[0x0400..0xC000].iter_mut().enumerate() {
            *byte = (i as u32).wrapping_mul(2_654_435_761).to_le_bytes()[3];
        }
        robot.reset();
        robot
    }

    fn reset(&mut self) {
        let [ul, uh] = RESET_UNKNOWN.to_le_bytes();
        let [ll, lh] = RESET_LOOP.to_le_bytes();
        self.memory[0x0200..0x0206].copy_from_slice(&[0x4C, ul, uh, 0x4C, ll, lh]);
        if self.reset_clears {
            self.memory[0x0400..0xC000].fill(0);
        }
    }

    pub(crate) fn hook(&self, address: u16) -> u16 {
        let at = usize::from(address);
        u16::from_le_bytes([self.memory[at + 1], self.memory[at + 2]])
    }

    fn ct(&self) -> Duration {
        char_time(1, self.baud)
    }

    fn answer(&mut self, at: Duration, answer: &Answer) {
        let bytes = answer.encode();
        let mut time = self.robot_free.max(at);
        for byte in bytes {
            time += self.ct();
            self.to_host.push_back((time, byte));
        }
        self.robot_free = time;
        if self.sync_tx {
            self.busy_until = time;
        }
    }

    fn execute(&mut self, at: Duration, text: &[u8]) {
        let Ok(command) = Command::parse(text) else {
            return;
        };
        match command {
            Command::Busy => self.answer(at, &Answer::Busy(BusyByte(0))),
            Command::ReadMemory(span) => {
                let start = usize::from(span.address());
                let data = self.memory[start..start + usize::from(span.count())].to_vec();
                self.answer(at, &Answer::Memory(data));
            }
            Command::WriteByte { address, value } => self.poke(at, address, value),
            Command::WriteWord(write) => {
                let [first, second] = write.bytes();
                self.poke(at, write.address(), first);
                self.poke(at, write.address() + 1, second);
            }
            Command::Reset => {
                self.resets += 1;
                self.reset();
            }
            _ => {}
        }
    }

    fn poke(&mut self, at: Duration, address: u16, value: u8) {
        if address < 0xC000 {
            self.memory[usize::from(address)] = value;
            self.writes.push((at, address));
        }
    }

    /// The ROM's parser: bytes outside a command are ignored until `/`; a
    /// `/` inside a command restarts it.
    fn take(&mut self, at: Duration, byte: u8) {
        if byte == b'/' {
            self.command = Some(vec![byte]);
            return;
        }
        let Some(command) = self.command.as_mut() else {
            return;
        };
        command.push(byte);
        if command.len() == 2 && !(b'1'..=b'9').contains(&byte) {
            self.command = None;
            return;
        }
        if command.len() >= 2 && command.len() == usize::from(command[1] - b'0') + 2 {
            let text = std::mem::take(command);
            self.command = None;
            self.execute(at, &text);
        }
    }

    /// Runs the robot up to `until`.
    fn advance(&mut self, until: Duration) {
        loop {
            let arrival = self
                .to_robot
                .front()
                .map(|&(t, _)| t)
                .filter(|&t| t <= until);
            let process = self
                .pending
                .front()
                .map(|&(t, _)| t.max(self.busy_until))
                .filter(|&t| t <= until);
            match (arrival, process) {
                (Some(a), p) if p.is_none_or(|p| a <= p) => {
                    let Some(byte) = self.to_robot.pop_front() else {
                        break;
                    };
                    if self.pending.len() >= self.rx_capacity {
                        self.overruns += 1;
                    } else {
                        self.pending.push_back(byte);
                    }
                    self.now = self.now.max(a);
                }
                (_, Some(p)) => {
                    let Some((_, byte)) = self.pending.pop_front() else {
                        break;
                    };
                    self.now = self.now.max(p);
                    self.take(p, byte);
                }
                _ => break,
            }
        }
        self.now = self.now.max(until);
    }
}

impl Transport for ModelRobot {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        let mut time = self.host_free.max(self.now);
        for &byte in bytes {
            time += self.ct();
            self.to_robot.push_back((time, byte));
        }
        self.host_free = time;
        Ok(())
    }

    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        let deadline = self.now + timeout;
        loop {
            let step = (self.now + self.ct()).min(deadline);
            self.advance(step);
            let mut count = 0;
            while let Some(&(time, byte)) = self.to_host.front() {
                if time > self.now {
                    break;
                }
                self.to_host.pop_front();
                into.push(byte);
                count += 1;
            }
            if count > 0 || self.now >= deadline {
                return Ok(count);
            }
        }
    }

    fn baud(&self) -> u32 {
        self.baud
    }

    fn now(&self) -> Duration {
        self.now
    }

    fn clear_input(&mut self) -> Result<()> {
        let now = self.now;
        self.to_host.retain(|&(time, _)| time > now);
        Ok(())
    }

    fn name(&self) -> String {
        "the model robot".into()
    }
}
