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
    fn answers_parse_and_garbage_does_not() {
        assert_eq!(parse(b"K0400A1B2\r"), Some((0x0400, 0xA1B2)));
        assert_eq!(parse(b"K0400A1B\r"), None);
        assert_eq!(parse(b"R0400A1B2\r"), None);
        assert_eq!(parse(b"K0400A1BZ\r"), None);
        assert_eq!(question((0xF000, 0x1000)), b"/9KF0001000");
    }
}
