//! The 6551 ACIA at [`crate::map::ACIA`]: register offsets and bits, named
//! as in the Rockwell/Synertek datasheets, and its baud-rate generator.

/// Register offsets (RS1, RS0).
pub mod reg {
    /// Read: receive data register. Write: transmit data register.
    pub const DATA: u16 = 0;
    /// Read: status register. Write: programmed reset.
    pub const STATUS: u16 = 1;
    /// Command register.
    pub const COMMAND: u16 = 2;
    /// Control register.
    pub const CONTROL: u16 = 3;
}

/// Status register bits.
pub mod status {
    /// Parity error.
    pub const PARITY_ERROR: u8 = 0x01;
    /// Framing error.
    pub const FRAMING_ERROR: u8 = 0x02;
    /// Overrun: a character arrived while the receive register was full.
    pub const OVERRUN: u8 = 0x04;
    /// Receive data register full.
    pub const RDRF: u8 = 0x08;
    /// Transmit data register empty.
    pub const TDRE: u8 = 0x10;
    /// /DCD is high (no carrier). Always 0 on the Scorpion.
    pub const DCD: u8 = 0x20;
    /// /DSR is high (not ready). Always 0 on the Scorpion.
    pub const DSR: u8 = 0x40;
    /// An interrupt occurred (cleared by reading the status register).
    pub const IRQ: u8 = 0x80;
}

/// Command register bits.
pub mod command {
    /// DTR: enable the receiver and all interrupts.
    pub const DTR: u8 = 0x01;
    /// Receive interrupts disabled (IRD).
    pub const IRD: u8 = 0x02;
    /// Transmitter control (TIC), two bits: 00 off, 01 on with transmit
    /// interrupts, 10 on, 11 on sending a break.
    pub const TIC_MASK: u8 = 0x0C;
    /// TIC = 01: transmitter on, transmit interrupt enabled.
    pub const TIC_IRQ: u8 = 0x04;
    /// TIC = 10: transmitter on, no transmit interrupt.
    pub const TIC_ON: u8 = 0x08;
    /// Receiver echo mode (with TIC = 00).
    pub const ECHO: u8 = 0x10;
    /// What the ROM runs with: DTR, receive interrupts on, transmitter on
    /// without its interrupt.
    pub const RUN: u8 = DTR | TIC_ON;
}

/// Control register bits.
pub mod control {
    /// Baud-rate select, four bits (0 = 16x external clock).
    pub const BAUD_MASK: u8 = 0x0F;
    /// Receiver clock: the baud-rate generator (1) or RxC (0).
    pub const RCS: u8 = 0x10;
    /// Word length, two bits: 00 = 8, 01 = 7, 10 = 6, 11 = 5.
    pub const WORD_MASK: u8 = 0x60;
    /// Two stop bits (one and a half with 5 bits and no parity, one with
    /// 8 bits and parity).
    pub const STOP2: u8 = 0x80;
    /// 8 data bits, no parity, one stop bit, the receiver clocked by the
    /// baud-rate generator: the format the ROM sets; OR in a baud code.
    pub const FORMAT_8N1: u8 = RCS;
    /// The control code for 9600 baud, 8N1, internal receiver clock.
    pub const B9600_8N1: u8 = FORMAT_8N1 | 0x0E;
}

/// The 6551's crystal: every internal baud rate divides it by 16 and by a
/// divisor.
pub const CRYSTAL_HZ: u64 = 1_843_200;

/// The divisor of crystal / 16 for each baud-select code (code 0 is the
/// external clock, which the board leaves unconnected).
pub const DIVISORS: [u16; 16] = [
    0, 2304, 1536, 1048, 856, 768, 384, 192, 96, 64, 48, 32, 24, 16, 12, 6,
];

/// The 6551's standard rates as people name them (its control codes 1 to
/// 15 in order; 110 and 135 are 109.92 and 134.58 exactly).
pub const RATES: [u32; 15] = [
    50, 75, 110, 135, 150, 300, 600, 1200, 1800, 2400, 3600, 4800, 7200, 9600, 19200,
];

/// [`RATES`] as a sentence names them: `50, 75, ... 9600 or 19200`.
#[must_use]
pub fn rates_text() -> String {
    let named: Vec<String> = RATES.iter().map(u32::to_string).collect();
    let (last, rest) = named.split_last().expect("rates");
    format!("{} or {last}", rest.join(", "))
}

/// The control-register baud code for a standard rate, if the 6551 has it:
/// the code whose rate is within 2% of `bits_per_second` either way (what a
/// 16x-sampling UART receives over a 10-bit character).
#[must_use]
pub fn baud_code(bits_per_second: u32) -> Option<u8> {
    let wanted = u64::from(bits_per_second.max(1));
    (1u8..16).find(|&code| {
        // crystal / (16 * divisor) against wanted, in integers.
        let generated = CRYSTAL_HZ;
        let asked = wanted * 16 * u64::from(DIVISORS[usize::from(code)]);
        generated.abs_diff(asked) * 50 <= generated.min(asked)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_rates_have_the_datasheets_codes() {
        for (code, rate) in (1u8..).zip(RATES) {
            assert_eq!(baud_code(rate), Some(code), "{rate} baud");
        }
        assert_eq!(baud_code(38400), None);
        assert_eq!(baud_code(9000), None, "6.7% off 9600");
        assert_eq!(baud_code(0), None);
    }

    #[test]
    fn the_rom_formats_are_the_bits_they_name() {
        assert_eq!(control::B9600_8N1, 0x1E);
        assert_eq!(command::RUN, 0x09);
    }
}
