//! What an upload puts into the robot: loaded areas and hook records, and
//! the robot's memory rules that decide whether it may.

use std::ops::RangeInclusive;

use isa::objfmt::{HookKind, HookRecord};

use crate::{Error, Result};

use platform::map::KIM_BUS;

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

    pub(crate) fn contains(&self, address: u16) -> bool {
        (u32::from(self.address)..self.end()).contains(&u32::from(address))
    }
}

/// An image ready to upload: its loaded areas (sorted, disjoint) and the
/// hooks it takes over.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadImage {
    areas: Vec<Area>,
    hooks: Vec<HookRecord>,
    /// The memory the image owns: its areas, and where a linked image's
    /// segments run (BSS and zero page too), merged.
    extents: Vec<std::ops::RangeInclusive<u16>>,
    /// Where the image loads code (its `SHF_EXECINSTR` sections), sorted
    /// and merged, when known: what the program cannot change, unlike its
    /// data. `None`: every loaded byte counts as code.
    code: Option<Vec<std::ops::RangeInclusive<u16>>>,
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
        let extents = crate::table::extents_of(&areas);
        let image = UploadImage {
            areas,
            hooks,
            extents,
            code: None,
        };
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

    /// The memory the image owns, sorted and merged: what the table of
    /// installed extensions records for it.
    #[must_use]
    pub fn extents(&self) -> &[std::ops::RangeInclusive<u16>] {
        &self.extents
    }

    /// Where the image loads code (its executable sections), sorted and
    /// merged, when known; `None` when every loaded byte is to be taken
    /// for code (an image made of bare areas, or one whose sections say
    /// nothing executable). The robot's bytes there must stay the image's;
    /// the rest (`.data`, tables) is the program's to change.
    #[must_use]
    pub fn code(&self) -> Option<&[std::ops::RangeInclusive<u16>]> {
        self.code.as_deref()
    }

    /// Says where the image loads code (see [`UploadImage::code`]): an
    /// image merged from several linked ones keeps theirs. An empty list
    /// is taken as not known.
    pub fn set_code(&mut self, ranges: Vec<std::ops::RangeInclusive<u16>>) {
        let merged = romlib::installed::merge(ranges.into_iter().map(|range| {
            (
                u64::from(*range.start()),
                u64::from(*range.end()) - u64::from(*range.start()) + 1,
            )
        }));
        self.code = (!merged.is_empty()).then_some(merged);
    }

    /// Whether `address` is code the robot must hold as the image has it:
    /// inside [`UploadImage::code`], or loaded at all when that is not
    /// known.
    #[must_use]
    pub fn is_code(&self, address: u16) -> bool {
        match &self.code {
            Some(ranges) => ranges.iter().any(|range| range.contains(&address)),
            None => self.contains(address),
        }
    }

    /// The addresses of its chain slots' bytes, which the upload fills
    /// (with where each hook went before) rather than the image.
    #[must_use]
    pub fn chain_slot_bytes(&self) -> Vec<u16> {
        self.hooks
            .iter()
            .filter_map(|record| record.chain)
            .flat_map(|slot| [slot, slot.wrapping_add(1)])
            .collect()
    }

    /// Its id in the table of installed extensions (24 bits of a hash of
    /// its loaded bytes as linked, chain slots unfilled).
    #[must_use]
    pub fn id(&self) -> u32 {
        romlib::installed::image_id(self.areas.iter().flat_map(|a| a.bytes.iter().copied()))
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

    /// Adds an area the upload writes besides the image's own (its entry in
    /// the table of installed extensions), keeping the areas sorted.
    pub(crate) fn push_area(&mut self, area: Area) {
        let at = self.areas.partition_point(|a| a.address < area.address);
        self.areas.insert(at, area);
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
        let mut upload = UploadImage::new(areas, image.hooks.records.clone())?;
        upload.extents = romlib::installed::image_extents(image);
        // Where code is loaded (not where it runs: the upload writes the
        // load addresses).
        upload.set_code(
            image
                .sections
                .iter()
                .filter(|section| section.exec && section.size > 0)
                .filter_map(|section| {
                    let start = u16::try_from(section.load).ok()?;
                    let end = section.load.checked_add(section.size - 1)?.min(0xFFFF);
                    Some(start..=u16::try_from(end).ok()?)
                })
                .collect(),
        );
        Ok(upload)
    }
}

