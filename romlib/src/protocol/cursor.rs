//! A byte cursor shared by the command and answer parsers: each read names
//! what it expected, so a failure becomes an error with the offset.

/// A failed read: where, and what was wanted there.
#[derive(Debug)]
pub(crate) struct Miss {
    pub(crate) position: usize,
    pub(crate) expected: String,
}

/// Reads fields left to right from one command or answer.
#[derive(Debug)]
pub(crate) struct Cursor<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) position: usize,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Cursor { bytes, position: 0 }
    }

    fn miss<T>(&self, expected: impl Into<String>) -> Result<T, Miss> {
        Err(Miss {
            position: self.position,
            expected: expected.into(),
        })
    }

    pub(crate) fn peek(&self) -> Option<u8> {
        self.bytes.get(self.position).copied()
    }

    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len() - self.position
    }

    /// Takes one byte equal to `want`.
    pub(crate) fn literal(&mut self, want: u8) -> Result<(), Miss> {
        if self.peek() == Some(want) {
            self.position += 1;
            Ok(())
        } else {
            self.miss(format!("`{}`", want.escape_ascii()))
        }
    }

    /// Takes one byte if it is `want`; reports whether it did.
    pub(crate) fn optional(&mut self, want: u8) -> bool {
        let found = self.peek() == Some(want);
        if found {
            self.position += 1;
        }
        found
    }

    /// Takes one of `choices`, returning its index.
    pub(crate) fn one_of(&mut self, choices: &[u8], expected: &str) -> Result<usize, Miss> {
        match self
            .peek()
            .and_then(|b| choices.iter().position(|&c| c == b))
        {
            Some(index) => {
                self.position += 1;
                Ok(index)
            }
            None => self.miss(expected),
        }
    }

    /// Takes one hex digit; lower case only when `lower_ok` (the ROM accepts
    /// it on input, but always sends upper case).
    fn hex_digit(&mut self, lower_ok: bool) -> Result<u8, Miss> {
        let value = match self.peek() {
            Some(b @ b'0'..=b'9') => b - b'0',
            Some(b @ b'A'..=b'F') => b - b'A' + 10,
            Some(b @ b'a'..=b'f') if lower_ok => b - b'a' + 10,
            _ => {
                return self.miss(if lower_ok {
                    "a hex digit"
                } else {
                    "an upper-case hex digit"
                });
            }
        };
        self.position += 1;
        Ok(value)
    }

    /// Takes two hex digits as one byte.
    pub(crate) fn hex_byte(&mut self, lower_ok: bool) -> Result<u8, Miss> {
        let high = self.hex_digit(lower_ok)?;
        let low = self.hex_digit(lower_ok)?;
        Ok(high << 4 | low)
    }

    /// Takes four hex digits as an address.
    pub(crate) fn hex_word(&mut self, lower_ok: bool) -> Result<u16, Miss> {
        let high = self.hex_byte(lower_ok)?;
        let low = self.hex_byte(lower_ok)?;
        Ok(u16::from_be_bytes([high, low]))
    }

    /// Takes exactly `digits` decimal digits.
    pub(crate) fn decimal(&mut self, digits: usize) -> Result<u16, Miss> {
        let mut value = 0u16;
        for _ in 0..digits {
            match self.peek() {
                Some(b @ b'0'..=b'9') => {
                    value = value * 10 + u16::from(b - b'0');
                    self.position += 1;
                }
                _ => return self.miss("a decimal digit"),
            }
        }
        Ok(value)
    }

    /// Fails unless every byte has been read.
    pub(crate) fn end(&self, expected: &str) -> Result<(), Miss> {
        if self.remaining() == 0 {
            Ok(())
        } else {
            self.miss(expected)
        }
    }
}
