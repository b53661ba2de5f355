//! Writing through the RAM loader verified by checksums computed on the
//! robot: each frame is followed by the loader's `/9K` question over the
//! bytes it carried, so the return wire carries 14 characters a frame
//! instead of two a byte (the `/7R` verification of `body`), and the
//! transfer runs at the sending wire's rate.
//!
//! A range whose sum differs is written again; one whose answer was lost
//! is asked again (its frame may or may not have landed: the sum tells).
//! After any fault, every range is summed again in a round that writes
//! nothing, since noise in a frame's address that still checked may have
//! put bytes on a range already passed. The robot's sum over at most
//! [`FRAME_MAX`] bytes changes with any change of one or two bytes
//! ([`crate::sums`]): the same trust a delta upload puts in the sums of
//! the ranges it leaves alone.

use crate::body::Limits;
use crate::client::Client;
use crate::image::Area;
use crate::loader::{FRAME_MAX, frame};
use crate::progress::{Phase, Progress};
use crate::sums::{ANSWER_LEN, parse, question, robot_sum, work};
use crate::transport::Transport;
use crate::{Error, Result};

/// Rounds in a row in which no answer came before the loader is taken
/// for gone (a reset) and the caller checks it.
const SILENT_ROUNDS: u32 = 2;

/// The shortest range a failing one is split into: a frame that lost a
/// character to noise is probably too long for the line.
const SHORTEST: usize = 8;

/// One frame's worth of bytes and its sum.
struct Unit {
    area: Area,
    sum: u32,
    writes: u32,
}

/// `areas` in frames of at most [`FRAME_MAX`] bytes, each one a frame can
/// carry (a key exists for it).
fn units(areas: &[Area]) -> Vec<Unit> {
    let mut out = Vec::new();
    for area in areas {
        let mut pending = vec![(area.address, area.bytes.as_slice())];
        while let Some((address, bytes)) = pending.pop() {
            let len = bytes.len().min(FRAME_MAX);
            let (head, rest) = bytes.split_at(len);
            if !rest.is_empty() {
                pending.push((address + len as u16, rest));
            }
            if frame(address, head).is_empty() && head.len() > 1 {
                // No key leaves every byte clear of a slash: halves.
                let half = head.len() / 2;
                pending.push((address + half as u16, &head[half..]));
                pending.push((address, &head[..half]));
                continue;
            }
            out.push(Unit {
                area: Area {
                    address,
                    bytes: head.to_vec(),
                },
                sum: robot_sum(head),
                writes: 0,
            });
        }
    }
    out.sort_by_key(|unit| unit.area.address);
    out
}

/// What a summed transfer did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Summed {
    /// Bytes written again after their range summed wrong.
    pub(crate) rewrites: usize,
    /// Rounds of sums that wrote nothing, run after faults.
    pub(crate) passes: u32,
}

