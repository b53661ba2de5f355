//! `.scorpion.condes`: routines an object lists for the linker's tables
//! (ca65's `.constructor`, `.destructor`, `.interruptor` and `.condes`),
//! which a layout's `CONDES` feature gathers into a table of addresses
//! with a label and a count (`__CONSTRUCTOR_TABLE__`,
//! `__CONSTRUCTOR_COUNT__`).
//!
//! Layout (version 1): magic `SCCD`, version, a count, then per routine:
//! the table type `u8` (0 constructor, 1 destructor, 2 interruptor, 3 to 6
//! the user's), the priority `u8` (1 to 32) and the routine's symbol
//! (`.symtab` index) `u32`.

use super::CONDES_SECTION;
use super::codec::{FormatError, Reader, Writer};

const MAGIC: &[u8; 4] = b"SCCD";
const VERSION: u8 = 1;

/// The highest table type (ca65 has seven).
pub const MAX_CONDES_TYPE: u8 = 6;

/// One routine for a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CondesEntry {
    /// The table type.
    pub kind: u8,
    /// Its priority, 1 to 32 (ca65's default 7).
    pub priority: u8,
    /// The routine's `.symtab` index.
    pub symbol: u32,
}

impl CondesEntry {
    /// Serialises entries as a section's contents.
    #[must_use]
    pub fn encode_all(entries: &[CondesEntry]) -> Vec<u8> {
        let mut out = Writer::header(MAGIC, VERSION);
        out.len32(entries.len());
        for entry in entries {
            out.u8(entry.kind);
            out.u8(entry.priority);
            out.u32(entry.symbol);
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not version-1 entries or one has a
    /// type above 6 or a priority outside 1 to 32.
    pub fn decode_all(bytes: &[u8]) -> Result<Vec<CondesEntry>, FormatError> {
        let mut input = Reader::new(CONDES_SECTION, bytes);
        input.header(MAGIC, VERSION)?;
        let count = input.count(6)?;
        let mut entries = Vec::with_capacity(count);
        for _ in 0..count {
            let entry = CondesEntry {
                kind: input.u8()?,
                priority: input.u8()?,
                symbol: input.u32()?,
            };
            if entry.kind > MAX_CONDES_TYPE || !(1..=32).contains(&entry.priority) {
                return Err(input.error(format!(
                    "table type {} priority {} (types 0 to 6, priorities 1 to 32)",
                    entry.kind, entry.priority
                )));
            }
            entries.push(entry);
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last entry"));
        }
        Ok(entries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_round_trip_and_bad_ones_are_errors() {
        let entries = vec![
            CondesEntry {
                kind: 0,
                priority: 24,
                symbol: 5,
            },
            CondesEntry {
                kind: 2,
                priority: 1,
                symbol: 9,
            },
        ];
        let bytes = CondesEntry::encode_all(&entries);
        assert_eq!(CondesEntry::decode_all(&bytes), Ok(entries.clone()));
        for cut in 0..bytes.len() {
            assert!(CondesEntry::decode_all(&bytes[..cut]).is_err());
        }
        let bad = CondesEntry::encode_all(&[CondesEntry {
            kind: 7,
            ..entries[0]
        }]);
        assert!(CondesEntry::decode_all(&bad).is_err());
        let bad = CondesEntry::encode_all(&[CondesEntry {
            priority: 0,
            ..entries[0]
        }]);
        assert!(CondesEntry::decode_all(&bad).is_err());
    }
}
