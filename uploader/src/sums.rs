//! Checksums computed on the robot by the RAM loader's `sums` part
//! (`/9Kaaaannnn`, answered `Kaaaassssssss`): what tells an upload which
//! ranges a robot holds already, and a robot's ROM from another, without
//! reading every byte over the line.
//!
//! The sum ([`robot_sum`]) is Fletcher's with both sums mod 65536 and
//! starting at zero: the first is the sum of the bytes, the second the sum
//! of the running first sums. Over up to [`EXACT`] bytes the first is the
//! bytes' true sum, so any one byte changed changes it, and two bytes that
//! change by `+d` and `-d`, `k` apart, change the second by `d * k`, which
//! is less than 65536: no change of one or two bytes goes unseen. Both
//! sums were mod 256 once, and two bytes whose distance times their change
//! was a multiple of 256 (bit 7 of two bytes two apart, `$40` moved four
//! bytes) passed as held (hostile30 F1-F4). Three or more bytes can still
//! change together unseen (`+1, -2, +1` in a row, as with every sum of
//! this kind): `--full` reads back every byte.

use std::time::Duration;

use romlib::protocol::EOL;

use crate::client::Client;
use crate::transport::Transport;
use crate::{Error, Result};

/// The loader's time per byte summed at most (42 cycles at 1 MHz, 35
/// where the first sum's low byte does not carry), plus the command's
/// parsing.
const CYCLES_PER_BYTE: u64 = 42;

/// Characters of an answer: `K`, four address digits, eight sum digits,
/// the carriage return.
pub(crate) const ANSWER_LEN: usize = 14;

/// The longest range over which the first sum is exact (255 x 257 <
/// 65536), and so over which [`robot_sum`] sees every change of one or
/// two bytes, and only zeros sum to zero. Every range whose sum decides
/// anything is at most this long.
pub const EXACT: usize = 257;

/// The most a range is asked again after its answer was lost.
const ATTEMPTS: u32 = 6;

/// The checksum of `bytes` as the loader's `sums` computes it: the
/// first sum (of the bytes, mod 65536) in the high half, the second (of
/// the running first sums, mod 65536) in the low half.
#[must_use]
pub fn robot_sum(bytes: &[u8]) -> u32 {
    let (mut first, mut second) = (0u16, 0u16);
    for &byte in bytes {
        first = first.wrapping_add(u16::from(byte));
        second = second.wrapping_add(first);
    }
    u32::from(first) << 16 | u32::from(second)
}

/// Whether a range of `len` bytes that the robot summed to `sum` holds
/// nothing but zeros, known without a read: over at most [`EXACT`]
/// bytes only zeros sum to nothing.
#[must_use]
pub(crate) fn sums_as_zeros(sum: u32, len: usize) -> bool {
    sum == 0 && len <= EXACT
}

/// The Fletcher-16 of `bytes` as the loader computed it before
/// hostile30 (both sums mod 256, the first in the high byte): what the
/// witnesses of a version 1 backup file hold.
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

/// `len` bytes as the fewest pieces of at most `about` bytes (and at
/// most [`EXACT`]), as even in length as they can be: `(offset, len)`.
/// For sums asked where the count of questions costs line time (a delta
/// upload's passes): 2048 bytes are 8 pieces of 256.
#[must_use]
pub(crate) fn partition(len: usize, about: usize) -> Vec<(usize, usize)> {
    if len == 0 {
        return Vec::new();
    }
    let about = about.clamp(1, EXACT);
    let count = len.div_ceil(about);
    let (base, longer) = (len / count, len % count);
    let mut pieces = Vec::with_capacity(count);
    let mut at = 0;
    for i in 0..count {
        let piece = base + usize::from(i < longer);
        pieces.push((at, piece));
        at += piece;
    }
    pieces
}

/// `len` bytes as pieces of at most `most` bytes (and at most
/// [`EXACT`]), the last one shorter: `(offset, len)`.
#[must_use]
pub(crate) fn pieces(len: usize, most: usize) -> Vec<(usize, usize)> {
    let most = most.clamp(1, EXACT);
    (0..len)
        .step_by(most)
        .map(|at| (at, most.min(len - at)))
        .collect()
}

