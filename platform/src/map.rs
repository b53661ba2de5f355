//! The Scorpion board's memory map and I/O register map.
//!
//! The memory map is fixed by docs/PROTOCOL.md section 3; the I/O page's
//! layout and the wiring of the chips' pins are this board's (the protocol
//! leaves them to the developers) and are documented here and in
//! docs/ARCHITECTURE.md. The reference ROM's `hardware.inc` is generated
//! from these constants ([`crate::hardware_inc`]).
//!
//! | address | register |
//! |---|---|
//! | `$C000-$C00F` | 6522 VIA (ORB, ORA, DDRB, DDRA, T1C-L ... IER, ORA without handshake) |
//! | `$C010-$C013` | 6551 ACIA (data, status / programmed reset, command, control) |
//! | `$C020` | `DRIVE` latch (write; reads back): bit 0 right eye, 1 left eye, 2 tracker lamps, 3 left-drive enable, 4 right-drive enable, 5 H-scanner enable, 6 V-scanner enable, 7 speaker amplifier |
//! | `$C021` | `SENSE` (read): bit 0 right ground-tracker phototransistor, bit 1 left (1 = lit); bits 2-7 read 0 |
//! | `$C022` | `SWITCHES` (read): the configuration DIP switches; bits 0-3 the 6551 baud code the ROM programs (`$E` = 9600) |
//! | `$C023` | `SCANNER` (read): the infrared detector's 8-bit reading where the scanners point now |
//! | rest of `$C0xx` | unconnected: reads return `$C0` (the bus floats at the address's high byte), writes do nothing |
//!
//! VIA wiring: port A = the eight bumper microswitches, **low when closed**
//! (inputs); CA1 = all bumpers ANDed, so closing any bumper is a falling
//! edge. Port B (outputs): PB0 left-drive step, PB1 left-drive direction
//! (1 = forward, `+`), PB2 right-drive step, PB3 right-drive direction,
//! PB4 H-scanner step, PB5 V-scanner step, PB6 scanner direction (1 = `+`,
//! right or up; the scanners move one at a time), PB7 the speaker (timer 1
//! output). A stepper driver moves its motor one step on each rising edge of
//! its step line while the driver is enabled in `DRIVE`.
//!
//! The 6551's /IRQ and the 6522's /IRQ are wired-OR onto the CPU's IRQ
//! input; NMI is not connected. DCD, DSR and CTS are tied active.

use std::ops::RangeInclusive;

/// First byte of the controller card's RAM.
pub const RAM_START: u16 = 0x0000;
/// Last byte of the controller card's RAM.
pub const RAM_END: u16 = 0x0FFF;
/// First byte of the KIM-bus expansion space.
pub const KIM_START: u16 = 0x1000;
/// Last byte of the KIM-bus expansion space.
pub const KIM_END: u16 = 0xBFFF;
/// The KIM-bus expansion space: peripheral cards, or RAM on the virtual
/// robot where no card is mapped.
pub const KIM_BUS: RangeInclusive<u16> = KIM_START..=KIM_END;
/// First byte of the I/O page.
pub const IO_START: u16 = 0xC000;
/// Last byte of the I/O page.
pub const IO_END: u16 = 0xC0FF;
/// First byte of the ROM.
pub const ROM_START: u16 = 0xF000;
/// The ROM's size in bytes.
pub const ROM_SIZE: usize = 0x1000;
/// What an erased EPROM reads: the fill of the ROM's unused bytes.
pub const ROM_FILL: u8 = 0xFF;

/// The 6522 VIA's base address (16 registers).
pub const VIA: u16 = 0xC000;
/// The VIA's last register.
pub const VIA_END: u16 = VIA + 0x0F;
/// The 6551 ACIA's base address (4 registers).
pub const ACIA: u16 = 0xC010;
/// The ACIA's last register.
pub const ACIA_END: u16 = ACIA + 0x03;
/// The drive latch: eyes, lamps, stepper-driver enables, speaker amplifier.
pub const DRIVE: u16 = 0xC020;
/// The ground-tracker phototransistors.
pub const SENSE: u16 = 0xC021;
/// The configuration DIP switches.
pub const SWITCHES: u16 = 0xC022;
/// The infrared scanner's detector.
pub const SCANNER: u16 = 0xC023;

/// What a read of an unconnected I/O address returns: the data bus floats
/// at the last byte it carried, the address's high byte.
pub const OPEN_BUS: u8 = 0xC0;

/// `DRIVE` bits.
pub mod drive {
    /// The right eye lamp.
    pub const RIGHT_EYE: u8 = 0x01;
    /// The left eye lamp.
    pub const LEFT_EYE: u8 = 0x02;
    /// The ground-tracker lamps.
    pub const LAMPS: u8 = 0x04;
    /// The left drive motor's stepper driver.
    pub const LEFT_MOTOR: u8 = 0x08;
    /// The right drive motor's stepper driver.
    pub const RIGHT_MOTOR: u8 = 0x10;
    /// The horizontal scanner's stepper driver.
    pub const H_SCANNER: u8 = 0x20;
    /// The vertical scanner's stepper driver.
    pub const V_SCANNER: u8 = 0x40;
    /// The speaker amplifier.
    pub const SPEAKER: u8 = 0x80;
}

/// Port B bits.
pub mod port_b {
    /// Left drive: step (rising edge).
    pub const LEFT_STEP: u8 = 0x01;
    /// Left drive: direction, 1 = forward.
    pub const LEFT_DIR: u8 = 0x02;
    /// Right drive: step.
    pub const RIGHT_STEP: u8 = 0x04;
    /// Right drive: direction, 1 = forward.
    pub const RIGHT_DIR: u8 = 0x08;
    /// Horizontal scanner: step.
    pub const H_STEP: u8 = 0x10;
    /// Vertical scanner: step.
    pub const V_STEP: u8 = 0x20;
    /// Scanner direction, 1 = `+` (right, up).
    pub const SCAN_DIR: u8 = 0x40;
    /// The speaker, driven by timer 1.
    pub const SPEAKER: u8 = 0x80;
}

/// `SENSE` bits.
pub mod sense {
    /// The right ground-tracker phototransistor sees light.
    pub const RIGHT: u8 = 0x01;
    /// The left ground-tracker phototransistor sees light.
    pub const LEFT: u8 = 0x02;
}

/// The switch setting the board ships with: the 6551's code for
/// [`crate::line::DEFAULT_BAUD`].
pub const DEFAULT_SWITCHES: u8 = 0x0E;