/// What the uploader must know about the ROM in the robot: where its hooks
/// are and what they point at after a reset, which memory an upload may
/// write, where the RAM loader may run and which services it calls, and
/// how much its receive buffer holds (which bounds pipelining).
///
/// [`RomProfile::reference`] (the default) is the reference ROM's, taken
/// from the names it exports (`romlib::symbols`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RomProfile {
    /// `HOOK_UNKNOWN`'s address (a `JMP` in RAM).
    pub hook_unknown: u16,
    /// `HOOK_LOOP`'s address.
    pub hook_loop: u16,
    /// The targets the ROM's reset gives the two hooks (unknown, loop), when
    /// known: used to disarm a hook that points into memory being
    /// overwritten, and to recognise a reset.
    pub reset_targets: Option<(u16, u16)>,
    /// Memory an upload may write.
    pub writable: Vec<RangeInclusive<u16>>,
    /// RAM every robot with this ROM has and the ROM leaves to extensions:
    /// where the RAM loader may run when the image leaves room.
    pub user_ram: RangeInclusive<u16>,
    /// The zero page the ROM leaves to extensions, when known: the RAM
    /// loader keeps its state in eight bytes of it that the image does not
    /// load (no loader without it).
    pub user_zero_page: Option<RangeInclusive<u8>>,
    /// The ROM services the RAM loader calls; `None` if the ROM lacks
    /// one (then there is no loader).
    pub loader_services: Option<Services>,
    /// Characters the ROM buffers while it is busy (answering, say) without
    /// losing any: the most the host may send ahead of an answer. From the
    /// ROM's exported `RXBUF_SIZE` (less the slot a ring keeps free).
    pub rx_buffer: usize,
    /// The ROM's table of installed extensions (`EXTTAB`, in
    /// `romlib::installed`'s format) and its entries; `None` for a ROM that
    /// keeps none, whose robot cannot say what is installed.
    pub table: Option<(u16, usize)>,
    /// The ROM's name, for messages (a file, or the reference ROM).
    pub name: String,
    /// The ROM's bytes (`$F000`-`$FFFF`), when the profile has them: what
    /// a robot's ROM is compared with before anything is written.
    pub rom: Option<Area>,
    /// Where an image's calls into the ROM land: the service jump table
    /// and the vectors, compared byte by byte before any write.
    pub jump_table: Vec<RangeInclusive<u16>>,
}

/// The ROM services the RAM loader calls (jump-table entries).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Services {
    /// `GETCH`: wait for the next received byte.
    pub getch: u16,
    /// `CHKCH`: the next received byte, or carry set if none.
    pub chkch: u16,
    /// `CMD_DONE`: back to the control loop.
    pub cmd_done: u16,
    /// `GETHEX`: two hex digits of the command into A (`sums` reads its
    /// fields with it).
    pub gethex: u16,
    /// `PUTCH`: send A.
    pub putch: u16,
    /// `PUTHEX`: send A as two hex digits.
    pub puthex: u16,
    /// `PUTEOL`: end the answer.
    pub puteol: u16,
    /// The receive ring, when the ROM exports it (`RXBUF`, `RXHEAD`,
    /// `RXTAIL`) and it is 256 bytes (`RXBUF_SIZE`), so that its indexes
    /// wrap by themselves: the loader then takes its data straight from
    /// the ring, in half the time `CHKCH` takes.
    pub ring: Option<ReceiveRing>,
}

/// Where the ROM's serial receive ring is: bytes wait at `buffer + tail`
/// up to `buffer + head`; the interrupt handler advances `head`, the main
/// loop (a command handler reading its own data) advances `tail`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReceiveRing {
    /// `RXBUF`: the ring's 256 bytes.
    pub buffer: u16,
    /// `RXHEAD` (zero page): the next free slot.
    pub head: u8,
    /// `RXTAIL` (zero page): the next byte to take.
    pub tail: u8,
}

