//! The 6522 VIA at [`crate::map::VIA`]: register offsets and interrupt bits,
//! named as in the MOS/Rockwell datasheet, and the board's use of them.

/// Register offsets (RS3..RS0), named as in the datasheet.
pub mod reg {
    /// Output/input register B.
    pub const ORB: u16 = 0x0;
    /// Output/input register A (with handshake).
    pub const ORA: u16 = 0x1;
    /// Data direction register B (1 = output).
    pub const DDRB: u16 = 0x2;
    /// Data direction register A (1 = output).
    pub const DDRA: u16 = 0x3;
    /// Timer 1 counter low (read; clears the T1 flag) / latch low (write).
    pub const T1C_L: u16 = 0x4;
    /// Timer 1 counter high: a write loads the counter and starts T1.
    pub const T1C_H: u16 = 0x5;
    /// Timer 1 latch low.
    pub const T1L_L: u16 = 0x6;
    /// Timer 1 latch high.
    pub const T1L_H: u16 = 0x7;
    /// Timer 2 counter low (read; clears the T2 flag) / latch low (write).
    pub const T2C_L: u16 = 0x8;
    /// Timer 2 counter high: a write loads the counter and starts T2.
    pub const T2C_H: u16 = 0x9;
    /// Shift register.
    pub const SR: u16 = 0xA;
    /// Auxiliary control register.
    pub const ACR: u16 = 0xB;
    /// Peripheral control register.
    pub const PCR: u16 = 0xC;
    /// Interrupt flag register.
    pub const IFR: u16 = 0xD;
    /// Interrupt enable register.
    pub const IER: u16 = 0xE;
    /// Output/input register A without handshake.
    pub const ORA_NH: u16 = 0xF;
}

/// Interrupt flag and enable bits.
pub mod irq {
    /// CA2 active edge.
    pub const CA2: u8 = 0x01;
    /// CA1 active edge.
    pub const CA1: u8 = 0x02;
    /// Shift register: eight shifts done.
    pub const SR: u8 = 0x04;
    /// CB2 active edge.
    pub const CB2: u8 = 0x08;
    /// CB1 active edge.
    pub const CB1: u8 = 0x10;
    /// Timer 2 time-out.
    pub const T2: u8 = 0x20;
    /// Timer 1 time-out.
    pub const T1: u8 = 0x40;
    /// In IFR: any enabled flag is set. In a write to IER: set (1) or clear
    /// (0) the bits written as 1.
    pub const ANY: u8 = 0x80;
}

/// The VIA interrupts the reference ROM enables, as wired on this board.
pub mod wiring {
    /// CA1: a bumper closed (all bumpers ANDed, so any closing is a falling
    /// edge).
    pub const BUMPER: u8 = super::irq::CA1;
    /// Timer 2: the ROM's motion tick.
    pub const TICK: u8 = super::irq::T2;
}
