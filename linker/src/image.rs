//! Linked images: the one reader (and the in-memory model) of what the
//! linker writes.
//!
//! A linked image is an ELF32 `ET_EXEC`, `EM_MOS` file (docs/ARCHITECTURE.md,
//! "Linked images"): a `PT_LOAD` per loaded area (`p_paddr` = where the
//! bytes are stored, `p_vaddr` = where they run), a section header per
//! placed segment, the full `.symtab`, `e_entry`, and `.scorpion.hooks` when
//! the image takes over a ROM hook. The emulator CLI, the virtual Scorpion
//! and the uploader all read images through [`Image::parse`].
//!
//! `p_memsz` equals `p_filesz`: BSS is not part of any `PT_LOAD` (nothing
//! clears it on upload; start-up code does, as cc65's does). BSS segments
//! still appear as `SHT_NOBITS` section headers.

use goblin::elf::{Elf, program_header as ph, section_header as sh, sym};
use isa::elf as mos;
use isa::objfmt::{HOOKS_SECTION, HookKind, Hooks, LINES_SECTION, SrcMap};

use crate::error::Error;
use crate::layout::SegmentKind;

/// Bytes stored at one address range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadArea {
    /// Where the bytes are stored (`p_paddr`): what an uploader writes.
    pub load: u32,
    /// Where they run (`p_vaddr`); equals `load` unless start-up code
    /// copies them.
    pub run: u32,
    /// The bytes.
    pub bytes: Vec<u8>,
}

impl LoadArea {
    /// One past the last load address.
    #[must_use]
    pub fn end(&self) -> u64 {
        u64::from(self.load) + self.bytes.len() as u64
    }
}

/// A placed segment (a section header of the image).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageSection {
    /// The segment's name.
    pub name: String,
    /// Where it runs (`sh_addr`).
    pub run: u32,
    /// Where its bytes are stored (same as `run` unless copied at start-up).
    pub load: u32,
    /// Size in bytes.
    pub size: u32,
    /// What it holds.
    pub kind: SegmentKind,
    /// Holds code (`SHF_EXECINSTR`): disassemblers and debuggers start here.
    pub exec: bool,
}

/// A symbol of the image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageSymbol {
    /// Its name (scoped names use `::`).
    pub name: String,
    /// Its value: an address, or a constant (32-bit two's complement).
    pub value: u32,
    /// `st_size`, 0 when unknown.
    pub size: u32,
    /// Exported (`STB_GLOBAL`) rather than local to its object.
    pub global: bool,
    /// The section it lies in (index in [`Image::sections`]), or `None` for
    /// constants.
    pub section: Option<usize>,
}

/// A linked program.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Image {
    /// The start address (`e_entry`).
    pub entry: u32,
    /// `e_flags`: the OR of the inputs' CPU flags.
    pub flags: u32,
    /// Loaded bytes, in output order.
    pub areas: Vec<LoadArea>,
    /// Placed segments.
    pub sections: Vec<ImageSection>,
    /// All symbols: locals first, then globals.
    pub symbols: Vec<ImageSymbol>,
    /// The ROM hooks it takes over.
    pub hooks: Hooks,
    /// Where its bytes came from, by run address (`.scorpion.lines`: see
    /// [`isa::objfmt::LINES_SECTION`]); empty if its objects had no source
    /// map.
    pub lines: SrcMap,
}

impl Image {
    /// Where the byte at run address `address` came from: the source
    /// file (as given to the assembler), line and column. `None` outside
    /// the image's sections.
    #[must_use]
    pub fn source_of(&self, address: u32) -> Option<(&str, u32, u32)> {
        let inside = self.sections.iter().any(|s| {
            (u64::from(s.run)..u64::from(s.run) + u64::from(s.size)).contains(&u64::from(address))
        });
        if !inside {
            return None;
        }
        let loc = self.lines.lookup(0, address)?;
        Some((self.lines.file_name(loc)?, loc.line, loc.column))
    }

    /// The line a user is shown for the byte at run address `address`
    /// ([`isa::objfmt::user_place`]: a built-in macro's code at the
    /// user's line that called it); `is_users` says whether a file is one
    /// the user can open. `None` outside the image's sections.
    #[must_use]
    pub fn user_source_of(
        &self,
        address: u32,
        is_users: &dyn Fn(&str) -> bool,
    ) -> Option<(&str, u32)> {
        let (file, line, _) = self.source_of(address)?;
        let call = self
            .lines
            .call(0, address)
            .and_then(|loc| Some((self.lines.file_name(loc)?, loc.line)));
        Some(isa::objfmt::user_place((file, line), call, is_users))
    }

