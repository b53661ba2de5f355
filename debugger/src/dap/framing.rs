//! The Debug Adapter Protocol's base protocol: each message is a header
//! block (`Content-Length: N`, other headers, a blank line; lines end in
//! CRLF) and N bytes of JSON, with nothing between messages.
//!
//! What comes in is bounded: a header line is at most [`MAX_HEADER_LINE`]
//! bytes and a body at most [`MAX_BODY`]; anything else (a longer line, a
//! larger or unreadable length, bytes outside a message) is a
//! [`FrameError`] and the reader goes on with the next message it finds,
//! so one bad message never ends a session nor takes more memory than
//! those bounds. What goes out is framed exactly: the header, the blank
//! line, the body, and not a byte more.

use std::io::{BufRead, Read, Write};

/// The longest header line taken, in bytes (without its line end).
pub const MAX_HEADER_LINE: usize = 1024;

/// The largest body taken, in bytes: far above any request an editor
/// sends (breakpoints for a whole file fit in a few kilobytes).
pub const MAX_BODY: u64 = 4 << 20;

/// The largest body skipped to keep in step with the messages after it;
/// a larger length is taken as a lie (or garbage), and the reader looks
/// for the next `Content-Length:` instead.
const MAX_SKIP: u64 = 64 << 20;

/// How much of a body too large to take is kept, to answer its request.
pub const HEAD: u64 = 4096;

/// The header that frames a message.
const CONTENT_LENGTH: &[u8] = b"Content-Length:";

/// Why a message could not be read; the reader has gone past it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// A header line longer than [`MAX_HEADER_LINE`].
    #[error("a header line longer than {MAX_HEADER_LINE} bytes")]
    HeaderTooLong,
    /// A `Content-Length` that is not a number of bytes.
    #[error("`Content-Length: {found}` is not a number of bytes")]
    BadLength {
        /// The value as sent (its first bytes).
        found: String,
    },
    /// A header block that ended without a `Content-Length`.
    #[error("a message's headers end without a `Content-Length`")]
    NoLength,
    /// A body larger than [`MAX_BODY`].
    #[error("a message of {length} bytes: at most {MAX_BODY} are taken")]
    TooLarge {
        /// Its `Content-Length`.
        length: u64,
        /// Its first bytes (at most [`HEAD`]), where its `seq` and
        /// `command` usually are: read when the body is skipped, so that the
        /// request can still be answered.
        head: Vec<u8>,
    },
    /// Bytes where a header should be: a message longer than its
    /// `Content-Length` said, or not framed at all.
    #[error("bytes outside any message: `{found}`")]
    Outside {
        /// The first of them.
        found: String,
    },
    /// The input ended inside a message.
    #[error("the input ended inside a message")]
    Truncated,
}

/// One line of a header block, as read.
enum HeaderLine {
    /// A line (without its line end).
    Line(Vec<u8>),
    /// A line longer than [`MAX_HEADER_LINE`]; its rest was not read.
    TooLong,
    /// The end of the input before any byte of the line.
    End,
}

/// Reads messages from a stream of the base protocol.
#[derive(Debug)]
pub struct FrameReader<R> {
    input: R,
    /// After an error that lost the message's bounds: look for the next
    /// `Content-Length:` before anything else.
    lost: bool,
    /// A header line found inside a line of garbage, to read next.
    pending: Option<Vec<u8>>,
    /// The input ended.
    ended: bool,
}

impl<R: BufRead> FrameReader<R> {
    /// Reads messages from `input`.
    pub fn new(input: R) -> FrameReader<R> {
        FrameReader {
            input,
            lost: false,
            pending: None,
            ended: false,
        }
    }

