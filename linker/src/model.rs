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
    pub(crate) map: MapData,
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
