//! The 6522 Versatile Interface Adapter, after the MOS/Rockwell datasheets.
//!
//! Modelled: ports A and B with their data-direction registers and input
//! latching; CA1/CB1 edge inputs; CA2/CB2 as edge inputs (with the
//! independent-interrupt modes) and as handshake, pulse and manual outputs;
//! timer 1 in one-shot and free-running mode with its PB7 output; timer 2
//! as a one-shot and as a PB6 pulse counter; IFR/IER with their bit-7 rules
//! and the IRQ output.
//!
//! Not modelled: the shift register's shifting (the Scorpion connects
//! nothing to CB1/CB2, so the register only stores what is written and its
//! flag is cleared by accesses, as the datasheet says).
//!
//! Timers follow the datasheet's timing: after a write of `N` to the high
//! counter at cycle `w`, the counter reads `N` at `w + 1`, reaches 0 at
//! `w + 1 + N` and the interrupt flag is seen from `w + N + 2` (the
//! datasheet's "N + 1.5 cycles"). In free-running mode the counter shows
//! `$FFFF` for one cycle and reloads from the latch, a period of `N + 2`.
//! Nothing is ticked: the timers are computed from the cycle they were
//! loaded at whenever the CPU looks at them.

use std::any::Any;

use super::device::Device;

pub use platform::via::{irq, reg};

/// ACR bits.
mod acr {
    pub(super) const PA_LATCH: u8 = 0x01;
    pub(super) const PB_LATCH: u8 = 0x02;
    pub(super) const T2_PULSE_COUNT: u8 = 0x20;
    pub(super) const T1_FREE_RUN: u8 = 0x40;
    pub(super) const T1_PB7: u8 = 0x80;
}

/// What a CA2 or CB2 line does, from its three PCR bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum C2Mode {
    /// Input; the flag is cleared by an access to the port register.
    Input { positive: bool },
    /// Input; the flag is cleared only by writing IFR.
    IndependentInput { positive: bool },
    /// Output: low after a port access, high again on the C1 active edge.
    Handshake,
    /// Output: a one-cycle low pulse after a port access.
    Pulse,
    /// Output held at this level.
    Manual(bool),
}

impl C2Mode {
    fn from_bits(bits: u8) -> C2Mode {
        match bits & 0x7 {
            0 => C2Mode::Input { positive: false },
            1 => C2Mode::IndependentInput { positive: false },
            2 => C2Mode::Input { positive: true },
            3 => C2Mode::IndependentInput { positive: true },
            4 => C2Mode::Handshake,
            5 => C2Mode::Pulse,
            6 => C2Mode::Manual(false),
            _ => C2Mode::Manual(true),
        }
    }

    fn is_output(self) -> bool {
        matches!(self, C2Mode::Handshake | C2Mode::Pulse | C2Mode::Manual(_))
    }
}

/// A 6522 VIA.
#[derive(Debug, Clone)]
pub struct Via {
    /// The last cycle caught up to.
    now: u64,
    ora: u8,
    orb: u8,
    ddra: u8,
    ddrb: u8,
    acr: u8,
    pcr: u8,
    /// Flags, bits 0-6.
    ifr: u8,
    /// Enables, bits 0-6.
    ier: u8,
    sr: u8,
    /// Levels driven onto the port pins from outside (inputs).
    pa_pins: u8,
    pb_pins: u8,
    /// Input latches (ACR bits 0 and 1), loaded on the C1 active edge.
    ira_latch: u8,
    irb_latch: u8,
    ca1: bool,
    cb1: bool,
    ca2_in: bool,
    cb2_in: bool,
    /// CA2/CB2 output levels in the handshake modes.
    ca2_handshake: bool,
    cb2_handshake: bool,
    /// Counts of one-cycle CA2/CB2 pulses.
    ca2_pulses: u64,
    cb2_pulses: u64,
    t1_latch: u16,
    /// The cycle at which the T1 counter reads (or read) zero.
    t1_zero: u64,
    /// One-shot: the next time-out still sets the flag and PB7.
    t1_armed: bool,
    /// The cycle of the last time-out (the counter reads $FFFF then).
    t1_last_timeout: Option<u64>,
    /// The T1 output on PB7.
    pb7: bool,
    /// How many times PB7 changed level under T1 control.
    pb7_toggles: u64,
    t2_latch_lo: u8,
    /// Timer mode: the cycle at which the T2 counter reads zero.
    t2_zero: u64,
    /// Pulse-counting mode: the counter's value.
    t2_count: u16,
    t2_armed: bool,
}

