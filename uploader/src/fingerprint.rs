//! The right ROM, or no write: before an upload writes anything, the
//! robot's jump table and vectors (where an image's calls into the ROM
//! land) are read and compared byte by byte with the ROM profile the image
//! was linked against; once the RAM loader is in, its `sums` adds a
//! checksum of the whole ROM, computed on the robot. A mismatch refuses
//! the upload and says what differs.
//!
//! The jump table is read rather than summed because it is checked
//! before the loader (which calls into it) is written: a robot whose
//! `GETCH` is elsewhere must not run a loader linked against ours.

use std::ops::RangeInclusive;

use isa::objfmt::HookKind;
use romlib::protocol::{Answer, Command, ReadSpan};

use crate::client::{Client, spans};
use crate::image::RomProfile;
use crate::sums::robot_sum;
use crate::transport::Transport;
use crate::{Error, Result};

/// A range of the ROM whose sums on the robot differ from the profile's:
/// the range, the profile's sum, the robot's.
pub type RomSum = ((u16, usize), u32, u32);

/// The services of the ROM's jump table (docs/PROTOCOL.md section 4), at
/// fixed addresses: an image calls them by address.
pub const SERVICES: [&str; 16] = [
    "PUTCH",
    "PUTHEX",
    "PUTDEC4",
    "PUTEOL",
    "GETHEX",
    "GETDEC",
    "IOINHIBIT",
    "IOAPPLY",
    "GETCH",
    "CHKCH",
    "CMD_DONE",
    "BAD_COMMAND",
    "ROM_LOOP",
    "ROM_RESET",
    "INJECT",
    "PENDING",
];

/// The 6502's vectors (NMI, reset, IRQ): the last six bytes.
const VECTORS: RangeInclusive<u16> = 0xFFFA..=0xFFFF;

/// The ranges compared byte by byte: from the first service exported (by
/// `lookup`) to the end of the last one's `JMP`, and the vectors.
pub(crate) fn jump_table(lookup: impl Fn(&str) -> Option<u16>) -> Vec<RangeInclusive<u16>> {
    let addresses: Vec<u16> = SERVICES.iter().filter_map(|name| lookup(name)).collect();
    let mut ranges = Vec::new();
    if let (Some(&first), Some(&last)) = (addresses.iter().min(), addresses.iter().max()) {
        ranges.push(first..=last.saturating_add(2).min(*VECTORS.start() - 1));
    }
    ranges.push(VECTORS);
    ranges
}

/// The profile's bytes of `range`, if it has them.
fn expected(profile: &RomProfile, range: &RangeInclusive<u16>) -> Option<Vec<u8>> {
    let rom = profile.rom.as_ref()?;
    let start = usize::from(range.start().checked_sub(rom.address)?);
    let end = usize::from(*range.end() - rom.address) + 1;
    rom.bytes.get(start..end).map(<[u8]>::to_vec)
}

/// Compares the robot's jump table and vectors with the profile's (a
/// profile without the ROM's bytes has nothing to compare: it passes).
/// One read of each span that matches is enough (noise does not make the
/// expected bytes); one that differs is read until two answers agree
/// before the upload is refused.
///
/// # Errors
/// [`Error::WrongRom`] with every byte that differs; a line error.
pub(crate) fn check_jump_table<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<()> {
    check_ranges(client, profile, &profile.jump_table)
}

/// The jump-table entries (`JMP`s) of the hooks' targets at reset, which
/// an upload points hooks back at before its loader runs (an extension
/// replaced, a hook disarmed): compared before those writes, the rest of
/// the table once the loader runs at the fast rate.
pub(crate) fn check_reset_entries<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<()> {
    let mut ranges: Vec<RangeInclusive<u16>> = Vec::new();
    let mut targets: Vec<u16> = HookKind::ALL
        .into_iter()
        .filter_map(|kind| profile.reset_target(kind))
        .collect();
    targets.sort_unstable();
    for at in targets {
        let entry = at..=at.saturating_add(2);
        // Neighbouring entries are read in one span.
        match ranges.last_mut() {
            Some(last) if u32::from(*last.end()) + 1 >= u32::from(at) => {
                *last = *last.start()..=(*last.end()).max(*entry.end());
            }
            _ => ranges.push(entry),
        }
    }
    check_ranges(client, profile, &ranges)
}