    /// The lowest run address whose bytes came from line `line` of the
    /// source file whose path ends with `file` (`adc.s` finds
    /// `examples/adc/adc.s`), or that a macro called on that line made
    /// (its first byte: a line that calls a macro is where the macro's
    /// code begins).
    #[must_use]
    pub fn address_of_line(&self, file: &str, line: u32) -> Option<u32> {
        self.lines
            .entries
            .iter()
            .chain(&self.lines.calls)
            .filter(|entry| entry.loc.line == line)
            .filter(|entry| {
                self.lines
                    .file_name(entry.loc)
                    .is_some_and(|name| same_file(name, file))
            })
            .map(|entry| entry.offset)
            .min()
    }

    /// A symbol's value, globals before locals.
    #[must_use]
    pub fn symbol(&self, name: &str) -> Option<u32> {
        self.symbols
            .iter()
            .filter(|symbol| symbol.name == name)
            .max_by_key(|symbol| symbol.global)
            .map(|symbol| symbol.value)
    }

    /// The byte stored at `address`, if an area holds it.
    #[must_use]
    pub fn byte_at(&self, address: u32) -> Option<u8> {
        self.areas.iter().find_map(|area| {
            let offset = address.checked_sub(area.load)? as usize;
            area.bytes.get(offset).copied()
        })
    }

    /// Parses a linked image.
    ///
    /// # Errors
    /// [`Error::BadImage`] for anything that is not an `EM_MOS` `ET_EXEC`
    /// ELF32 file with consistent headers, and for a malformed
    /// `.scorpion.hooks` section.
    pub fn parse(name: &str, bytes: &[u8]) -> Result<Image, Error> {
        let bad = |reason: String| Error::BadImage {
            file: name.to_owned(),
            reason,
        };
        if bytes.starts_with(&crate::input::XO65_MAGIC) {
            return Err(bad(crate::input::XO65_REASON.into()));
        }
        let elf = Elf::parse(bytes).map_err(|error| bad(format!("not ELF: {error}")))?;
        if elf.is_64 || !elf.little_endian {
            return Err(bad("not ELF32 little-endian".into()));
        }
        if elf.header.e_machine != mos::EM_MOS {
            return Err(bad(format!(
                "machine {} is not EM_MOS (6502)",
                elf.header.e_machine
            )));
        }
        if elf.header.e_type != goblin::elf::header::ET_EXEC {
            return Err(bad(format!(
                "ET_{} is not an executable (ET_EXEC); link it first",
                goblin::elf::header::et_to_str(elf.header.e_type)
            )));
        }
        let file_range = |offset: u64, size: u64, what: &str| -> Result<&[u8], Error> {
            let start =
                usize::try_from(offset).map_err(|_| bad(format!("{what} is outside the file")))?;
            let len =
                usize::try_from(size).map_err(|_| bad(format!("{what} is outside the file")))?;
            start
                .checked_add(len)
                .and_then(|end| bytes.get(start..end))
                .ok_or_else(|| bad(format!("{what} lies outside the file")))
        };
        let address = |value: u64, what: &str| -> Result<u32, Error> {
            u32::try_from(value)
                .map_err(|_| bad(format!("{what} address {value:#x} is not 32-bit")))
        };

        let mut areas = Vec::new();
        for (index, header) in elf.program_headers.iter().enumerate() {
            if header.p_type != ph::PT_LOAD {
                continue;
            }
            let what = format!("PT_LOAD {index}");
            if header.p_memsz < header.p_filesz {
                return Err(bad(format!("{what} has p_memsz < p_filesz")));
            }
            if header.p_filesz == 0 {
                // Only reserves memory (another linker's BSS): nothing to load.
                continue;
            }
            let data = file_range(header.p_offset, header.p_filesz, &what)?;
            let load = address(header.p_paddr, &what)?;
            let run = address(header.p_vaddr, &what)?;
            if u64::from(load) + data.len() as u64 > 1 << 32 {
                return Err(bad(format!("{what} runs past the 32-bit address space")));
            }
            areas.push(LoadArea {
                load,
                run,
                bytes: data.to_vec(),
            });
        }

        let mut sections = Vec::new();
        let mut position_of = vec![None; elf.section_headers.len()];
        let mut hooks = Hooks::default();
        let mut lines = SrcMap::default();
        for (index, header) in elf.section_headers.iter().enumerate() {
            let section_name = elf.shdr_strtab.get_at(header.sh_name).unwrap_or("");
            if section_name == HOOKS_SECTION {
                let data = file_range(header.sh_offset, header.sh_size, HOOKS_SECTION)?;
                hooks = Hooks::decode(data).map_err(|error| bad(error.to_string()))?;
                continue;
            }
            if section_name == LINES_SECTION {
                let data = file_range(header.sh_offset, header.sh_size, LINES_SECTION)?;
                lines = SrcMap::decode(data).map_err(|error| bad(error.to_string()))?;
                continue;
            }
            if header.sh_flags & u64::from(sh::SHF_ALLOC) == 0 {
                continue;
            }
            let nobits = header.sh_type == sh::SHT_NOBITS;
            let zeropage = header.sh_flags & u64::from(mos::SHF_MOS_ZEROPAGE) != 0;
            let write = header.sh_flags & u64::from(sh::SHF_WRITE) != 0;
            let exec = header.sh_flags & u64::from(sh::SHF_EXECINSTR) != 0;
            let kind = match (nobits, zeropage, write) {
                (true, true, _) => SegmentKind::ZeroPage,
                (true, false, _) => SegmentKind::Bss,
                (false, _, true) => SegmentKind::ReadWrite,
                (false, _, false) => SegmentKind::ReadOnly,
            };
            let run = address(header.sh_addr, section_name)?;
            let size = u32::try_from(header.sh_size)
                .map_err(|_| bad(format!("section {section_name} is larger than 4 GiB")))?;
            // The load address: where the PT_LOAD holding its file bytes stores them.
            let load = if nobits {
                run
            } else {
                elf.program_headers
                    .iter()
                    .filter(|p| p.p_type == ph::PT_LOAD)
                    .find(|p| {
                        header.sh_offset >= p.p_offset
                            && header.sh_offset.saturating_add(header.sh_size)
                                <= p.p_offset.saturating_add(p.p_filesz)
                    })
                    .map_or(Ok(run), |p| {
                        address(
                            p.p_paddr.saturating_add(header.sh_offset - p.p_offset),
                            section_name,
                        )
                    })?
            };
            position_of[index] = Some(sections.len());
            sections.push(ImageSection {
                name: section_name.to_owned(),
                run,
                load,
                size,
                kind,
                exec,
            });
        }

        let mut symbols = Vec::with_capacity(elf.syms.len());
        for entry in elf.syms.iter().skip(1) {
            if matches!(entry.st_type(), sym::STT_SECTION | sym::STT_FILE) {
                continue;
            }
            let section = if entry.st_shndx == sh::SHN_ABS as usize || entry.st_shndx == 0 {
                None
            } else {
                position_of.get(entry.st_shndx).copied().flatten()
            };
            symbols.push(ImageSymbol {
                name: elf.strtab.get_at(entry.st_name).unwrap_or("").to_owned(),
                value: entry.st_value as u32,
                size: entry.st_size as u32,
                global: entry.st_bind() != sym::STB_LOCAL,
                section,
            });
        }

        let image = Image {
            entry: address(elf.header.e_entry, "entry")?,
            flags: elf.header.e_flags,
            areas,
            sections,
            symbols,
            hooks,
            lines,
        };
        image.check_hooks(name)?;
        Ok(image)
    }

