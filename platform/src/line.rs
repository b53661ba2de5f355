//! The robot's clock and serial line as the board ships (docs/PROTOCOL.md
//! section 3).

/// The CPU clock: 1 MHz.
pub const CPU_HZ: u64 = 1_000_000;

/// The line's rate with the switches as shipped ([`crate::map::DEFAULT_SWITCHES`]).
pub const DEFAULT_BAUD: u32 = 9600;

/// Data bits, parity and stop bits: 8N1, no handshake lines.
pub const FORMAT: &str = "8N1";

#[cfg(test)]
mod tests {
    #[test]
    fn the_shipped_switches_select_the_default_rate() {
        assert_eq!(
            crate::acia::baud_code(super::DEFAULT_BAUD),
            Some(crate::map::DEFAULT_SWITCHES)
        );
    }
}
