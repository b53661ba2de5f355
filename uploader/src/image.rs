//! What an upload puts into the robot: loaded areas and hook records, and
//! the robot's memory rules that decide whether it may.

use std::ops::RangeInclusive;

use isa::objfmt::{HookKind, HookRecord};

use crate::{Error, Result};

/// Bytes to load at an address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Area {
    /// The load address of the first byte.
    pub address: u16,
    /// The bytes.
    pub bytes: Vec<u8>,
}

impl Area {
    /// The address one past the last byte (as `u32`: may be `$10000`).
    #[must_use]
    pub fn end(&self) -> u32 {
        u32::from(self.address) + self.bytes.len() as u32
    }

    fn contains(&self, address: u16) -> bool {
        (u32::from(self.address)..self.end()).contains(&u32::from(address))
    }
}

/// An image ready to upload: its loaded areas (sorted, disjoint) and the
/// hooks it takes over.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadImage {
    areas: Vec<Area>,
    hooks: Vec<HookRecord>,
}

impl UploadImage {
    /// Checks and sorts the areas, and checks that every handler and chain
    /// slot lies in them.
    ///
    /// # Errors
    /// [`Error::BadImage`] for an empty image, an area past `$FFFF` or
    /// overlapping areas; [`Error::BadHookRecord`] for a handler or chain
    /// slot outside the image.
    pub fn new(mut areas: Vec<Area>, hooks: Vec<HookRecord>) -> Result<Self> {
        areas.retain(|area| !area.bytes.is_empty());
        areas.sort_by_key(|area| area.address);
        if areas.is_empty() {
            return Err(Error::BadImage {
                reason: "it loads no bytes".into(),
            });
        }
        for area in &areas {
            if area.end() > 0x1_0000 {
                return Err(Error::BadImage {
                    reason: format!("the area at ${:04X} runs past $FFFF", area.address),
                });
            }
        }
        for pair in areas.windows(2) {
            if pair[0].end() > u32::from(pair[1].address) {
                return Err(Error::BadImage {
                    reason: format!(
                        "the areas at ${:04X} and ${:04X} overlap",
                        pair[0].address, pair[1].address
                    ),
                });
            }
        }
        let image = UploadImage { areas, hooks };
        for record in &image.hooks {
            if !image.contains(record.handler) {
                return Err(Error::BadHookRecord {
                    kind: record.kind,
                    address: record.handler,
                });
            }
            if let Some(slot) = record.chain
                && (!image.contains(slot) || slot == 0xFFFF || !image.contains(slot + 1))
            {
                return Err(Error::BadHookRecord {
                    kind: record.kind,
                    address: slot,
                });
            }
        }
        Ok(image)
    }

    /// The loaded areas, sorted by address.
    #[must_use]
    pub fn areas(&self) -> &[Area] {
        &self.areas
    }

    /// The hooks the image takes over.
    #[must_use]
    pub fn hooks(&self) -> &[HookRecord] {
        &self.hooks
    }

    /// Total bytes loaded.
    #[must_use]
    pub fn len(&self) -> usize {
        self.areas.iter().map(|area| area.bytes.len()).sum()
    }

    /// Whether the image loads `address`.
    #[must_use]
    pub fn contains(&self, address: u16) -> bool {
        self.areas.iter().any(|area| area.contains(address))
    }

    /// The image's byte at `address`, if it loads one.
    #[must_use]
    pub fn byte(&self, address: u16) -> Option<u8> {
        self.areas
            .iter()
            .find(|area| area.contains(address))
            .map(|area| area.bytes[usize::from(address - area.address)])
    }

    /// Overwrites a loaded byte (used to fill chain slots). Returns whether
    /// the address was loaded.
    pub(crate) fn set_byte(&mut self, address: u16, value: u8) -> bool {
        match self.areas.iter_mut().find(|area| area.contains(address)) {
            Some(area) => {
                area.bytes[usize::from(address - area.address)] = value;
                true
            }
            None => false,
        }
    }
}

impl TryFrom<&linker::Image> for UploadImage {
    type Error = Error;

    /// Takes the load addresses of a linked image's areas (what an upload
    /// writes) and its hook records.
    fn try_from(image: &linker::Image) -> Result<Self> {
        let mut areas = Vec::new();
        for area in &image.areas {
            let address = u16::try_from(area.load).map_err(|_| Error::BadImage {
                reason: format!("an area loads at ${:X}, past $FFFF", area.load),
            })?;
            areas.push(Area {
                address,
                bytes: area.bytes.clone(),
            });
        }
        UploadImage::new(areas, image.hooks.records.clone())
    }
}

/// Where a ROM keeps its hooks and which memory an upload may write: the
/// reference ROM's values by default (PLATFORM.md section 4,
/// docs/ARCHITECTURE.md's memory map).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RomProfile {
    /// `HOOK_UNKNOWN`'s address (a `JMP` in RAM).
    pub hook_unknown: u16,
    /// `HOOK_LOOP`'s address.
    pub hook_loop: u16,
    /// The targets the ROM's reset gives the two hooks (unknown, loop), when
    /// known: used to disarm a hook that points into memory being
    /// overwritten.
    pub reset_targets: Option<(u16, u16)>,
    /// Memory an upload may write.
    pub writable: Vec<RangeInclusive<u16>>,
}

impl Default for RomProfile {
    fn default() -> Self {
        RomProfile {
            hook_unknown: 0x0200,
            hook_loop: 0x0203,
            reset_targets: None,
            // Extension RAM and the KIM-bus expansion space; never the
            // ROM's zero page, stack and state, the I/O page or the ROM.
            writable: vec![0x0400..=0xBFFF],
        }
    }
}

impl RomProfile {
    /// The address of a hook's `JMP`.
    #[must_use]
    pub fn hook_address(&self, kind: HookKind) -> u16 {
        match kind {
            HookKind::Unknown => self.hook_unknown,
            HookKind::Loop => self.hook_loop,
        }
    }

    /// The reset target of a hook, when known.
    #[must_use]
    pub fn reset_target(&self, kind: HookKind) -> Option<u16> {
        self.reset_targets.map(|(unknown, main)| match kind {
            HookKind::Unknown => unknown,
            HookKind::Loop => main,
        })
    }

    /// Checks that every byte of `image` is writable.
    ///
    /// # Errors
    /// [`Error::BadImage`] naming the first area that is not.
    pub fn check(&self, image: &UploadImage) -> Result<()> {
        for area in image.areas() {
            let last = (area.end() - 1) as u16;
            let inside = self
                .writable
                .iter()
                .any(|range| range.contains(&area.address) && range.contains(&last));
            if !inside {
                let ranges: Vec<String> = self
                    .writable
                    .iter()
                    .map(|range| format!("${:04X}-${:04X}", range.start(), range.end()))
                    .collect();
                return Err(Error::BadImage {
                    reason: format!(
                        "${:04X}-${last:04X} is outside the memory an upload may write ({})",
                        area.address,
                        ranges.join(", ")
                    ),
                });
            }
        }
        Ok(())
    }
}
