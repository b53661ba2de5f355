//! Checksums computed on the robot by the RAM loader's `sums` part
//! (`/9Kaaaannnn`, answered `Kaaaassss`): what tells an upload which
//! ranges a robot holds already, and a robot's ROM from another, without
//! reading every byte over the line.
//!
//! The sum is Fletcher-16 with both sums mod 256 and starting at zero:
//! the first is the sum of the bytes, so any one byte changed changes it;
//! the second, the sum of the running first sums, catches swaps.

use std::time::Duration;

use romlib::protocol::EOL;

use crate::client::Client;
use crate::transport::Transport;
use crate::{Error, Result};

/// The loader's time per byte summed (24 cycles at 1 MHz), plus the
/// command's parsing.
const CYCLES_PER_BYTE: u64 = 24;

/// Characters of an answer: `K`, four address digits, four sum digits,
/// the carriage return.
pub(crate) const ANSWER_LEN: usize = 10;

/// The most a range is asked again after its answer was lost.
const ATTEMPTS: u32 = 6;

/// The Fletcher-16 of `bytes` as `sums` computes it: the first sum in
/// the high byte.
#[must_use]
pub fn fletcher16(bytes: &[u8]) -> u16 {
    let (mut first, mut second) = (0u8, 0u8);
    for &byte in bytes {
        first = first.wrapping_add(byte);
        second = second.wrapping_add(first);
    }
    u16::from_be_bytes([first, second])
}

/// A range of robot memory: first address and length (up to `$10000`).
pub(crate) type Range = (u16, usize);

/// The sum of two ranges, one after the other, from their sums (`second`
/// over `second_len` bytes): the first sums add, and every byte of the
/// second range adds the first range's first sum to the running sum once
/// more.
#[must_use]
pub(crate) fn fletcher16_joined(first: u16, second: u16, second_len: usize) -> u16 {
    let [first_a, second_a] = first.to_be_bytes();
    let [first_b, second_b] = second.to_be_bytes();
    // Mod 256: only the length's low byte counts.
    let times = (second_len & 0xFF) as u8;
    u16::from_be_bytes([
        first_a.wrapping_add(first_b),
        second_a
            .wrapping_add(first_a.wrapping_mul(times))
            .wrapping_add(second_b),
    ])
}

/// The robot's sum of `range`, put together from `known` sums of ranges
/// that tile it exactly (each taken from the robot at the same moment as
/// far as the range goes: before anything was written); `None` where they
/// do not.
#[must_use]
pub(crate) fn joined_from(known: &[(Range, u16)], (address, len): Range) -> Option<u16> {
    let end = usize::from(address) + len;
    let mut at = usize::from(address);
    let mut sum = fletcher16(&[]);
    while at < end {
        // The longest known range starting here that stays inside.
        let &((_, part_len), part) = known
            .iter()
            .filter(|((start, part_len), _)| {
                usize::from(*start) == at && *part_len > 0 && at + part_len <= end
            })
            .max_by_key(|((_, part_len), _)| *part_len)?;
        sum = fletcher16_joined(sum, part, part_len);
        at += part_len;
    }
    Some(sum)
}

/// The question for one range.
pub(crate) fn question((address, len): Range) -> Vec<u8> {
    // A length of $10000 cannot be asked; nothing asks for it.
    format!("/9K{address:04X}{:04X}", len.min(0xFFFF)).into_bytes()
}

/// An answer's address and sum, if it is one.
pub(crate) fn parse(frame: &[u8]) -> Option<(u16, u16)> {
    let text = frame.strip_suffix(&[EOL])?.strip_prefix(b"K")?;
    if text.len() != 8 || !text.iter().all(u8::is_ascii_hexdigit) {
        return None;
    }
    let text = std::str::from_utf8(text).ok()?;
    let address = u16::from_str_radix(&text[..4], 16).ok()?;
    let sum = u16::from_str_radix(&text[4..], 16).ok()?;
    Some((address, sum))
}

/// The robot's time to answer one question over at most `longest` bytes,
/// besides the characters.
pub(crate) fn work(longest: usize) -> Duration {
    Duration::from_micros(longest as u64 * CYCLES_PER_BYTE + 2_000)
}