impl ReceiveRing {
    /// The ring, if every part of it is known and it is 256 bytes long.
    fn new(
        buffer: Option<u16>,
        size: Option<u16>,
        head: Option<u16>,
        tail: Option<u16>,
    ) -> Option<Self> {
        let byte = |at: Option<u16>| at.and_then(|at| u8::try_from(at).ok());
        match (buffer, size, byte(head), byte(tail)) {
            (Some(buffer), Some(0x100), Some(head), Some(tail)) => {
                Some(ReceiveRing { buffer, head, tail })
            }
            _ => None,
        }
    }
}

/// The characters the reference ROM's serial receive ring holds: its
/// exported `RXBUF_SIZE` (256 bytes at `RXBUF`, romlib/rom/ram.inc) less
/// the one slot `rx_put` (romlib/rom/services.s) keeps free to tell full
/// from empty. `uploader`'s tests measure it on the emulated ROM
/// (`the_reference_rom_buffers_255_characters`).
pub const REFERENCE_RX_BUFFER: usize = romlib::symbols::RXBUF_SIZE as usize - 1;

/// The receive buffer assumed for a ROM profile that does not export
/// `RXBUF_SIZE`: small enough for a ROM that polls its 6551 one command
/// at a time with a modest buffer.
pub const CONSERVATIVE_RX_BUFFER: usize = 64;

/// The characters a receive ring of `size` bytes holds: one slot stays
/// free to tell a full ring from an empty one.
fn ring_capacity(size: u16) -> usize {
    usize::from(size).saturating_sub(1).max(1)
}

impl Default for RomProfile {
    fn default() -> Self {
        RomProfile::reference()
    }
}

impl RomProfile {
    /// The reference ROM's profile, from its exported names: hooks and
    /// their reset targets (`BAD_COMMAND`, `ROM_LOOP`), the user zero page
    /// and user RAM, the KIM-bus expansion space (RAM on the virtual
    /// Scorpion, a peripheral card's business on a real one), and the
    /// receive ring's size (`RXBUF_SIZE`).
    #[must_use]
    pub fn reference() -> RomProfile {
        use romlib::symbols as rom;
        RomProfile {
            hook_unknown: rom::HOOK_UNKNOWN,
            hook_loop: rom::HOOK_LOOP,
            reset_targets: Some((rom::BAD_COMMAND, rom::ROM_LOOP)),
            writable: vec![
                rom::USER_ZP_START..=rom::USER_ZP_END,
                rom::USER_RAM_START..=rom::USER_RAM_END,
                KIM_BUS,
            ],
            user_ram: rom::USER_RAM_START..=rom::USER_RAM_END,
            user_zero_page: u8::try_from(rom::USER_ZP_START)
                .ok()
                .zip(u8::try_from(rom::USER_ZP_END).ok())
                .map(|(first, last)| first..=last),
            loader_services: Some(Services {
                getch: rom::GETCH,
                chkch: rom::CHKCH,
                cmd_done: rom::CMD_DONE,
                gethex: rom::GETHEX,
                putch: rom::PUTCH,
                puthex: rom::PUTHEX,
                puteol: rom::PUTEOL,
                ring: ReceiveRing::new(
                    Some(rom::RXBUF),
                    Some(rom::RXBUF_SIZE),
                    Some(rom::RXHEAD),
                    Some(rom::RXTAIL),
                ),
            }),
            rx_buffer: ring_capacity(rom::RXBUF_SIZE),
            table: Some((romlib::installed::TABLE, romlib::installed::ENTRIES)),
            name: "scorpion-rom.elf".to_owned(),
            rom: Some(Area {
                address: platform::map::ROM_START,
                bytes: romlib::ROM.to_vec(),
            }),
            jump_table: crate::fingerprint::jump_table(|name| {
                romlib::symbols::find(name).map(|symbol| symbol.value)
            }),
        }
    }

