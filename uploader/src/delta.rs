//! Delta uploads: which ranges of an image the robot does not hold yet,
//! found by checksums the loader's `sums` computes on the robot, not by
//! reading every byte. A coarse pass sums ranges of [`COARSE`] bytes;
//! where few differ, each differing one is summed again in ranges of
//! [`FINE`] bytes, so a one-byte change is written (and read back) as one
//! short range. Where most differ (a robot that never held the image),
//! the fine pass would cost more than it saves: the coarse ranges are
//! written whole.
//!
//! A frame costs one character a byte on the way out and its `/7R`
//! verification two on the way back; a sum question and its answer cost
//! 25 characters whatever the range. So a fine pass over a coarse range
//! (8 questions) pays when it spares most of the range's bytes.

use crate::Result;
use crate::client::Client;
use crate::image::{Area, UploadImage};
use crate::sums::{Range, partition, robot_sum, robot_sums};
use crate::transport::Transport;

/// Bytes of a range of the coarse pass, about ([`partition`]).
pub const COARSE: usize = 256;

/// Bytes of a range of the fine pass, about: a coarse range is 7 of them.
pub const FINE: usize = 37;

/// `image`'s ranges of about `size` bytes, each within an area
/// ([`partition`]), with their bytes.
fn split(areas: &[Area], size: usize) -> Vec<(Range, &[u8])> {
    let mut out = Vec::new();
    for area in areas {
        for (at, len) in partition(area.bytes.len(), size) {
            out.push(((area.address + at as u16, len), &area.bytes[at..at + len]));
        }
    }
    out
}

/// A range's index and the robot's sum of it.
type Differs = (usize, u32);

/// Ranges with the robot's sums of them.
pub(crate) type Known = Vec<(Range, u32)>;

/// The ranges of `ranges` whose robot sum differs from the host's, the
/// robot's sums of `first` (asked first, in the same batch), and every
/// range asked with the robot's sum of it.
fn differ<T: Transport>(
    client: &mut Client<T>,
    first: &[Range],
    ranges: &[(Range, &[u8])],
) -> Result<(Vec<Differs>, Vec<u32>, Known)> {
    let mut asked: Vec<Range> = first.to_vec();
    asked.extend(ranges.iter().map(|(range, _)| *range));
    let mut found = robot_sums(client, &asked)?;
    let known = asked.iter().copied().zip(found.iter().copied()).collect();
    let rest = found.split_off(first.len());
    let wrong = ranges
        .iter()
        .zip(rest)
        .enumerate()
        .filter(|(_, ((_, bytes), found))| robot_sum(bytes) != *found)
        .map(|(i, (_, found))| (i, found))
        .collect();
    Ok((wrong, found, known))
}

/// A range of the image and the robot's sum of what it holds there.
pub(crate) type Held = (Area, u32);

/// What the sums of an upload found, before anything was written.
pub(crate) struct Summed {
    /// The ranges of the image to write, each with the robot's sum of
    /// what it holds there.
    pub held: Vec<Held>,
    /// The robot's sums of the ranges asked first.
    pub first: Vec<u32>,
    /// Every range asked, with the robot's sum of it: what a later sum
    /// of the same memory, still unwritten, can be put together from.
    pub known: Known,
}

/// The ranges of `image` the robot does not hold, merged where they
/// touch; empty when it holds every byte. The loader's `sums` must be
/// hooked.
///
/// # Errors
/// A line error, or [`crate::Error::Unreadable`] when sums keep being lost.
pub(crate) fn differing<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
) -> Result<Vec<Area>> {
    Ok(merged(&differing_and(client, &[], image)?.held))
}

/// The ranges of `image` the robot does not hold, each with the robot's
/// sum of what it holds there (what an undo keeps is checked against
/// it), and the robot's sums of `first`, asked in the same batch as the
/// coarse pass (the whole ROM's, say: the robot sums it while the other
/// questions are on their way).
///
/// # Errors
/// As [`differing`].
pub(crate) fn differing_and<T: Transport>(
    client: &mut Client<T>,
    first: &[Range],
    image: &UploadImage,
) -> Result<Summed> {
    let coarse = split(image.areas(), COARSE);
    let (wrong, sums, mut known) = differ(client, first, &coarse)?;
    let held = |range: &(Range, &[u8]), sum: u32| {
        (
            Area {
                address: range.0.0,
                bytes: range.1.to_vec(),
            },
            sum,
        )
    };
    // Most of a large image differs: written whole, no finer pass. The
    // table entry, which an edited image always changes, and a range no
    // longer than a fine one do not count (they would make half of a
    // small image), nor does an image of one or two ranges (a finer pass
    // costs less than writing 256 bytes).
    let big = |i: usize| coarse[i].1.len() > FINE;
    let ranges = (0..coarse.len()).filter(|&i| big(i)).count();
    let differing = wrong.iter().filter(|&&(i, _)| big(i)).count();
    if ranges > 2 && differing * 2 > ranges {
        let held = wrong
            .iter()
            .map(|&(i, sum)| held(&coarse[i], sum))
            .collect();
        return Ok(Summed {
            held,
            first: sums,
            known,
        });
    }
    // A range no longer than a fine one is summed already: asking again
    // would get the same answer.
    let (short, long): (Vec<Differs>, Vec<Differs>) =
        wrong.iter().partition(|&&(i, _)| coarse[i].1.len() <= FINE);
    let pieces: Vec<Area> = long.iter().map(|&(i, _)| held(&coarse[i], 0).0).collect();
    let fine = split(&pieces, FINE);
    let mut out: Vec<Held> = short
        .iter()
        .map(|&(i, sum)| held(&coarse[i], sum))
        .collect();
    if !fine.is_empty() {
        let (wrong_fine, _, known_fine) = differ(client, &[], &fine)?;
        out.extend(wrong_fine.iter().map(|&(i, sum)| held(&fine[i], sum)));
        known.extend(known_fine);
    }
    out.sort_by_key(|(area, _)| area.address);
    Ok(Summed {
        held: out,
        first: sums,
        known,
    })
}

