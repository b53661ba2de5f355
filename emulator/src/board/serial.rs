//! Serial-line timing: baud rates as exact fractions and back-to-back
//! character framing in emulated CPU cycles.
//!
//! Characters sent back to back must not drift: at 9600 baud a bit lasts
//! 104.1666... cycles of the 1 MHz CPU, so rounding each character to whole
//! cycles would gain or lose a cycle every few characters. A [`FrameClock`]
//! therefore keeps the cycle at which a burst started and the number of
//! half-bits sent since, and rounds only the absolute times.

use platform::acia::CRYSTAL_HZ as ACIA_CRYSTAL_HZ;
pub use platform::line::CPU_HZ;

/// A bit rate, kept as the exact fraction `numerator / denominator` bits per
/// second so that the 6551's odd rates (109.92, 134.58 baud) stay exact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Baud {
    numerator: u64,
    denominator: u64,
}

impl Baud {
    /// A whole number of bits per second (`Baud::new(9600)`). Zero is
    /// treated as one bit per second: a rate of zero would never deliver.
    #[must_use]
    pub const fn new(bits_per_second: u32) -> Baud {
        let numerator = if bits_per_second == 0 {
            1
        } else {
            bits_per_second as u64
        };
        Baud {
            numerator,
            denominator: 1,
        }
    }

    /// The rate the 6551's internal generator makes from its crystal with
    /// `divisor` (crystal / 16 / divisor).
    #[must_use]
    pub const fn from_crystal_divisor(divisor: u16) -> Baud {
        let divisor = if divisor == 0 { 1 } else { divisor as u64 };
        Baud {
            numerator: ACIA_CRYSTAL_HZ,
            denominator: 16 * divisor,
        }
    }

    /// Bits per second, rounded to the nearest hundredth.
    #[must_use]
    pub fn bits_per_second(self) -> f64 {
        #[allow(clippy::cast_precision_loss, reason = "a display value")]
        let value = self.numerator as f64 / self.denominator as f64;
        (value * 100.0).round() / 100.0
    }

    /// The emulated CPU cycles that `half_bits` half-bit times last,
    /// rounded down.
    #[must_use]
    pub fn cycles_for_half_bits(self, half_bits: u64) -> u64 {
        let cycles = u128::from(half_bits) * u128::from(CPU_HZ) * u128::from(self.denominator)
            / (2 * u128::from(self.numerator));
        u64::try_from(cycles).unwrap_or(u64::MAX)
    }

    /// The first whole cycle at or after the end of `half_bits` half-bit
    /// times: where a level change on the wire becomes visible.
    #[must_use]
    pub fn cycles_for_half_bits_ceil(self, half_bits: u64) -> u64 {
        let numerator = u128::from(half_bits) * u128::from(CPU_HZ) * u128::from(self.denominator);
        let cycles = numerator.div_ceil(2 * u128::from(self.numerator));
        u64::try_from(cycles).unwrap_or(u64::MAX)
    }

    /// How many whole bit times fit in `cycles`.
    #[must_use]
    pub fn bits_in_cycles(self, cycles: u64) -> u64 {
        let bits = u128::from(cycles) * u128::from(self.numerator)
            / (u128::from(CPU_HZ) * u128::from(self.denominator));
        u64::try_from(bits).unwrap_or(u64::MAX)
    }

    /// Whether two rates are the same fraction (`Baud::new(9600)` and the
    /// 6551's crystal / 16 / 12 are).
    #[must_use]
    pub fn same_rate(self, other: Baud) -> bool {
        u128::from(self.numerator) * u128::from(other.denominator)
            == u128::from(other.numerator) * u128::from(self.denominator)
    }

    /// Whether two rates are close enough for a UART to receive what the
    /// other sends: within 2%, the usual tolerance of a 16x-sampling
    /// receiver over a 10-bit character.
    #[must_use]
    pub fn matches(self, other: Baud) -> bool {
        // |a - b| <= a / 50, in integers: |a_n*b_d - b_n*a_d| * 50 <= a_n*b_d.
        let a = u128::from(self.numerator) * u128::from(other.denominator);
        let b = u128::from(other.numerator) * u128::from(self.denominator);
        a.abs_diff(b) * 50 <= a
    }
}

/// Parity of a character frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parity {
    /// No parity bit.
    None,
    /// Odd parity.
    Odd,
    /// Even parity.
    Even,
    /// A parity bit that is always 1 (not checked).
    Mark,
    /// A parity bit that is always 0 (not checked).
    Space,
}

