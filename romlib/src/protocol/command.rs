//! Commands: every instruction and question of docs/PROTOCOL.md section 2, with
//! checked field types, built into the exact ASCII the ROM reads and parsed
//! back from it.

use std::fmt;

use super::SLASH;
use super::answer::{Answer, Pair};
use super::cursor::{Cursor, Miss};
use super::error::{ProtocolError, escape};
use super::table::{self, CommandSpec, Reply};

/// One of the two drive motors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motor {
    /// The left motor, letter `C`.
    Left,
    /// The right motor, letter `D`.
    Right,
}

impl Motor {
    /// The command and answer letter (`C` left, `D` right).
    #[must_use]
    pub const fn letter(self) -> u8 {
        match self {
            Motor::Left => b'C',
            Motor::Right => b'D',
        }
    }
}

/// The direction sign of a motor command (`d` in `/8Cdff####`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// `+`.
    Plus,
    /// `-`.
    Minus,
}

impl Direction {
    /// The sign character.
    #[must_use]
    pub const fn sign(self) -> u8 {
        match self {
            Direction::Plus => b'+',
            Direction::Minus => b'-',
        }
    }
}

/// A scanner axis: `H` horizontal, `V` vertical.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The horizontal scanner, `H`.
    Horizontal,
    /// The vertical scanner, `V`.
    Vertical,
}

impl Axis {
    /// The command and answer letter.
    #[must_use]
    pub const fn letter(self) -> u8 {
        match self {
            Axis::Horizontal => b'H',
            Axis::Vertical => b'V',
        }
    }
}

macro_rules! decimal_field {
    ($(#[$doc:meta])* $name:ident($repr:ty), $what:literal, $min:literal..=$max:literal) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name($repr);

        impl $name {
            /// The smallest value the protocol can carry.
            pub const MIN: $name = $name($min);
            /// The largest value the protocol can carry.
            pub const MAX: $name = $name($max);

            /// Checks the range.
            ///
            /// # Errors
            /// [`ProtocolError::OutOfRange`] outside it.
            pub fn new(value: $repr) -> Result<Self, ProtocolError> {
                if ($min..=$max).contains(&value) {
                    Ok($name(value))
                } else {
                    Err(ProtocolError::OutOfRange {
                        what: $what,
                        value: u32::from(value),
                        min: $min,
                        max: $max,
                    })
                }
            }

            /// The value.
            #[must_use]
            pub const fn get(self) -> $repr {
                self.0
            }
        }
    };
}

decimal_field!(
    /// A motor speed, `00` (stop) to `99`.
    Speed(u8), "speed", 0..=99
);
decimal_field!(
    /// A step count, `0000` to `9999`.
    Steps(u16), "step count", 0..=9999
);
decimal_field!(
    /// Scan steps each side, `01` to `99`.
    ScanSteps(u8), "scan steps", 1..=99
);
decimal_field!(
    /// A `/7R` byte count, `00` to `99`.
    ReadCount(u8), "read count", 0..=99
);

/// The most characters an extension command carries after `/N`.
pub const EXTENSION_MAX_LEN: usize = 9;

/// A command the ROM does not know, for an extension to handle: 1 to 9
/// printable characters, letter first, that is not a ROM command's
/// (count, letter) pair.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Extension(Vec<u8>);

impl Extension {
    /// Checks that the bytes can travel as one command.
    ///
    /// # Errors
    /// [`ProtocolError::BadExtension`] when empty, longer than 9, holding a
    /// byte that is not printable ASCII or is `/`, or when the ROM itself
    /// dispatches on that count and letter.
    pub fn new(bytes: impl Into<Vec<u8>>) -> Result<Self, ProtocolError> {
        let bytes = bytes.into();
        let bad = |reason: String| ProtocolError::BadExtension {
            text: escape(&bytes),
            reason,
        };
        if bytes.is_empty() || bytes.len() > EXTENSION_MAX_LEN {
            return Err(bad(format!(
                "{} characters; a command carries 1 to {EXTENSION_MAX_LEN}",
                bytes.len()
            )));
        }
        if let Some(&b) = bytes
            .iter()
            .find(|&&b| !(0x20..0x7F).contains(&b) || b == SLASH)
        {
            return Err(bad(format!(
                "`{}` cannot be sent inside a command",
                escape(&[b])
            )));
        }
        if is_rom_command(bytes.len(), bytes[0]) {
            return Err(bad(format!(
                "/{}{} is a ROM command; build it as such",
                bytes.len(),
                char::from(bytes[0])
            )));
        }
        Ok(Extension(bytes))
    }

    /// The command bytes after `/N`, letter first.
    #[must_use]
    pub fn bytes(&self) -> &[u8] {
        &self.0
    }
}

/// Whether the ROM dispatches on this (count, letter) pair.
fn is_rom_command(count: usize, letter: u8) -> bool {
    table::find(count, letter).is_some()
}

/// A memory read `/7Raaaa##`: an address and 0 to 99 bytes that do not run
/// past `$FFFF`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ReadSpan {
    address: u16,
    count: ReadCount,
}

