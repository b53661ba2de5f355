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

/// `len` bytes as the fewest pieces of odd length about `about` bytes
/// long (a piece may be one or two longer), as even in length as odd
/// counts allow: `(offset, len)`. For sums asked where the count of
/// questions costs line time (a delta upload's passes): 2048 bytes are 8
/// pieces of 255 and 257, as 8 of 256 were. Odd, as [`odd_pieces`] says.
#[must_use]
pub(crate) fn odd_partition(len: usize, about: usize) -> Vec<(usize, usize)> {
    if len == 0 {
        return Vec::new();
    }
    let mut count = len.div_ceil(about.max(1));
    // Odd pieces add up to `len` only in a count of its parity.
    if count % 2 != len % 2 {
        count += 1;
    }
    let base = len / count;
    let base = if base % 2 == 0 { base - 1 } else { base };
    // Even, and less than two a piece: the first pieces take two more.
    let longer = (len - base * count) / 2;
    let mut pieces = Vec::with_capacity(count);
    let mut at = 0;
    for i in 0..count {
        let piece = if i < longer { base + 2 } else { base };
        pieces.push((at, piece));
        at += piece;
    }
    pieces
}

/// hostile29 F2: `len` bytes as pieces of at most `most` bytes (odd),
/// each of odd length (an even rest is one byte shorter, its last byte a
/// piece of its own): `(offset, len)`. Both sums are mod 256, so over an
/// even count some runs of one byte sum as zeros do (256 bytes of `$EA`,
/// a page of `NOP`s; 32 of `$10`), and an upload took such a page on a
/// robot holding zeros for held. Over an odd count the first sum of a run
/// of one byte is that byte times an odd number: no two runs sum alike.
#[must_use]
pub(crate) fn odd_pieces(len: usize, most: usize) -> Vec<(usize, usize)> {
    let most = most.max(1);
    let most = if most % 2 == 0 { most - 1 } else { most };
    let mut pieces = Vec::new();
    let mut at = 0;
    while at < len {
        let take = match (len - at).min(most) {
            even if even % 2 == 0 => even - 1,
            odd => odd,
        };
        pieces.push((at, take));
        at += take;
    }
    pieces
}

/// `range` as odd-length ranges (hostile29 F2): the `known` ones of odd
/// length that tile it where they do, with their sums; the rest as odd
/// pieces to ask ([`odd_pieces`]), `None`.
#[must_use]
pub(crate) fn tiled_odd(
    known: &[(Range, u16)],
    (address, len): Range,
) -> Vec<(Range, Option<u16>)> {
    let end = usize::from(address) + len;
    let odd_known = |at: usize| {
        known
            .iter()
            .filter(|((start, part), _)| {
                usize::from(*start) == at && part % 2 == 1 && at + part <= end
            })
            .max_by_key(|((_, part), _)| *part)
            .copied()
    };
    let mut out = Vec::new();
    let mut at = usize::from(address);
    while at < end {
        if let Some((range, sum)) = odd_known(at) {
            out.push((range, Some(sum)));
            at += range.1;
            continue;
        }
        // Up to where a known range starts, or the end.
        let gap_end = (at + 1..end)
            .find(|&next| odd_known(next).is_some())
            .unwrap_or(end);
        for (offset, piece) in odd_pieces(gap_end - at, gap_end - at) {
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
    fn known_odd_ranges_tile_what_they_can_and_the_rest_is_asked_in_odd_pieces() {
        let known: Vec<(Range, u16)> = vec![
            ((0x0400, 255), 1),
            ((0x04FF, 257), 2),
            ((0x0600, 32), 3), // even: no witness
        ];
        assert_eq!(
            tiled_odd(&known, (0x0400, 512)),
            vec![((0x0400, 255), Some(1)), ((0x04FF, 257), Some(2))]
        );
        assert_eq!(
            tiled_odd(&known, (0x03FC, 300)),
            vec![
                ((0x03FC, 3), None),
                ((0x03FF, 1), None),
                ((0x0400, 255), Some(1)),
                ((0x04FF, 41), None),
            ]
        );
        assert_eq!(
            tiled_odd(&known, (0x0600, 32)),
            vec![((0x0600, 31), None), ((0x061F, 1), None)]
        );
    }

    /// hostile29 F2: a run of one byte over an odd count sums as no run
    /// of another byte does (over 256, every even byte sums as zeros).
    #[test]
    fn odd_pieces_tell_every_run_of_one_byte_apart() {
        assert_eq!(
            fletcher16(&[0xEA; 256]),
            fletcher16(&[0; 256]),
            "the blind spot"
        );
        for most in [255usize, 31, 127] {
            let mut sums = std::collections::HashMap::new();
            for byte in 0..=255u8 {
                let pieces: Vec<u16> = odd_pieces(256, most)
                    .into_iter()
                    .map(|(_, len)| fletcher16(&vec![byte; len]))
                    .collect();
                if let Some(other) = sums.insert(pieces, byte) {
                    panic!("${byte:02X} sums as ${other:02X} in pieces of {most}");
                }
            }
        }
        for len in 0..600 {
            let pieces = odd_pieces(len, 255);
            assert_eq!(pieces.iter().map(|p| p.1).sum::<usize>(), len, "{len}");
            assert!(
                pieces.iter().all(|p| p.1 % 2 == 1 && p.1 <= 255),
                "{len}: {pieces:?}"
            );
            assert!(
                pieces.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0),
                "{len}"
            );
        }
        assert_eq!(odd_pieces(256, 256), vec![(0, 255), (255, 1)]);
        for len in 1..3000 {
            for about in [31usize, 37, 256] {
                let pieces = odd_partition(len, about);
                assert_eq!(
                    pieces.iter().map(|p| p.1).sum::<usize>(),
                    len,
                    "{len}/{about}"
                );
                assert!(
                    pieces.iter().all(|p| p.1 % 2 == 1 && p.1 <= about + 2),
                    "{len}/{about}: {pieces:?}"
                );
                assert!(
                    pieces.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0),
                    "{len}/{about}"
                );
                assert!(
                    pieces.len() <= len.div_ceil(about) + 1,
                    "{len}/{about}: {pieces:?}"
                );
            }
        }
        assert_eq!(odd_partition(2048, 256).len(), 8);
        assert_eq!(odd_partition(255, 37).len(), 7);
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
