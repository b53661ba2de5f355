//! Writing images: the linked ELF executable and the flat and record formats
//! that EPROM programmers, monitors and other tools take.
//!
//! | format | what |
//! |---|---|
//! | `elf` | the canonical image ([`crate::image`]) |
//! | `bin` | the loaded areas' bytes, concatenated in layout order (ld65's output) |
//! | `ihex` | Intel HEX: 16 data bytes a record, `04` records above 64 KiB, `01` end |
//! | `srec` | Motorola S-record: `S0` header, `S1`/`S2`/`S3` data by address width, `S5`/`S6` count, `S9`/`S8`/`S7` entry |
//! | `kim` | MOS/KIM-1 paper tape: `;LLAAAA` data `CCCC` records of up to 24 bytes, then `;00` count and checksum |
//!
//! Record formats hold each area at its load address; every format writes
//! the same bytes for the same image.

mod elf;
mod files;
mod records;

use core::fmt;
use core::str::FromStr;

pub use elf::write_elf;
pub use files::OutputFile;
pub(crate) use files::Part;
pub(crate) use records::append_without;
pub use records::{write_bin, write_ihex, write_kim, write_srec};

use crate::error::Error;
use crate::image::Image;

/// An output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// ELF32 executable: areas, sections, symbols, entry, hooks.
    Elf,
    /// Raw bytes.
    Bin,
    /// Intel HEX.
    Ihex,
    /// Motorola S-record.
    Srec,
    /// MOS Technology / KIM-1 paper tape.
    Kim,
}

impl Format {
    /// Every format, in `--format` order.
    pub const ALL: [Format; 5] = [
        Format::Elf,
        Format::Bin,
        Format::Ihex,
        Format::Srec,
        Format::Kim,
    ];

    /// The `--format` name.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Format::Elf => "elf",
            Format::Bin => "bin",
            Format::Ihex => "ihex",
            Format::Srec => "srec",
            Format::Kim => "kim",
        }
    }

    /// Writes `image` in this format.
    ///
    /// # Errors
    /// [`Error::Format`] when the image does not fit the format (KIM-1 tape
    /// has 16-bit addresses); [`Error::Format`] from the ELF writer.
    pub fn write(self, image: &Image) -> Result<Vec<u8>, Error> {
        match self {
            Format::Elf => write_elf(image),
            Format::Bin => Ok(write_bin(image)),
            Format::Ihex => Ok(write_ihex(image)),
            Format::Srec => Ok(write_srec(image)),
            Format::Kim => write_kim(image),
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Format {
    type Err = String;

    fn from_str(text: &str) -> Result<Format, String> {
        Format::ALL
            .into_iter()
            .find(|format| format.name() == text)
            .ok_or_else(|| format!("unknown format `{text}` (elf, bin, ihex, srec or kim)"))
    }
}