impl Default for Via {
    fn default() -> Via {
        Via::new()
    }
}

impl Via {
    /// A VIA just after /RES: all registers cleared except the timers,
    /// latches and shift register, which the datasheet leaves undefined
    /// (here: zero, with both timers idle).
    #[must_use]
    pub fn new() -> Via {
        Via {
            now: 0,
            ora: 0,
            orb: 0,
            ddra: 0,
            ddrb: 0,
            acr: 0,
            pcr: 0,
            ifr: 0,
            ier: 0,
            sr: 0,
            pa_pins: 0xFF,
            pb_pins: 0xFF,
            ira_latch: 0xFF,
            irb_latch: 0xFF,
            ca1: true,
            cb1: true,
            ca2_in: true,
            cb2_in: true,
            ca2_handshake: true,
            cb2_handshake: true,
            ca2_pulses: 0,
            cb2_pulses: 0,
            t1_latch: 0xFFFF,
            t1_zero: 0xFFFF,
            t1_armed: false,
            t1_last_timeout: None,
            pb7: true,
            pb7_toggles: 0,
            t2_latch_lo: 0xFF,
            t2_zero: 0xFFFF,
            t2_count: 0xFFFF,
            t2_armed: false,
        }
    }

    /// /RES at `cycle`: the registers go back to their reset values; the
    /// pins driven from outside keep their levels.
    pub fn reset(&mut self, cycle: u64) {
        let (pa, pb, ca1, cb1, ca2, cb2) = (
            self.pa_pins,
            self.pb_pins,
            self.ca1,
            self.cb1,
            self.ca2_in,
            self.cb2_in,
        );
        *self = Via::new();
        self.now = cycle;
        self.t1_zero = cycle + 0xFFFF;
        self.t2_zero = cycle + 0xFFFF;
        self.pa_pins = pa;
        self.pb_pins = pb;
        self.ca1 = ca1;
        self.cb1 = cb1;
        self.ca2_in = ca2;
        self.cb2_in = cb2;
    }

    fn ca2_mode(&self) -> C2Mode {
        C2Mode::from_bits(self.pcr >> 1)
    }

    fn cb2_mode(&self) -> C2Mode {
        C2Mode::from_bits(self.pcr >> 5)
    }

    fn t1_free_run(&self) -> bool {
        self.acr & acr::T1_FREE_RUN != 0
    }

    fn t2_pulse_mode(&self) -> bool {
        self.acr & acr::T2_PULSE_COUNT != 0
    }

    /// Catches the timers up to `cycle`: every time-out up to and
    /// including `cycle` sets its flag and drives PB7.
    fn catch_up(&mut self, cycle: u64) {
        if cycle <= self.now {
            return;
        }
        self.now = cycle;
        let first = self.t1_zero + 1;
        if cycle >= first {
            if self.t1_free_run() {
                let period = u64::from(self.t1_latch) + 2;
                let count = (cycle - first) / period + 1;
                self.t1_last_timeout = Some(first + (count - 1) * period);
                self.t1_zero += count * period;
                self.ifr |= irq::T1;
                if count % 2 == 1 {
                    self.pb7 = !self.pb7;
                }
                self.pb7_toggles += count;
            } else if self.t1_armed {
                self.t1_armed = false;
                self.t1_last_timeout = Some(first);
                self.ifr |= irq::T1;
                if !self.pb7 {
                    self.pb7_toggles += 1;
                }
                self.pb7 = true;
            }
        }
        if !self.t2_pulse_mode() && self.t2_armed && cycle > self.t2_zero {
            self.t2_armed = false;
            self.ifr |= irq::T2;
        }
    }