/// `range` as ranges of at most [`EXACT`] bytes: the `known` ones (with
/// their sums) that tile it where they do, the rest as pieces to ask
/// ([`pieces`]), `None`.
#[must_use]
pub(crate) fn tiled(known: &[(Range, u32)], (address, len): Range) -> Vec<(Range, Option<u32>)> {
    let end = usize::from(address) + len;
    let known_at = |at: usize| {
        known
            .iter()
            .filter(|((start, part), _)| {
                usize::from(*start) == at && (1..=EXACT).contains(part) && at + part <= end
            })
            .max_by_key(|((_, part), _)| *part)
            .copied()
    };
    let mut out = Vec::new();
    let mut at = usize::from(address);
    while at < end {
        if let Some((range, sum)) = known_at(at) {
            out.push((range, Some(sum)));
            at += range.1;
            continue;
        }
        // Up to where a known range starts, or the end.
        let gap_end = (at + 1..end)
            .find(|&next| known_at(next).is_some())
            .unwrap_or(end);
        for (offset, piece) in pieces(gap_end - at, EXACT) {
            out.push((((at + offset) as u16, piece), None));
        }
        at = gap_end;
    }
    out
}

/// The question for one range.
pub(crate) fn question((address, len): Range) -> Vec<u8> {
    // A length of $10000 cannot be asked; nothing asks for it.
    format!("/9K{address:04X}{:04X}", len.min(0xFFFF)).into_bytes()
}