impl ReadSpan {
    /// Checks the count (0 to 99) and that the span ends at or before `$FFFF`.
    ///
    /// # Errors
    /// [`ProtocolError::OutOfRange`] or [`ProtocolError::ReadWraps`].
    pub fn new(address: u16, count: u8) -> Result<Self, ProtocolError> {
        let count = ReadCount::new(count)?;
        if u32::from(address) + u32::from(count.get()) > 0x1_0000 {
            return Err(ProtocolError::ReadWraps {
                address,
                count: count.get(),
            });
        }
        Ok(ReadSpan { address, count })
    }

    /// The first address read.
    #[must_use]
    pub const fn address(self) -> u16 {
        self.address
    }

    /// The number of bytes read.
    #[must_use]
    pub const fn count(self) -> u8 {
        self.count.get()
    }
}

/// A two-byte write `/9Waaaahhhh`: bytes at `address` and `address + 1`,
/// never wrapping past `$FFFF`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct WordWrite {
    address: u16,
    bytes: [u8; 2],
}

impl WordWrite {
    /// Checks that both bytes lie at or below `$FFFF`.
    ///
    /// # Errors
    /// [`ProtocolError::OutOfRange`] for address `$FFFF`.
    pub fn new(address: u16, bytes: [u8; 2]) -> Result<Self, ProtocolError> {
        if address == 0xFFFF {
            return Err(ProtocolError::OutOfRange {
                what: "two-byte write address",
                value: u32::from(address),
                min: 0,
                max: 0xFFFE,
            });
        }
        Ok(WordWrite { address, bytes })
    }

    /// The address of the first byte.
    #[must_use]
    pub const fn address(self) -> u16 {
        self.address
    }

    /// The bytes, in address order (the first goes to `address`).
    #[must_use]
    pub const fn bytes(self) -> [u8; 2] {
        self.bytes
    }
}

/// Every instruction and question of docs/PROTOCOL.md section 2, plus commands
/// for extensions.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Command {
    /// `/1R`: reset to the power-up state.
    Reset,
    /// `/3Yhh`: set the Master I/O byte.
    SetIo(u8),
    /// `/3Zhh`: set the obey mask.
    SetObeyMask(u8),
    /// `/8Cdff####`, `/8Ddff####`: move a motor a number of steps.
    Move {
        /// Which motor.
        motor: Motor,
        /// Which way.
        direction: Direction,
        /// How fast.
        speed: Speed,
        /// How far.
        steps: Steps,
    },
    /// `/4Cdff`, `/4Ddff`: continuous mode (speed 00 stops).
    Continuous {
        /// Which motor.
        motor: Motor,
        /// Which way.
        direction: Direction,
        /// How fast.
        speed: Speed,
    },
    /// `/2E#`: set the eyes.
    SetEyes(Pair),
    /// `/2G#`: tracker lamps on (`true`) or off.
    SetLamps(bool),
    /// `/3Khh`: speaker tone, pitch code (00 off).
    Tone(u8),
    /// `/3H##`, `/3V##`: scan, filling the scanner buffer.
    Scan {
        /// Which scanner.
        axis: Axis,
        /// Steps each side.
        steps: ScanSteps,
    },
    /// `/7Waaaahh`: write one byte.
    WriteByte {
        /// Where.
        address: u16,
        /// What.
        value: u8,
    },
    /// `/9Waaaahhhh`: write two bytes at once (how a hook is switched
    /// atomically).
    WriteWord(WordWrite),
    /// `/1B`: the bumper microswitches.
    Bumpers,
    /// `/1S`: the scanner buffer.
    Scanner,
    /// `/1E`: the eyes.
    Eyes,
    /// `/1G`: the tracker lamps.
    Lamps,
    /// `/1T`: the ground-tracker phototransistors.
    Tracker,
    /// `/1M`: steps moved since the last `/1M` (clears the counts).
    Moves,
    /// `/1X`: the busy byte.
    Busy,
    /// `/7Raaaa##`: read memory.
    ReadMemory(ReadSpan),
    /// `/1C`, `/1D`: steps still to go in a motor's specific move.
    Remaining(Motor),
    /// `/1P`: almost everything at once (clears the move counts).
    Everything,
    /// A command the ROM does not know, for an extension.
    Extension(Extension),
}

