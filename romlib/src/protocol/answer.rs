//! Answers: every answer form of docs/PROTOCOL.md section 2 parsed into typed
//! structs (and encoded back, for robots modelled in tests).

use super::EOL;
use super::command::{Axis, Direction, Motor, Steps};
use super::cursor::{Cursor, Miss};
use super::error::{ProtocolError, describe_at, escape};
use super::{MAX_READ, MAX_SCAN_BYTES};

/// Two lamps or sensors, left and right, as `E#` and `T#` encode them:
/// `0` none, `1` right only, `2` left only, `3` both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Pair {
    /// The left one is on.
    pub left: bool,
    /// The right one is on.
    pub right: bool,
}

impl Pair {
    /// The ASCII digit for this pair.
    #[must_use]
    pub const fn digit(self) -> u8 {
        b'0' + self.right as u8 + 2 * self.left as u8
    }

    /// The pair for a digit's value, 0 to 3 (higher bits are ignored).
    #[must_use]
    pub const fn from_digit(value: u8) -> Pair {
        Pair {
            left: value & 2 != 0,
            right: value & 1 != 0,
        }
    }
}

/// The bumper microswitches of a `Bhh` answer, one bit each (1 = closed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Bumpers(pub u8);

impl Bumpers {
    /// Whether any switch is closed.
    #[must_use]
    pub const fn any_closed(self) -> bool {
        self.0 != 0
    }
}

/// The busy byte of an `Xhh` answer (docs/PROTOCOL.md section 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct BusyByte(pub u8);

impl BusyByte {
    /// Bit 0: a tone is playing.
    pub const TONE: u8 = 0x01;
    /// Bit 1: an eye is on.
    pub const EYE: u8 = 0x02;
    /// Bit 2: the tracker lamps are on.
    pub const LAMPS: u8 = 0x04;
    /// Bit 3: the horizontal scanner is busy.
    pub const H_SCANNER: u8 = 0x08;
    /// Bit 4: the vertical scanner is busy.
    pub const V_SCANNER: u8 = 0x10;
    /// Bit 5: the left motor is on.
    pub const LEFT_MOTOR: u8 = 0x20;
    /// Bit 6: the right motor is on.
    pub const RIGHT_MOTOR: u8 = 0x40;
    /// Bit 7: any of the above.
    pub const ANY: u8 = 0x80;

    /// Whether every bit of `mask` is set.
    #[must_use]
    pub const fn has(self, mask: u8) -> bool {
        self.0 & mask == mask
    }
}

/// One motor's movement in a `/1M` answer: `s####`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MoveCount {
    /// The direction sign.
    pub direction: Direction,
    /// Steps moved.
    pub steps: Steps,
}

/// Both motors' movement since the last `/1M` or `/1P`: `Ms####s####`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MoveCounts {
    /// The left motor.
    pub left: MoveCount,
    /// The right motor.
    pub right: MoveCount,
}

/// The scanner buffer of a `/1S` answer: `Sd` and 1 to 199 bytes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ScanAnswer {
    /// The direction of the last scan.
    pub axis: Axis,
    /// The buffer, 1 to 199 bytes.
    pub data: Vec<u8>,
}

/// The `/1P` answer: every field of the other questions but the scanner
/// buffer and memory, plus the Master I/O byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Status {
    /// `Bhh`.
    pub bumpers: Bumpers,
    /// `E#`.
    pub eyes: Pair,
    /// `G#`.
    pub lamps: bool,
    /// `T#`.
    pub tracker: Pair,
    /// `Ms####s####`.
    pub moves: MoveCounts,
    /// `Yhh`: the Master I/O byte.
    pub io: u8,
    /// `Xhh`.
    pub busy: BusyByte,
    /// `C####`: steps left in the left motor's specific move.
    pub left_remaining: Steps,
    /// `D####`: steps left in the right motor's specific move.
    pub right_remaining: Steps,
}

/// One answer from the robot, without its carriage return.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Answer {
    /// `Bhh` to `/1B`.
    Bumpers(Bumpers),
    /// `Sd…` to `/1S`.
    Scan(ScanAnswer),
    /// `E#` to `/1E`.
    Eyes(Pair),
    /// `G#` to `/1G`: lamps on.
    Lamps(bool),
    /// `T#` to `/1T`.
    Tracker(Pair),
    /// `Ms####s####` (optionally with a space before the second group) to `/1M`.
    Moves(MoveCounts),
    /// `Xhh` to `/1X`.
    Busy(BusyByte),
    /// `Rhh…` to `/7Raaaa##`: 0 to 99 bytes.
    Memory(Vec<u8>),
    /// `C####` to `/1C`, `D####` to `/1D`.
    Remaining {
        /// Which motor.
        motor: Motor,
        /// Steps still to go.
        steps: Steps,
    },
    /// `P…` to `/1P`.
    Everything(Status),
    /// An extension's answer: printable ASCII, kept as text.
    Text(String),
}

