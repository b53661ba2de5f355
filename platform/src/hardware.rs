//! The reference ROM's `hardware.inc`, written from this crate's constants:
//! the ROM's build script generates it, so the ROM addresses the chips where
//! the emulator wires them.

use std::fmt::Write as _;

use crate::{acia, map, via};

/// One equate: its name, value and the comment after it.
struct Equate {
    name: &'static str,
    value: u16,
    comment: &'static str,
}

const fn eq(name: &'static str, value: u16, comment: &'static str) -> Equate {
    Equate {
        name,
        value,
        comment,
    }
}

const fn bits(name: &'static str, value: u8, comment: &'static str) -> Equate {
    eq(name, value as u16, comment)
}

/// The groups of the file, each under its heading.
fn groups() -> [(&'static str, Vec<Equate>); 4] {
    use via::reg as v;
    let via_at = |offset: u16| map::VIA + offset;
    let acia_at = |offset: u16| map::ACIA + offset;
    [
        (
            "6522 VIA",
            vec![
                eq(
                    "VIA_ORB",
                    via_at(v::ORB),
                    "port B: steppers' step and direction lines, PB7 speaker",
                ),
                eq(
                    "VIA_ORA",
                    via_at(v::ORA),
                    "port A: bumpers, low when closed (clears the CA1 flag)",
                ),
                eq("VIA_DDRB", via_at(v::DDRB), ""),
                eq("VIA_DDRA", via_at(v::DDRA), ""),
                eq("VIA_T1CL", via_at(v::T1C_L), ""),
                eq("VIA_T1CH", via_at(v::T1C_H), ""),
                eq("VIA_T1LL", via_at(v::T1L_L), ""),
                eq("VIA_T1LH", via_at(v::T1L_H), ""),
                eq("VIA_T2CL", via_at(v::T2C_L), ""),
                eq("VIA_T2CH", via_at(v::T2C_H), ""),
                eq("VIA_SR", via_at(v::SR), ""),
                eq("VIA_ACR", via_at(v::ACR), ""),
                eq("VIA_PCR", via_at(v::PCR), ""),
                eq("VIA_IFR", via_at(v::IFR), ""),
                eq("VIA_IER", via_at(v::IER), ""),
                eq(
                    "VIA_ORA_NH",
                    via_at(v::ORA_NH),
                    "port A without handshake (leaves the CA1 flag alone)",
                ),
                bits("IRQ_CA1", via::wiring::BUMPER, "a bumper closed"),
                bits("IRQ_T2", via::wiring::TICK, "the motion tick"),
                bits("IRQ_T1", via::irq::T1, ""),
            ],
        ),
        (
            "6551 ACIA",
            vec![
                eq("ACIA_DATA", acia_at(acia::reg::DATA), ""),
                eq(
                    "ACIA_STATUS",
                    acia_at(acia::reg::STATUS),
                    "reading it clears the IRQ bit; writing is a programmed reset",
                ),
                eq("ACIA_CMD", acia_at(acia::reg::COMMAND), ""),
                eq("ACIA_CTRL", acia_at(acia::reg::CONTROL), ""),
                bits("ST_RDRF", acia::status::RDRF, ""),
                bits("ST_TDRE", acia::status::TDRE, ""),
                bits(
                    "ACIA_CMD_RUN",
                    acia::command::RUN,
                    "DTR, receive interrupts on, transmitter on, no transmit interrupt",
                ),
                bits(
                    "ACIA_CTRL_8N1",
                    acia::control::FORMAT_8N1,
                    "8N1, receiver clocked by the baud generator; OR the baud code",
                ),
            ],
        ),
        (
            "board latches",
            vec![
                eq(
                    "DRIVE",
                    map::DRIVE,
                    "write: eyes, lamps, stepper-driver enables, speaker amplifier",
                ),
                eq("SENSE", map::SENSE, "read: ground-tracker phototransistors"),
                eq(
                    "SWITCHES",
                    map::SWITCHES,
                    "read: DIP switches, bits 0-3 the 6551 baud code",
                ),
                eq(
                    "SCANNER",
                    map::SCANNER,
                    "read: the infrared detector where the scanners point",
                ),
                bits("DRV_RIGHT_EYE", map::drive::RIGHT_EYE, ""),
                bits("DRV_LEFT_EYE", map::drive::LEFT_EYE, ""),
                bits("DRV_LAMPS", map::drive::LAMPS, ""),
                bits("DRV_LEFT", map::drive::LEFT_MOTOR, ""),
                bits("DRV_RIGHT", map::drive::RIGHT_MOTOR, ""),
                bits("DRV_HSCAN", map::drive::H_SCANNER, ""),
                bits("DRV_VSCAN", map::drive::V_SCANNER, ""),
                bits("DRV_SPEAKER", map::drive::SPEAKER, ""),
            ],
        ),
        (
            "VIA port B lines",
            vec![
                bits("PB_LEFT_STEP", map::port_b::LEFT_STEP, ""),
                bits("PB_LEFT_DIR", map::port_b::LEFT_DIR, ""),
                bits("PB_RIGHT_STEP", map::port_b::RIGHT_STEP, ""),
                bits("PB_RIGHT_DIR", map::port_b::RIGHT_DIR, ""),
                bits("PB_H_STEP", map::port_b::H_STEP, ""),
                bits("PB_V_STEP", map::port_b::V_STEP, ""),
                bits("PB_SCAN_DIR", map::port_b::SCAN_DIR, ""),
                bits("PB_SPEAKER", map::port_b::SPEAKER, "timer 1's output"),
            ],
        ),
    ]
}

/// The text of `hardware.inc`: `NAME = $XXXX` equates for the I/O page's
/// registers and the bits the ROM uses, addresses as four hex digits and
/// bit masks as two.
#[must_use]
pub fn hardware_inc() -> String {
    let mut text = String::from(
        "; hardware.inc: the Scorpion controller card's I/O page. Generated from\n\
         ; the platform crate (platform/src/map.rs, via.rs, acia.rs); do not edit.\n",
    );
    for (heading, equates) in groups() {
        let _ = write!(text, "\n; {heading}\n");
        for Equate {
            name,
            value,
            comment,
        } in equates
        {
            let value = if is_mask(name) {
                format!("${value:02X}")
            } else {
                format!("${value:04X}")
            };
            let line = format!("{name:<13} = {value}");
            if comment.is_empty() {
                let _ = writeln!(text, "{line}");
            } else {
                let _ = writeln!(text, "{line:<24} ; {comment}");
            }
        }
    }
    text
}

/// Bit masks are written as two hex digits, addresses as four.
fn is_mask(name: &str) -> bool {
    ["IRQ_", "ST_", "DRV_", "PB_", "ACIA_CMD_", "ACIA_CTRL_"]
        .iter()
        .any(|prefix| name.starts_with(prefix))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `NAME = $XXXX` lines, as an assembler reads them.
    fn equates(text: &str) -> Vec<(String, u32)> {
        text.lines()
            .filter_map(|line| {
                let code = line.split(';').next()?;
                let (name, value) = code.split_once('=')?;
                let value = value.trim().strip_prefix('$')?;
                Some((name.trim().to_owned(), u32::from_str_radix(value, 16).ok()?))
            })
            .collect()
    }

    #[test]
    fn every_register_of_the_io_page_is_named_at_its_address() {
        let text = hardware_inc();
        let found = equates(&text);
        let value = |name: &str| {
            found
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| *v)
                .unwrap_or_else(|| panic!("hardware.inc defines {name}:\n{text}"))
        };
        for offset in 0..16u16 {
            let at = u32::from(map::VIA + offset);
            assert!(
                found.iter().any(|(_, v)| *v == at),
                "the VIA's register {offset} has a name"
            );
        }
        assert_eq!(value("VIA_IFR"), 0xC00D);
        assert_eq!(value("ACIA_CTRL"), 0xC013);
        assert_eq!(value("SCANNER"), 0xC023);
        assert_eq!(value("IRQ_CA1"), 0x02);
        assert_eq!(value("ACIA_CTRL_8N1"), 0x10);
        assert_eq!(value("PB_SCAN_DIR"), 0x40);
        let mut names: Vec<&str> = found.iter().map(|(n, _)| n.as_str()).collect();
        names.sort_unstable();
        let count = names.len();
        names.dedup();
        assert_eq!(names.len(), count, "no name twice");
    }

    #[test]
    fn masks_are_bytes_and_addresses_are_words() {
        for line in hardware_inc().lines().filter(|l| l.contains('=')) {
            let digits = line
                .split('$')
                .nth(1)
                .map(|rest| rest.chars().take_while(char::is_ascii_hexdigit).count());
            let name = line.split_whitespace().next().unwrap_or_default();
            assert_eq!(digits, Some(if is_mask(name) { 2 } else { 4 }), "{line}");
        }
    }
}
