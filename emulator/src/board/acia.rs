//! The 6551 Asynchronous Communication Interface Adapter, after the
//! Rockwell/Synertek datasheets, with the host's end of the RS-232 line.
//!
//! Modelled: the four registers (data, status / programmed reset, command,
//! control); the internal baud-rate generator (1.8432 MHz crystal, the 15
//! rates); word length, parity and stop bits; a one-byte receive data
//! register, so a character that arrives while the previous one is unread
//! is lost and sets the overrun bit; framing and parity errors with the
//! datasheet's "cleared by a read of the data register and the next
//! error-free character" rule; a transmit data register in front of the
//! shift register; the receive and transmit interrupts and the IRQ bit that
//! a status read clears; echo mode. DCD, DSR and CTS are tied active, as on
//! the Scorpion's board.
//!
//! Not modelled: transmitting a break (the line stays idle) and the 16x
//! external clock (the board leaves RxC unconnected, so a program that
//! selects it hears nothing and sends nothing).
//!
//! Both directions run on [`Wire`]s at the rates each end is set to: the
//! host's characters are received by sampling them at the 6551's rate, and
//! the 6551's at the host's, so a wrong baud rate on either side produces
//! the framing errors and garbage it would on a real robot.

use std::any::Any;

use super::device::Device;
use super::serial::{Baud, FrameFormat, Parity};
use super::wire::{Received, Sampler, Wire};

pub use platform::acia::{DIVISORS, baud_code, command, control, reg, status};

/// The rate a baud code selects.
#[must_use]
pub fn code_rate(code: u8) -> Option<Baud> {
    let divisor = DIVISORS[usize::from(code & 0x0F)];
    (divisor != 0).then(|| Baud::from_crystal_divisor(divisor))
}

/// A character the 6551 sent, as the host's UART received it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HostByte {
    /// The byte.
    pub byte: u8,
    /// The cycle the host had it.
    pub at: u64,
    /// The host saw a framing or parity error (wrong baud rate or format).
    pub error: bool,
}

/// A 6551 ACIA and the host end of its RS-232 line.
#[derive(Debug, Clone)]
pub struct Acia {
    now: u64,
    command: u8,
    control: u8,
    rdr: u8,
    rdrf: bool,
    overrun: bool,
    framing_error: bool,
    parity_error: bool,
    irq_flag: bool,
    /// The transmit data register, when full.
    tdr: Option<u8>,
    /// The cycle the transmit shift register is free again.
    shift_free_at: u64,
    /// Host to 6551.
    rx_wire: Wire,
    rx_sampler: Sampler,
    /// 6551 to host.
    tx_wire: Wire,
    host_sampler: Sampler,
    host_baud: Baud,
    host_format: FrameFormat,
    /// Characters lost to overrun since power-up (a host-side statistic).
    overruns: u64,
}

impl Default for Acia {
    fn default() -> Acia {
        Acia::new()
    }
}

impl Acia {
    /// A 6551 after hardware reset, with a host at 9600 baud 8N1.
    #[must_use]
    pub fn new() -> Acia {
        Acia {
            now: 0,
            command: command::IRD,
            control: 0,
            rdr: 0,
            rdrf: false,
            overrun: false,
            framing_error: false,
            parity_error: false,
            irq_flag: false,
            tdr: None,
            shift_free_at: 0,
            rx_wire: Wire::new(),
            rx_sampler: Sampler::new(),
            tx_wire: Wire::new(),
            host_sampler: Sampler::new(),
            host_baud: Baud::new(platform::line::DEFAULT_BAUD),
            host_format: FrameFormat::EIGHT_N_ONE,
            overruns: 0,
        }
    }

    /// Hardware reset (/RES) at `cycle`: command and control cleared (receive
    /// interrupts disabled), status empty; the line and the host keep going.
    pub fn reset(&mut self, cycle: u64) {
        self.catch_up(cycle);
        self.command = command::IRD;
        self.control = 0;
        self.rdrf = false;
        self.overrun = false;
        self.framing_error = false;
        self.parity_error = false;
        self.irq_flag = false;
        self.tdr = None;
    }

    /// The host's line settings.
    pub fn set_host_line(&mut self, baud: Baud, format: FrameFormat) {
        self.host_baud = baud;
        self.host_format = format;
    }

    /// The host's baud rate.
    #[must_use]
    pub fn host_baud(&self) -> Baud {
        self.host_baud
    }