fn push_hex(out: &mut Vec<u8>, value: u8) {
    out.extend(format!("{value:02X}").bytes());
}

fn push_decimal4(out: &mut Vec<u8>, steps: Steps) {
    out.extend(format!("{:04}", steps.get()).bytes());
}

fn push_moves(out: &mut Vec<u8>, moves: &MoveCounts) {
    for count in [moves.left, moves.right] {
        out.push(count.direction.sign());
        push_decimal4(out, count.steps);
    }
}

impl Answer {
    /// The answer's bytes as the ROM sends them, carriage return included
    /// (no space in `/1M` answers).
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        match self {
            Answer::Bumpers(bumpers) => {
                out.push(b'B');
                push_hex(&mut out, bumpers.0);
            }
            Answer::Scan(scan) => {
                out.extend([b'S', scan.axis.letter()]);
                for &byte in &scan.data {
                    push_hex(&mut out, byte);
                }
            }
            Answer::Eyes(pair) => out.extend([b'E', pair.digit()]),
            Answer::Lamps(on) => out.extend([b'G', b'0' + u8::from(*on)]),
            Answer::Tracker(pair) => out.extend([b'T', pair.digit()]),
            Answer::Moves(moves) => {
                out.push(b'M');
                push_moves(&mut out, moves);
            }
            Answer::Busy(busy) => {
                out.push(b'X');
                push_hex(&mut out, busy.0);
            }
            Answer::Memory(data) => {
                out.push(b'R');
                for &byte in data {
                    push_hex(&mut out, byte);
                }
            }
            Answer::Remaining { motor, steps } => {
                out.push(motor.letter());
                push_decimal4(&mut out, *steps);
            }
            Answer::Everything(status) => {
                out.extend(b"PB");
                push_hex(&mut out, status.bumpers.0);
                out.extend([b'E', status.eyes.digit()]);
                out.extend([b'G', b'0' + u8::from(status.lamps)]);
                out.extend([b'T', status.tracker.digit()]);
                out.push(b'M');
                push_moves(&mut out, &status.moves);
                out.push(b'Y');
                push_hex(&mut out, status.io);
                out.push(b'X');
                push_hex(&mut out, status.busy.0);
                out.push(b'C');
                push_decimal4(&mut out, status.left_remaining);
                out.push(b'D');
                push_decimal4(&mut out, status.right_remaining);
            }
            Answer::Text(text) => out.extend(text.bytes()),
        }
        out.push(EOL);
        out
    }

    /// Parses one ROM answer: its bytes up to and including the carriage
    /// return, nothing after it. Hex digits must be upper case (the ROM
    /// always sends upper case).
    ///
    /// # Errors
    /// [`ProtocolError::MalformedAnswer`] naming the form, the character
    /// offset, what was expected and what was found.
    pub fn parse(bytes: &[u8]) -> Result<Answer, ProtocolError> {
        let mut cursor = Cursor::new(bytes);
        let letter = cursor.peek();
        let form = match letter {
            Some(b'B') => "/1B",
            Some(b'S') => "/1S",
            Some(b'E') => "/1E",
            Some(b'G') => "/1G",
            Some(b'T') => "/1T",
            Some(b'M') => "/1M",
            Some(b'X') => "/1X",
            Some(b'R') => "/7R",
            Some(b'C') => "/1C",
            Some(b'D') => "/1D",
            Some(b'P') => "/1P",
            _ => "an",
        };
        parse_fields(&mut cursor).map_err(|miss| ProtocolError::MalformedAnswer {
            form,
            text: escape(bytes),
            position: miss.position,
            expected: miss.expected,
            found: describe_at(bytes, miss.position, "end of answer"),
        })
    }

    /// Parses an extension's answer: printable ASCII up to a final carriage
    /// return.
    ///
    /// # Errors
    /// [`ProtocolError::MalformedAnswer`] at the first byte that is not
    /// printable, or when the carriage return is missing.
    pub fn parse_text(bytes: &[u8]) -> Result<Answer, ProtocolError> {
        let end = bytes.len().saturating_sub(1);
        let bad = bytes[..end]
            .iter()
            .position(|&b| !(0x20..0x7F).contains(&b))
            .or((bytes.last() != Some(&EOL)).then_some(bytes.len()));
        match bad {
            None => Ok(Answer::Text(
                String::from_utf8_lossy(&bytes[..end]).into_owned(),
            )),
            Some(position) => Err(ProtocolError::MalformedAnswer {
                form: "an extension's",
                text: escape(bytes),
                position,
                expected: if position < end {
                    "a printable character".into()
                } else {
                    "the carriage return that ends every answer".into()
                },
                found: describe_at(bytes, position, "end of answer"),
            }),
        }
    }
}

