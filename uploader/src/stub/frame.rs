//! The stub's framing (docs/PROTOCOL.md, section 5): frames to the stub
//! in hex digits after [`SOF_IN`], frames from it in binary after
//! [`SOF_OUT`]; in both a length, the payload and a sum that brings the
//! three to zero mod 256. Neither start byte is ASCII, so no command or
//! answer of the protocol holds one.

/// Starts a frame from the stub.
pub const SOF_OUT: u8 = 0xF0;

/// Starts a frame to the stub.
pub const SOF_IN: u8 = 0xF1;

/// The longest payload the stub takes (`BUFLEN` in `stub.s`).
pub const IN_MAX: usize = 40;

/// A frame to the stub carrying `payload` (1 to [`IN_MAX`] bytes):
/// [`SOF_IN`], then the length, the payload and the sum, each byte as two
/// upper-case hex digits (so a frame never holds a slash, and a robot not
/// stopped ignores it whole).
#[must_use]
pub fn encode(payload: &[u8]) -> Vec<u8> {
    let len = payload.len() as u8;
    let sum = payload
        .iter()
        .fold(len, |sum, &b| sum.wrapping_add(b))
        .wrapping_neg();
    let mut out = vec![SOF_IN];
    for byte in std::iter::once(len)
        .chain(payload.iter().copied())
        .chain(std::iter::once(sum))
    {
        out.extend_from_slice(format!("{byte:02X}").as_bytes());
    }
    out
}

/// What the line brought, read from the front of a buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Heard {
    /// A frame from the stub with a good sum: its payload.
    Frame(Vec<u8>),
    /// A frame whose sum is wrong: its bytes as they came.
    BadFrame(Vec<u8>),
    /// A line of text through its carriage return (an answer of the ROM
    /// or an extension).
    Text(Vec<u8>),
}

/// Takes the next whole frame or answer from the front of `rx`: `None`
/// while it is not all there.
pub fn take(rx: &mut Vec<u8>) -> Option<Heard> {
    let first = *rx.first()?;
    if first == SOF_OUT {
        let len = usize::from(*rx.get(1)?);
        if rx.len() < len + 3 {
            return None;
        }
        let bytes: Vec<u8> = rx.drain(..len + 3).collect();
        let sum = bytes[1..].iter().fold(0u8, |sum, &b| sum.wrapping_add(b));
        return Some(if sum == 0 {
            Heard::Frame(bytes[2..2 + len].to_vec())
        } else {
            Heard::BadFrame(bytes)
        });
    }
    // Text runs to its carriage return, or to a frame's start (the answer
    // lost its end).
    let end = rx.iter().position(|&b| b == b'\r' || b == SOF_OUT)?;
    if rx[end] == SOF_OUT {
        return Some(Heard::Text(rx.drain(..end).collect()));
    }
    Some(Heard::Text(rx.drain(..=end).collect()))
}