/// Every range of `image` (coarse), each with the robot's sum of what it
/// holds there, and the robot's sums of `first`: for an upload that
/// writes every byte and keeps what it overwrites.
///
/// # Errors
/// As [`differing`].
pub(crate) fn all_and<T: Transport>(
    client: &mut Client<T>,
    first: &[Range],
    image: &UploadImage,
) -> Result<Summed> {
    let coarse = split(image.areas(), COARSE);
    let mut asked: Vec<Range> = first.to_vec();
    asked.extend(coarse.iter().map(|(range, _)| *range));
    let mut found = robot_sums(client, &asked)?;
    let known = asked.iter().copied().zip(found.iter().copied()).collect();
    let rest = found.split_off(first.len());
    let held = coarse
        .iter()
        .zip(rest)
        .map(|(((address, _), bytes), sum)| {
            (
                Area {
                    address: *address,
                    bytes: bytes.to_vec(),
                },
                sum,
            )
        })
        .collect();
    Ok(Summed {
        held,
        first: found,
        known,
    })
}

/// The ranges of `held`, merged where they touch.
pub(crate) fn merged(held: &[Held]) -> Vec<Area> {
    let mut out = Vec::new();
    for (area, _) in held {
        push(&mut out, area.address, &area.bytes);
    }
    out
}

/// Appends a range, merged with the last one if it follows it.
pub(crate) fn push(out: &mut Vec<Area>, address: u16, bytes: &[u8]) {
    if let Some(last) = out.last_mut()
        && last.end() == u32::from(address)
    {
        last.bytes.extend_from_slice(bytes);
        return;
    }
    out.push(Area {
        address,
        bytes: bytes.to_vec(),
    });
}

/// hostile31 F1: `held` (the ranges to write) and every range the sums
/// took for held in which `previous` (the earlier version the robot's
/// table listed in the image's place, as it was uploaded) differs from
/// the image: an edit that only moves bytes about (instructions swapped,
/// constants rotated, a table shifted) can balance the robot's sums. The
/// smallest range asked (`known`) that holds each such byte is written,
/// with the robot's sum of it. Only adds ranges: a wrong `previous` costs
/// writes, never a byte left unwritten.
pub(crate) fn with_known_changes(
    mut held: Vec<Held>,
    known: &Known,
    image: &UploadImage,
    previous: &[Area],
) -> Vec<Held> {
    if previous.is_empty() {
        return held;
    }
    let within = |at: u32, start: u16, len: usize| {
        u32::from(start) <= at && at < u32::from(start) + len as u32
    };
    // The upload fills its chain slots with where each hook went before:
    // not the image's bytes as linked, nor the earlier version's.
    let slots = image.chain_slot_bytes();
    for area in image.areas() {
        for (i, &byte) in area.bytes.iter().enumerate() {
            let at = u32::from(area.address) + i as u32;
            if slots.contains(&(at as u16)) {
                continue;
            }
            let before = previous.iter().find_map(|earlier| {
                let offset = at.checked_sub(u32::from(earlier.address))?;
                earlier.bytes.get(offset as usize).copied()
            });
            if before.is_none_or(|before| before == byte)
                || held
                    .iter()
                    .any(|(range, _)| within(at, range.address, range.bytes.len()))
            {
                continue;
            }
            let range = known
                .iter()
                .filter(|((start, len), _)| within(at, *start, *len))
                .filter(|((start, len), _)| {
                    u32::from(*start) >= u32::from(area.address)
                        && u32::from(*start) + *len as u32 <= area.end()
                })
                .min_by_key(|((_, len), _)| *len);
            if let Some(&((start, len), sum)) = range {
                let from = usize::from(start - area.address);
                held.push((
                    Area {
                        address: start,
                        bytes: area.bytes[from..from + len].to_vec(),
                    },
                    sum,
                ));
            }
        }
    }
    held.sort_by_key(|(range, _)| range.address);
    held
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_stay_within_their_areas_and_merge_when_they_touch() {
        let areas = vec![
            Area {
                address: 0x0400,
                bytes: vec![1; 70],
            },
            Area {
                address: 0x1000,
                bytes: vec![2; 10],
            },
        ];
        let ranges: Vec<Range> = split(&areas, 31).into_iter().map(|(r, _)| r).collect();
        assert_eq!(
            ranges,
            vec![(0x0400, 24), (0x0418, 23), (0x042F, 23), (0x1000, 10),]
        );
        let mut out = Vec::new();
        push(&mut out, 0x0400, &[1, 2]);
        push(&mut out, 0x0402, &[3]);
        push(&mut out, 0x0404, &[4]);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].bytes, vec![1, 2, 3]);
    }
}
