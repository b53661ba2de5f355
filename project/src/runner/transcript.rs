//! Transcripts (`.expect` files) as tests: read with their errors at
//! `file:line`, and checked to the end, every line that differs said as a
//! test's failure with its `file:line`, the command, what was expected and
//! what came back, and when (robot time on the virtual Scorpion).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

use miette::Context;
use uploader::{Expectations, Mismatch};

/// Reads the transcript at `path`, shown to the user as `shown`.
pub fn read(path: &Path, shown: &str) -> miette::Result<Expectations> {
    let text =
        hostfs::read_text(path, hostfs::TEXT).wrap_err_with(|| format!("cannot read {shown}"))?;
    Expectations::parse(&text).map_err(|error| match error {
        uploader::Error::BadExpectations { line, reason } => miette::miette!(
            code = "uploader::bad_expectations",
            help = "each line is `COMMAND` or `COMMAND => ANSWER`; `#` starts a comment",
            "{shown}:{line}: {reason}"
        ),
        other => miette::Report::new(other).wrap_err(format!("in {shown}")),
    })
}

/// What the times of a check are measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// The virtual Scorpion's emulated time.
    Robot,
    /// Time on a real line, as this computer measured it.
    Line,
}

/// A time for people: milliseconds, to the microsecond.
fn time(at: Duration, clock: Clock) -> String {
    let ms = at.as_secs_f64() * 1000.0;
    match clock {
        Clock::Robot => format!("{ms:.3} ms of robot time"),
        Clock::Line => format!("{ms:.3} ms on the line"),
    }
}

/// A line per mismatch, each `FILE:LINE: ...`, in the file's order.
pub fn describe(shown: &str, mismatches: &[Mismatch], clock: Clock) -> String {
    let mut text = String::new();
    for mismatch in mismatches {
        let _ = writeln!(
            text,
            "{shown}:{}: `{}` answered `{}`, expected `{}` (at {} into the transcript)",
            mismatch.line,
            mismatch.command,
            mismatch.found,
            mismatch.expected,
            time(mismatch.at, clock)
        );
    }
    text
}

/// A transcript whose lines were not all answered as they require; the
/// lines themselves are [`describe`]d before it, a line each (a message
/// of many lines would be rewrapped by the error's renderer).
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{shown}: {count} of {lines} lines not answered as they require")]
#[diagnostic(code(scorpion::transcript_failed))]
pub struct TranscriptFailed {
    shown: String,
    count: usize,
    lines: usize,
    #[help]
    help: Option<String>,
}

impl TranscriptFailed {
    /// The failure of `expectations`, read from `shown`, if any line
    /// differed.
    pub fn of(
        shown: &str,
        expectations: &Expectations,
        mismatches: &[Mismatch],
        help: &str,
    ) -> Option<TranscriptFailed> {
        (!mismatches.is_empty()).then(|| TranscriptFailed {
            shown: shown.to_owned(),
            count: mismatches.len(),
            lines: expectations.lines.len(),
            help: Some(help.to_owned()),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mismatch_is_a_line_with_its_place_and_time() {
        let mismatches = [
            Mismatch {
                line: 4,
                command: "/1V".into(),
                expected: "V01".into(),
                found: "V02".into(),
                at: Duration::from_micros(12_345),
            },
            Mismatch {
                line: 9,
                command: "/1X".into(),
                expected: "X01".into(),
                found: "X00".into(),
                at: Duration::from_micros(20_000),
            },
        ];
        assert_eq!(
            describe("tests/probe.expect", &mismatches, Clock::Robot),
            "tests/probe.expect:4: `/1V` answered `V02`, expected `V01` (at 12.345 ms of robot time into the transcript)\n\
             tests/probe.expect:9: `/1X` answered `X00`, expected `X01` (at 20.000 ms of robot time into the transcript)\n"
        );
    }
}
