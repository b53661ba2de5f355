//! Expectation files: commands and the answers they must produce, run
//! against a robot (the virtual Scorpion, in a dry run) after an upload.
//!
//! ```text
//! # comment
//! /1X => X00          a question and its exact answer (no carriage return)
//! /1Q => QHELLO       an extension's new command
//! /1P => *            any well-formed answer will do
//! /9Z => nothing      the robot must not answer
//! /2E3                a ROM instruction: sent (the ROM never answers one)
//! /9W10000102         an extension's command without `=>`: whatever comes
//!                     back, an answer or nothing, is accepted and shown
//! ```
//!
//! A file with no command in it is an error: it would check nothing.

use romlib::protocol::{Answer, Command};

/// What an expectation line writes after `=>` for "no answer at all".
pub const NOTHING: &str = "nothing";

use crate::client::Client;
use crate::transport::Transport;
use crate::{Error, Result};

/// What one line requires.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Required {
    /// A ROM instruction with no `=>`: sent; the ROM never answers one.
    Sent,
    /// `=> nothing`: the robot must stay silent for as long as the longest
    /// answer takes.
    Nothing,
    /// An extension's command with no `=>`: an answer or none, either is
    /// accepted, and an answer is kept for the transcript.
    Whatever,
    /// Any well-formed answer.
    Any,
    /// This exact answer, without its carriage return.
    Exactly(String),
}

/// One line of an expectation file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Expectation {
    /// 1-based line number.
    pub line: usize,
    /// The command to send.
    pub command: Command,
    /// What must come back.
    pub required: Required,
    /// `within 2ms`: the longest the answer may take, from sending the
    /// command to its carriage return (the line's own time included).
    pub within: Option<std::time::Duration>,
}

/// `within N` with `cycles` (of the 1 MHz CPU), `us` or `ms`.
fn budget(text: &str) -> Option<std::time::Duration> {
    let text = text.trim();
    let (number, unit) = text.split_at(text.find(|c: char| !c.is_ascii_digit())?);
    let n: u64 = number.parse().ok()?;
    match unit.trim() {
        "cycles" | "us" => Some(std::time::Duration::from_micros(n)),
        "ms" => Some(std::time::Duration::from_millis(n)),
        _ => None,
    }
}

/// A parsed expectation file.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Expectations {
    /// The lines, in order.
    pub lines: Vec<Expectation>,
}