    /// The next message's body; an error for a message that could not be
    /// read (the next call goes on after it); `None` at the end of the
    /// input.
    ///
    /// # Errors
    /// The input's own read errors.
    pub fn next_message(&mut self) -> std::io::Result<Option<Result<Vec<u8>, FrameError>>> {
        if self.ended {
            return Ok(None);
        }
        if std::mem::take(&mut self.lost) {
            if !self.skip_past(CONTENT_LENGTH)? {
                self.ended = true;
                return Ok(None);
            }
            let mut line = CONTENT_LENGTH.to_vec();
            match self.header_line()? {
                HeaderLine::Line(rest) => line.extend(rest),
                HeaderLine::TooLong => return Ok(Some(self.lose(FrameError::HeaderTooLong))),
                HeaderLine::End => return Ok(self.truncated()),
            }
            self.pending = Some(line);
        }
        let mut length = None;
        let mut headers = 0;
        loop {
            let line = match self.pending.take() {
                Some(line) => line,
                None => match self.header_line()? {
                    HeaderLine::Line(line) => line,
                    HeaderLine::TooLong => return Ok(Some(self.lose(FrameError::HeaderTooLong))),
                    HeaderLine::End if headers == 0 => {
                        self.ended = true;
                        return Ok(None);
                    }
                    HeaderLine::End => return Ok(self.truncated()),
                },
            };
            if line.is_empty() {
                match length {
                    Some(length) => return self.body(length).map(Some),
                    // A blank line between messages (some servers write
                    // one after each) frames nothing: passed over.
                    None if headers == 0 => continue,
                    None => return Ok(Some(self.lose(FrameError::NoLength))),
                }
            }
            headers += 1;
            if let Some(value) = strip_prefix_ignore_case(&line, CONTENT_LENGTH) {
                let text = String::from_utf8_lossy(value).trim().to_owned();
                let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
                match text.parse::<u64>() {
                    Ok(n) if digits => length = Some(n),
                    // All digits but beyond u64: larger than anything taken.
                    Err(_) if digits => length = Some(u64::MAX),
                    _ => {
                        return Ok(Some(self.lose(FrameError::BadLength {
                            found: shown(text.as_bytes()),
                        })));
                    }
                }
            } else if !is_header(&line) {
                // Garbage; if a message's header starts inside it (after
                // a body longer than its length said), read on from there.
                let found = shown(&line);
                match find(&line, CONTENT_LENGTH) {
                    Some(at) => self.pending = Some(line[at..].to_vec()),
                    None => self.lost = true,
                }
                return Ok(Some(Err(FrameError::Outside { found })));
            }
        }
    }

    /// The body of `length` bytes (or the error for one too large, skipped
    /// when that keeps the reader in step).
    fn body(&mut self, length: u64) -> std::io::Result<Result<Vec<u8>, FrameError>> {
        if length > MAX_BODY {
            let mut head = Vec::new();
            if length <= MAX_SKIP {
                let read = (&mut self.input).take(HEAD).read_to_end(&mut head)? as u64;
                let skipped = read
                    + std::io::copy(
                        &mut (&mut self.input).take(length - read),
                        &mut std::io::sink(),
                    )?;
                if skipped < length {
                    self.ended = true;
                }
            } else {
                self.lost = true;
            }
            return Ok(Err(FrameError::TooLarge { length, head }));
        }
        // Bounded by MAX_BODY, so the conversion holds.
        let mut body = Vec::with_capacity(usize::try_from(length).unwrap_or(0));
        let read = (&mut self.input).take(length).read_to_end(&mut body)?;
        if (read as u64) < length {
            self.ended = true;
            return Ok(Err(FrameError::Truncated));
        }
        Ok(Ok(body))
    }

    /// A header line, its length bounded.
    fn header_line(&mut self) -> std::io::Result<HeaderLine> {
        let mut line = Vec::new();
        let limit = MAX_HEADER_LINE as u64 + 2;
        let read = (&mut self.input).take(limit).read_until(b'\n', &mut line)?;
        if read == 0 {
            return Ok(HeaderLine::End);
        }
        if line.last() != Some(&b'\n') {
            if line.len() as u64 >= limit {
                return Ok(HeaderLine::TooLong);
            }
            // The input ended inside the line: taken as it is.
        } else {
            line.pop();
        }
        if line.last() == Some(&b'\r') {
            line.pop();
        }
        if line.len() > MAX_HEADER_LINE {
            return Ok(HeaderLine::TooLong);
        }
        Ok(HeaderLine::Line(line))
    }

    /// Reads past the next `pattern`; false if the input ends first.
    fn skip_past(&mut self, pattern: &[u8]) -> std::io::Result<bool> {
        let mut matched = 0;
        loop {
            let buffer = match self.input.fill_buf() {
                Ok(buffer) => buffer,
                Err(error) if error.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(error) => return Err(error),
            };
            if buffer.is_empty() {
                return Ok(false);
            }
            let mut used = 0;
            let mut found = false;
            for &byte in buffer {
                used += 1;
                // The pattern's first byte occurs nowhere else in it, so a
                // failed match starts again at this byte or the next.
                matched = if byte == pattern[matched] {
                    matched + 1
                } else {
                    usize::from(byte == pattern[0])
                };
                if matched == pattern.len() {
                    found = true;
                    break;
                }
            }
            self.input.consume(used);
            if found {
                return Ok(true);
            }
        }
    }

