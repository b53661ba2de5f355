//! Output files as an ld65 configuration names them: the main one (`%O`)
//! and others (`file = "%O.1"`), each in its `FILES` format: ld65's raw
//! binary, or the Atari DOS executable.

use crate::image::LoadArea;
use crate::layout::OutputFormat;

/// The Atari executable's RUNAD and INITAD vectors.
const RUNAD: u16 = 0x02E0;
const INITAD: u16 = 0x02E2;

/// Where one of a file's [`LoadArea`]s came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Part {
    /// The layout's memory area (a memory area may give several load
    /// areas, where its run address stops following its load address).
    pub(crate) area: String,
    /// Load ranges of the BSS segments in that memory area (`start..end`),
    /// which take no room in a binary file.
    pub(crate) holes: Vec<(u64, u64)>,
}

/// An output file of a link: the bytes of the areas that name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFile {
    /// Its name as the layout gives it; `%O` stands for the image's file
    /// name (see [`OutputFile::path`]).
    pub name: String,
    /// Its areas, in layout order.
    pub areas: Vec<LoadArea>,
    /// Per area, where it came from.
    pub(crate) parts: Vec<Part>,
    /// How it is written.
    pub(crate) format: OutputFormat,
    /// For the Atari format: the RUNAD address, and the INITAD address
    /// after each memory area that names one.
    pub(crate) run: Option<u16>,
    pub(crate) inits: Vec<(String, u16)>,
}

impl OutputFile {
    /// An empty file named `name`, written in `format`.
    pub(crate) fn new(name: &str, format: OutputFormat) -> OutputFile {
        OutputFile {
            name: name.to_owned(),
            areas: Vec::new(),
            parts: Vec::new(),
            format,
            run: None,
            inits: Vec::new(),
        }
    }

    /// Its name with `%O` replaced by `output`, the image's file name.
    #[must_use]
    pub fn path(&self, output: &str) -> String {
        self.name.replace("%O", output)
    }

    /// Its contents, as ld65 writes them in its format.
    #[must_use]
    pub fn bytes(&self) -> Vec<u8> {
        self.bytes_of(&self.areas)
    }

    /// The contents with `areas` as its areas: the main file's are the
    /// image's, which it does not keep a copy of.
    pub(crate) fn bytes_of(&self, areas: &[LoadArea]) -> Vec<u8> {
        match self.format {
            OutputFormat::Bin => {
                let mut out = Vec::new();
                for (area, part) in areas.iter().zip(&self.parts) {
                    super::append_without(&mut out, area, &part.holes);
                }
                out
            }
            OutputFormat::Atari => self.atari(areas),
        }
    }

    /// `$FFFF`, then for each memory area its runs of bytes (BSS inside
    /// it starts a new run, as it takes no room) as blocks of first
    /// address, last address and bytes, followed by an INITAD block if
    /// the area names one; a RUNAD block last.
    fn atari(&self, areas: &[LoadArea]) -> Vec<u8> {
        let mut out = vec![0xFF, 0xFF];
        let block = |out: &mut Vec<u8>, start: u64, bytes: &[u8]| {
            let start = start as u16;
            let last = start.wrapping_add(bytes.len() as u16).wrapping_sub(1);
            out.extend(start.to_le_bytes());
            out.extend(last.to_le_bytes());
            out.extend(bytes);
        };
        let mut index = 0;
        while index < areas.len() {
            let name = &self.parts[index].area;
            // Runs of (start address, bytes) over the area's pieces.
            let mut runs: Vec<(u64, Vec<u8>)> = Vec::new();
            while index < areas.len() && self.parts[index].area == *name {
                let area = &areas[index];
                let holes = &self.parts[index].holes;
                for (offset, byte) in area.bytes.iter().enumerate() {
                    let address = u64::from(area.load) + offset as u64;
                    if holes
                        .iter()
                        .any(|(from, to)| (*from..*to).contains(&address))
                    {
                        continue;
                    }
                    match runs.last_mut() {
                        Some((start, bytes)) if *start + bytes.len() as u64 == address => {
                            bytes.push(*byte);
                        }
                        _ => runs.push((address, vec![*byte])),
                    }
                }
                index += 1;
            }
            for (start, bytes) in &runs {
                block(&mut out, *start, bytes);
            }
            for (_, address) in self.inits.iter().filter(|(area, _)| area == name) {
                block(&mut out, u64::from(INITAD), &address.to_le_bytes());
            }
        }
        if let Some(address) = self.run {
            block(&mut out, u64::from(RUNAD), &address.to_le_bytes());
        }
        out
    }
}
