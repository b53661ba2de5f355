//! Expectation files: commands and the answers they must produce, run
//! against a robot (the virtual Scorpion, in a dry run) after an upload.
//!
//! ```text
//! # comment
//! /1X => X00          a question and its exact answer (no carriage return)
//! /1Q => QHELLO       an extension's new command
//! /2E3                an instruction: sent, nothing expected back
//! /1P => *            any well-formed answer will do
//! ```

use romlib::protocol::{Answer, Command};

use crate::client::Client;
use crate::transport::Transport;
use crate::{Error, Result};

/// What one line requires.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Required {
    /// No answer (an instruction).
    Nothing,
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
            let command: Command = command.parse().map_err(|error| Error::BadExpectations {
                line,
                reason: format!("{error}"),
            })?;
            let required = match answer {
                None if command.is_question() => Required::Any,
                None => Required::Nothing,
                Some("*") => Required::Any,
                Some("") => {
                    return Err(Error::BadExpectations {
                        line,
                        reason: "nothing after `=>`; write `*` to accept any answer".into(),
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
            lines.push(Expectation {
                line,
                command,
                required,
            });
        }
        Ok(Expectations { lines })
    }

    /// Sends every command and checks every answer.
    ///
    /// # Errors
    /// [`Error::RehearsalFailed`] at the first difference, or a line error.
    pub fn check<T: Transport>(
        &self,
        client: &mut Client<T>,
    ) -> Result<Vec<(Command, Option<Answer>)>> {
        let mut transcript = Vec::new();
        for expectation in &self.lines {
            let command = &expectation.command;
            let answer = match &expectation.required {
                Required::Nothing => {
                    client.send(command)?;
                    None
                }
                Required::Any | Required::Exactly(_) => {
                    let answer = client
                        .ask(command)
                        .map_err(|error| Error::RehearsalFailed {
                            command: command.to_string(),
                            expected: match &expectation.required {
                                Required::Exactly(text) => text.clone(),
                                _ => "an answer".into(),
                            },
                            found: format!("no valid answer ({error})"),
                        })?;
                    if let Required::Exactly(text) = &expectation.required {
                        let encoded = answer.encode();
                        let found = String::from_utf8_lossy(&encoded[..encoded.len() - 1]);
                        if found != text.as_str() {
                            return Err(Error::RehearsalFailed {
                                command: command.to_string(),
                                expected: text.clone(),
                                found: found.into_owned(),
                            });
                        }
                    }
                    Some(answer)
                }
            };
            transcript.push((command.clone(), answer));
        }
        Ok(transcript)
    }
}
