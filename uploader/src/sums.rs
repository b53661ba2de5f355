//! Checksums computed on the robot by the RAM loader's `sums` part
//! (`/9Kaaaassnn`: `nn` pieces of `ss` bytes from `aaaa`, answered `Kaaaa`
//! and eight digits a piece): what tells an upload which ranges a robot
//! holds already, and a robot's ROM from another, without reading every
//! byte over the line. Ranges of one length that follow each other go in
//! one question ([`robot_sums`]): the robot waits for the line at each
//! character it answers, and the address and the question are paid once.
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
//! change together unseen where they balance both sums: `+1, -2, +1` in a
//! row, and edits that only move bytes about (hostile31 F1: two
//! instructions whose bytes add up alike swapped, constants rotated, a
//! table shifted by an entry). Where the caller knows the earlier version
//! (`UploadOptions::previous`), the ranges where it differs are written
//! anyway; `--full` writes every byte. A third
//! sum (of the running second sums) would see those; measured on the
//! bench it costs the one-byte change about 0.12 s of robot time (19
//! cycles a byte more, four digits a piece), which the one-second goal
//! cannot take until the upload's reads at the base rate are fewer.

use std::time::Duration;

use romlib::protocol::EOL;

use crate::client::Client;
use crate::transport::Transport;
use crate::{Error, Result};

/// The loader's time per byte summed at most (42 cycles at 1 MHz, 35
/// where the first sum's low byte does not carry), plus the command's
/// parsing.
const CYCLES_PER_BYTE: u64 = 42;

/// Characters of an answer of one piece: `K`, four address digits, eight
/// sum digits, the carriage return.
pub(crate) const ANSWER_LEN: usize = 14;

/// The longest piece the loader sums (a question's `ss`), over which the
/// first sum is exact (255 x 256 < 65536), and so over which [`robot_sum`]
/// sees every change of one or two bytes, and only zeros sum to zero.
/// Every range whose sum decides anything is at most this long.
pub const EXACT: usize = 256;

/// The most pieces one question asks (an answer of 262 characters).
const MOST_PIECES: usize = 32;

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

/// The question for `count` pieces of `size` bytes (1 to [`EXACT`]) from
/// `address`.
fn question_of(address: u16, size: usize, count: usize) -> Vec<u8> {
    format!("/9K{address:04X}{:02X}{count:02X}", size & 0xFF).into_bytes()
}

/// The question for one range of at most [`EXACT`] bytes.
pub(crate) fn question((address, len): Range) -> Vec<u8> {
    question_of(address, len.clamp(1, EXACT), 1)
}

/// An answer's address and sums (one a piece), if it is one.
pub(crate) fn parse(frame: &[u8]) -> Option<(u16, Vec<u32>)> {
    let text = frame.strip_suffix(&[EOL])?.strip_prefix(b"K")?;
    if text.len() < 12 || (text.len() - 4) % 8 != 0 || !text.iter().all(u8::is_ascii_hexdigit) {
        return None;
    }
    let text = std::str::from_utf8(text).ok()?;
    let address = u16::from_str_radix(&text[..4], 16).ok()?;
    let sums = (4..text.len())
        .step_by(8)
        .map(|at| u32::from_str_radix(&text[at..at + 8], 16).ok())
        .collect::<Option<Vec<u32>>>()?;
    Some((address, sums))
}

/// The sum of two ranges one after the other, from the sum of each and
/// the length of the second: the second sum of the first range's bytes
/// gains the first range's first sum once for each byte after them.
#[must_use]
pub(crate) fn joined(first: u32, second: u32, second_len: usize) -> u32 {
    let (a1, a2) = ((first >> 16) as u16, first as u16);
    let (b1, b2) = ((second >> 16) as u16, second as u16);
    let one = a1.wrapping_add(b1);
    let two = a2
        .wrapping_add(b2)
        .wrapping_add(a1.wrapping_mul(second_len as u16));
    u32::from(one) << 16 | u32::from(two)
}

/// One question: `count` pieces of `size` bytes from `address`, and the
/// pieces' indexes among those asked.
struct Asked {
    address: u16,
    size: usize,
    pieces: Vec<usize>,
}

