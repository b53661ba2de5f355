//! A serial wire as levels over time, and a UART receiver that samples it.
//!
//! The sender puts whole characters on a [`Wire`] (start bit, data bits LSB
//! first, optional parity, stop bits). A [`Sampler`] receives them the way a
//! real UART does: it waits for a falling edge, checks the start bit in its
//! middle, samples each bit in its middle at its *own* rate and reports a
//! framing error when the stop bit is low. With matching rates and formats
//! it gets back exactly what was sent; with a wrong baud rate it gets the
//! garbage and framing errors a real robot would, so host code meets a
//! misconfigured line in the emulator first.

use std::collections::VecDeque;

use super::serial::{Baud, FrameClock, FrameFormat, Parity};

/// One character on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Character {
    /// The cycle its start bit begins.
    pub start: u64,
    /// The cycle its last stop bit ends.
    pub end: u64,
    /// The data as sent (bits above the data length are ignored).
    pub data: u8,
    baud: Baud,
    format: FrameFormat,
    /// The cycle its first stop bit begins: no falling edge from then on.
    stop_start: u64,
}

impl Character {
    /// The level of bit `k` of the frame (0 = start bit).
    fn bit(&self, k: u64) -> bool {
        let data_bits = u64::from(self.format.data_bits);
        if k == 0 {
            return false;
        }
        if k <= data_bits {
            return (self.data >> (k - 1)) & 1 == 1;
        }
        if k == data_bits + 1 {
            return parity_bit(self.data, self.format).unwrap_or(true);
        }
        true
    }

    /// The number of bits before the stop bits.
    fn leading_bits(&self) -> u64 {
        1 + u64::from(self.format.data_bits) + u64::from(self.format.parity != Parity::None)
    }

    fn level_at(&self, cycle: u64) -> bool {
        if cycle < self.start || cycle >= self.end {
            return true;
        }
        self.bit(self.baud.bits_in_cycles(cycle - self.start))
    }

    fn bit_start(&self, k: u64) -> u64 {
        self.start + self.baud.cycles_for_half_bits_ceil(2 * k)
    }
}

/// The bits of a byte that `format` carries.
fn data_mask(format: FrameFormat) -> u8 {
    if format.data_bits >= 8 {
        0xFF
    } else {
        (1u8 << format.data_bits) - 1
    }
}

/// The parity bit for `data` in `format`, or `None` without parity.
fn parity_bit(data: u8, format: FrameFormat) -> Option<bool> {
    let ones = (data & data_mask(format)).count_ones();
    match format.parity {
        Parity::None => None,
        Parity::Odd => Some(ones % 2 == 0),
        Parity::Even => Some(ones % 2 == 1),
        Parity::Mark => Some(true),
        Parity::Space => Some(false),
    }
}

/// One direction of a serial line: the characters on it, in time order.
#[derive(Debug, Clone, Default)]
pub struct Wire {
    chars: VecDeque<Character>,
    clock: FrameClock,
}

impl Wire {
    /// An idle wire.
    #[must_use]
    pub fn new() -> Wire {
        Wire::default()
    }

    /// Sends `data` at `baud` in `format`, starting at `now` or as soon as
    /// the character before it ends.
    pub fn send(&mut self, data: u8, now: u64, baud: Baud, format: FrameFormat) -> Character {
        let (start, end) = self.clock.schedule(now, format.half_bits(), baud);
        let mut character = Character {
            start,
            end,
            data,
            baud,
            format,
            stop_start: end,
        };
        character.stop_start = character.bit_start(character.leading_bits());
        self.chars.push_back(character);
        character
    }

    /// The cycle the last character sent ends (the wire is free from then).
    #[must_use]
    pub fn free_at(&self) -> u64 {
        self.clock.free_at()
    }

    /// Characters still on the wire (not yet forgotten).
    #[must_use]
    pub fn pending(&self) -> usize {
        self.chars.len()
    }

    /// The level at `cycle` (idle is high).
    #[must_use]
    pub fn level(&self, cycle: u64) -> bool {
        self.chars
            .iter()
            .find(|c| c.start <= cycle && cycle < c.end)
            .is_none_or(|c| c.level_at(cycle))
    }

    /// The first high-to-low transition at or after `from`, and the
    /// character it is in.
    fn next_falling_edge(&self, from: u64) -> Option<(u64, &Character)> {
        // A character whose edges all lie before `from` (the last one a
        // receiver took stays on the wire until its stop bit ends) is
        // passed over without looking at its bits.
        for character in self.chars.iter().filter(|c| c.stop_start > from) {
            for k in 0..character.leading_bits() {
                let before = k == 0 || character.bit(k - 1);
                if before && !character.bit(k) {
                    let at = character.bit_start(k);
                    if at >= from {
                        return Some((at, character));
                    }
                }
            }
        }
        None
    }

