//! The linked ELF executable, written with `object`'s low-level ELF writer
//! (its high-level API rejects `EM_MOS`).
//!
//! File order: header, program headers, each area's bytes, the hooks
//! section, `.symtab`, `.strtab`, `.shstrtab`, section headers. A section
//! with bytes points into the area that stores it, so the bytes exist once.

use isa::elf as mos;
use isa::objfmt::{HOOKS_SECTION, LINES_SECTION};
use object::elf;
use object::write::elf::{FileHeader, ProgramHeader, SectionHeader, SectionIndex, Sym, Writer};

use crate::error::Error;
use crate::image::Image;
use crate::layout::SegmentKind;

fn failed(error: object::write::Error) -> Error {
    Error::Format {
        format: "elf".into(),
        reason: error.to_string(),
    }
}

/// Writes `image` as an ELF32 `ET_EXEC` file.
///
/// # Errors
/// [`Error::Format`] if the writer fails (a file over 4 GiB).
pub fn write_elf(image: &Image) -> Result<Vec<u8>, Error> {
    let hooks = if image.hooks.records.is_empty() {
        None
    } else {
        Some(image.hooks.encode())
    };
    let lines = if image.lines.entries.is_empty() {
        None
    } else {
        Some(image.lines.encode())
    };
    let mut buffer = Vec::new();
    let mut writer = Writer::new(object::Endianness::Little, false, &mut buffer);

    // Phase one: reserve.
    writer.reserve_file_header();
    writer.reserve_program_headers(image.areas.len() as u32);
    let area_offsets: Vec<u64> = image
        .areas
        .iter()
        .map(|area| writer.reserve(area.bytes.len() as u64, 1))
        .collect();
    writer.reserve_null_section_index();
    let section_names: Vec<_> = image
        .sections
        .iter()
        .map(|section| writer.add_section_name(section.name.as_bytes()))
        .collect();
    let section_indices: Vec<SectionIndex> = image
        .sections
        .iter()
        .map(|_| writer.reserve_section_index())
        .collect();
    let hooks_name = hooks
        .as_ref()
        .map(|_| writer.add_section_name(HOOKS_SECTION.as_bytes()));
    let hooks_index = hooks.as_ref().map(|_| writer.reserve_section_index());
    let hooks_offset = hooks
        .as_ref()
        .map_or(0, |data| writer.reserve(data.len() as u64, 1));
    let lines_name = lines
        .as_ref()
        .map(|_| writer.add_section_name(LINES_SECTION.as_bytes()));
    let lines_index = lines.as_ref().map(|_| writer.reserve_section_index());
    let lines_offset = lines
        .as_ref()
        .map_or(0, |data| writer.reserve(data.len() as u64, 1));
    writer.reserve_null_symbol_index();
    let symbol_names: Vec<_> = image
        .symbols
        .iter()
        .map(|symbol| writer.add_string(symbol.name.as_bytes()))
        .collect();
    for symbol in &image.symbols {
        writer.reserve_symbol_index(symbol.section.map(|index| section_indices[index]));
    }
    let num_local = 1 + image.symbols.iter().filter(|s| !s.global).count() as u32;
    writer.reserve_symtab_section_index();
    writer.reserve_symtab();
    writer.reserve_strtab_section_index();
    writer.reserve_strtab().map_err(failed)?;
    writer.reserve_shstrtab_section_index();
    writer.reserve_shstrtab().map_err(failed)?;
    writer.reserve_section_headers();

    // Phase two: write, in the same order.
    writer
        .write_file_header(&FileHeader {
            os_abi: elf::ELFOSABI_NONE,
            abi_version: 0,
            e_type: elf::ET_EXEC,
            e_machine: elf::Machine(mos::EM_MOS),
            e_entry: u64::from(image.entry),
            e_flags: elf::FileFlags(image.flags),
        })
        .map_err(failed)?;
    writer.write_align_program_headers();
    for (area, offset) in image.areas.iter().zip(&area_offsets) {
        writer.write_program_header(&ProgramHeader {
            p_type: elf::PT_LOAD,
            p_flags: elf::PF_R | elf::PF_W | elf::PF_X,
            p_offset: *offset,
            p_vaddr: u64::from(area.run),
            p_paddr: u64::from(area.load),
            p_filesz: area.bytes.len() as u64,
            p_memsz: area.bytes.len() as u64,
            p_align: 1,
        });
    }
    for area in &image.areas {
        writer.write(&area.bytes);
    }
    if let Some(data) = &hooks {
        writer.write(data);
    }
    if let Some(data) = &lines {
        writer.write(data);
    }
    writer.write_null_symbol();
    for (symbol, name) in image.symbols.iter().zip(&symbol_names) {
        writer.write_symbol(&Sym {
            section: symbol.section.map(|index| section_indices[index].0),
            st_name: writer.string_offset(Some(*name)),
            st_info: elf::SymbolInfo::new(
                if symbol.global {
                    elf::STB_GLOBAL
                } else {
                    elf::STB_LOCAL
                },
                if symbol.section.is_some() {
                    elf::STT_OBJECT
                } else {
                    elf::STT_NOTYPE
                },
            ),
            st_other: elf::SymbolOther(elf::STV_DEFAULT.0),
            st_shndx: if symbol.section.is_some() {
                elf::SymbolSection(0)
            } else {
                elf::SHN_ABS
            },
            st_value: u64::from(symbol.value),
            st_size: u64::from(symbol.size),
        });
    }
    writer.write_strtab();
    writer.write_shstrtab();
    writer.write_null_section_header();
    for (section, name) in image.sections.iter().zip(&section_names) {
        let nobits = matches!(section.kind, SegmentKind::Bss | SegmentKind::ZeroPage);
        // Where the section's bytes sit in the file: inside the area storing them.
        let offset = image
            .areas
            .iter()
            .zip(&area_offsets)
            .find(|(area, _)| {
                section.load >= area.load
                    && u64::from(section.load) + u64::from(section.size) <= area.end()
            })
            .map(|(area, offset)| offset + u64::from(section.load - area.load));
        let mut flags = elf::SHF_ALLOC.0;
        if section.exec {
            flags |= elf::SHF_EXECINSTR.0;
        }
        match section.kind {
            SegmentKind::ReadOnly => {}
            SegmentKind::ReadWrite | SegmentKind::Bss => flags |= elf::SHF_WRITE.0,
            SegmentKind::ZeroPage => flags |= elf::SHF_WRITE.0 | u64::from(mos::SHF_MOS_ZEROPAGE),
        }
        let (sh_type, sh_offset) = match (nobits, offset) {
            (false, Some(offset)) => (elf::SHT_PROGBITS, offset),
            _ => (elf::SHT_NOBITS, area_offsets.last().copied().unwrap_or(0)),
        };
        writer.write_section_header(&SectionHeader {
            sh_name: writer.section_name_offset(Some(*name)),
            sh_type,
            sh_flags: elf::SectionFlags(flags),
            sh_addr: u64::from(section.run),
            sh_offset,
            sh_size: u64::from(section.size),
            sh_link: 0,
            sh_info: 0,
            sh_addralign: 1,
            sh_entsize: 0,
        });
    }
    if let (Some(data), Some(name), Some(_)) = (&hooks, hooks_name, hooks_index) {
        writer.write_section_header(&SectionHeader {
            sh_name: writer.section_name_offset(Some(name)),
            sh_type: elf::SHT_PROGBITS,
            sh_flags: elf::SectionFlags(0),
            sh_addr: 0,
            sh_offset: hooks_offset,
            sh_size: data.len() as u64,
            sh_link: 0,
            sh_info: 0,
            sh_addralign: 1,
            sh_entsize: 0,
        });
    }
    if let (Some(data), Some(name), Some(_)) = (&lines, lines_name, lines_index) {
        writer.write_section_header(&SectionHeader {
            sh_name: writer.section_name_offset(Some(name)),
            sh_type: elf::SHT_PROGBITS,
            sh_flags: elf::SectionFlags(0),
            sh_addr: 0,
            sh_offset: lines_offset,
            sh_size: data.len() as u64,
            sh_link: 0,
            sh_info: 0,
            sh_addralign: 1,
            sh_entsize: 0,
        });
    }
    writer.write_symtab_section_header(num_local);
    writer.write_strtab_section_header();
    writer.write_shstrtab_section_header();
    drop(writer);
    Ok(buffer)
}