    /// The host sends `byte`: it goes on the wire at `cycle`, or when the
    /// host's previous character ends. Returns the cycle it ends.
    pub fn host_send(&mut self, byte: u8, cycle: u64) -> u64 {
        self.catch_up(cycle);
        self.rx_wire
            .send(byte, cycle.max(self.now), self.host_baud, self.host_format)
            .end
    }

    /// The cycle the host's last character ends.
    #[must_use]
    pub fn host_line_free_at(&self) -> u64 {
        self.rx_wire.free_at()
    }

    /// What the host has received by `cycle`.
    pub fn host_receive(&mut self, cycle: u64) -> Vec<HostByte> {
        self.catch_up(cycle);
        let mut out = Vec::new();
        while let Some(r) =
            self.host_sampler
                .receive(&mut self.tx_wire, cycle, self.host_baud, self.host_format)
        {
            out.push(HostByte {
                byte: r.data,
                at: r.at,
                error: r.framing_error || r.parity_error,
            });
        }
        out
    }

    /// When to look next for a byte reaching the host: the cycle the host
    /// receives the next byte it has not taken, or, while the only byte
    /// to come waits in the transmit register, the cycle it goes on the
    /// wire (a look then finds when it arrives). `None`: nothing is on its
    /// way.
    #[must_use]
    pub fn host_byte_due(&self) -> Option<u64> {
        if let Some(next) = self
            .host_sampler
            .peek(&self.tx_wire, self.host_baud, self.host_format)
        {
            return Some(next.at);
        }
        (self.tdr.is_some() && self.transmitter_enabled()).then_some(self.shift_free_at)
    }

    /// The cycle the 6551's last character ends on the wire (the host has
    /// everything sent so far once this cycle has passed).
    #[must_use]
    pub fn transmit_idle_at(&self) -> u64 {
        self.tx_wire.free_at()
    }

    /// Characters lost to overrun since power-up.
    #[must_use]
    pub fn overruns(&self) -> u64 {
        self.overruns
    }

    /// The command register.
    #[must_use]
    pub fn command(&self) -> u8 {
        self.command
    }

    /// The control register.
    #[must_use]
    pub fn control(&self) -> u8 {
        self.control
    }

    fn receiver_enabled(&self) -> bool {
        self.command & command::DTR != 0
    }

    fn rx_irq_enabled(&self) -> bool {
        self.receiver_enabled() && self.command & command::IRD == 0
    }

    fn tx_irq_enabled(&self) -> bool {
        self.command & command::DTR != 0 && self.command & command::TIC_MASK == command::TIC_IRQ
    }

    fn transmitter_enabled(&self) -> bool {
        self.command & command::TIC_MASK != 0
    }

    fn echo(&self) -> bool {
        self.command & command::ECHO != 0 && self.command & command::TIC_MASK == 0
    }

    /// The rate of the internal generator, or `None` for the external clock.
    fn rate(&self) -> Option<Baud> {
        code_rate(self.control & control::BAUD_MASK)
    }

    /// The receiver's clock: the generator if RCS is set, else RxC, which
    /// the board leaves unconnected.
    fn receiver_rate(&self) -> Option<Baud> {
        if self.control & control::RCS != 0 {
            self.rate()
        } else {
            None
        }
    }

    /// The character format from the control and command registers.
    #[must_use]
    pub fn format(&self) -> FrameFormat {
        let data_bits = 8 - ((self.control & control::WORD_MASK) >> 5);
        let parity = match self.command >> 5 {
            1 => Parity::Odd,
            3 => Parity::Even,
            5 => Parity::Mark,
            7 => Parity::Space,
            _ => Parity::None,
        };
        let stop_half_bits = if self.control & control::STOP2 == 0 {
            2
        } else if data_bits == 5 && parity == Parity::None {
            3
        } else if data_bits == 8 && parity != Parity::None {
            2
        } else {
            4
        };
        FrameFormat {
            data_bits,
            parity,
            stop_half_bits,
        }
    }

    fn status(&self) -> u8 {
        let mut value = 0;
        if self.parity_error {
            value |= status::PARITY_ERROR;
        }
        if self.framing_error {
            value |= status::FRAMING_ERROR;
        }
        if self.overrun {
            value |= status::OVERRUN;
        }
        if self.rdrf {
            value |= status::RDRF;
        }
        if self.tdr.is_none() {
            value |= status::TDRE;
        }
        if self.irq_flag {
            value |= status::IRQ;
        }
        value
    }