/// Writes `areas` through the loader's frames (its `sums` hooked),
/// verified by the robot's sums; with `held_maybe`, the bytes may be there
/// already (after a reset, say), and each range is summed before it is
/// written.
///
/// # Errors
/// [`Error::SumFailed`] for a range that keeps summing wrong;
/// [`Error::NoAnswer`] when no sum comes back (the loader is gone: the
/// caller checks it and calls this again with `held_maybe`); a line error.
pub(crate) fn write_summed<T: Transport>(
    client: &mut Client<T>,
    areas: &[Area],
    held_maybe: bool,
    limits: Limits,
    progress: &mut dyn Progress,
) -> Result<Summed> {
    let mut units = units(areas);
    let total: usize = units.iter().map(|unit| unit.area.bytes.len()).sum();
    progress.phase(Phase::Write, total);
    // `ask`: not yet matched since its last write (or since the check
    // round began); `write`: to be written in the next round.
    let mut ask: Vec<bool> = vec![true; units.len()];
    let mut write: Vec<bool> = vec![!held_maybe; units.len()];
    let mut summed = Summed::default();
    // A range summed wrong since the last round that wrote nothing: a
    // write may have gone astray, so every range is summed again.
    let mut astray = held_maybe;
    let mut silent = 0;
    // When the rounds that heard no sum began, for the error.
    let mut silent_since = None;
    loop {
        if !ask.contains(&true) {
            if !astray {
                return Ok(summed);
            }
            // Every range again, writing nothing.
            ask.fill(true);
            astray = false;
            summed.passes += 1;
            if summed.passes > limits.max_passes {
                return Err(Error::SumFailed {
                    address: units.first().map_or(0, |unit| unit.area.address),
                    len: total,
                    attempts: summed.passes,
                });
            }
        }
        let asked: Vec<usize> = (0..units.len()).filter(|&i| ask[i]).collect();
        let mut entries = Vec::with_capacity(asked.len());
        for &i in &asked {
            let unit = &mut units[i];
            let mut entry = Vec::new();
            if write[i] {
                // Half the allowance spent (each time in a shorter range): a
                // byte that will not hold, or a very noisy line; the caller
                // writes and reads back byte by byte with the other half,
                // which names the byte.
                if unit.writes >= (limits.max_writes / 2).max(1) {
                    return Err(Error::SumFailed {
                        address: unit.area.address,
                        len: unit.area.bytes.len(),
                        attempts: unit.writes,
                    });
                }
                unit.writes += 1;
                entry = frame(unit.area.address, &unit.area.bytes);
            }
            entry.extend(question((unit.area.address, unit.area.bytes.len())));
            entries.push(entry);
        }
        let longest = asked
            .iter()
            .map(|&i| units[i].area.bytes.len())
            .max()
            .unwrap_or(0);
        let asked_at = client.transport().now();
        let frames = client.batch(&entries, ANSWER_LEN, work(longest))?;
        let mut found: Vec<Option<u32>> = vec![None; units.len()];
        let answers = frames.iter().filter_map(|frame| parse(frame));
        for (address, sum) in answers.filter_map(|(address, sums)| match sums[..] {
            [sum] => Some((address, sum)),
            _ => None,
        }) {
            if let Some(&i) = asked.iter().find(|&&i| units[i].area.address == address) {
                found[i] = Some(sum);
            }
        }
        let (mut wrong, mut lost) = (0, 0);
        for &i in &asked {
            write[i] = false;
            match found[i] {
                Some(sum) if sum == units[i].sum => ask[i] = false,
                Some(_) => {
                    if units[i].writes > 0 {
                        summed.rewrites += units[i].area.bytes.len();
                    }
                    write[i] = true;
                    wrong += 1;
                }
                // Asked again: the sum tells whether its frame landed.
                None => lost += 1,
            }
        }
        let done: usize = (0..units.len())
            .filter(|&i| !ask[i])
            .map(|i| units[i].area.bytes.len())
            .sum();
        progress.advanced(done.min(total));
        if wrong > 0 {
            astray = true;
            split_failing(&mut units, &mut ask, &mut write);
        }
        if lost == asked.len() {
            silent += 1;
            let now = client.transport().now();
            let since = *silent_since.get_or_insert(asked_at);
            if silent >= SILENT_ROUNDS {
                return Err(Error::NoAnswer {
                    port: client.transport().name(),
                    baud: client.transport().baud(),
                    question: "/9K".into(),
                    waited: now.saturating_sub(since),
                });
            }
        } else {
            silent = 0;
            silent_since = None;
        }
    }
}

/// Splits each range about to be written again (one that summed wrong)
/// in two, down to [`SHORTEST`] bytes; the halves keep its count of writes.
fn split_failing(units: &mut Vec<Unit>, ask: &mut Vec<bool>, write: &mut Vec<bool>) {
    let mut out = Vec::with_capacity(units.len());
    let (mut new_ask, mut new_write) = (Vec::new(), Vec::new());
    for (i, unit) in std::mem::take(units).into_iter().enumerate() {
        let len = unit.area.bytes.len();
        if !write[i] || len < 2 * SHORTEST {
            out.push(unit);
            new_ask.push(ask[i]);
            new_write.push(write[i]);
            continue;
        }
        let half = len / 2;
        let halves = [(0, half), (half, len - half)].into_iter();
        for (address, bytes) in
            halves.map(|(at, l)| (unit.area.address + at as u16, &unit.area.bytes[at..at + l]))
        {
            out.push(Unit {
                area: Area {
                    address,
                    bytes: bytes.to_vec(),
                },
                sum: robot_sum(bytes),
                writes: unit.writes,
            });
            new_ask.push(true);
            new_write.push(true);
        }
    }
    *units = out;
    *ask = new_ask;
    *write = new_write;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_cover_the_areas_in_frames() {
        let areas = vec![
            Area {
                address: 0x0400,
                bytes: (0..300).map(|i| i as u8).collect(),
            },
            Area {
                address: 0x0F00,
                bytes: vec![7; 5],
            },
        ];
        let units = units(&areas);
        let ranges: Vec<(u16, usize)> = units
            .iter()
            .map(|unit| (unit.area.address, unit.area.bytes.len()))
            .collect();
        assert_eq!(
            ranges,
            vec![(0x0400, 128), (0x0480, 128), (0x0500, 44), (0x0F00, 5)]
        );
        assert!(
            units
                .iter()
                .all(|unit| unit.sum == robot_sum(&unit.area.bytes))
        );
    }
}