    fn t1_counter(&self) -> u16 {
        if self.t1_last_timeout == Some(self.now) {
            return 0xFFFF;
        }
        // Past zero in one-shot mode the counter keeps counting down.
        (self.t1_zero.wrapping_sub(self.now) & 0xFFFF) as u16
    }

    fn t2_counter(&self) -> u16 {
        if self.t2_pulse_mode() {
            self.t2_count
        } else {
            (self.t2_zero.wrapping_sub(self.now) & 0xFFFF) as u16
        }
    }

    fn port_a_input(&self) -> u8 {
        if self.acr & acr::PA_LATCH != 0 {
            self.ira_latch
        } else {
            self.pa_level()
        }
    }

    fn port_b_value(&self) -> u8 {
        let inputs = if self.acr & acr::PB_LATCH != 0 {
            self.irb_latch
        } else {
            self.pb_pins
        };
        let mut value = (self.orb & self.ddrb) | (inputs & !self.ddrb);
        if self.acr & acr::T1_PB7 != 0 {
            value = (value & 0x7F) | if self.pb7 { 0x80 } else { 0 };
        }
        value
    }

    /// The levels on the port A pins: outputs drive ORA, inputs read what
    /// is applied from outside.
    #[must_use]
    pub fn pa_level(&self) -> u8 {
        (self.ora & self.ddra) | (self.pa_pins & !self.ddra)
    }

    /// The levels on the port B pins as the outside world sees them,
    /// including PB7 under timer 1 control.
    #[must_use]
    pub fn pb_level(&self) -> u8 {
        let mut level = (self.orb & self.ddrb) | (self.pb_pins & !self.ddrb);
        if self.acr & acr::T1_PB7 != 0 {
            level = (level & 0x7F) | if self.pb7 { 0x80 } else { 0 };
        }
        level
    }

    /// Drives the port A pins from outside (bits programmed as outputs
    /// ignore it).
    pub fn set_pa_pins(&mut self, value: u8, cycle: u64) {
        self.catch_up(cycle);
        self.pa_pins = value;
    }

    /// Drives the port B pins from outside. A falling edge on PB6 counts
    /// down timer 2 in pulse-counting mode.
    pub fn set_pb_pins(&mut self, value: u8, cycle: u64) {
        self.catch_up(cycle);
        let old = self.pb_pins;
        self.pb_pins = value;
        if old & 0x40 != 0 && value & 0x40 == 0 && self.t2_pulse_mode() {
            self.t2_count = self.t2_count.wrapping_sub(1);
            if self.t2_count == 0 && self.t2_armed {
                self.t2_armed = false;
                self.ifr |= irq::T2;
            }
        }
    }

    /// Drives CA1. The active edge (PCR bit 0) sets the CA1 flag, loads
    /// the port A input latch and ends a CA2 handshake.
    pub fn set_ca1(&mut self, level: bool, cycle: u64) {
        self.catch_up(cycle);
        let positive = self.pcr & 0x01 != 0;
        if level != self.ca1 && level == positive {
            self.ifr |= irq::CA1;
            self.ira_latch = self.pa_level();
            if self.ca2_mode() == C2Mode::Handshake {
                self.ca2_handshake = true;
            }
        }
        self.ca1 = level;
    }

    /// Drives CB1. The active edge (PCR bit 4) sets the CB1 flag, loads
    /// the port B input latch and ends a CB2 handshake.
    pub fn set_cb1(&mut self, level: bool, cycle: u64) {
        self.catch_up(cycle);
        let positive = self.pcr & 0x10 != 0;
        if level != self.cb1 && level == positive {
            self.ifr |= irq::CB1;
            self.irb_latch = self.pb_level();
            if self.cb2_mode() == C2Mode::Handshake {
                self.cb2_handshake = true;
            }
        }
        self.cb1 = level;
    }