    /// Starts shifting out `byte` at `cycle` (the shift register is free).
    fn shift_out(&mut self, byte: u8, cycle: u64) {
        let Some(rate) = self.rate() else {
            // No clock: the shift register never empties.
            self.shift_free_at = u64::MAX;
            return;
        };
        let character = self.tx_wire.send(byte, cycle, rate, self.format());
        self.shift_free_at = character.end;
    }

    fn take_character(&mut self, received: Received) {
        if self.rdrf {
            self.overrun = true;
            self.overruns += 1;
            return;
        }
        self.rdr = received.data;
        self.rdrf = true;
        if received.framing_error || received.parity_error {
            self.framing_error |= received.framing_error;
            self.parity_error |= received.parity_error;
        } else {
            self.framing_error = false;
            self.parity_error = false;
            self.overrun = false;
        }
        if self.rx_irq_enabled() {
            self.irq_flag = true;
        }
        if self.echo() && self.shift_free_at <= received.at {
            self.shift_out(received.data, received.at);
        }
    }

    fn catch_up(&mut self, cycle: u64) {
        // Not only forward: a receiver whose rate changed can find a
        // character whose stop bit it sampled before `now` (its next event
        // in the past), which is taken now; else the board waited on that
        // event for ever (a noisy line's `/1F` hung the virtual robot).
        let cycle = cycle.max(self.now);
        // Receive and transmit events in time order, so that an overrun
        // depends only on when characters arrive against when they are read.
        loop {
            let next_rx = if self.receiver_enabled() {
                self.receiver_rate().and_then(|rate| {
                    self.rx_sampler
                        .peek(&self.rx_wire, rate, self.format())
                        .filter(|r| r.at <= cycle)
                })
            } else {
                None
            };
            let next_tx =
                (self.tdr.is_some() && self.transmitter_enabled() && self.shift_free_at <= cycle)
                    .then_some(self.shift_free_at);
            match (next_rx, next_tx) {
                (Some(rx), tx) if tx.is_none_or(|tx| rx.at < tx) => {
                    if let Some(rate) = self.receiver_rate() {
                        let format = self.format();
                        self.rx_sampler
                            .receive(&mut self.rx_wire, rx.at, rate, format);
                    }
                    self.take_character(rx);
                }
                (_, Some(at)) => {
                    if let Some(byte) = self.tdr.take() {
                        self.shift_out(byte, at);
                        if self.tx_irq_enabled() {
                            self.irq_flag = true;
                        }
                    }
                }
                _ => break,
            }
        }
        if !self.receiver_enabled() || self.receiver_rate().is_none() {
            // A deaf receiver misses everything sent meanwhile.
            self.rx_sampler.skip_to(&mut self.rx_wire, cycle);
        }
        self.now = cycle;
    }
}

