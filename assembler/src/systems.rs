//! ca65's target systems (`-t c64`): the symbols a system defines
//! (`__C64__`, `__CBM__`), the character set its strings and characters
//! are translated to (PETSCII on Commodore machines, ATASCII's control
//! codes on the Atari), and its CPU. The translations are ca65 2.19's,
//! checked character by character against it.

/// How strings and character constants are translated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Charset {
    /// As written.
    Ascii,
    /// Commodore PETSCII: the cases swap places, some punctuation and
    /// control codes move.
    Petscii,
    /// Atari ATASCII: three control codes move.
    Atascii,
    /// Ohio Scientific's Challenger 1P: `|` `}` and `~` DEL swap.
    Osi,
}

/// A target system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct System {
    /// Its name for `-t`.
    pub name: &'static str,
    /// The symbols it defines (each = 1).
    pub defines: &'static [&'static str],
    /// Its strings' character set.
    pub charset: Charset,
    /// Its CPU when not the NMOS 6502 (which this toolchain refuses).
    pub other_cpu: Option<&'static str>,
}

const fn system(
    name: &'static str,
    defines: &'static [&'static str],
    charset: Charset,
    other_cpu: Option<&'static str>,
) -> System {
    System {
        name,
        defines,
        charset,
        other_cpu,
    }
}

use Charset::{Ascii, Atascii, Osi, Petscii};

/// ca65 2.19's systems.
pub const SYSTEMS: &[System] = &[
    system("none", &[], Ascii, None),
    system("apple2", &["__APPLE2__"], Ascii, None),
    system(
        "apple2enh",
        &["__APPLE2__", "__APPLE2ENH__"],
        Ascii,
        Some("65C02"),
    ),
    system("atari", &["__ATARI__"], Atascii, None),
    system("atarixl", &["__ATARI__", "__ATARIXL__"], Atascii, None),
    system("atari2600", &["__ATARI2600__"], Ascii, None),
    system("atari5200", &["__ATARI5200__"], Atascii, None),
    system("atmos", &["__ATMOS__"], Ascii, None),
    system("bbc", &["__BBC__"], Ascii, None),
    system("c16", &["__C16__", "__CBM__"], Petscii, None),
    system("c64", &["__C64__", "__CBM__"], Petscii, None),
    system("c65", &["__C65__", "__CBM__"], Petscii, Some("4510")),
    system("c128", &["__C128__", "__CBM__"], Petscii, None),
    system("cbm510", &["__CBM510__", "__CBM__"], Petscii, None),
    system("cbm610", &["__CBM610__", "__CBM__"], Petscii, None),
    system("creativision", &["__CREATIVISION__"], Ascii, None),
    system("cx16", &["__CX16__", "__CBM__"], Petscii, Some("65C02")),
    system("gamate", &["__GAMATE__"], Ascii, None),
    system(
        "geos-apple",
        &["__GEOS__", "__GEOS_APPLE__"],
        Ascii,
        Some("65C02"),
    ),
    system("geos-cbm", &["__GEOS__", "__GEOS_CBM__"], Ascii, None),
    system("lunix", &["__LUNIX__"], Ascii, None),
    system("lynx", &["__LYNX__"], Ascii, Some("65SC02")),
    system("nes", &["__NES__"], Ascii, None),
    system("osic1p", &["__OSIC1P__"], Osi, None),
    system("pce", &["__PCE__"], Ascii, Some("HuC6280")),
    system("pet", &["__PET__", "__CBM__"], Petscii, None),
    system("plus4", &["__PLUS4__", "__C16__", "__CBM__"], Petscii, None),
    system("sim6502", &["__SIM6502__"], Ascii, None),
    system("sim65c02", &["__SIM65C02__"], Ascii, Some("65C02")),
    system("supervision", &["__SUPERVISION__"], Ascii, Some("65SC02")),
    system("telestrat", &["__TELESTRAT__"], Ascii, None),
    system("vic20", &["__VIC20__", "__CBM__"], Petscii, None),
];

/// The system called `name`.
#[must_use]
pub fn find(name: &str) -> Option<&'static System> {
    SYSTEMS.iter().find(|s| s.name == name)
}

impl Charset {
    /// The byte each source byte becomes.
    #[must_use]
    pub fn table(self) -> [u8; 256] {
        let mut table = [0u8; 256];
        for (i, slot) in table.iter_mut().enumerate() {
            *slot = i as u8;
        }
        match self {
            Ascii => {}
            Petscii => {
                for c in b'A'..=b'Z' {
                    table[usize::from(c)] = c + 0x80;
                }
                for c in b'a'..=b'z' {
                    table[usize::from(c)] = c - 0x20;
                }
                for c in 0xC0..=0xDFu8 {
                    table[usize::from(c)] = c - 0x60;
                }
                for (from, to) in [
                    (0x08, 0x14), // backspace: DEL
                    (0x14, 0x08),
                    (0x0B, 0x11), // vertical tab: cursor down
                    (0x11, 0x0B),
                    (0x0C, 0x93), // form feed: clear screen
                    (0x93, 0x0C),
                    (b'\\', 0xBF),
                    (b'_', 0xA4),
                    (b'`', 0xAD),
                    (b'{', 0xB3),
                    (b'|', 0xDD),
                    (b'}', 0xAB),
                    (b'~', 0xB1),
                    (0x7F, 0xDF),
                ] {
                    table[usize::from(from)] = to;
                }
            }
            Osi => {
                table.swap(0x7C, 0x7D);
                table.swap(0x7E, 0x7F);
            }
            Atascii => {
                // Bell, tab and form feed: the Atari's buzzer, tab and
                // clear-screen codes.
                table[0x07] = 0xFD;
                table[0x09] = 0x7F;
                table[0x0C] = 0x7D;
            }
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn petscii_swaps_the_cases_and_moves_punctuation() {
        let table = Petscii.table();
        assert_eq!(&[table[b'A' as usize], table[b'a' as usize]], &[0xC1, 0x41]);
        assert_eq!(table[b'_' as usize], 0xA4);
        assert_eq!(table[0xC1], 0x61);
        assert_eq!(table[b'0' as usize], b'0');
        assert_eq!(Atascii.table()[0x0C], 0x7D);
        assert_eq!(Ascii.table()[0x41], 0x41);
        assert!(find("c64").is_some() && find("kim1").is_none());
    }
}
