//! `.scorpion.fill`: the bytes of a section that are reserved, not written.
//!
//! ca65's `.res n` and `.align n` without a fill value leave a gap that
//! ld65 fills with the memory area's `fillval`; an ELF section can only hold
//! bytes. The assembler writes zeros there and lists the ranges here, and
//! the linker overwrites them with the fill value of the area the section
//! is loaded into (a layout's `fill-value`), so that a ROM filled with `$FF`
//! has `$FF` in its gaps as ld65 would give it.
//!
//! Layout (version 1): magic `SCFL`, version, then a count and the runs:
//! `section: u32, offset: u32, length: u32`, sorted by (section, offset),
//! none empty, none overlapping. `section` is an ELF section header index.

use super::FILL_SECTION;
use super::codec::{FormatError, Reader, Writer};

const MAGIC: &[u8; 4] = b"SCFL";
const VERSION: u8 = 1;

/// A run of reserved bytes in one section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FillRun {
    /// ELF section header index.
    pub section: u32,
    /// Byte offset of the first reserved byte in the section.
    pub offset: u32,
    /// How many bytes (never 0).
    pub length: u32,
}

impl FillRun {
    /// The byte after the run (saturating: a decoded run is in range).
    #[must_use]
    pub fn end(&self) -> u32 {
        self.offset.saturating_add(self.length)
    }

    /// Serialises runs (sorted, adjacent runs of a section merged, empty
    /// ones dropped).
    #[must_use]
    pub fn encode_all(runs: &[FillRun]) -> Vec<u8> {
        let mut sorted: Vec<FillRun> = runs.iter().copied().filter(|r| r.length > 0).collect();
        sorted.sort_unstable();
        let mut merged: Vec<FillRun> = Vec::with_capacity(sorted.len());
        for run in sorted {
            match merged.last_mut() {
                Some(last) if last.section == run.section && run.offset <= last.end() => {
                    last.length = last.length.max(run.end() - last.offset);
                }
                _ => merged.push(run),
            }
        }
        let mut out = Writer::header(MAGIC, VERSION);
        out.bytes.reserve(4 + 12 * merged.len());
        out.len32(merged.len());
        for run in &merged {
            out.u32(run.section);
            out.u32(run.offset);
            out.u32(run.length);
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not version-1 fill runs, or the runs
    /// are empty, unsorted, overlapping or run past 4 GiB.
    pub fn decode_all(bytes: &[u8]) -> Result<Vec<FillRun>, FormatError> {
        let mut input = Reader::new(FILL_SECTION, bytes);
        input.header(MAGIC, VERSION)?;
        let count = input.count(12)?;
        let mut runs: Vec<FillRun> = Vec::with_capacity(count);
        for _ in 0..count {
            let run = FillRun {
                section: input.u32()?,
                offset: input.u32()?,
                length: input.u32()?,
            };
            if run.length == 0 || run.offset.checked_add(run.length).is_none() {
                return Err(input.error(format!(
                    "run of {} bytes at offset {} of section {} is empty or too long",
                    run.length, run.offset, run.section
                )));
            }
            if let Some(last) = runs.last()
                && (run.section, run.offset) < (last.section, last.end())
            {
                return Err(input.error(format!(
                    "run at offset {} of section {} is out of order or overlaps the one before",
                    run.offset, run.section
                )));
            }
            runs.push(run);
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the runs"));
        }
        Ok(runs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(section: u32, offset: u32, length: u32) -> FillRun {
        FillRun {
            section,
            offset,
            length,
        }
    }

    #[test]
    fn round_trips_sorted_and_merged() {
        let runs = [
            run(3, 10, 2),
            run(2, 4, 4),
            run(3, 0, 1),
            run(2, 8, 3),
            run(2, 20, 0),
        ];
        let decoded = FillRun::decode_all(&FillRun::encode_all(&runs)).unwrap();
        assert_eq!(decoded, [run(2, 4, 7), run(3, 0, 1), run(3, 10, 2)]);
        assert_eq!(FillRun::decode_all(&FillRun::encode_all(&[])).unwrap(), []);
    }

    #[test]
    fn every_truncation_is_an_error() {
        let bytes = FillRun::encode_all(&[run(1, 0, 3), run(1, 8, 1)]);
        for len in 0..bytes.len() {
            assert!(FillRun::decode_all(&bytes[..len]).is_err(), "length {len}");
        }
    }

    #[test]
    fn bad_runs_are_errors() {
        let raw = |runs: &[(u32, u32, u32)]| {
            let mut bytes = b"SCFL\x01".to_vec();
            bytes.extend_from_slice(&(runs.len() as u32).to_le_bytes());
            for (section, offset, length) in runs {
                for value in [section, offset, length] {
                    bytes.extend_from_slice(&value.to_le_bytes());
                }
            }
            bytes
        };
        let reason = |runs: &[(u32, u32, u32)]| FillRun::decode_all(&raw(runs)).unwrap_err().reason;
        assert!(reason(&[(1, 0, 0)]).contains("empty"));
        assert!(reason(&[(1, u32::MAX, 2)]).contains("too long"));
        assert!(reason(&[(1, 4, 4), (1, 6, 1)]).contains("overlaps"));
        assert!(reason(&[(2, 0, 1), (1, 0, 1)]).contains("out of order"));
        assert!(FillRun::decode_all(&raw(&[(1, 0, 2), (1, 2, 1)])).is_ok());
        let mut bytes = raw(&[]);
        bytes.push(0);
        assert!(
            FillRun::decode_all(&bytes)
                .unwrap_err()
                .reason
                .contains("trailing")
        );
        let mut huge = b"SCFL\x01".to_vec();
        huge.extend_from_slice(&u32::MAX.to_le_bytes());
        assert!(
            FillRun::decode_all(&huge)
                .unwrap_err()
                .reason
                .contains("does not fit")
        );
    }
}
