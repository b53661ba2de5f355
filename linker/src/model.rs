//! The linker's model: what the stages pass on. A global symbol with
//! where it came from, and the finished link.

use crate::error::Error;
use crate::image::Image;
use crate::layout::Layout;
use crate::map::MapData;

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
    /// Per image area, its BSS holes for the `bin` format (see
    /// [`Linked::write`]).
    pub(crate) main_holes: Vec<Vec<(u64, u64)>>,
    pub(crate) map: MapData,
}

impl Linked {
    /// The image in `format`. For `bin`, a BSS segment inside a written
    /// area takes no room, as in ld65's output (the bytes after it follow
    /// the bytes before it); every other format keeps addresses.
    ///
    /// # Errors
    /// As [`crate::Format::write`].
    pub fn write(&self, format: crate::Format) -> Result<Vec<u8>, Error> {
        if format != crate::Format::Bin {
            return format.write(&self.image);
        }
        let mut out = Vec::new();
        for (area, holes) in self.image.areas.iter().zip(&self.main_holes) {
            crate::output::append_without(&mut out, area, holes);
        }
        Ok(out)
    }
}

/// Another output file of a link: the bytes of the areas that name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFile {
    /// Its name as the layout gives it; `%O` stands for the image's file
    /// name (see [`OutputFile::path`]).
    pub name: String,
    /// Its areas, in layout order.
    pub areas: Vec<crate::image::LoadArea>,
    /// Per area, the load ranges of the BSS segments in it, which take
    /// no room in the file (`start..end`).
    pub(crate) holes: Vec<Vec<(u64, u64)>>,
}

impl OutputFile {
    /// Its name with `%O` replaced by `output`, the image's file name.
    #[must_use]
    pub fn path(&self, output: &str) -> String {
        self.name.replace("%O", output)
    }

    /// Its contents: the areas' bytes one after the other, as ld65's
    /// binary format writes them (see [`crate::output::write_bin`]).
    #[must_use]
    pub fn bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for (area, holes) in self.areas.iter().zip(&self.holes) {
            crate::output::append_without(&mut out, area, holes);
        }
        out
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