/// [`check_jump_table`] over `ranges`.
fn check_ranges<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    ranges: &[RangeInclusive<u16>],
) -> Result<()> {
    let mut differences = Vec::new();
    for range in ranges {
        let Some(expected) = expected(profile, range) else {
            continue;
        };
        for span in spans(*range.start(), expected.len()) {
            let offset = usize::from(span.address() - range.start());
            let wanted = &expected[offset..offset + usize::from(span.count())];
            if read_once(client, span)?.as_deref() == Some(wanted) {
                continue;
            }
            let found = client.read_memory(span.address(), usize::from(span.count()))?;
            differences.extend(
                wanted
                    .iter()
                    .zip(&found)
                    .enumerate()
                    .filter(|(_, (wanted, found))| wanted != found)
                    .map(|(i, (&wanted, &found))| (span.address() + i as u16, wanted, found)),
            );
        }
    }
    if differences.is_empty() {
        Ok(())
    } else {
        Err(Error::WrongRom {
            profile: profile.name.clone(),
            differences,
            whole_sum: None,
        })
    }
}

/// The spans of the profile's jump table and vectors with their bytes,
/// for a comparison that rides on another transfer (see
/// `Body::add_checks`); empty for a profile without the ROM's bytes.
pub(crate) fn table_checks(profile: &RomProfile) -> Vec<(ReadSpan, Vec<u8>)> {
    let mut out = Vec::new();
    for range in &profile.jump_table {
        let Some(expected) = expected(profile, range) else {
            continue;
        };
        for span in spans(*range.start(), expected.len()) {
            let offset = usize::from(span.address() - range.start());
            out.push((
                span,
                expected[offset..offset + usize::from(span.count())].to_vec(),
            ));
        }
    }
    out
}

/// One `/7R` answer, if it came and parsed.
fn read_once<T: Transport>(client: &mut Client<T>, span: ReadSpan) -> Result<Option<Vec<u8>>> {
    match client.ask(&Command::ReadMemory(span)) {
        Ok(Answer::Memory(bytes)) if bytes.len() == usize::from(span.count()) => Ok(Some(bytes)),
        Ok(_) | Err(Error::Protocol(_) | Error::NoAnswer { .. } | Error::WrongBaud { .. }) => {
            Ok(None)
        }
        Err(error) => Err(error),
    }
}