/// The shape of one asynchronous character: start bit, data bits, optional
/// parity, stop bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameFormat {
    /// Data bits, 5 to 8.
    pub data_bits: u8,
    /// The parity bit, if any.
    pub parity: Parity,
    /// Stop bits in half-bit units: 2 (one), 3 (one and a half) or 4 (two).
    pub stop_half_bits: u8,
}

impl FrameFormat {
    /// 8 data bits, no parity, one stop bit: the Scorpion's default.
    pub const EIGHT_N_ONE: FrameFormat = FrameFormat {
        data_bits: 8,
        parity: Parity::None,
        stop_half_bits: 2,
    };

    /// The length of one character in half-bit times.
    #[must_use]
    pub fn half_bits(self) -> u64 {
        let parity = u64::from(self.parity != Parity::None);
        2 * (1 + u64::from(self.data_bits) + parity) + u64::from(self.stop_half_bits)
    }

    /// Whether a receiver set to `self` reads what a sender set to `other`
    /// sends: the same data length and parity presence. (Stop bits differ
    /// harmlessly: a receiver checks only the first.)
    #[must_use]
    pub fn compatible(self, other: FrameFormat) -> bool {
        self.data_bits == other.data_bits
            && (self.parity == Parity::None) == (other.parity == Parity::None)
    }
}

/// Times characters sent back to back on one wire without drift.
#[derive(Debug, Clone, Default)]
pub struct FrameClock {
    /// The cycle the current burst started at.
    anchor: u64,
    /// Half-bits sent since `anchor`.
    half_bits: u64,
    /// The cycle the wire is next free at (the last stop bit's end).
    free_at: u64,
}

impl FrameClock {
    /// A wire that has been idle since cycle 0.
    #[must_use]
    pub fn new() -> FrameClock {
        FrameClock::default()
    }

    /// Schedules one character of `frame_half_bits` at `baud`, starting at
    /// `now` or when the previous character ends, whichever is later.
    /// Returns the cycles at which it starts and at which its last stop bit
    /// ends.
    pub fn schedule(&mut self, now: u64, frame_half_bits: u64, baud: Baud) -> (u64, u64) {
        // A character that starts exactly as the last one ends continues
        // the burst; only a gap restarts the count.
        if now > self.free_at {
            self.anchor = now;
            self.half_bits = 0;
        }
        let start = self.anchor + baud.cycles_for_half_bits(self.half_bits);
        self.half_bits += frame_half_bits;
        let done = self.anchor + baud.cycles_for_half_bits(self.half_bits);
        self.free_at = done;
        (start, done)
    }

    /// The cycle the wire is next free at.
    #[must_use]
    pub fn free_at(&self) -> u64 {
        self.free_at
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ninety_six_hundred_baud_frames_do_not_drift() {
        let baud = Baud::new(9600);
        let mut clock = FrameClock::new();
        let frame = FrameFormat::EIGHT_N_ONE.half_bits();
        assert_eq!(frame, 20);
        let mut last = 0;
        for _ in 0..960 {
            last = clock.schedule(0, frame, baud).1;
        }
        // 960 characters of 10 bits at 9600 baud: exactly one second.
        assert_eq!(last, CPU_HZ);
        // One character: 1041.67 cycles, rounded down.
        let mut one = FrameClock::new();
        assert_eq!(one.schedule(100, frame, baud), (100, 1141));
    }

    #[test]
    fn an_idle_wire_restarts_at_the_send_time() {
        let baud = Baud::new(9600);
        let mut clock = FrameClock::new();
        let frame = FrameFormat::EIGHT_N_ONE.half_bits();
        let (_, done) = clock.schedule(0, frame, baud);
        let (start, _) = clock.schedule(done + 500, frame, baud);
        assert_eq!(start, done + 500);
        // A character queued while the wire is busy waits for it.
        let (start2, _) = clock.schedule(start + 10, frame, baud);
        assert!(start2 > start + 1000);
    }

    #[test]
    fn the_6551_generator_rates() {
        assert_eq!(Baud::from_crystal_divisor(12).bits_per_second(), 9600.0);
        assert_eq!(Baud::from_crystal_divisor(1048).bits_per_second(), 109.92);
        assert!(Baud::from_crystal_divisor(12).matches(Baud::new(9600)));
        assert!(!Baud::from_crystal_divisor(24).matches(Baud::new(9600)));
        assert!(Baud::new(9600).matches(Baud::new(9700)));
        assert!(!Baud::new(9600).matches(Baud::new(9900)));
    }

    #[test]
    fn frame_lengths() {
        let seven_e_two = FrameFormat {
            data_bits: 7,
            parity: Parity::Even,
            stop_half_bits: 4,
        };
        assert_eq!(seven_e_two.half_bits(), 2 * 11);
        assert!(!seven_e_two.compatible(FrameFormat::EIGHT_N_ONE));
    }
}