    /// The profile of another ROM, from its linked ELF (the file its
    /// extensions link against): the names of docs/PROTOCOL.md section 4, and
    /// `RXBUF_SIZE` if it exports one.
    ///
    /// # Errors
    /// [`Error::BadRomProfile`] naming the first missing symbol.
    pub fn from_rom_image(name: &str, rom: &linker::Image) -> Result<RomProfile> {
        let symbol = |symbol: &str| {
            rom.symbols
                .iter()
                .find(|s| s.global && s.name == symbol)
                .and_then(|s| u16::try_from(s.value).ok())
        };
        let need = |wanted: &str| {
            symbol(wanted).ok_or_else(|| Error::BadRomProfile {
                name: name.to_owned(),
                reason: format!("it does not export {wanted}"),
            })
        };
        let zp = need("USER_ZP_START")?..=need("USER_ZP_END")?;
        let ram = need("USER_RAM_START")?..=need("USER_RAM_END")?;
        let reset_targets = symbol("BAD_COMMAND").zip(symbol("ROM_LOOP"));
        Ok(RomProfile {
            hook_unknown: need("HOOK_UNKNOWN")?,
            hook_loop: need("HOOK_LOOP")?,
            reset_targets,
            user_zero_page: u8::try_from(*zp.start())
                .ok()
                .zip(u8::try_from(*zp.end()).ok())
                .map(|(first, last)| first..=last),
            writable: vec![zp, ram.clone(), KIM_BUS],
            user_ram: ram,
            loader_services: match (
                symbol("GETCH"),
                symbol("CHKCH"),
                symbol("CMD_DONE"),
                symbol("GETHEX"),
                symbol("PUTCH"),
                symbol("PUTHEX"),
                symbol("PUTEOL"),
            ) {
                (
                    Some(getch),
                    Some(chkch),
                    Some(cmd_done),
                    Some(gethex),
                    Some(putch),
                    Some(puthex),
                    Some(puteol),
                ) => Some(Services {
                    getch,
                    chkch,
                    cmd_done,
                    gethex,
                    putch,
                    puthex,
                    puteol,
                    ring: ReceiveRing::new(
                        symbol("RXBUF"),
                        symbol("RXBUF_SIZE"),
                        symbol("RXHEAD"),
                        symbol("RXTAIL"),
                    ),
                }),
                _ => None,
            },
            rx_buffer: symbol("RXBUF_SIZE").map_or(CONSERVATIVE_RX_BUFFER, ring_capacity),
            table: symbol("EXTTAB")
                .zip(symbol("EXTTAB_ENTRIES"))
                .filter(|_| symbol("EXTTAB_ENTRY_LEN") == Some(romlib::installed::ENTRY_LEN as u16))
                .map(|(at, entries)| (at, usize::from(entries))),
            name: name.to_owned(),
            rom: (u32::from(platform::map::ROM_START)..=0xFFFF)
                .map(|address| rom.byte_at(address))
                .collect::<Option<Vec<u8>>>()
                .map(|bytes| Area {
                    address: platform::map::ROM_START,
                    bytes,
                }),
            jump_table: crate::fingerprint::jump_table(symbol),
        })
    }

    /// The most characters the client sends ahead of an answer: the
    /// receive buffer less room for one whole command in progress.
    #[must_use]
    pub fn window(&self) -> usize {
        self.rx_buffer.saturating_sub(16).max(1)
    }

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

    /// Whether every byte of `first..=last` is writable, in one range or
    /// several that meet (hostile21 F5: an undo file's record of the
    /// table's last entry and of KIM-bus RAM after it, `$0FF1-$1011`, lies
    /// in two ranges, and its undo was refused).
    #[must_use]
    pub fn writable_span(&self, first: u16, last: u16) -> bool {
        let mut at = u32::from(first);
        while at <= u32::from(last) {
            let Some(range) = self
                .writable
                .iter()
                .find(|range| u32::from(*range.start()) <= at && at <= u32::from(*range.end()))
            else {
                return false;
            };
            at = u32::from(*range.end()) + 1;
        }
        true
    }

    /// Checks that every byte of `image` is writable.
    ///
    /// # Errors
    /// [`Error::BadImage`] naming the first area that is not.
    pub fn check(&self, image: &UploadImage) -> Result<()> {
        for area in image.areas() {
            let last = (area.end() - 1) as u16;
            if !self.writable_span(area.address, last) {
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