    /// Drops characters that end at or before `cycle`.
    fn forget_before(&mut self, cycle: u64) {
        while self.chars.front().is_some_and(|c| c.end <= cycle) {
            self.chars.pop_front();
        }
    }
}

/// A character as a receiver saw it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Received {
    /// The data bits sampled (bits above the data length are 0).
    pub data: u8,
    /// The stop bit was low.
    pub framing_error: bool,
    /// The parity bit did not match (only with odd or even parity).
    pub parity_error: bool,
    /// The cycle of the stop-bit sample, when the receiver has the
    /// character.
    pub at: u64,
}

/// The receiving half of a UART, hunting for start bits on a [`Wire`].
#[derive(Debug, Clone, Default)]
pub struct Sampler {
    hunt_from: u64,
}

impl Sampler {
    /// A receiver that starts listening at cycle 0.
    #[must_use]
    pub fn new() -> Sampler {
        Sampler::default()
    }

    /// The next character the receiver will assemble from what is on the
    /// wire now, at `baud` in `format` (its `at` may be in the future).
    #[must_use]
    pub fn peek(&self, wire: &Wire, baud: Baud, format: FrameFormat) -> Option<Received> {
        let (edge, character) = wire.next_falling_edge(self.hunt_from)?;
        if edge == character.start && character.baud.same_rate(baud) && character.format == format {
            // Sent at this receiver's own rate and format, and found by its
            // start bit: every sample falls in the middle of the bit it is
            // meant for, so the character reads back exactly as sent (what
            // sampling it bit by bit would find, as a test checks).
            return Some(Received {
                data: character.data & data_mask(format),
                framing_error: false,
                parity_error: false,
                at: edge + baud.cycles_for_half_bits(2 * character.leading_bits() + 1),
            });
        }
        self.sample(wire, baud, format)
    }

    /// [`Sampler::peek`] the long way: every bit sampled on the wire.
    fn sample(&self, wire: &Wire, baud: Baud, format: FrameFormat) -> Option<Received> {
        let mut from = self.hunt_from;
        loop {
            let (edge, _) = wire.next_falling_edge(from)?;
            let sample = |half_bits: u64| edge + baud.cycles_for_half_bits(half_bits);
            let start = sample(1);
            if wire.level(start) {
                // A glitch, not a start bit: hunt again after it.
                from = start;
                continue;
            }
            let mut data = 0u8;
            for bit in 0..u64::from(format.data_bits) {
                if wire.level(sample(2 * (bit + 1) + 1)) {
                    data |= 1 << bit;
                }
            }
            let mut next_bit = 1 + u64::from(format.data_bits);
            let mut parity_error = false;
            if let Some(expected) = parity_bit(data, format) {
                let seen = wire.level(sample(2 * next_bit + 1));
                next_bit += 1;
                parity_error =
                    matches!(format.parity, Parity::Odd | Parity::Even) && seen != expected;
            }
            let stop = sample(2 * next_bit + 1);
            return Some(Received {
                data,
                framing_error: !wire.level(stop),
                parity_error,
                at: stop,
            });
        }
    }

    /// Takes the next character if the receiver has it by `now`, and
    /// forgets what the wire no longer needs.
    pub fn receive(
        &mut self,
        wire: &mut Wire,
        now: u64,
        baud: Baud,
        format: FrameFormat,
    ) -> Option<Received> {
        let received = self.peek(wire, baud, format).filter(|r| r.at <= now)?;
        self.hunt_from = received.at;
        wire.forget_before(received.at);
        Some(received)
    }