    /// Drives CA2 from outside; it acts only when CA2 is an input.
    pub fn set_ca2(&mut self, level: bool, cycle: u64) {
        self.catch_up(cycle);
        if let C2Mode::Input { positive } | C2Mode::IndependentInput { positive } = self.ca2_mode()
        {
            if level != self.ca2_in && level == positive {
                self.ifr |= irq::CA2;
            }
        }
        self.ca2_in = level;
    }

    /// Drives CB2 from outside; it acts only when CB2 is an input.
    pub fn set_cb2(&mut self, level: bool, cycle: u64) {
        self.catch_up(cycle);
        if let C2Mode::Input { positive } | C2Mode::IndependentInput { positive } = self.cb2_mode()
        {
            if level != self.cb2_in && level == positive {
                self.ifr |= irq::CB2;
            }
        }
        self.cb2_in = level;
    }

    /// The CA2 pin: the VIA's output level in an output mode, else the
    /// level applied from outside.
    #[must_use]
    pub fn ca2_level(&self) -> bool {
        match self.ca2_mode() {
            C2Mode::Handshake => self.ca2_handshake,
            C2Mode::Pulse => true,
            C2Mode::Manual(level) => level,
            _ => self.ca2_in,
        }
    }

    /// The CB2 pin, as [`Via::ca2_level`].
    #[must_use]
    pub fn cb2_level(&self) -> bool {
        match self.cb2_mode() {
            C2Mode::Handshake => self.cb2_handshake,
            C2Mode::Pulse => true,
            C2Mode::Manual(level) => level,
            _ => self.cb2_in,
        }
    }

    /// How many one-cycle low pulses CA2 and CB2 have given in pulse mode.
    #[must_use]
    pub fn c2_pulses(&self) -> (u64, u64) {
        (self.ca2_pulses, self.cb2_pulses)
    }

    /// The frequency of the square wave timer 1 puts on PB7, in hertz of
    /// a clock of `cpu_hz`, or `None` when PB7 is not a free-running
    /// timer output.
    #[must_use]
    pub fn pb7_square_wave_hz(&self, cpu_hz: u64) -> Option<f64> {
        if self.acr & acr::T1_PB7 == 0 || !self.t1_free_run() {
            return None;
        }
        #[allow(
            clippy::cast_precision_loss,
            reason = "a frequency for display and tests"
        )]
        let hz = cpu_hz as f64 / (2.0 * (f64::from(self.t1_latch) + 2.0));
        Some(hz)
    }

    /// How many times PB7 has changed level under timer 1 control, up to
    /// `cycle`.
    pub fn pb7_toggles(&mut self, cycle: u64) -> u64 {
        self.catch_up(cycle);
        self.pb7_toggles
    }

    /// The raw interrupt flags (bits 0-6) as of the last cycle caught up to.
    #[must_use]
    pub fn flags(&self) -> u8 {
        self.ifr
    }

    /// The value read from the IFR: flags plus bit 7 when any enabled flag
    /// is set.
    fn ifr_value(&self) -> u8 {
        self.ifr | if self.irq_asserted() { irq::ANY } else { 0 }
    }

    fn irq_asserted(&self) -> bool {
        self.ifr & self.ier & 0x7F != 0
    }

    /// An access to ORA (with handshake): clears the CA1 flag and, unless
    /// CA2 is an independent input, the CA2 flag; starts a CA2 handshake
    /// or pulse.
    fn port_a_access(&mut self) {
        self.ifr &= !irq::CA1;
        let mode = self.ca2_mode();
        if !matches!(mode, C2Mode::IndependentInput { .. }) {
            self.ifr &= !irq::CA2;
        }
        match mode {
            C2Mode::Handshake => self.ca2_handshake = false,
            C2Mode::Pulse => self.ca2_pulses += 1,
            _ => {}
        }
    }

    /// An access to ORB: clears CB1 and (unless independent) CB2.
    fn port_b_access(&mut self, write: bool) {
        self.ifr &= !irq::CB1;
        let mode = self.cb2_mode();
        if !matches!(mode, C2Mode::IndependentInput { .. }) {
            self.ifr &= !irq::CB2;
        }
        // CB2's handshake and pulse answer writes only.
        if write {
            match mode {
                C2Mode::Handshake => self.cb2_handshake = false,
                C2Mode::Pulse => self.cb2_pulses += 1,
                _ => {}
            }
        }
    }

    fn write_acr(&mut self, value: u8) {
        let was_free = self.t1_free_run();
        let was_pulse = self.t2_pulse_mode();
        self.acr = value;
        if self.t1_free_run() && !was_free && self.t1_zero < self.now {
            // A one-shot that already timed out keeps counting down; it
            // next reaches zero when the counter wraps.
            let behind = self.now - self.t1_zero;
            self.t1_zero += behind.div_ceil(0x1_0000) * 0x1_0000;
        }
        if !self.t1_free_run() && was_free {
            self.t1_armed = true;
        }
        if self.t2_pulse_mode() && !was_pulse {
            self.t2_count = (self.t2_zero.wrapping_sub(self.now) & 0xFFFF) as u16;
        } else if !self.t2_pulse_mode() && was_pulse {
            self.t2_zero = self.now + u64::from(self.t2_count);
        }
    }
}

