//! Little-endian readers and writers shared by the metadata sections.

use core::fmt;

/// A metadata section that does not decode.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormatError {
    /// Which section (its ELF name).
    pub section: &'static str,
    /// Byte offset inside the section where decoding failed.
    pub offset: usize,
    /// What was wrong.
    pub reason: String,
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "malformed {} section at byte {}: {}",
            self.section, self.offset, self.reason
        )
    }
}

impl std::error::Error for FormatError {}

pub(crate) struct Reader<'a> {
    section: &'static str,
    bytes: &'a [u8],
    offset: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(section: &'static str, bytes: &'a [u8]) -> Reader<'a> {
        Reader {
            section,
            bytes,
            offset: 0,
        }
    }

    pub(crate) fn error(&self, reason: impl Into<String>) -> FormatError {
        FormatError {
            section: self.section,
            offset: self.offset,
            reason: reason.into(),
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.offset >= self.bytes.len()
    }

    pub(crate) fn take(&mut self, count: usize) -> Result<&'a [u8], FormatError> {
        let end = self
            .offset
            .checked_add(count)
            .filter(|end| *end <= self.bytes.len())
            .ok_or_else(|| self.error(format!("{count} bytes needed, section ends first")))?;
        let slice = &self.bytes[self.offset..end];
        self.offset = end;
        Ok(slice)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, FormatError> {
        Ok(self.take(1)?[0])
    }

    pub(crate) fn u16(&mut self) -> Result<u16, FormatError> {
        let bytes = self.take(2)?;
        Ok(u16::from_le_bytes([bytes[0], bytes[1]]))
    }

    pub(crate) fn u32(&mut self) -> Result<u32, FormatError> {
        let bytes = self.take(4)?;
        Ok(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
    }

    pub(crate) fn i64(&mut self) -> Result<i64, FormatError> {
        let bytes = self.take(8)?;
        let mut array = [0u8; 8];
        array.copy_from_slice(bytes);
        Ok(i64::from_le_bytes(array))
    }

    pub(crate) fn string(&mut self) -> Result<String, FormatError> {
        let len = self.u32()? as usize;
        let start = self.offset;
        let bytes = self.take(len)?;
        String::from_utf8(bytes.to_vec()).map_err(|_| FormatError {
            section: self.section,
            offset: start,
            reason: "string is not UTF-8".into(),
        })
    }

    /// A count of records that each take at least `min_size` bytes: refuses
    /// counts the rest of the section cannot hold, so a corrupt count cannot
    /// make the decoder allocate gigabytes.
    pub(crate) fn count(&mut self, min_size: usize) -> Result<usize, FormatError> {
        let count = self.u32()? as usize;
        let remaining = self.bytes.len() - self.offset;
        if count.saturating_mul(min_size.max(1)) > remaining {
            return Err(self.error(format!(
                "count {count} does not fit in the {remaining} bytes left"
            )));
        }
        Ok(count)
    }

    pub(crate) fn header(&mut self, magic: &[u8; 4], version: u8) -> Result<(), FormatError> {
        self.header_versions(magic, version..=version).map(|_| ())
    }

    /// The header of a format read in any of `versions`; the version found.
    pub(crate) fn header_versions(
        &mut self,
        magic: &[u8; 4],
        versions: std::ops::RangeInclusive<u8>,
    ) -> Result<u8, FormatError> {
        if self.take(4)? != magic {
            return Err(FormatError {
                section: self.section,
                offset: 0,
                reason: format!("bad magic (expected {:?})", String::from_utf8_lossy(magic)),
            });
        }
        let found = self.u8()?;
        if !versions.contains(&found) {
            let expected = match versions.start() == versions.end() {
                true => versions.start().to_string(),
                false => format!("{} to {}", versions.start(), versions.end()),
            };
            return Err(self.error(format!(
                "version {found} is not supported (expected {expected})"
            )));
        }
        Ok(found)
    }
}

#[derive(Default)]
pub(crate) struct Writer {
    pub(crate) bytes: Vec<u8>,
}

impl Writer {
    pub(crate) fn header(magic: &[u8; 4], version: u8) -> Writer {
        let mut writer = Writer::default();
        writer.bytes.extend_from_slice(magic);
        writer.u8(version);
        writer
    }

    pub(crate) fn u8(&mut self, value: u8) {
        self.bytes.push(value);
    }

    pub(crate) fn u16(&mut self, value: u16) {
        self.bytes.extend_from_slice(&value.to_le_bytes());
    }

    pub(crate) fn u32(&mut self, value: u32) {
        self.bytes.extend_from_slice(&value.to_le_bytes());
    }

    pub(crate) fn i64(&mut self, value: i64) {
        self.bytes.extend_from_slice(&value.to_le_bytes());
    }

    pub(crate) fn len32(&mut self, len: usize) {
        // Metadata sections are far below 4 GiB; saturate rather than wrap.
        self.u32(u32::try_from(len).unwrap_or(u32::MAX));
    }

    pub(crate) fn string(&mut self, text: &str) {
        self.len32(text.len());
        self.bytes.extend_from_slice(text.as_bytes());
    }
}