/// `pieces` (each at most [`EXACT`] bytes) as questions: pieces of one
/// length that follow each other, up to `most` ([`MOST_PIECES`] at most),
/// in one.
fn questions(pieces: &[Range], todo: &[usize], most: usize) -> Vec<Asked> {
    let most = most.clamp(1, MOST_PIECES);
    let mut out: Vec<Asked> = Vec::new();
    for &i in todo {
        let (address, size) = pieces[i];
        if let Some(last) = out.last_mut() {
            let next = usize::from(last.address) + last.size * last.pieces.len();
            if last.size == size && next == usize::from(address) && last.pieces.len() < most {
                last.pieces.push(i);
                continue;
            }
        }
        out.push(Asked {
            address,
            size,
            pieces: vec![i],
        });
    }
    out
}

/// The robot's time to answer one question over at most `longest` bytes,
/// besides the characters.
pub(crate) fn work(longest: usize) -> Duration {
    Duration::from_micros(longest as u64 * CYCLES_PER_BYTE + 2_000)
}

/// `asked` in batches in which no two questions start at one address:
/// answers are matched by their address (ranges of two lengths there go
/// in separate batches).
fn batches(asked: Vec<Asked>) -> Vec<Vec<Asked>> {
    let mut out: Vec<Vec<Asked>> = Vec::new();
    for question in asked {
        match out
            .iter_mut()
            .find(|batch| batch.iter().all(|q| q.address != question.address))
        {
            Some(batch) => batch.push(question),
            None => out.push(vec![question]),
        }
    }
    out
}

/// Asks `asked` (distinct first addresses) in one batch; each answer's
/// sums go to its question's pieces in `found`.
fn ask_batch<T: Transport>(
    client: &mut Client<T>,
    asked: &[Asked],
    found: &mut [Option<u32>],
) -> Result<()> {
    let longest = asked
        .iter()
        .map(|q| q.size * q.pieces.len())
        .max()
        .unwrap_or(0);
    let most = asked.iter().map(|q| q.pieces.len()).max().unwrap_or(1);
    let texts: Vec<Vec<u8>> = asked
        .iter()
        .map(|q| question_of(q.address, q.size, q.pieces.len()))
        .collect();
    let answer_len = ANSWER_LEN + 8 * (most - 1);
    let frames = client.batch(&texts, answer_len, work(longest))?;
    for (address, sums) in frames.iter().filter_map(|frame| parse(frame)) {
        let question = asked
            .iter()
            .find(|q| q.address == address && q.pieces.len() == sums.len());
        if let Some(question) = question {
            for (&i, &sum) in question.pieces.iter().zip(&sums) {
                found[i] = Some(sum);
            }
        }
    }
    Ok(())
}