fn pair(cursor: &mut Cursor<'_>, what: &str) -> Result<Pair, Miss> {
    let digit = cursor.one_of(b"0123", what)?;
    Ok(Pair::from_digit(digit as u8))
}

fn lamps(cursor: &mut Cursor<'_>) -> Result<bool, Miss> {
    Ok(cursor.one_of(b"01", "a lamp digit 0 or 1")? == 1)
}

fn steps(cursor: &mut Cursor<'_>) -> Result<Steps, Miss> {
    let value = cursor.decimal(4)?;
    // Four decimal digits are at most 9999, which `Steps` always accepts.
    Ok(Steps::new(value).unwrap_or(Steps::MAX))
}

fn move_count(cursor: &mut Cursor<'_>) -> Result<MoveCount, Miss> {
    let direction = if cursor.one_of(b"+-", "a direction `+` or `-`")? == 0 {
        Direction::Plus
    } else {
        Direction::Minus
    };
    Ok(MoveCount {
        direction,
        steps: steps(cursor)?,
    })
}

fn moves(cursor: &mut Cursor<'_>) -> Result<MoveCounts, Miss> {
    let left = move_count(cursor)?;
    // docs/PROTOCOL.md: hosts accept a space between the two groups.
    cursor.optional(b' ');
    let right = move_count(cursor)?;
    Ok(MoveCounts { left, right })
}

/// Reads hex bytes up to the carriage return.
fn hex_run(cursor: &mut Cursor<'_>, max: usize) -> Result<Vec<u8>, Miss> {
    let mut data = Vec::new();
    while cursor.peek() != Some(EOL) {
        if data.len() == max {
            return Err(Miss {
                position: cursor.position,
                expected: format!("the carriage return after {max} bytes"),
            });
        }
        data.push(cursor.hex_byte(false)?);
    }
    Ok(data)
}

fn parse_fields(cursor: &mut Cursor<'_>) -> Result<Answer, Miss> {
    let letter = cursor.one_of(
        b"BSEGTMXRCDP",
        "an answer letter (B, S, E, G, T, M, X, R, C, D or P)",
    )?;
    let answer = match b"BSEGTMXRCDP"[letter] {
        b'B' => Answer::Bumpers(Bumpers(cursor.hex_byte(false)?)),
        b'S' => {
            let axis = if cursor.one_of(b"HV", "a scan direction `H` or `V`")? == 0 {
                Axis::Horizontal
            } else {
                Axis::Vertical
            };
            let data = hex_run(cursor, MAX_SCAN_BYTES)?;
            if data.is_empty() {
                return Err(Miss {
                    position: cursor.position,
                    expected: "at least one scanner byte".into(),
                });
            }
            Answer::Scan(ScanAnswer { axis, data })
        }
        b'E' => Answer::Eyes(pair(cursor, "an eye digit 0-3")?),
        b'G' => Answer::Lamps(lamps(cursor)?),
        b'T' => Answer::Tracker(pair(cursor, "a tracker digit 0-3")?),
        b'M' => Answer::Moves(moves(cursor)?),
        b'X' => Answer::Busy(BusyByte(cursor.hex_byte(false)?)),
        b'R' => Answer::Memory(hex_run(cursor, usize::from(MAX_READ))?),
        b'C' => Answer::Remaining {
            motor: Motor::Left,
            steps: steps(cursor)?,
        },
        b'D' => Answer::Remaining {
            motor: Motor::Right,
            steps: steps(cursor)?,
        },
        _ => {
            cursor.literal(b'B')?;
            let bumpers = Bumpers(cursor.hex_byte(false)?);
            cursor.literal(b'E')?;
            let eyes = pair(cursor, "an eye digit 0-3")?;
            cursor.literal(b'G')?;
            let lamps = lamps(cursor)?;
            cursor.literal(b'T')?;
            let tracker = pair(cursor, "a tracker digit 0-3")?;
            cursor.literal(b'M')?;
            let moves = moves(cursor)?;
            cursor.literal(b'Y')?;
            let io = cursor.hex_byte(false)?;
            cursor.literal(b'X')?;
            let busy = BusyByte(cursor.hex_byte(false)?);
            cursor.literal(b'C')?;
            let left_remaining = steps(cursor)?;
            cursor.literal(b'D')?;
            let right_remaining = steps(cursor)?;
            Answer::Everything(Status {
                bumpers,
                eyes,
                lamps,
                tracker,
                moves,
                io,
                busy,
                left_remaining,
                right_remaining,
            })
        }
    };
    cursor.literal(EOL).map_err(|miss| Miss {
        expected: "the carriage return that ends every answer".into(),
        ..miss
    })?;
    cursor.end("nothing after the carriage return")?;
    Ok(answer)
}
