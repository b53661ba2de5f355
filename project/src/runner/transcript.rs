//! Transcripts (`.expect` files) as tests: read with their errors at
//! `file:line`, and checked to the end, every line that differs said as a
//! test's failure with its `file:line`, the command, what was expected and
//! what came back, and when (robot time on the virtual Scorpion).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

use uploader::{Expectation, Expectations, Mismatch};

use super::error::{BadTranscript, Error, Result};
use super::room_lines::{self, RoomLine};

/// A transcript's line: a command for the robot (the uploader's
/// grammar) or a line about the robot in its room ([`room_lines`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A command and what it must answer.
    Command(Expectation),
    /// A line about the room, at its line (from 1).
    Room(usize, RoomLine),
}

/// A transcript read: its lines in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Transcript {
    /// The lines, in the file's order.
    pub steps: Vec<Step>,
}

impl Transcript {
    /// The command lines alone, as the uploader checks them.
    #[must_use]
    pub fn expectations(&self) -> Expectations {
        Expectations {
            lines: self
                .steps
                .iter()
                .filter_map(|step| match step {
                    Step::Command(e) => Some(e.clone()),
                    Step::Room(..) => None,
                })
                .collect(),
        }
    }

    /// The first room line, if any: what a robot without a room cannot
    /// check.
    #[must_use]
    pub fn first_room_line(&self) -> Option<usize> {
        self.steps.iter().find_map(|step| match step {
            Step::Room(line, _) => Some(*line),
            Step::Command(_) => None,
        })
    }
}

/// Reads the transcript at `path`, shown to the user as `shown`.
///
/// # Errors
/// [`Error::Read`] if the file cannot be read, [`Error::BadTranscript`]
/// at the first line that is not a transcript's.
pub fn read(path: &Path, shown: &str) -> Result<Transcript> {
    let text = hostfs::read_text(path, hostfs::TEXT).map_err(|source| Error::Read {
        shown: shown.to_owned(),
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text, shown)
}

/// Reads the transcript at `path` for a robot that has no room (an
/// upload's rehearsal and check): its commands alone.
///
/// # Errors
/// As [`read`], and [`Error::BadTranscript`] at a room line.
pub fn read_commands(path: &Path, shown: &str) -> Result<Expectations> {
    let transcript = read(path, shown)?;
    if let Some(line) = transcript.first_room_line() {
        return Err(no_room(shown, line));
    }
    Ok(transcript.expectations())
}

/// The error of a room line (`wait`, `pose`, `bumped`) on a real robot,
/// whose room the host cannot see (fresh11 F8: the message told the user
/// to add the world file the project had).
#[must_use]
pub fn no_room_on_port(shown: &str, line: usize) -> Error {
    Error::BadTranscript(Box::new(BadTranscript {
        shown: shown.to_owned(),
        line,
        reason: "a robot on a port is seen through its line alone: `wait`, `pose` and `bumped` \
                 are checked on the virtual Scorpion in the project's room (`scorpion test` \
                 without --port, the rehearsal of this run); no line of this transcript was sent"
            .into(),
    }))
}

/// The error of a room line (`wait`, `pose`, `bumped`) where the robot
/// has no room to see it in.
#[must_use]
pub fn no_room(shown: &str, line: usize) -> Error {
    Error::BadTranscript(Box::new(BadTranscript {
        shown: shown.to_owned(),
        line,
        reason: "the robot has no room to check this line in: `wait`, `pose` and `bumped` \
                 need the virtual Scorpion in a room: the project's world file (`world = \
                 \"room.toml\"` under [robot] in Scorpion.toml; docs/WORLD.md), with which \
                 `scorpion test` runs its transcripts"
            .into(),
    }))
}

/// Parses a transcript's `text`, shown to the user as `shown`.
///
/// # Errors
/// [`Error::BadTranscript`] at the first line that is not a transcript's.
pub fn parse(text: &str, shown: &str) -> Result<Transcript> {
    let bad = |line: usize, reason: String| {
        Error::BadTranscript(Box::new(BadTranscript {
            shown: shown.to_owned(),
            line,
            reason,
        }))
    };
    // The room lines are taken out, blank, so the uploader reads the
    // commands at their own lines.
    let mut room = Vec::new();
    let mut commands = String::new();
    let mut any_command = false;
    for (index, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("").trim();
        match room_lines::parse(content) {
            Some(Ok(line)) => room.push(Step::Room(index + 1, line)),
            Some(Err(reason)) => return Err(bad(index + 1, reason)),
            None => {
                any_command |= !content.is_empty();
                commands.push_str(raw);
            }
        }
        commands.push('\n');
    }
    let expectations = if any_command || room.is_empty() {
        Expectations::parse(&commands).map_err(|error| match error {
            uploader::Error::BadExpectations { line, reason } => bad(line, reason),
            source => Error::Transcript {
                shown: shown.to_owned(),
                source: Box::new(source),
            },
        })?
    } else {
        Expectations::default()
    };
    let mut steps: Vec<Step> = expectations.lines.into_iter().map(Step::Command).collect();
    steps.extend(room);
    steps.sort_by_key(|step| match step {
        Step::Command(e) => e.line,
        Step::Room(line, _) => *line,
    });
    Ok(Transcript { steps })
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