    /// Stops listening until `cycle` (a receiver switched off or without a
    /// clock misses whatever is sent before then).
    pub fn skip_to(&mut self, wire: &mut Wire, cycle: u64) {
        self.hunt_from = self.hunt_from.max(cycle);
        wire.forget_before(cycle);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn receive_all(wire: &mut Wire, baud: Baud, format: FrameFormat) -> Vec<Received> {
        let mut sampler = Sampler::new();
        let mut out = Vec::new();
        while let Some(r) = sampler.receive(wire, u64::MAX, baud, format) {
            out.push(r);
        }
        out
    }

    /// The shortcut for characters sent at the receiver's own rate gives
    /// what sampling every bit gives, for every byte, format and rate,
    /// including the 6551's crystal rates against the host's round ones.
    #[test]
    fn the_matching_rate_shortcut_reads_what_sampling_reads() {
        let formats = [
            FrameFormat::EIGHT_N_ONE,
            FrameFormat {
                data_bits: 7,
                parity: Parity::Even,
                stop_half_bits: 2,
            },
            FrameFormat {
                data_bits: 5,
                parity: Parity::Odd,
                stop_half_bits: 3,
            },
            FrameFormat {
                data_bits: 8,
                parity: Parity::Mark,
                stop_half_bits: 4,
            },
        ];
        let rates = [
            (Baud::new(9600), Baud::from_crystal_divisor(12)),
            (Baud::new(19200), Baud::new(19200)),
            (
                Baud::from_crystal_divisor(1047),
                Baud::from_crystal_divisor(1047),
            ),
        ];
        for format in formats {
            for (sent, heard) in rates {
                assert!(sent.same_rate(heard));
                let mut wire = Wire::new();
                for byte in 0..=255u8 {
                    wire.send(byte, u64::from(byte) * 7, sent, format);
                }
                let mut sampler = Sampler::new();
                for byte in 0..=255u8 {
                    let quick = sampler.peek(&wire, heard, format);
                    let slow = sampler.sample(&wire, heard, format);
                    assert_eq!(quick, slow, "{byte} in {format:?} at {sent:?}");
                    let quick = quick.expect("a character");
                    assert_eq!(quick.data, byte & data_mask(format));
                    sampler.receive(&mut wire, quick.at, heard, format);
                }
            }
        }
    }

    #[test]
    fn matching_rates_receive_what_was_sent() {
        let baud = Baud::new(9600);
        let format = FrameFormat::EIGHT_N_ONE;
        let mut wire = Wire::new();
        let sent: Vec<u8> = (0..=255).collect();
        for &byte in &sent {
            wire.send(byte, 0, baud, format);
        }
        let got = receive_all(&mut wire, baud, format);
        assert_eq!(got.iter().map(|r| r.data).collect::<Vec<_>>(), sent);
        assert!(got.iter().all(|r| !r.framing_error && !r.parity_error));
        // The first character is there at the middle of its stop bit:
        // 9.5 bit times.
        assert_eq!(got[0].at, 989);
        assert_eq!(wire.pending(), 1, "the last stop bit is still on the wire");
    }

    #[test]
    fn the_6551_rate_receives_a_9600_baud_host() {
        let mut wire = Wire::new();
        for byte in b"/1P" {
            wire.send(*byte, 0, Baud::new(9600), FrameFormat::EIGHT_N_ONE);
        }
        let got = receive_all(
            &mut wire,
            Baud::from_crystal_divisor(12),
            FrameFormat::EIGHT_N_ONE,
        );
        assert_eq!(got.iter().map(|r| r.data).collect::<Vec<_>>(), b"/1P");
    }

    #[test]
    fn a_wrong_rate_gives_garbage_and_framing_errors() {
        let mut wire = Wire::new();
        for byte in b"/1X/1X/1X" {
            wire.send(*byte, 0, Baud::new(9600), FrameFormat::EIGHT_N_ONE);
        }
        let got = receive_all(&mut wire, Baud::new(4800), FrameFormat::EIGHT_N_ONE);
        let data: Vec<u8> = got.iter().map(|r| r.data).collect();
        assert_ne!(data, b"/1X/1X/1X");
        assert!(got.iter().any(|r| r.framing_error), "{got:?}");
    }

    #[test]
    fn parity_is_checked() {
        let even = FrameFormat {
            data_bits: 7,
            parity: Parity::Even,
            stop_half_bits: 2,
        };
        let odd = FrameFormat {
            parity: Parity::Odd,
            ..even
        };
        let baud = Baud::new(1200);
        let mut wire = Wire::new();
        wire.send(b'A', 0, baud, even);
        let got = receive_all(&mut wire, baud, even);
        assert_eq!((got[0].data, got[0].parity_error), (b'A', false));
        let mut wire = Wire::new();
        wire.send(b'A', 0, baud, even);
        let got = receive_all(&mut wire, baud, odd);
        assert_eq!((got[0].data, got[0].parity_error), (b'A', true));
    }

    #[test]
    fn a_receiver_skipping_ahead_misses_characters() {
        let baud = Baud::new(9600);
        let format = FrameFormat::EIGHT_N_ONE;
        let mut wire = Wire::new();
        let first = wire.send(b'a', 0, baud, format);
        wire.send(b'b', 0, baud, format);
        let mut sampler = Sampler::new();
        sampler.skip_to(&mut wire, first.end);
        let got = sampler.receive(&mut wire, u64::MAX, baud, format);
        assert_eq!(got.map(|r| r.data), Some(b'b'));
    }
}