/// An answer's address and sum, if it is one.
pub(crate) fn parse(frame: &[u8]) -> Option<(u16, u32)> {
    let text = frame.strip_suffix(&[EOL])?.strip_prefix(b"K")?;
    if text.len() != 12 || !text.iter().all(u8::is_ascii_hexdigit) {
        return None;
    }
    let text = std::str::from_utf8(text).ok()?;
    let address = u16::from_str_radix(&text[..4], 16).ok()?;
    let sum = u32::from_str_radix(&text[4..], 16).ok()?;
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
) -> Result<Vec<u32>> {
    let mut found: Vec<Option<u32>> = vec![None; ranges.len()];
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

    /// hostile30 F1-F4: no change of one or two bytes in a range of up to
    /// `EXACT` bytes sums as the bytes did, whatever the bytes and the
    /// distance. Both sums mod 256 missed bit 7 of two bytes two apart,
    /// `$40` moved four bytes, +1/-1 256 apart, and a page of `NOP`s
    /// summed as zeros.
    #[test]
    fn no_change_of_one_or_two_bytes_sums_alike() {
        let mut rng = 0x2545_f491_u32;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            rng
        };
        for len in [2usize, 3, 5, 37, 256, EXACT] {
            let bytes: Vec<u8> = (0..len).map(|_| next() as u8).collect();
            let sum = robot_sum(&bytes);
            for at in 0..len {
                for new in 0..=255u8 {
                    if new == bytes[at] {
                        continue;
                    }
                    let mut changed = bytes.clone();
                    changed[at] = new;
                    assert_ne!(robot_sum(&changed), sum, "{len}: byte {at} to {new:02X}");
                }
            }
            // Every pair of places, every pair of changes would take
            // long: every distance with the changes that cancel in the
            // first sum (the only ones that can cancel in both), and a
            // sample of the rest.
            for first in 0..len {
                for second in first + 1..len {
                    for d in 1..=255u8 {
                        let mut changed = bytes.clone();
                        changed[first] = changed[first].wrapping_add(d);
                        changed[second] = changed[second].wrapping_sub(d);
                        assert_ne!(
                            robot_sum(&changed),
                            sum,
                            "{len}: +{d} at {first}, -{d} at {second}"
                        );
                    }
                    let mut changed = bytes.clone();
                    changed[first] ^= next() as u8 | 1;
                    changed[second] ^= next() as u8 | 1;
                    assert_ne!(robot_sum(&changed), sum, "{len}: {first} and {second}");
                }
            }
        }
        // The narrow sums' blind spots, as hostile30 met them.
        assert_eq!(fletcher16(&[0x80, 0, 0x80]), fletcher16(&[0, 0, 0]));
        assert_ne!(robot_sum(&[0x80, 0, 0x80]), robot_sum(&[0, 0, 0]));
        assert_eq!(fletcher16(&[0xEA; 256]), fletcher16(&[0; 256]));
        assert_ne!(robot_sum(&[0xEA; 256]), robot_sum(&[0; 256]));
        // What three bytes can do, and why `--full` exists.
        assert_eq!(robot_sum(&[2, 1, 2]), robot_sum(&[1, 3, 1]));
    }

    #[test]
    fn only_zeros_sum_as_zeros_and_only_where_the_first_sum_is_exact() {
        for byte in 1..=255u8 {
            for len in [1usize, 2, 255, 256, EXACT] {
                assert_ne!(robot_sum(&vec![byte; len]), 0, "{len} x {byte:02X}");
            }
        }
        assert!(sums_as_zeros(robot_sum(&[0; EXACT]), EXACT));
        assert!(!sums_as_zeros(0, EXACT + 1), "no longer exact");
        assert_eq!(robot_sum(&vec![0x80; 512]) >> 16, 0, "the first sum wraps");
    }

    #[test]
    fn the_sum_is_what_the_loader_answers() {
        // Worked by hand: first = 1 + 2 + 3 = 6; second = 1 + 3 + 6 = 10.
        assert_eq!(robot_sum(&[1, 2, 3]), 0x0006_000A);
        assert_eq!(robot_sum(&[0xFF; 2]), 0x01FE_02FD);
        assert_eq!(robot_sum(&[]), 0);
    }

    #[test]
    fn known_ranges_tile_what_they_can_and_the_rest_is_asked_in_pieces() {
        let known: Vec<(Range, u32)> = vec![
            ((0x0400, 256), 1),
            ((0x0500, 256), 2),
            ((0x0600, 300), 3), // longer than a sum sees whole: no witness
        ];
        assert_eq!(
            tiled(&known, (0x0400, 512)),
            vec![((0x0400, 256), Some(1)), ((0x0500, 256), Some(2))]
        );
        assert_eq!(
            tiled(&known, (0x03FC, 300)),
            vec![
                ((0x03FC, 4), None),
                ((0x0400, 256), Some(1)),
                ((0x0500, 40), None),
            ]
        );
        assert_eq!(
            tiled(&known, (0x0600, 300)),
            vec![((0x0600, EXACT), None), ((0x0701, 43), None)]
        );
    }

    #[test]
    fn pieces_and_partitions_cover_their_bytes_within_what_a_sum_sees() {
        for len in 0..3000 {
            for most in [1usize, 31, 37, 256, EXACT, 0xFFFF] {
                let pieces = pieces(len, most);
                assert_eq!(pieces.iter().map(|p| p.1).sum::<usize>(), len, "{len}");
                assert!(pieces.iter().all(|p| p.1 <= most.min(EXACT) && p.1 > 0));
                assert!(pieces.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0));
            }
            for about in [31usize, 37, 256, 1000] {
                let pieces = partition(len, about);
                assert_eq!(pieces.iter().map(|p| p.1).sum::<usize>(), len);
                assert!(pieces.iter().all(|p| p.1 <= about.min(EXACT) && p.1 > 0));
                assert!(pieces.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0));
                assert_eq!(pieces.len(), len.div_ceil(about.min(EXACT)));
            }
        }
        assert_eq!(
            partition(2048, 256),
            (0..8).map(|i| (i * 256, 256)).collect::<Vec<_>>()
        );
        assert_eq!(partition(256, 37).len(), 7);
    }

    #[test]
    fn answers_parse_and_garbage_does_not() {
        assert_eq!(parse(b"K04000102A1B2\r"), Some((0x0400, 0x0102_A1B2)));
        assert_eq!(parse(b"K0400A1B2\r"), None, "the narrow sums' answer");
        assert_eq!(parse(b"K04000102A1B\r"), None);
        assert_eq!(parse(b"R04000102A1B2\r"), None);
        assert_eq!(parse(b"K04000102A1BZ\r"), None);
        assert_eq!(question((0xF000, 0x1000)), b"/9KF0001000");
    }
}
