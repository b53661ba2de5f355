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

/// The most bytes the host asks the stub for in one read.
pub const READ_MAX: usize = 64;

/// The longest payload from the stub: `M`, the address and a read of
/// [`READ_MAX`] bytes (a stop is 8, a NAK 1). Each starts with `M`, `S`
/// or `N`, all above it: a frame whose length byte was lost claims more,
/// and is taken for noise at once rather than waited for while it
/// swallows the frames after it (hostile10 F13).
pub const OUT_MAX: usize = 3 + READ_MAX;

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
        if len == 0 || len > OUT_MAX {
            return Some(Heard::BadFrame(rx.drain(..1).collect()));
        }
        if rx.len() < len + 3 {
            return None;
        }
        let sum = rx[1..len + 3]
            .iter()
            .fold(0u8, |sum, &b| sum.wrapping_add(b));
        if sum == 0 {
            let bytes: Vec<u8> = rx.drain(..len + 3).collect();
            return Some(Heard::Frame(bytes[2..2 + len].to_vec()));
        }
        // A byte lost here made this frame take in the start of the next:
        // that one is read from its own start.
        let cut = rx[1..len + 3]
            .iter()
            .position(|&b| b == SOF_OUT)
            .map_or(len + 3, |at| at + 1);
        return Some(Heard::BadFrame(rx.drain(..cut).collect()));
    }
    // Text runs to its carriage return, or to a frame's start (the answer
    // lost its end).
    let end = rx.iter().position(|&b| b == b'\r' || b == SOF_OUT)?;
    if rx[end] == SOF_OUT {
        return Some(Heard::Text(rx.drain(..end).collect()));
    }
    Some(Heard::Text(rx.drain(..=end).collect()))
}

/// Gives up a frame at the front of `rx` that has not come whole (the
/// host asks again: it never will). Its length byte may have been changed
/// by noise into a larger one, and it would wait for the replies after it
/// and swallow them (the noisy-line run of seed 60). What follows its
/// start is read from the next frame's start. Returns the bytes given up.
pub fn give_up_incomplete(rx: &mut Vec<u8>) -> Vec<u8> {
    if rx.first() != Some(&SOF_OUT) {
        return Vec::new();
    }
    let whole = rx
        .get(1)
        .is_some_and(|&len| rx.len() >= usize::from(len) + 3);
    if whole {
        return Vec::new();
    }
    let cut = rx[1..]
        .iter()
        .position(|&b| b == SOF_OUT)
        .map_or(rx.len(), |at| at + 1);
    rx.drain(..cut).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `M`, $0418 and one byte ($42), as the stub sends it.
    fn reply() -> Vec<u8> {
        let payload = [b'M', 0x18, 0x04, 0x42];
        let sum = payload
            .iter()
            .fold(4u8, |sum, &b| sum.wrapping_add(b))
            .wrapping_neg();
        let mut frame = vec![SOF_OUT, 4];
        frame.extend_from_slice(&payload);
        frame.push(sum);
        frame
    }

    fn heard(mut rx: Vec<u8>) -> Vec<Heard> {
        std::iter::from_fn(|| take(&mut rx)).collect()
    }

    #[test]
    fn a_whole_frame_and_an_answer_are_told_apart() {
        let mut rx = reply();
        rx.extend_from_slice(b"Q42\r");
        assert_eq!(
            heard(rx),
            [
                Heard::Frame(vec![b'M', 0x18, 0x04, 0x42]),
                Heard::Text(b"Q42\r".to_vec())
            ]
        );
    }

    /// hostile10 F13: a frame that lost a byte swallowed the next ones.
    /// Its length byte lost, `M` (77) was taken for the length and the
    /// replies to the next ten requests went waiting for 80 bytes; a byte
    /// lost inside, its sum took the next frame's start.
    #[test]
    fn a_frame_that_lost_a_byte_does_not_swallow_the_next() {
        for lost in [1, 4] {
            let mut rx = reply();
            rx.remove(lost);
            rx.extend(reply());
            let heard = heard(rx);
            assert_eq!(
                heard.last(),
                Some(&Heard::Frame(vec![b'M', 0x18, 0x04, 0x42])),
                "byte {lost} lost: {heard:?}"
            );
        }
    }
}