/// The robot's checksums of `ranges` (distinct first addresses), asked
/// of the loader's `sums`, which must be hooked. Lost answers are asked
/// again.
///
/// # Errors
/// [`Error::Unreadable`] when a range's answer keeps being lost; a line
/// error.
pub(crate) fn robot_sums<T: Transport>(
    client: &mut Client<T>,
    ranges: &[Range],
) -> Result<Vec<u16>> {
    let mut found: Vec<Option<u16>> = vec![None; ranges.len()];
    for attempt in 0..ATTEMPTS {
        let missing: Vec<usize> = (0..ranges.len()).filter(|&i| found[i].is_none()).collect();
        if missing.is_empty() {
            break;
        }
        let longest = missing.iter().map(|&i| ranges[i].1).max().unwrap_or(0);
        let questions: Vec<Vec<u8>> = missing.iter().map(|&i| question(ranges[i])).collect();
        let frames = client.batch(&questions, ANSWER_LEN, work(longest))?;
        for (address, sum) in frames.iter().filter_map(|frame| parse(frame)) {
            if let Some(&i) = missing.iter().find(|&&i| ranges[i].0 == address) {
                found[i] = Some(sum);
            }
        }
        if attempt + 1 == ATTEMPTS {
            if let Some(&i) = missing.iter().find(|&&i| found[i].is_none()) {
                return Err(Error::Unreadable {
                    address: ranges[i].0,
                    attempts: ATTEMPTS,
                    last: None,
                });
            }
        }
    }
    Ok(found.into_iter().map(|sum| sum.unwrap_or(0)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_byte_changed_changes_the_sum() {
        let bytes: Vec<u8> = (0..=255u8).cycle().take(2048).collect();
        let sum = fletcher16(&bytes);
        for at in [0usize, 1, 255, 1024, 2047] {
            for delta in [1u8, 0x80, 0xFF] {
                let mut changed = bytes.clone();
                changed[at] = changed[at].wrapping_add(delta);
                assert_ne!(fletcher16(&changed), sum, "byte {at} + {delta}");
            }
        }
        let mut swapped = bytes.clone();
        swapped.swap(3, 4);
        assert_ne!(fletcher16(&swapped), sum, "a swap");
    }

    #[test]
    fn sums_of_parts_join_into_the_sum_of_the_whole() {
        let bytes: Vec<u8> = (0..700u32).map(|i| (i * 37 % 251) as u8).collect();
        for cut in [0usize, 1, 31, 256, 300, 699, 700] {
            let (a, b) = bytes.split_at(cut);
            assert_eq!(
                fletcher16_joined(fletcher16(a), fletcher16(b), b.len()),
                fletcher16(&bytes),
                "cut at {cut}"
            );
        }
        let known: Vec<(Range, u16)> =
            [(0x400u16, 256usize), (0x500, 256), (0x600, 32), (0x620, 32)]
                .iter()
                .map(|&(address, len)| {
                    let start = usize::from(address - 0x400);
                    ((address, len), fletcher16(&bytes[start..start + len]))
                })
                .collect();
        assert_eq!(
            joined_from(&known, (0x400, 576)),
            Some(fletcher16(&bytes[..576]))
        );
        assert_eq!(
            joined_from(&known, (0x500, 288)),
            Some(fletcher16(&bytes[256..544]))
        );
        // A gap, a range that runs past what is known, one that starts
        // inside a known range: asked of the robot instead.
        assert_eq!(joined_from(&known, (0x400, 600)), None);
        assert_eq!(joined_from(&known, (0x410, 16)), None);
        assert_eq!(joined_from(&known, (0x400, 0)), Some(fletcher16(&[])));
    }

    #[test]
    fn answers_parse_and_garbage_does_not() {
        assert_eq!(parse(b"K0400A1B2\r"), Some((0x0400, 0xA1B2)));
        assert_eq!(parse(b"K0400A1B\r"), None);
        assert_eq!(parse(b"R0400A1B2\r"), None);
        assert_eq!(parse(b"K0400A1BZ\r"), None);
        assert_eq!(question((0xF000, 0x1000)), b"/9KF0001000");
    }
}
