//! The linker's model: what the stages pass on. A global symbol with
//! where it came from, and the finished link.

use crate::error::Error;
use crate::image::Image;
use crate::layout::Layout;
use crate::map::MapData;
use crate::output::OutputFile;

/// A successful link.
#[derive(Debug)]
pub struct Linked {
    /// The program.
    pub image: Image,
    /// The layout used.
    pub layout: Layout,
    /// Warnings (failed `.assert`s with the warning action, misaligned
    /// segments, empty required segments).
    pub warnings: Vec<Error>,
    /// Output files besides the image, from a layout whose areas name
    /// other files (ld65's `file = "%O.1"`): each written as raw bytes.
    pub other_files: Vec<OutputFile>,
    /// The main output file as ld65 would write it (see
    /// [`Linked::write`]), without areas of its own: they are the image's.
    pub(crate) main_file: OutputFile,
    pub(crate) map: MapData,
}

impl Linked {
    /// The image in `format`. `bin` is the main output file as ld65
    /// writes it: a BSS segment inside a written area takes no room (the
    /// bytes after it follow the bytes before it), and an ld65
    /// configuration's `FILES` format applies (`atari`); every other
    /// format keeps addresses.
    ///
    /// # Errors
    /// As [`crate::Format::write`].
    pub fn write(&self, format: crate::Format) -> Result<Vec<u8>, Error> {
        if format != crate::Format::Bin {
            return format.write(&self.image);
        }
        Ok(self.main_file.bytes_of(&self.image.areas))
    }
}

/// Where a global symbol comes from.
#[derive(Debug, Clone)]
pub(crate) enum Origin {
    Object { object: usize, symbol: usize },
    Layout,
    File(String),
}

#[derive(Debug, Clone)]
pub(crate) struct Global {
    /// `None` when its section could not be placed (already an error).
    pub(crate) value: Option<i64>,
    pub(crate) origin: Origin,
    pub(crate) weak: bool,
    /// The segment it lies in.
    pub(crate) segment: Option<usize>,
    pub(crate) size: u32,
}