    /// `error`, the message's bounds lost: look for the next one.
    fn lose(&mut self, error: FrameError) -> Result<Vec<u8>, FrameError> {
        self.lost = true;
        Err(error)
    }

    fn truncated(&mut self) -> Option<Result<Vec<u8>, FrameError>> {
        self.ended = true;
        Some(Err(FrameError::Truncated))
    }
}

/// `body` framed as one message, written and flushed.
///
/// # Errors
/// The output's write errors.
pub fn write_message(out: &mut impl Write, body: &[u8]) -> std::io::Result<()> {
    write!(out, "Content-Length: {}\r\n\r\n", body.len())?;
    out.write_all(body)?;
    out.flush()
}

/// A header line's shape: a token, a colon, a value.
fn is_header(line: &[u8]) -> bool {
    let Some(colon) = line.iter().position(|&b| b == b':') else {
        return false;
    };
    colon > 0
        && line[..colon]
            .iter()
            .all(|&b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
}

fn strip_prefix_ignore_case<'a>(line: &'a [u8], prefix: &[u8]) -> Option<&'a [u8]> {
    (line.len() >= prefix.len() && line[..prefix.len()].eq_ignore_ascii_case(prefix))
        .then(|| &line[prefix.len()..])
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// The first bytes of `bytes`, for an error.
fn shown(bytes: &[u8]) -> String {
    const SHOWN: usize = 40;
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(SHOWN)]).into_owned();
    if bytes.len() > SHOWN {
        format!("{text}...")
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{body}", body.len())
    }

    /// Everything read from `input`: bodies as text, errors.
    fn read_all(input: &[u8]) -> Vec<Result<String, FrameError>> {
        let mut reader = FrameReader::new(input);
        let mut all = Vec::new();
        while let Some(message) = reader.next_message().expect("a slice reads") {
            all.push(message.map(|body| String::from_utf8_lossy(&body).into_owned()));
            assert!(all.len() < 10_000, "the reader goes on for ever");
        }
        all
    }

    #[test]
    fn messages_back_to_back_other_headers_and_blank_lines_between() {
        let input = format!(
            "{}Content-Type: application/vscode-jsonrpc; charset=utf-8\r\n{}\r\n{}",
            frame("{\"a\":1}"),
            frame("{\"b\":2}"),
            frame("{}")
        );
        assert_eq!(
            read_all(input.as_bytes()),
            vec![
                Ok("{\"a\":1}".to_owned()),
                Ok("{\"b\":2}".to_owned()),
                Ok("{}".to_owned())
            ]
        );
    }

    #[test]
    fn written_messages_are_exactly_their_frame() {
        let mut out = Vec::new();
        write_message(&mut out, b"{\"seq\":1}").expect("writes");
        write_message(&mut out, b"{}").expect("writes");
        assert_eq!(
            String::from_utf8_lossy(&out),
            "Content-Length: 9\r\n\r\n{\"seq\":1}Content-Length: 2\r\n\r\n{}"
        );
    }

    /// Issue 23, item 7: the lengths that panicked or aborted the old reader.
    #[test]
    fn huge_lengths_are_errors_and_the_next_message_is_read() {
        for length in [
            "18446744073709551615",
            "99999999999",
            "184467440737095516150000",
        ] {
            let input = format!(
                "Content-Length: {length}\r\n\r\n{{}}{}",
                frame("{\"ok\":1}")
            );
            let all = read_all(input.as_bytes());
            assert!(
                matches!(all[0], Err(FrameError::TooLarge { .. })),
                "{length}: {all:?}"
            );
            assert_eq!(all.last(), Some(&Ok("{\"ok\":1}".to_owned())), "{length}");
        }
    }

    #[test]
    fn a_large_body_is_skipped_whole() {
        let body = "x".repeat(usize::try_from(MAX_BODY).expect("fits") + 10);
        let input = format!("{}{}", frame(&body), frame("{}"));
        assert_eq!(
            read_all(input.as_bytes()),
            vec![
                Err(FrameError::TooLarge {
                    length: MAX_BODY + 10,
                    head: b"x".repeat(4096),
                }),
                Ok("{}".to_owned())
            ]
        );
    }

    /// Issue 23, item 8: a length shorter than the body.
    #[test]
    fn a_body_longer_than_its_length_and_the_next_message() {
        let input = format!(
            "Content-Length: 5\r\n\r\n{{\"seq\":1}}{}",
            frame("{\"seq\":2}")
        );
        let all = read_all(input.as_bytes());
        assert_eq!(all[0], Ok("{\"seq".to_owned()));
        assert!(matches!(all[1], Err(FrameError::Outside { .. })), "{all:?}");
        assert_eq!(all[2], Ok("{\"seq\":2}".to_owned()));
        assert_eq!(all.len(), 3);
    }

    #[test]
    fn bad_headers_are_errors_and_the_next_message_is_read() {
        type Expected = fn(&FrameError) -> bool;
        let cases: [(&str, Expected); 5] = [
            ("Content-Length: -4\r\n\r\n{}", |e| {
                matches!(e, FrameError::BadLength { .. })
            }),
            ("Content-Length: 0x10\r\n\r\n{}", |e| {
                matches!(e, FrameError::BadLength { .. })
            }),
            ("Content-Type: x\r\n\r\n{}", |e| *e == FrameError::NoLength),
            ("hello there\r\n", |e| {
                matches!(e, FrameError::Outside { .. })
            }),
            ("X-Long: \r\n", |_| true),
        ];
        for (bad, expected) in cases {
            let input = format!("{bad}{}", frame("{\"ok\":1}"));
            let all = read_all(input.as_bytes());
            if bad.starts_with("X-Long") {
                assert_eq!(all, vec![Ok("{\"ok\":1}".to_owned())], "{bad}");
                continue;
            }
            assert!(all[0].as_ref().is_err_and(expected), "{bad:?}: {all:?}");
            assert_eq!(all.last(), Some(&Ok("{\"ok\":1}".to_owned())), "{bad:?}");
            assert_eq!(all.len(), 2, "one error per bad message: {bad:?}: {all:?}");
        }
    }

    #[test]
    fn a_header_line_too_long_is_an_error_and_the_next_message_is_read() {
        let long = format!("X-Padding: {}\r\n\r\n", "y".repeat(100_000));
        let input = format!("{long}{}", frame("{\"ok\":1}"));
        let all = read_all(input.as_bytes());
        assert_eq!(all[0], Err(FrameError::HeaderTooLong));
        assert_eq!(all.last(), Some(&Ok("{\"ok\":1}".to_owned())));
    }

    #[test]
    fn the_input_ending_inside_a_message_is_said_once() {
        for cut in ["Content-Length: 10\r\n\r\n{\"a", "Content-Length: 10\r\n"] {
            let all = read_all(cut.as_bytes());
            assert_eq!(all, vec![Err(FrameError::Truncated)], "{cut:?}");
        }
        let all = read_all(b"Content-Len");
        assert!(
            matches!(all[..], [Err(FrameError::Outside { .. })]),
            "{all:?}"
        );
        assert_eq!(read_all(b""), vec![]);
        assert_eq!(read_all(b"\r\n\r\n"), vec![]);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        /// Any bytes: the reader ends, each message at most MAX_BODY.
        #[test]
        fn any_bytes_end_with_bounded_messages(input in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..2000)) {
            for message in read_all(&input).into_iter().flatten() {
                proptest::prop_assert!(message.len() as u64 <= MAX_BODY);
            }
        }

        /// Garbage of a few kinds, then a message: the message is read.
        #[test]
        fn after_garbage_the_next_message_is_read(
            garbage in "(Content-Length: [0-9]{0,25}\r\n|[a-z :]{0,40}\r?\n|\r\n|\\{\"seq\":[0-9]\\}){0,6}",
            body in "\\{\"seq\":[0-9]{1,5}\\}",
        ) {
            let input = format!("{garbage}\r\n\r\n{}", frame(&body));
            let all = read_all(input.as_bytes());
            // A garbage length may swallow the message; never more than it.
            let found = all.iter().any(|m| m.as_ref().is_ok_and(|m| *m == body))
                || garbage.contains("Content-Length");
            proptest::prop_assert!(found, "{:?}", all);
        }

        /// Well-framed messages, each read exactly as written.
        #[test]
        fn framed_messages_come_back_exactly(bodies in proptest::collection::vec("\\PC{0,60}", 0..8)) {
            let mut out = Vec::new();
            for body in &bodies {
                write_message(&mut out, body.as_bytes()).expect("writes");
            }
            let all: Vec<_> = read_all(&out);
            let expected: Vec<Result<String, FrameError>> = bodies.into_iter().map(Ok).collect();
            proptest::prop_assert_eq!(all, expected);
        }
    }
}
