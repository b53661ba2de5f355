//! The last verification spans of a transfer through the ROM's commands,
//! chosen by simulating the robot.
//!
//! The ROM takes in one command at a time and cannot take in the next
//! while it sends an answer, so `/9W`s that arrive during an answer wait
//! in its receive ring. After the last write has arrived, what is left is
//! the time to work off that backlog plus the answers still to come. The
//! spans are chosen so that both are short: each answer ends about when
//! the writes behind it are in, and the last answer is small. For a large
//! area that is its last few dozen bytes; for a loader part, all of it.
//!
//! The costs are the reference ROM's (measured on the virtual Scorpion);
//! another ROM only makes the choice less good, never wrong.

use std::time::Duration;

use crate::client::COUNT_SPACING;
use crate::transport::char_time;

/// The reference ROM's time to take in one `/9W` or `/7W` once it has
/// arrived: parse, dispatch, store, the end of the command.
const ROM_WRITE: Duration = Duration::from_micros(2900);

/// Its time from a `/7R`'s arrival to the start of its answer.
const ROM_READ_SETUP: Duration = Duration::from_micros(1000);

/// The bytes at the end of a transfer whose spans are chosen here.
pub(crate) const TAIL: usize = 64;

/// The most spans the tail is cut into.
const MAX_SPANS: usize = 4;

/// Spans for the last `len` bytes of a transfer through the ROM at
/// `baud` (`len` at most [`TAIL`]; the caller keeps the tail's start on a
/// `/9W` boundary): the split whose simulated end is earliest, among
/// splits on even offsets into spans whose sizes differ by at least
/// [`COUNT_SPACING`], so their questions can all be in flight together.
pub(crate) fn rom_tail(len: usize, baud: u32) -> Vec<usize> {
    let len = len.min(TAIL);
    if len == 0 {
        return Vec::new();
    }
    let mut best = (simulate(&[len], baud), vec![len]);
    let mut cuts = Vec::new();
    search(len, baud, 2, &mut cuts, &mut best);
    best.1
}

/// Tries every set of even cuts from `from` on, up to [`MAX_SPANS`] spans.
fn search(
    len: usize,
    baud: u32,
    from: usize,
    cuts: &mut Vec<usize>,
    best: &mut (Duration, Vec<usize>),
) {
    for cut in (from..len).step_by(2) {
        cuts.push(cut);
        let spans = spans_of(len, cuts);
        if distinct(&spans) {
            let end = simulate(&spans, baud);
            if end < best.0 {
                *best = (end, spans);
            }
        }
        if cuts.len() + 1 < MAX_SPANS {
            search(len, baud, cut + 2, cuts, best);
        }
        cuts.pop();
    }
}

fn spans_of(len: usize, cuts: &[usize]) -> Vec<usize> {
    let mut spans = Vec::with_capacity(cuts.len() + 1);
    let mut at = 0;
    for &cut in cuts.iter().chain(std::iter::once(&len)) {
        spans.push(cut - at);
        at = cut;
    }
    spans
}

/// Whether every two spans differ by at least [`COUNT_SPACING`].
fn distinct(spans: &[usize]) -> bool {
    spans.iter().enumerate().all(|(i, &a)| {
        spans[i + 1..]
            .iter()
            .all(|&b| a.abs_diff(b) >= usize::from(COUNT_SPACING))
    })
}

/// When the last answer ends, for `spans` written and read back in turn
/// from time zero, the host sending without pause and the robot idle at
/// the start.
fn simulate(spans: &[usize], baud: u32) -> Duration {
    let (mut arrived, mut robot, mut end) = (Duration::ZERO, Duration::ZERO, Duration::ZERO);
    let last = spans.iter().sum::<usize>();
    let mut written = 0;
    for &span in spans {
        let span_end = written + span;
        let mut at = written;
        while at < span_end {
            // A `/9W` for two bytes; a `/7W` for an odd last one.
            let (chars, bytes) = if at + 1 < last { (11, 2) } else { (9, 1) };
            arrived += char_time(chars, baud);
            robot = robot.max(arrived) + ROM_WRITE;
            at += bytes;
        }
        written = at;
        arrived += char_time(9, baud);
        robot = robot.max(arrived) + ROM_READ_SETUP + char_time(2 * span + 2, baud);
        end = robot;
    }
    end
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tails_cover_the_bytes_with_distinct_spans() {
        for baud in [9600, 19200] {
            for len in [1, 2, 7, 15, 30, 62, 64] {
                let spans = rom_tail(len, baud);
                assert_eq!(spans.iter().sum::<usize>(), len, "{len} at {baud}");
                assert!(distinct(&spans), "{spans:?}");
            }
        }
    }

    #[test]
    fn a_tapered_tail_ends_sooner_than_one_read() {
        // The loader's `frames` part at 19200 baud.
        let spans = rom_tail(62, 19200);
        let one = simulate(&[62], 19200);
        let tapered = simulate(&spans, 19200);
        assert!(
            tapered + Duration::from_millis(20) < one,
            "{spans:?}: {tapered:?} against {one:?}"
        );
    }
}