/// The jump table's and the vectors' ranges with the profile's sums of
/// them, for a robot whose loader was found in RAM (see `upload`); empty
/// for a profile without the ROM's bytes.
pub(crate) fn table_sums(profile: &RomProfile) -> Vec<((u16, usize), u32)> {
    profile
        .jump_table
        .iter()
        .flat_map(|range| {
            let start = *range.start();
            let bytes = expected(profile, range).unwrap_or_default();
            crate::sums::pieces(bytes.len(), crate::sums::EXACT)
                .into_iter()
                .map(move |(at, len)| {
                    let piece = &bytes[at..at + len];
                    ((start.wrapping_add(at as u16), len), robot_sum(piece))
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The ranges of the profile's ROM the loader's `sums` checks, each of
/// at most [`crate::sums::EXACT`] bytes (over which the sums see every
/// change of one or two bytes; they go in one question), with their
/// sums; none for a profile without the ROM's bytes.
pub(crate) fn whole_rom(profile: &RomProfile) -> Vec<((u16, usize), u32)> {
    let Some(rom) = profile.rom.as_ref() else {
        return Vec::new();
    };
    crate::sums::pieces(rom.bytes.len().min(0x1_0000), crate::sums::EXACT)
        .into_iter()
        .map(|(at, piece)| {
            let range = (rom.address.wrapping_add(at as u16), piece);
            (range, robot_sum(&rom.bytes[at..at + piece]))
        })
        .collect()
}

/// Compares the robot's sums of its whole ROM (from the loader's `sums`,
/// in the order of [`whole_rom`]) with the profile's. A range whose sum
/// differs is asked again (noise may have turned a digit of its answer
/// into another digit) until an answer is the profile's, or the same
/// other sum comes twice.
///
/// # Errors
/// [`Error::WrongRom`] with the first range that differs and both sums;
/// a line error.
pub(crate) fn check_whole<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    expected: &[((u16, usize), u32)],
    found: &[u32],
) -> Result<()> {
    for (i, &(range, sum)) in expected.iter().enumerate() {
        let mut seen = vec![found.get(i).copied().unwrap_or(!sum)];
        while seen.last() != Some(&sum) {
            let last = seen[seen.len() - 1];
            if seen[..seen.len() - 1].contains(&last) || seen.len() > 4 {
                return Err(Error::WrongRom {
                    profile: profile.name.clone(),
                    differences: Vec::new(),
                    whole_sum: Some((range, sum, last)),
                });
            }
            seen.extend(crate::sums::robot_sums(client, &[range])?);
        }
    }
    Ok(())
}

/// A ROM profile for a robot's ROM read whole: `base`'s image (its
/// names, sections and hooks) with the bytes from `start` to `$FFFF`
/// replaced by `bytes`, and how many of them differ from `base`'s.
#[must_use]
pub fn rom_profile_image(base: &linker::Image, start: u16, bytes: &[u8]) -> (linker::Image, usize) {
    let first = u32::from(start);
    let end = first + bytes.len() as u32;
    let differences = bytes
        .iter()
        .enumerate()
        .filter(|&(i, &byte)| base.byte_at(first + i as u32) != Some(byte))
        .count();
    let mut image = base.clone();
    image
        .areas
        .retain(|area| area.end() <= u64::from(first) || u64::from(area.load) >= u64::from(end));
    image.areas.push(linker::LoadArea {
        load: first,
        run: first,
        bytes: bytes.to_vec(),
    });
    image.areas.sort_by_key(|area| area.load);
    (image, differences)
}

/// What differs, for the error message.
pub(crate) fn describe(differences: &[(u16, u8, u8)], whole_sum: Option<RomSum>) -> String {
    if let Some(((address, len), expected, found)) = whole_sum {
        return format!(
            "its jump table and vectors agree, but a checksum of ${address:04X}-${:04X} computed on the robot is ${found:08X}, expected ${expected:08X}",
            usize::from(address) + len - 1
        );
    }
    let shown: Vec<String> = differences
        .iter()
        .take(8)
        .map(|(address, expected, found)| {
            format!("${address:04X}: expected ${expected:02X}, found ${found:02X}")
        })
        .collect();
    let more = differences.len().saturating_sub(shown.len());
    let mut text = format!(
        "{} byte{} of its jump table or vectors differ ({})",
        differences.len(),
        if differences.len() == 1 { "" } else { "s" },
        shown.join("; ")
    );
    if more > 0 {
        text.push_str(&format!(" and {more} more"));
    }
    text.push_str("; an image's calls into the ROM would land elsewhere");
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_jump_table_is_its_services_and_the_vectors() {
        let profile = RomProfile::reference();
        assert_eq!(profile.jump_table, vec![0xFF00..=0xFF2F, 0xFFFA..=0xFFFF]);
        let table = expected(&profile, &profile.jump_table[0]).expect("the ROM's bytes");
        assert_eq!(table.len(), 48);
        assert!(table.chunks(3).all(|jmp| jmp[0] == 0x4C), "JMPs");
    }
}
