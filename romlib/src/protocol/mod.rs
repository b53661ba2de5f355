//! The host side of the Scorpion command protocol, typed (docs/PROTOCOL.md
//! section 2).
//!
//! Every instruction and question is a [`Command`]: its fields are value
//! types whose constructors check the ranges the protocol allows
//! ([`Speed`] 00-99, [`Steps`] 0000-9999, [`ReadCount`] 00-99 and never past
//! `$FFFF`...), so an encoded command is always one the ROM accepts.
//! [`Command::encode`] builds the exact ASCII (`/7R020010`), and
//! [`Command::parse`] reads it back (for command lines and expectation
//! files).
//!
//! Every answer form is an [`Answer`] variant holding a typed struct;
//! [`Answer::parse`] takes the bytes of one answer, carriage return
//! included, and [`Command::parse_answer`] also checks that the answer is
//! the one the question asks for (the letter, and for `/7R` the byte count).
//! A malformed answer is a [`ProtocolError`] naming what was expected and
//! at which character.
//!
//! [`COMMANDS`] is the one table of the ROM's commands (count, letter, form,
//! answer): whether a command is a question, how long its answer is and
//! which (count, letter) pairs are left to extensions all come from it.
//!
//! Nothing else in the workspace formats a command string or parses an
//! answer (docs/ARCHITECTURE.md).

mod answer;
mod command;
mod cursor;
mod error;
mod table;

pub use answer::{Answer, Bumpers, BusyByte, MoveCount, MoveCounts, Pair, ScanAnswer, Status};
pub use command::{
    Axis, Command, Direction, EXTENSION_MAX_LEN, Extension, Motor, ReadCount, ReadSpan, ScanSteps,
    Speed, Steps, WordWrite,
};
pub use error::ProtocolError;
pub use table::{COMMANDS, CommandSpec, Reply, find as find_command};

/// The carriage return that ends every answer (docs/PROTOCOL.md section 2).
pub const EOL: u8 = b'\r';

/// The byte that starts every command.
pub const SLASH: u8 = b'/';

/// The most bytes one `/7Raaaa##` reads (the count is two decimal digits).
pub const MAX_READ: u8 = 99;

/// The most scanner-buffer bytes a `/1S` answer carries.
pub const MAX_SCAN_BYTES: usize = 199;

/// Characters on the wire per byte written by `/9Waaaahhhh` (11 characters
/// move 2 bytes): the cost that a RAM-resident loader exists to beat.
pub const WRITE_WORD_LEN: usize = 11;

#[cfg(test)]
mod tests;