fn hex_byte(out: &mut Vec<u8>, value: u8) {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    out.push(DIGITS[usize::from(value >> 4)]);
    out.push(DIGITS[usize::from(value & 0x0F)]);
}

fn hex_word(out: &mut Vec<u8>, value: u16) {
    let [high, low] = value.to_be_bytes();
    hex_byte(out, high);
    hex_byte(out, low);
}

fn decimal(out: &mut Vec<u8>, value: u16, digits: u32) {
    for power in (0..digits).rev() {
        let digit = (value / 10u16.pow(power)) % 10;
        out.push(b'0' + digit as u8);
    }
}

impl Command {
    /// The ROM's entry for this command in [`table::COMMANDS`]; `None` for
    /// an extension's.
    #[must_use]
    pub fn spec(&self) -> Option<&'static CommandSpec> {
        if let Command::Extension(_) = self {
            return None;
        }
        let encoded = self.encode();
        table::find(usize::from(encoded[1] - b'0'), encoded[2])
    }

    /// Whether the ROM answers this command (questions do, instructions do
    /// not). Extension commands may or may not; this says `false` for them,
    /// as the protocol cannot know.
    #[must_use]
    pub fn is_question(&self) -> bool {
        self.spec().is_some_and(CommandSpec::is_question)
    }

    /// The length of the answer in characters, carriage return included,
    /// when the question fixes it (all but `/1S` and extensions).
    #[must_use]
    pub fn answer_len(&self) -> Option<usize> {
        match (self, self.spec()?.reply) {
            (_, Reply::Fixed(len)) => Some(len),
            (Command::ReadMemory(span), Reply::PerByte) => Some(2 + 2 * usize::from(span.count())),
            _ => None,
        }
    }

    /// The exact bytes sent on the line: `/`, the count, the letter and the
    /// fields, upper-case hex.
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut body = Vec::with_capacity(EXTENSION_MAX_LEN);
        match self {
            Command::Reset => body.push(b'R'),
            Command::SetIo(value) => {
                body.push(b'Y');
                hex_byte(&mut body, *value);
            }
            Command::SetObeyMask(value) => {
                body.push(b'Z');
                hex_byte(&mut body, *value);
            }
            Command::Move {
                motor,
                direction,
                speed,
                steps,
            } => {
                body.extend([motor.letter(), direction.sign()]);
                decimal(&mut body, u16::from(speed.get()), 2);
                decimal(&mut body, steps.get(), 4);
            }
            Command::Continuous {
                motor,
                direction,
                speed,
            } => {
                body.extend([motor.letter(), direction.sign()]);
                decimal(&mut body, u16::from(speed.get()), 2);
            }
            Command::SetEyes(pair) => body.extend([b'E', pair.digit()]),
            Command::SetLamps(on) => body.extend([b'G', if *on { b'1' } else { b'0' }]),
            Command::Tone(pitch) => {
                body.push(b'K');
                hex_byte(&mut body, *pitch);
            }
            Command::Scan { axis, steps } => {
                body.push(axis.letter());
                decimal(&mut body, u16::from(steps.get()), 2);
            }
            Command::WriteByte { address, value } => {
                body.push(b'W');
                hex_word(&mut body, *address);
                hex_byte(&mut body, *value);
            }
            Command::WriteWord(write) => {
                body.push(b'W');
                hex_word(&mut body, write.address());
                let [first, second] = write.bytes();
                hex_byte(&mut body, first);
                hex_byte(&mut body, second);
            }
            Command::Bumpers => body.push(b'B'),
            Command::Scanner => body.push(b'S'),
            Command::Eyes => body.push(b'E'),
            Command::Lamps => body.push(b'G'),
            Command::Tracker => body.push(b'T'),
            Command::Moves => body.push(b'M'),
            Command::Busy => body.push(b'X'),
            Command::ReadMemory(span) => {
                body.push(b'R');
                hex_word(&mut body, span.address());
                decimal(&mut body, u16::from(span.count()), 2);
            }
            Command::Remaining(motor) => body.push(motor.letter()),
            Command::Everything => body.push(b'P'),
            Command::Extension(extension) => body.extend_from_slice(extension.bytes()),
        }
        let mut out = Vec::with_capacity(body.len() + 2);
        out.push(SLASH);
        // Every body is 1..=9 bytes: the variants above by construction,
        // extensions by `Extension::new`.
        out.push(b'0' + body.len() as u8);
        out.extend_from_slice(&body);
        out
    }

    /// Parses one command, `/` first, with nothing after it. Hex digits may
    /// be lower case (the ROM accepts them); letters must be upper case.
    ///
    /// # Errors
    /// [`ProtocolError::BadCommand`] naming the character that does not fit,
    /// or a range error from the field types.
    pub fn parse(text: &[u8]) -> Result<Command, ProtocolError> {
        let mut cursor = Cursor::new(text);
        let result = Self::parse_fields(&mut cursor);
        result
            .map_err(|miss| ProtocolError::BadCommand {
                text: escape(text),
                position: miss.position,
                expected: miss.expected,
                found: super::error::describe_at(text, miss.position, "end of command"),
            })
            .and_then(|command| command)
    }

    /// Reads the grammar; the inner result carries range and extension
    /// errors, which are not about a character position.
    fn parse_fields(cursor: &mut Cursor<'_>) -> Result<Result<Command, ProtocolError>, Miss> {
        cursor.literal(SLASH)?;
        let count = usize::from(cursor.decimal(1)?);
        if count == 0 {
            return Err(Miss {
                position: 1,
                expected: "a count from 1 to 9".into(),
            });
        }
        if cursor.remaining() != count {
            return Err(Miss {
                position: 2 + count.min(cursor.remaining()),
                expected: format!("exactly {count} characters after `/{count}`"),
            });
        }
        let letter = cursor.peek().unwrap_or(0);
        if !is_rom_command(count, letter) {
            let body = cursor.bytes[2..].to_vec();
            return Ok(Extension::new(body).map(Command::Extension));
        }
        cursor.position += 1;
        let motor = if letter == b'C' {
            Motor::Left
        } else {
            Motor::Right
        };
        let command = match (count, letter) {
            (1, b'R') => Ok(Command::Reset),
            (1, b'B') => Ok(Command::Bumpers),
            (1, b'S') => Ok(Command::Scanner),
            (1, b'E') => Ok(Command::Eyes),
            (1, b'G') => Ok(Command::Lamps),
            (1, b'T') => Ok(Command::Tracker),
            (1, b'M') => Ok(Command::Moves),
            (1, b'X') => Ok(Command::Busy),
            (1, b'C' | b'D') => Ok(Command::Remaining(motor)),
            (1, b'P') => Ok(Command::Everything),
            (2, b'E') => {
                let digit = cursor.one_of(b"0123", "an eye digit 0-3")?;
                Ok(Command::SetEyes(Pair::from_digit(digit as u8)))
            }
            (2, b'G') => {
                let digit = cursor.one_of(b"01", "a lamp digit 0 or 1")?;
                Ok(Command::SetLamps(digit == 1))
            }
            (3, b'Y') => Ok(Command::SetIo(cursor.hex_byte(true)?)),
            (3, b'Z') => Ok(Command::SetObeyMask(cursor.hex_byte(true)?)),
            (3, b'K') => Ok(Command::Tone(cursor.hex_byte(true)?)),
            (3, b'H' | b'V') => {
                let axis = if letter == b'H' {
                    Axis::Horizontal
                } else {
                    Axis::Vertical
                };
                let steps = cursor.decimal(2)?;
                ScanSteps::new(steps as u8).map(|steps| Command::Scan { axis, steps })
            }
            (4 | 8, b'C' | b'D') => {
                let direction = if cursor.one_of(b"+-", "a direction `+` or `-`")? == 0 {
                    Direction::Plus
                } else {
                    Direction::Minus
                };
                let speed = cursor.decimal(2)?;
                let speed = Speed::new(speed as u8);
                if count == 4 {
                    speed.map(|speed| Command::Continuous {
                        motor,
                        direction,
                        speed,
                    })
                } else {
                    let steps = Steps::new(cursor.decimal(4)?);
                    speed.and_then(|speed| {
                        steps.map(|steps| Command::Move {
                            motor,
                            direction,
                            speed,
                            steps,
                        })
                    })
                }
            }
            (7, b'R') => {
                let address = cursor.hex_word(true)?;
                let count = cursor.decimal(2)?;
                ReadSpan::new(address, count as u8).map(Command::ReadMemory)
            }
            (7, b'W') => {
                let address = cursor.hex_word(true)?;
                let value = cursor.hex_byte(true)?;
                Ok(Command::WriteByte { address, value })
            }
            (9, b'W') => {
                let address = cursor.hex_word(true)?;
                let first = cursor.hex_byte(true)?;
                let second = cursor.hex_byte(true)?;
                WordWrite::new(address, [first, second]).map(Command::WriteWord)
            }
            _ => {
                return Err(Miss {
                    position: 2,
                    expected: "a command letter".into(),
                });
            }
        };
        cursor.end("the end of the command")?;
        Ok(command)
    }

    /// Parses the answer to this question, checking that it is the one
    /// asked for: the right letter, and for `/7R` the right byte count.
    /// An extension's answer is returned as [`Answer::Text`] after a check
    /// that it is printable and ends in a carriage return.
    ///
    /// # Errors
    /// [`ProtocolError::NoAnswerExpected`] for an instruction, a parse error
    /// from [`Answer::parse`], or [`ProtocolError::UnexpectedAnswer`].
    pub fn parse_answer(&self, bytes: &[u8]) -> Result<Answer, ProtocolError> {
        if let Command::Extension(_) = self {
            return Answer::parse_text(bytes);
        }
        if !self.is_question() {
            return Err(ProtocolError::NoAnswerExpected {
                command: self.to_string(),
            });
        }
        let answer = Answer::parse(bytes)?;
        let expected = match (self, &answer) {
            (Command::Bumpers, Answer::Bumpers(_))
            | (Command::Scanner, Answer::Scan(_))
            | (Command::Eyes, Answer::Eyes(_))
            | (Command::Lamps, Answer::Lamps(_))
            | (Command::Tracker, Answer::Tracker(_))
            | (Command::Moves, Answer::Moves(_))
            | (Command::Busy, Answer::Busy(_))
            | (Command::Everything, Answer::Everything(_)) => return Ok(answer),
            (Command::Remaining(asked), Answer::Remaining { motor, .. }) if asked == motor => {
                return Ok(answer);
            }
            (Command::ReadMemory(span), Answer::Memory(data))
                if data.len() == usize::from(span.count()) =>
            {
                return Ok(answer);
            }
            (Command::ReadMemory(span), _) => format!(
                "`R` and {} hex digits ({} bytes)",
                2 * usize::from(span.count()),
                span.count()
            ),
            (Command::Remaining(motor), _) => {
                format!("`{}####`", char::from(motor.letter()))
            }
            _ => {
                let letter = self.encode()[2];
                format!("an answer starting `{}`", char::from(letter))
            }
        };
        Err(ProtocolError::UnexpectedAnswer {
            question: self.to_string(),
            text: escape(bytes),
            expected,
        })
    }
}

impl fmt::Display for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Every encoded byte is printable ASCII.
        f.write_str(&String::from_utf8_lossy(&self.encode()))
    }
}

impl std::str::FromStr for Command {
    type Err = ProtocolError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Command::parse(text.as_bytes())
    }
}