    /// Every hook's handler and chain slot must lie in loaded bytes, or an
    /// uploader would point the ROM at code it never wrote.
    pub(crate) fn check_hooks(&self, name: &str) -> Result<(), Error> {
        for record in &self.hooks.records {
            let kind = match record.kind {
                HookKind::Unknown => "HOOK_UNKNOWN",
                HookKind::Loop => "HOOK_LOOP",
            };
            if !self.loaded_in_place(u32::from(record.handler)) {
                return Err(Error::BadImage {
                    file: name.to_owned(),
                    reason: format!(
                        "the {kind} handler ${:04X} is not inside a loaded area that runs where it loads",
                        record.handler
                    ),
                });
            }
            let slot_missing = record.chain.is_some_and(|slot| {
                !self.loaded_in_place(u32::from(slot)) || !self.loaded_in_place(u32::from(slot) + 1)
            });
            if let (true, Some(slot)) = (slot_missing, record.chain) {
                return Err(Error::BadImage {
                    file: name.to_owned(),
                    reason: format!("the {kind} chain slot ${slot:04X} is not two loaded bytes"),
                });
            }
        }
        Ok(())
    }

    /// Whether an area loads a byte at `address` and runs it there: an
    /// uploader installs a hook right after writing the image, before any
    /// start-up code could copy bytes to their run address.
    fn loaded_in_place(&self, address: u32) -> bool {
        self.areas.iter().any(|area| {
            area.load == area.run && address >= area.load && u64::from(address) < area.end()
        })
    }

    /// The byte that runs at `address`, if a loaded area holds it.
    #[must_use]
    pub fn run_byte(&self, address: u32) -> Option<u8> {
        self.areas.iter().find_map(|area| {
            let offset = address.checked_sub(area.run)? as usize;
            area.bytes.get(offset).copied()
        })
    }
}

/// Whether the path `name` (as the assembler was given it) and `file`
/// name the same file: equal, or one ends with the other at a path
/// component (`adc.s` and `/home/me/adc/adc.s`).
fn same_file(name: &str, file: &str) -> bool {
    let name = name.replace('\\', "/");
    let file = file.replace('\\', "/");
    let (name, file) = (name.trim_start_matches("./"), file.trim_start_matches("./"));
    name == file || name.ends_with(&format!("/{file}")) || file.ends_with(&format!("/{name}"))
}