impl Expectations {
    /// Parses the file's text.
    ///
    /// # Errors
    /// [`Error::BadExpectations`] naming the line.
    pub fn parse(text: &str) -> Result<Self> {
        let mut lines = Vec::new();
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let (command, answer) = match content.split_once("=>") {
                Some((command, answer)) => (command.trim(), Some(answer.trim())),
                None => (content, None),
            };
            let (answer, within) = match answer.and_then(|a| a.rsplit_once(" within ")) {
                Some((answer, limit)) => {
                    let within = budget(limit).ok_or_else(|| Error::BadExpectations {
                        line,
                        reason: format!(
                            "`within {}` is not a time: write `within 2ms`, `within 500us` or `within 3000 cycles`",
                            limit.trim()
                        ),
                    })?;
                    (Some(answer.trim()), Some(within))
                }
                None => (answer, None),
            };
            let command: Command = command.parse().map_err(|error| Error::BadExpectations {
                line,
                reason: format!("{error}"),
            })?;
            let required = match answer {
                None if command.is_question() => Required::Any,
                None if matches!(command, Command::Extension(_)) => Required::Whatever,
                None => Required::Sent,
                Some("*") => Required::Any,
                Some(NOTHING) => Required::Nothing,
                Some("") => {
                    return Err(Error::BadExpectations {
                        line,
                        reason: format!(
                            "nothing after `=>`; write `*` to accept any answer, `{NOTHING}` to require silence"
                        ),
                    });
                }
                Some(text) => {
                    let mut bytes = text.as_bytes().to_vec();
                    bytes.push(romlib::protocol::EOL);
                    command
                        .parse_answer(&bytes)
                        .map_err(|error| Error::BadExpectations {
                            line,
                            reason: format!("`{text}` cannot answer `{command}`: {error}"),
                        })?;
                    Required::Exactly(text.to_owned())
                }
            };
            if within.is_some() && !matches!(required, Required::Any | Required::Exactly(_)) {
                return Err(Error::BadExpectations {
                    line,
                    reason: "`within` needs an answer to time: write `=> ANSWER within 2ms` or `=> * within 2ms`".into(),
                });
            }
            lines.push(Expectation {
                line,
                command,
                required,
                within,
            });
        }
        if lines.is_empty() {
            return Err(Error::BadExpectations {
                line: text.lines().count().max(1),
                reason: "the file has no command in it, so it would check nothing".into(),
            });
        }
        Ok(Expectations { lines })
    }

    /// Sends every command and checks every answer, stopping at the first
    /// difference (an upload's rehearsal: nothing more is needed to refuse).
    ///
    /// # Errors
    /// [`Error::RehearsalFailed`] at the first difference, or a line error.
    pub fn check<T: Transport>(
        &self,
        client: &mut Client<T>,
    ) -> Result<Vec<(Command, Option<Answer>)>> {
        let checked = self.check_all(client)?;
        match checked.mismatches.into_iter().next() {
            Some(first) => Err(Error::RehearsalFailed {
                command: first.command,
                expected: first.expected,
                found: first.found,
            }),
            None => Ok(checked.transcript),
        }
    }

    /// Sends every command and checks every answer, going on after a
    /// difference, as a test run reports all of a file's failures.
    ///
    /// # Errors
    /// A line error, or a robot that stopped (it can say why): what leaves
    /// nothing to check the rest against.
    pub fn check_all<T: Transport>(&self, client: &mut Client<T>) -> Result<Checked> {
        let started = client.transport().now();
        let mut checked = Checked::default();
        for expectation in &self.lines {
            let command = &expectation.command;
            let sent_at = client.transport().now();
            let mut differs = |expected: String, found: String| {
                checked.mismatches.push(Mismatch {
                    line: expectation.line,
                    command: command.to_string(),
                    expected,
                    found,
                    at: sent_at.saturating_sub(started),
                });
            };
            let answer = match &expectation.required {
                Required::Sent => {
                    client.send(command)?;
                    None
                }
                Required::Nothing | Required::Whatever => {
                    let heard = client.listen(command)?;
                    if let (Required::Nothing, Some(answer)) = (&expectation.required, &heard) {
                        differs("no answer".into(), answer_text(answer));
                    }
                    heard
                }
                Required::Any | Required::Exactly(_) => match client.ask(command) {
                    Ok(answer) => {
                        let found = answer_text(&answer);
                        let took = client.transport().now().saturating_sub(sent_at);
                        match (&expectation.required, expectation.within) {
                            (Required::Exactly(text), _) if found != *text => {
                                differs(text.clone(), found);
                            }
                            (_, Some(within)) if took > within => differs(
                                format!("an answer within {} us", within.as_micros()),
                                format!("{found} after {} us", took.as_micros()),
                            ),
                            _ => {}
                        }
                        Some(answer)
                    }
                    Err(error) => {
                        // Silence from a robot that can show why says so.
                        client.transport().diagnose_silence()?;
                        differs(
                            match &expectation.required {
                                Required::Exactly(text) => text.clone(),
                                _ => "an answer".into(),
                            },
                            match &error {
                                // The script's place and what went wrong
                                // (hostile13 F1: only "the card failed").
                                crate::Error::Robot(romlib::Error::Card { message, .. }) => {
                                    format!("no valid answer ({error}: {message})")
                                }
                                _ => format!("no valid answer ({error})"),
                            },
                        );
                        None
                    }
                },
            };
            checked.transcript.push((command.clone(), answer));
        }
        // The robot must still be running its loop after the last line (a
        // handler that never returns answers nothing, which a line without
        // `=>` accepts).
        client.transport().diagnose_silence()?;
        Ok(checked)
    }
}

/// A line whose answer was not the one required.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mismatch {
    /// The line of the expectation file (1-based).
    pub line: usize,
    /// The command sent.
    pub command: String,
    /// What the line requires.
    pub expected: String,
    /// What came back (or `no valid answer (why)`).
    pub found: String,
    /// When the command was sent, from the start of the check: robot time
    /// on the virtual Scorpion, time on the line on a real one.
    pub at: std::time::Duration,
}

/// What [`Expectations::check_all`] found.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Checked {
    /// Every command sent and its answer, in order.
    pub transcript: Vec<(Command, Option<Answer>)>,
    /// The lines that were not answered as they require, in order.
    pub mismatches: Vec<Mismatch>,
}

/// An answer as the robot sent it, without its carriage return.
#[must_use]
pub fn answer_text(answer: &Answer) -> String {
    let encoded = answer.encode();
    let body = encoded
        .strip_suffix(&[romlib::protocol::EOL])
        .unwrap_or(&encoded);
    String::from_utf8_lossy(body).into_owned()
}