/// The robot's checksums of `ranges`, asked of the loader's `sums`,
/// which must be hooked: a range longer than [`EXACT`] in pieces, its sum
/// put together from theirs ([`joined`]). Lost answers are asked again.
///
/// # Errors
/// [`Error::Unreadable`] when a range's answer keeps being lost; a line
/// error.
pub(crate) fn robot_sums<T: Transport>(
    client: &mut Client<T>,
    ranges: &[Range],
) -> Result<Vec<u32>> {
    // Each range as pieces; `owner[i]` is the range piece `i` is of.
    let mut pieces: Vec<Range> = Vec::new();
    let mut owner: Vec<usize> = Vec::new();
    for (r, &(address, len)) in ranges.iter().enumerate() {
        for (at, piece) in self::pieces(len, EXACT) {
            pieces.push((address.wrapping_add(at as u16), piece));
            owner.push(r);
        }
    }
    let mut found: Vec<Option<u32>> = vec![None; pieces.len()];
    for attempt in 0..ATTEMPTS {
        let missing: Vec<usize> = (0..pieces.len()).filter(|&i| found[i].is_none()).collect();
        if missing.is_empty() {
            break;
        }
        // A long answer is more likely to lose a character to noise:
        // what is asked again goes in questions a quarter as long each
        // time, down to one piece a question.
        let asked = questions(&pieces, &missing, MOST_PIECES >> (2 * attempt));
        for batch in batches(asked) {
            ask_batch(client, &batch, &mut found)?;
        }
        if attempt + 1 == ATTEMPTS {
            if let Some(i) = (0..pieces.len()).find(|&i| found[i].is_none()) {
                return Err(Error::Unreadable {
                    address: pieces[i].0,
                    attempts: ATTEMPTS,
                    last: None,
                });
            }
        }
    }
    let mut sums: Vec<Option<u32>> = vec![None; ranges.len()];
    for (i, sum) in found.into_iter().enumerate() {
        let sum = sum.unwrap_or(0);
        let r = owner[i];
        sums[r] = Some(sums[r].map_or(sum, |before| joined(before, sum, pieces[i].1)));
    }
    Ok(sums.into_iter().map(|sum| sum.unwrap_or(0)).collect())
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

    /// hostile31 F1, as the README says: edits that only move bytes about
    /// balance both sums and pass (`--full` is the way past them).
    #[test]
    fn edits_that_move_bytes_about_can_balance_both_sums() {
        // Two two-byte instructions whose bytes add up alike, swapped.
        let before = [0xA9, 0x10, 0x69, 0x50, 0x60];
        let after = [0x69, 0x50, 0xA9, 0x10, 0x60];
        assert_eq!(robot_sum(&before), robot_sum(&after), "a swap");
        // A 64-entry sine table starting at its mean, shifted by an entry.
        let sine: Vec<u8> = (0..64)
            .map(|i| {
                let angle = f64::from(i) * std::f64::consts::TAU / 64.0;
                (128.0 + 100.0 * angle.sin()).round() as u8
            })
            .collect();
        let mut shifted = sine.clone();
        shifted.rotate_left(1);
        assert_ne!(sine, shifted);
        assert_eq!(robot_sum(&sine), robot_sum(&shifted), "a table shifted");
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
            ((0x0600, 300), 3), // longer than a piece: no witness
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
            vec![((0x0600, EXACT), None), ((0x0700, 44), None)]
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
        assert_eq!(parse(b"K04000102A1B2\r"), Some((0x0400, vec![0x0102_A1B2])));
        assert_eq!(
            parse(b"K04000102A1B2FFFF0000\r"),
            Some((0x0400, vec![0x0102_A1B2, 0xFFFF_0000]))
        );
        assert_eq!(parse(b"K0400A1B2\r"), None, "the narrow sums' answer");
        assert_eq!(parse(b"K04000102A1B\r"), None);
        assert_eq!(parse(b"K04000102A1B2FFFF\r"), None, "half a piece");
        assert_eq!(parse(b"R04000102A1B2\r"), None);
        assert_eq!(parse(b"K04000102A1BZ\r"), None);
        assert_eq!(question((0xF000, 256)), b"/9KF0000001");
        assert_eq!(question((0x0400, 37)), b"/9K04002501");
    }

    #[test]
    fn pieces_that_follow_each_other_go_in_one_question_and_join() {
        let pieces: Vec<Range> = vec![
            (0x0400, 256),
            (0x0500, 256),
            (0x0600, 256),
            (0x0700, 37),
            (0x0725, 37),
            (0x0800, 37), // not after the one before
            (0x0825, 36),
        ];
        let all: Vec<usize> = (0..pieces.len()).collect();
        let asked = questions(&pieces, &all, MOST_PIECES);
        let shape: Vec<(u16, usize, Vec<usize>)> = asked
            .iter()
            .map(|q| (q.address, q.size, q.pieces.clone()))
            .collect();
        assert_eq!(
            shape,
            vec![
                (0x0400, 256, vec![0, 1, 2]),
                (0x0700, 37, vec![3, 4]),
                (0x0800, 37, vec![5]),
                (0x0825, 36, vec![6]),
            ]
        );
        assert_eq!(question_of(0x0400, 256, 3), b"/9K04000003");
        // Missing ones only, still grouped where they follow each other.
        let asked = questions(&pieces, &[0, 2], MOST_PIECES);
        assert_eq!(asked.len(), 2);
        // Asked again, in shorter questions.
        assert_eq!(questions(&pieces, &all, 2)[0].pieces, vec![0, 1]);
        assert_eq!(questions(&pieces, &all, 0).len(), pieces.len());
        // Two ranges from one address: never in one batch.
        let twice: Vec<Range> = vec![(0x0400, 37), (0x0400, 36), (0x0500, 10)];
        let split = batches(questions(&twice, &[0, 1, 2], MOST_PIECES));
        let shape: Vec<Vec<(u16, usize)>> = split
            .iter()
            .map(|batch| batch.iter().map(|q| (q.address, q.size)).collect())
            .collect();
        assert_eq!(
            shape,
            vec![vec![(0x0400, 37), (0x0500, 10)], vec![(0x0400, 36)]]
        );
        let bytes: Vec<u8> = (0..1000u32).map(|i| (i * 7 + i / 3) as u8).collect();
        for cut in [0usize, 1, 256, 500, 999, 1000] {
            assert_eq!(
                joined(
                    robot_sum(&bytes[..cut]),
                    robot_sum(&bytes[cut..]),
                    1000 - cut
                ),
                robot_sum(&bytes),
                "cut at {cut}"
            );
        }
    }
}