impl Device for Via {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.catch_up(cycle);
        match offset & 0xF {
            reg::ORB => {
                self.port_b_access(false);
                self.port_b_value()
            }
            reg::ORA => {
                self.port_a_access();
                self.port_a_input()
            }
            reg::T1C_L => {
                self.ifr &= !irq::T1;
                (self.t1_counter() & 0xFF) as u8
            }
            reg::T2C_L => {
                self.ifr &= !irq::T2;
                (self.t2_counter() & 0xFF) as u8
            }
            reg::SR => {
                self.ifr &= !irq::SR;
                self.sr
            }
            other => self.peek(other),
        }
    }

    fn write(&mut self, offset: u16, value: u8, cycle: u64) {
        self.catch_up(cycle);
        match offset & 0xF {
            reg::ORB => {
                self.orb = value;
                self.port_b_access(true);
            }
            reg::ORA => {
                self.ora = value;
                self.port_a_access();
            }
            reg::DDRB => self.ddrb = value,
            reg::DDRA => self.ddra = value,
            reg::T1C_L | reg::T1L_L => {
                self.t1_latch = (self.t1_latch & 0xFF00) | u16::from(value);
            }
            reg::T1C_H => {
                self.t1_latch = (self.t1_latch & 0x00FF) | (u16::from(value) << 8);
                self.t1_zero = cycle + 1 + u64::from(self.t1_latch);
                self.t1_armed = true;
                self.t1_last_timeout = None;
                self.ifr &= !irq::T1;
                if self.acr & acr::T1_PB7 != 0 && self.pb7 {
                    self.pb7_toggles += 1;
                }
                // PB7 goes low when the timer starts, in both modes.
                self.pb7 = false;
            }
            reg::T1L_H => {
                self.t1_latch = (self.t1_latch & 0x00FF) | (u16::from(value) << 8);
                // The MOS datasheet: writing the high latch also clears
                // the T1 flag.
                self.ifr &= !irq::T1;
            }
            reg::T2C_L => self.t2_latch_lo = value,
            reg::T2C_H => {
                let count = (u16::from(value) << 8) | u16::from(self.t2_latch_lo);
                self.t2_zero = cycle + 1 + u64::from(count);
                self.t2_count = count;
                self.t2_armed = true;
                self.ifr &= !irq::T2;
            }
            reg::SR => {
                self.sr = value;
                self.ifr &= !irq::SR;
            }
            reg::ACR => self.write_acr(value),
            reg::PCR => {
                self.pcr = value;
                // Entering handshake mode leaves the line high until the
                // next port access.
                if !self.ca2_mode().is_output() {
                    self.ca2_handshake = true;
                }
                if !self.cb2_mode().is_output() {
                    self.cb2_handshake = true;
                }
            }
            reg::IFR => self.ifr &= !(value & 0x7F),
            reg::IER => {
                if value & irq::ANY != 0 {
                    self.ier |= value & 0x7F;
                } else {
                    self.ier &= !(value & 0x7F);
                }
            }
            _ => self.ora = value, // ORA without handshake
        }
    }

    fn peek(&self, offset: u16) -> u8 {
        match offset & 0xF {
            reg::ORB => self.port_b_value(),
            reg::ORA | reg::ORA_NH => self.port_a_input(),
            reg::DDRB => self.ddrb,
            reg::DDRA => self.ddra,
            reg::T1C_L => (self.t1_counter() & 0xFF) as u8,
            reg::T1C_H => (self.t1_counter() >> 8) as u8,
            reg::T1L_L => (self.t1_latch & 0xFF) as u8,
            reg::T1L_H => (self.t1_latch >> 8) as u8,
            reg::T2C_L => (self.t2_counter() & 0xFF) as u8,
            reg::T2C_H => (self.t2_counter() >> 8) as u8,
            reg::SR => self.sr,
            reg::ACR => self.acr,
            reg::PCR => self.pcr,
            reg::IFR => self.ifr_value(),
            _ => self.ier | 0x80,
        }
    }

    fn sync(&mut self, cycle: u64) {
        self.catch_up(cycle);
    }

    fn next_event(&self) -> Option<u64> {
        let mut next: Option<u64> = None;
        if self.ier & irq::T1 != 0
            && self.ifr & irq::T1 == 0
            && (self.t1_armed || self.t1_free_run())
        {
            next = Some(self.t1_zero + 1);
        }
        if self.ier & irq::T2 != 0
            && self.ifr & irq::T2 == 0
            && self.t2_armed
            && !self.t2_pulse_mode()
        {
            let t2 = self.t2_zero + 1;
            next = Some(next.map_or(t2, |t1| t1.min(t2)));
        }
        next
    }

    fn irq(&self) -> bool {
        self.irq_asserted()
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

    #[test]
    fn ports_mix_outputs_and_inputs_by_ddr() {
        let mut via = Via::new();
        via.set_pb_pins(0b1010_1010, 0);
        via.write(reg::DDRB, 0x0F, 1);
        via.write(reg::ORB, 0x55, 2);
        assert_eq!(via.read(reg::ORB, 3), 0b1010_0101);
        assert_eq!(via.pb_level(), 0b1010_0101);
        via.set_pa_pins(0x3C, 4);
        assert_eq!(via.read(reg::ORA, 5), 0x3C);
        via.write(reg::DDRA, 0xF0, 6);
        via.write(reg::ORA_NH, 0xA0, 7);
        assert_eq!(via.read(reg::ORA_NH, 8), 0xAC);
        assert_eq!(via.peek(reg::DDRA), 0xF0);
    }

    #[test]
    fn t1_one_shot_times_out_after_n_plus_1_5_cycles() {
        let mut via = Via::new();
        via.write(reg::IER, irq::ANY | irq::T1, 0);
        via.write(reg::T1C_L, 10, 100);
        via.write(reg::T1C_H, 0, 101);
        // The counter reads N on the next cycle and counts down.
        via.sync(102);
        assert_eq!(via.peek(reg::T1C_L), 10);
        via.sync(112);
        assert_eq!(via.peek(reg::T1C_L), 0);
        assert!(!via.irq());
        assert_eq!(via.next_event(), Some(113));
        via.sync(113);
        assert!(via.irq());
        assert_eq!(via.peek(reg::IFR), irq::ANY | irq::T1);
        assert_eq!(via.peek(reg::T1C_H), 0xFF);
        // One-shot: no second interrupt, the counter keeps counting down.
        assert_eq!(via.next_event(), None);
        // Reading T1C-L clears the flag.
        assert_eq!(via.read(reg::T1C_L, 114), 0xFE);
        assert!(!via.irq());
        via.sync(200_000);
        assert!(!via.irq());
    }

    #[test]
    fn t1_free_run_reloads_every_n_plus_2_and_toggles_pb7() {
        let mut via = Via::new();
        via.write(reg::ACR, 0xC0, 0);
        via.write(reg::T1C_L, 98, 1);
        via.write(reg::T1C_H, 0, 2);
        assert_eq!(via.pb_level() & 0x80, 0, "PB7 goes low at the start");
        // First time-out at 2 + 98 + 2 = 102, then every 100 cycles.
        via.sync(101);
        assert_eq!(via.flags() & irq::T1, 0);
        via.sync(102);
        assert_eq!(via.flags() & irq::T1, irq::T1);
        assert_eq!(via.peek(reg::T1C_H), 0xFF, "$FFFF for one cycle");
        via.sync(103);
        assert_eq!(via.peek(reg::T1C_L), 98, "then the latch");
        assert_eq!(via.pb_level() & 0x80, 0x80);
        // 10,000 cycles later: 101 time-outs in all, plus the fall at the
        // start; an odd number of time-outs leaves PB7 high.
        assert_eq!(via.pb7_toggles(10_102), 102);
        assert_eq!(via.pb_level() & 0x80, 0x80);
        assert_eq!(via.pb7_square_wave_hz(1_000_000), Some(5000.0));
        // Not enabled in IER: no interrupt and no event.
        assert!(!via.irq());
        assert_eq!(via.next_event(), None);
        via.write(reg::IER, irq::ANY | irq::T1, 10_103);
        assert!(via.irq(), "the pending flag asserts IRQ once enabled");
    }

    #[test]
    fn t1_latch_write_changes_the_next_period_only() {
        let mut via = Via::new();
        via.write(reg::ACR, 0x40, 0);
        via.write(reg::T1C_L, 48, 1);
        via.write(reg::T1C_H, 0, 2);
        // Time-out at 52; reload with 48 -> next time-out at 102.
        via.write(reg::T1L_L, 8, 60);
        via.write(reg::IER, irq::ANY | irq::T1, 61);
        via.write(reg::IFR, irq::T1, 62);
        assert_eq!(via.next_event(), Some(102));
        via.sync(102);
        assert!(via.irq());
        via.write(reg::IFR, 0x7F, 103);
        // Now the period is 8 + 2.
        assert_eq!(via.next_event(), Some(112));
    }

    #[test]
    fn t2_one_shot_and_pulse_counting() {
        let mut via = Via::new();
        via.write(reg::IER, irq::ANY | irq::T2, 0);
        via.write(reg::T2C_L, 0x00, 0);
        via.write(reg::T2C_H, 0x01, 10); // 256
        assert_eq!(via.next_event(), Some(10 + 256 + 2));
        via.sync(267);
        assert!(!via.irq());
        via.sync(268);
        assert!(via.irq());
        assert_eq!(via.read(reg::T2C_L, 269), 0xFE);
        assert!(!via.irq(), "reading T2C-L clears the flag");
        via.sync(100_000);
        assert!(!via.irq(), "one interrupt per load");

        via.write(reg::ACR, 0x20, 100_001);
        via.write(reg::T2C_L, 3, 100_002);
        via.write(reg::T2C_H, 0, 100_003);
        assert_eq!(via.next_event(), None, "pulses come from outside");
        for (i, cycle) in [100_010_u64, 100_020, 100_030].into_iter().enumerate() {
            via.set_pb_pins(0x00, cycle);
            via.set_pb_pins(0xFF, cycle + 5);
            assert_eq!(via.irq(), i == 2, "after pulse {}", i + 1);
        }
        assert_eq!(via.peek(reg::T2C_L), 0);
    }

    #[test]
    fn ier_bit_7_sets_or_clears_and_reads_as_one() {
        let mut via = Via::new();
        via.write(reg::IER, 0x80 | 0x42, 0);
        assert_eq!(via.peek(reg::IER), 0xC2);
        via.write(reg::IER, 0x02, 1);
        assert_eq!(via.peek(reg::IER), 0xC0);
        via.write(reg::IER, 0x7F, 2);
        assert_eq!(via.peek(reg::IER), 0x80);
    }

    #[test]
    fn ca1_edge_sets_flag_and_port_access_clears_it() {
        let mut via = Via::new();
        via.write(reg::IER, irq::ANY | irq::CA1, 0);
        // Negative edge by default.
        via.set_ca1(true, 1);
        assert!(!via.irq());
        via.set_ca1(false, 2);
        assert!(via.irq());
        assert_eq!(via.peek(reg::IFR), 0x82);
        // ORA without handshake does not clear it.
        via.read(reg::ORA_NH, 3);
        assert!(via.irq());
        via.read(reg::ORA, 4);
        assert!(!via.irq());
        // Positive edge when PCR bit 0 is set.
        via.write(reg::PCR, 0x01, 5);
        via.set_ca1(true, 6);
        assert!(via.irq());
        // Writing IFR clears flags too.
        via.write(reg::IFR, irq::CA1, 7);
        assert!(!via.irq());
    }

    #[test]
    fn port_a_latches_on_ca1_when_enabled() {
        let mut via = Via::new();
        via.write(reg::ACR, acr::PA_LATCH, 0);
        via.set_pa_pins(0x11, 1);
        via.set_ca1(false, 2);
        via.set_pa_pins(0x22, 3);
        assert_eq!(via.read(reg::ORA, 4), 0x11);
        via.write(reg::ACR, 0, 5);
        assert_eq!(via.read(reg::ORA, 6), 0x22);
    }

    #[test]
    fn ca2_independent_input_survives_port_access() {
        let mut via = Via::new();
        via.write(reg::PCR, 0b0000_0010, 0); // CA2 independent, negative edge
        via.set_ca2(false, 1);
        assert_eq!(via.flags() & irq::CA2, irq::CA2);
        via.read(reg::ORA, 2);
        assert_eq!(via.flags() & irq::CA2, irq::CA2);
        via.write(reg::PCR, 0b0000_0000, 3); // plain input
        via.read(reg::ORA, 4);
        assert_eq!(via.flags() & irq::CA2, 0);
    }

    #[test]
    fn c2_output_modes() {
        let mut via = Via::new();
        via.write(reg::PCR, 0b1100_1000, 0); // CB2 manual low, CA2 handshake
        assert!(!via.cb2_level());
        assert!(via.ca2_level());
        via.write(reg::ORA, 0, 1);
        assert!(!via.ca2_level(), "handshake: low after the access");
        via.set_ca1(false, 2);
        assert!(via.ca2_level(), "high again on the CA1 active edge");
        via.write(reg::PCR, 0b1010_1010, 3); // CB2 pulse, CA2 pulse
        via.write(reg::ORB, 0, 4);
        via.read(reg::ORB, 5);
        via.read(reg::ORA, 6);
        assert_eq!(via.c2_pulses(), (1, 1), "CB2 pulses on writes only");
    }

    #[test]
    fn reset_clears_registers_but_keeps_pins() {
        let mut via = Via::new();
        via.set_pa_pins(0x5A, 0);
        via.write(reg::DDRB, 0xFF, 1);
        via.write(reg::IER, 0xFF, 2);
        via.reset(3);
        assert_eq!(via.peek(reg::DDRB), 0);
        assert_eq!(via.peek(reg::IER), 0x80);
        assert_eq!(via.peek(reg::ORA), 0x5A);
    }
}