impl Device for Acia {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.catch_up(cycle);
        match offset & 3 {
            reg::DATA => {
                self.rdrf = false;
                self.rdr
            }
            reg::STATUS => {
                let value = self.status();
                self.irq_flag = false;
                value
            }
            reg::COMMAND => self.command,
            _ => self.control,
        }
    }

    fn write(&mut self, offset: u16, value: u8, cycle: u64) {
        self.catch_up(cycle);
        match offset & 3 {
            reg::DATA => {
                if self.tdr.is_none() && self.transmitter_enabled() && self.shift_free_at <= cycle {
                    self.shift_out(value, cycle);
                } else {
                    // Overwrites an unsent byte, as the real register does.
                    self.tdr = Some(value);
                }
            }
            reg::STATUS => {
                // Programmed reset: command bits 4-0 to 00010, overrun
                // cleared; the control register is kept.
                self.command = (self.command & 0xE0) | command::IRD;
                self.overrun = false;
            }
            reg::COMMAND => {
                self.command = value;
                if self.tx_irq_enabled() && self.tdr.is_none() {
                    self.irq_flag = true;
                }
            }
            _ => self.control = value,
        }
    }

    fn peek(&self, offset: u16) -> u8 {
        match offset & 3 {
            reg::DATA => self.rdr,
            reg::STATUS => self.status(),
            reg::COMMAND => self.command,
            _ => self.control,
        }
    }

    fn sync(&mut self, cycle: u64) {
        self.catch_up(cycle);
    }

    fn next_event(&self) -> Option<u64> {
        if self.irq_flag || self.command & command::DTR == 0 {
            return None;
        }
        let rx = if self.rx_irq_enabled() && !self.rdrf {
            self.receiver_rate().and_then(|rate| {
                self.rx_sampler
                    .peek(&self.rx_wire, rate, self.format())
                    .map(|r| r.at)
            })
        } else {
            None
        };
        let tx = (self.tx_irq_enabled() && self.tdr.is_some() && self.transmitter_enabled())
            .then_some(self.shift_free_at);
        match (rx, tx) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    fn irq(&self) -> bool {
        self.irq_flag && self.command & command::DTR != 0
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ACIA set up as the Scorpion ROM does: 9600 8N1, receiver and
    /// receive interrupts on, transmitter on without interrupts.
    fn scorpion_acia() -> Acia {
        let mut acia = Acia::new();
        acia.write(reg::CONTROL, control::B9600_8N1, 0);
        acia.write(reg::COMMAND, command::DTR | command::TIC_ON, 0);
        acia
    }

    const CHAR: u64 = 1042; // one 10-bit character at 9600 baud, rounded up

    #[test]
    fn receives_at_baud_pace_and_interrupts() {
        let mut acia = scorpion_acia();
        acia.host_send(b'/', 100);
        // The stop bit's middle: 9.5 bit times after the start.
        let at = 100 + 989;
        assert_eq!(acia.next_event(), Some(at));
        acia.sync(at - 1);
        assert_eq!(acia.peek(reg::STATUS) & status::RDRF, 0);
        acia.sync(at);
        assert!(acia.irq());
        let status_value = acia.read(reg::STATUS, at + 1);
        assert_eq!(status_value, status::IRQ | status::RDRF | status::TDRE);
        assert!(!acia.irq(), "reading the status clears IRQ");
        assert_eq!(acia.read(reg::DATA, at + 2), b'/');
        assert_eq!(acia.peek(reg::STATUS) & status::RDRF, 0);
    }

    /// A character half in when the rate goes from 9600 to 19200: at the
    /// new rate its stop bit was sampled before now. Its event was in the
    /// past, a sync there did nothing, and the board waited on it for
    /// ever (the noisy-line runs of `uploader`'s stub_faults hung).
    #[test]
    fn a_character_due_before_now_after_a_rate_change_is_taken() {
        let mut acia = scorpion_acia();
        acia.host_send(b'/', 100);
        acia.sync(800);
        acia.write(reg::CONTROL, control::FORMAT_8N1 | 0x0F, 800);
        let at = acia.next_event().expect("the character is due");
        acia.sync(at);
        assert_ne!(acia.next_event(), Some(at), "the event at {at} stays due");
    }

    #[test]
    fn a_byte_not_taken_before_the_next_arrives_is_lost() {
        let mut acia = scorpion_acia();
        for byte in b"abc" {
            acia.host_send(*byte, 0);
        }
        // Read only after all three arrived: the first is kept, the other
        // two are lost (overrun).
        acia.sync(4 * CHAR);
        let status_value = acia.read(reg::STATUS, 4 * CHAR);
        assert_eq!(status_value & status::OVERRUN, status::OVERRUN);
        assert_eq!(acia.read(reg::DATA, 4 * CHAR + 1), b'a');
        assert_eq!(acia.overruns(), 2);
        // The next error-free character clears the overrun bit.
        acia.host_send(b'd', 4 * CHAR + 2);
        acia.sync(6 * CHAR);
        assert_eq!(acia.read(reg::STATUS, 6 * CHAR) & status::OVERRUN, 0);
        assert_eq!(acia.read(reg::DATA, 6 * CHAR + 1), b'd');
    }

    #[test]
    fn bytes_read_in_time_are_all_received() {
        let mut acia = scorpion_acia();
        let text = b"/7R020010/1P";
        for byte in text {
            acia.host_send(*byte, 0);
        }
        let mut got = Vec::new();
        let mut cycle = 0;
        while got.len() < text.len() && cycle < 20 * CHAR {
            cycle = acia.next_event().expect("a character is coming");
            acia.sync(cycle);
            assert!(acia.irq());
            acia.read(reg::STATUS, cycle + 4);
            got.push(acia.read(reg::DATA, cycle + 8));
        }
        assert_eq!(got, text);
        assert_eq!(acia.overruns(), 0);
    }

    #[test]
    fn transmits_at_baud_pace_through_the_data_register() {
        let mut acia = scorpion_acia();
        acia.write(reg::DATA, b'O', 10);
        // The shift register took it at once: the data register is free.
        assert_ne!(acia.peek(reg::STATUS) & status::TDRE, 0);
        acia.write(reg::DATA, b'K', 11);
        assert_eq!(acia.peek(reg::STATUS) & status::TDRE, 0);
        // The host has the first byte at the middle of its stop bit.
        assert_eq!(acia.host_receive(10 + 988), vec![]);
        let first = acia.host_receive(10 + 989);
        assert_eq!(first.len(), 1);
        assert_eq!((first[0].byte, first[0].error), (b'O', false));
        // The second follows back to back once the first has left.
        acia.sync(10 + CHAR);
        assert_ne!(acia.peek(reg::STATUS) & status::TDRE, 0);
        let second = acia.host_receive(10 + 2 * CHAR);
        assert_eq!(second.iter().map(|b| b.byte).collect::<Vec<_>>(), b"K");
        assert_eq!(acia.transmit_idle_at(), 10 + 2083);
    }

    #[test]
    fn transmit_interrupt_when_the_data_register_empties() {
        let mut acia = scorpion_acia();
        acia.write(
            reg::COMMAND,
            command::DTR | command::IRD | command::TIC_IRQ,
            0,
        );
        assert!(acia.irq(), "TDRE is already set");
        acia.read(reg::STATUS, 1);
        acia.write(reg::DATA, 1, 2);
        acia.write(reg::DATA, 2, 3);
        assert!(!acia.irq());
        let event = acia.next_event().expect("TDRE will rise");
        acia.sync(event);
        assert!(acia.irq());
    }

    #[test]
    fn a_wrong_host_rate_gives_framing_errors() {
        let mut acia = scorpion_acia();
        acia.set_host_line(Baud::new(2400), FrameFormat::EIGHT_N_ONE);
        for byte in b"/1X" {
            acia.host_send(*byte, 0);
        }
        let mut saw_error = false;
        let mut data = Vec::new();
        let mut cycle = 0;
        while let Some(event) = acia.next_event() {
            cycle = event;
            acia.sync(cycle);
            saw_error |= acia.read(reg::STATUS, cycle) & status::FRAMING_ERROR != 0;
            data.push(acia.read(reg::DATA, cycle));
        }
        assert!(cycle > 0);
        assert!(saw_error);
        assert_ne!(data, b"/1X");
    }

    #[test]
    fn a_disabled_receiver_hears_nothing() {
        let mut acia = Acia::new();
        acia.write(reg::CONTROL, control::B9600_8N1, 0);
        acia.host_send(b'x', 0);
        acia.sync(3 * CHAR);
        assert_eq!(acia.peek(reg::STATUS) & status::RDRF, 0);
        acia.write(reg::COMMAND, command::DTR, 3 * CHAR);
        acia.host_send(b'y', 3 * CHAR);
        acia.sync(5 * CHAR);
        assert_eq!(acia.read(reg::DATA, 5 * CHAR), b'y');
    }

    #[test]
    fn echo_mode_sends_back_what_it_receives() {
        let mut acia = Acia::new();
        acia.write(reg::CONTROL, control::B9600_8N1, 0);
        acia.write(reg::COMMAND, command::DTR | command::IRD | command::ECHO, 0);
        acia.host_send(b'e', 0);
        let echoed = acia.host_receive(3 * CHAR);
        assert_eq!(echoed.iter().map(|b| b.byte).collect::<Vec<_>>(), b"e");
    }

    #[test]
    fn programmed_reset_and_formats() {
        let mut acia = scorpion_acia();
        acia.write(reg::COMMAND, 0xFF, 0);
        acia.write(reg::STATUS, 0, 1);
        assert_eq!(acia.peek(reg::COMMAND), 0xE2);
        assert_eq!(acia.peek(reg::CONTROL), control::B9600_8N1);
        acia.write(reg::CONTROL, 0x80 | 0x60 | 0x1E, 2);
        acia.write(reg::COMMAND, 0x00, 3);
        assert_eq!(acia.format().half_bits(), 2 * 6 + 3);
        assert_eq!(baud_code(9600), Some(0x0E));
        assert_eq!(baud_code(19200), Some(0x0F));
        assert_eq!(baud_code(300), Some(0x06));
        assert_eq!(baud_code(1000), None);
    }
}
