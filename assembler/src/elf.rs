//! Writes the ELF32 relocatable object (docs/ARCHITECTURE.md, "The object
//! format") with `object::write::elf::Writer`: a section per segment, the
//! symbol table, `.rela<segment>` sections with llvm-mos relocation
//! numbers, `.scorpion.srcmap`, `.scorpion.assert` and `.scorpion.fill`.

use isa::elf::{EM_MOS, SHF_MOS_ZEROPAGE, STO_MOS_ZEROPAGE};
use isa::objfmt::{
    ASSERT_SECTION, AssertAction, Assertion, Expr, FILL_SECTION, FillRun, SRCMAP_SECTION,
    SourceLoc, SrcMap, SymbolLoc,
};
use object::Endianness;
use object::elf;
use object::write::elf::{FileHeader, Rel, SectionHeader, Sym, Writer};

use crate::diag::Files;
use crate::layout::{OutSymKind, Output, Target, assert_ops};

fn section_flags(name: &str, zp: bool) -> u64 {
    let mut flags = elf::SHF_ALLOC.0;
    if name == "CODE" {
        flags |= elf::SHF_EXECINSTR.0;
    }
    if zp || matches!(name, "DATA" | "BSS" | "ZEROPAGE") {
        flags |= elf::SHF_WRITE.0;
    }
    if zp {
        flags |= u64::from(SHF_MOS_ZEROPAGE);
    }
    flags
}

/// Serialises `out` as an ELF object (its source map items are moved
/// into the object, not copied).
pub(crate) fn write_object(
    out: &mut Output,
    files: &Files,
    file_name: &str,
    e_flags: u32,
) -> Result<Vec<u8>, object::write::Error> {
    let rela_names: Vec<String> = out
        .sections
        .iter()
        .map(|s| format!(".rela{}", s.name))
        .collect();
    let mut buffer = Vec::new();
    let mut w = Writer::new(Endianness::Little, false, &mut buffer);
    w.reserve_file_header();

    // Section indices, in header order.
    let mut section_index = Vec::with_capacity(out.sections.len());
    let mut section_name = Vec::with_capacity(out.sections.len());
    for section in &out.sections {
        section_index.push(w.reserve_section_index());
        section_name.push(w.add_section_name(section.name.as_bytes()));
    }
    let mut rela = Vec::new();
    for (i, section) in out.sections.iter().enumerate() {
        if !section.relocs.is_empty() {
            w.reserve_section_index();
            rela.push((i, w.add_section_name(rela_names[i].as_bytes())));
        }
    }
    w.reserve_section_index();
    let srcmap_name = w.add_section_name(SRCMAP_SECTION.as_bytes());
    let assert_section = if out.asserts.is_empty() {
        None
    } else {
        let index = w.reserve_section_index();
        Some((index, w.add_section_name(ASSERT_SECTION.as_bytes())))
    };
    let fill_section = if out.fills.is_empty() {
        None
    } else {
        w.reserve_section_index();
        Some(w.add_section_name(FILL_SECTION.as_bytes()))
    };

    // Symbols: null, file, sections, locals, then globals.
    w.reserve_null_symbol_index();
    let file_sym_name = w.add_string(file_name.as_bytes());
    w.reserve_symbol_index(None);
    let mut section_sym = Vec::with_capacity(out.sections.len());
    for index in &section_index {
        section_sym.push(w.reserve_symbol_index(Some(*index)));
    }
    let mut sym_index = vec![0u32; out.symbols.len()];
    let mut sym_name = vec![None; out.symbols.len()];
    for pass_global in [false, true] {
        for (i, sym) in out.symbols.iter().enumerate() {
            if sym.global != pass_global {
                continue;
            }
            let section = match sym.kind {
                OutSymKind::Sec(section, _) => Some(section_index[section]),
                _ => None,
            };
            sym_index[i] = w.reserve_symbol_index(section).0;
            sym_name[i] = Some(w.add_string(sym.name.as_bytes()));
        }
    }
    let num_local =
        2 + out.sections.len() as u32 + out.symbols.iter().filter(|s| !s.global).count() as u32;
    w.reserve_symtab_section_index();
    w.reserve_strtab_section_index();

    // Metadata contents (they need the symbol numbers).
    let target_index = |target: Target| -> Option<u32> {
        match target {
            Target::Section(section) => section_sym.get(section).map(|s| s.0),
            Target::Symbol(symbol) => sym_index.get(symbol).copied(),
            Target::Absolute => Some(0),
        }
    };
    let mut entries = std::mem::take(&mut out.items);
    for entry in &mut entries {
        entry.section = section_index
            .get(entry.section as usize)
            .map_or(0, |index| index.0);
    }
    // Sorted here, in place, so that encoding needs no sorted copy.
    entries.sort_unstable();
    let srcmap = SrcMap {
        files: files.files.iter().map(|f| f.name.clone()).collect(),
        entries,
        symbols: out
            .symbols
            .iter()
            .enumerate()
            .filter_map(|(i, sym)| {
                let (file, line, column) = sym.place?;
                (line > 0).then_some(SymbolLoc {
                    symbol: sym_index[i],
                    loc: SourceLoc { file, line, column },
                    expanded_at: sym.expanded_at.map(|(file, line, column)| SourceLoc {
                        file,
                        line,
                        column,
                    }),
                })
            })
            .collect(),
    }
    .encode();
    let asserts: Vec<Assertion> = out
        .asserts
        .iter()
        .filter_map(|a| {
            Some(Assertion {
                action: if a.error {
                    AssertAction::Error
                } else {
                    AssertAction::Warning
                },
                file: files.name(a.file).to_string(),
                line: a.line,
                column: a.column,
                message: a.message.clone(),
                expr: Expr {
                    ops: assert_ops(&a.ops, target_index)?,
                },
            })
        })
        .collect();
    let assert_bytes = Assertion::encode_all(&asserts);
    let fills: Vec<FillRun> = out
        .fills
        .iter()
        .filter_map(|run| {
            Some(FillRun {
                section: section_index.get(run.section as usize)?.0,
                ..*run
            })
        })
        .collect();
    let fill_bytes = FillRun::encode_all(&fills);

    // File layout.
    let mut data_offset = Vec::with_capacity(out.sections.len());
    for section in &out.sections {
        let len = if section.nobits {
            0
        } else {
            section.data.len() as u64
        };
        data_offset.push(w.reserve(len, u64::from(section.align.max(1))));
    }
    let srcmap_offset = w.reserve(srcmap.len() as u64, 1);
    let assert_offset = if assert_section.is_some() {
        w.reserve(assert_bytes.len() as u64, 1)
    } else {
        0
    };
    let fill_offset = if fill_section.is_some() {
        w.reserve(fill_bytes.len() as u64, 1)
    } else {
        0
    };
    w.reserve_symtab();
    w.reserve_symtab_shndx();
    w.reserve_strtab()?;
    let mut rela_offset = Vec::with_capacity(rela.len());
    for (i, _) in &rela {
        rela_offset.push(w.reserve_relocations(out.sections[*i].relocs.len(), true));
    }
    w.reserve_shstrtab_section_index();
    w.reserve_shstrtab()?;
    w.reserve_section_headers();

    // Write.
    w.write_file_header(&FileHeader {
        os_abi: elf::ELFOSABI_NONE,
        abi_version: 0,
        e_type: elf::ET_REL,
        e_machine: elf::Machine(EM_MOS),
        e_entry: 0,
        e_flags: elf::FileFlags(e_flags),
    })?;
    for section in &out.sections {
        w.write_align(u64::from(section.align.max(1)));
        if !section.nobits {
            w.write(&section.data);
        }
    }
    w.write(&srcmap);
    if assert_section.is_some() {
        w.write(&assert_bytes);
    }
    if fill_section.is_some() {
        w.write(&fill_bytes);
    }
    w.write_null_symbol();
    w.write_symbol(&Sym {
        section: None,
        st_name: w.string_offset(Some(file_sym_name)),
        st_info: elf::SymbolInfo::new(elf::STB_LOCAL, elf::STT_FILE),
        st_other: elf::SymbolOther(0),
        st_shndx: elf::SHN_ABS,
        st_value: 0,
        st_size: 0,
    });
    for index in &section_index {
        w.write_symbol(&Sym {
            section: Some(index.0),
            st_name: 0,
            st_info: elf::SymbolInfo::new(elf::STB_LOCAL, elf::STT_SECTION),
            st_other: elf::SymbolOther(0),
            st_shndx: elf::SymbolSection(0),
            st_value: 0,
            st_size: 0,
        });
    }
    for pass_global in [false, true] {
        for (i, sym) in out.symbols.iter().enumerate() {
            if sym.global != pass_global {
                continue;
            }
            let bind = if sym.global {
                elf::STB_GLOBAL
            } else {
                elf::STB_LOCAL
            };
            let (section, st_shndx, st_value, st_other) = match sym.kind {
                OutSymKind::Abs(value) => (None, elf::SHN_ABS, u64::from(value as u32), 0),
                OutSymKind::Sec(section, offset) => (
                    Some(section_index[section].0),
                    elf::SymbolSection(0),
                    u64::from(offset),
                    0,
                ),
                OutSymKind::Undef { zp } => (
                    None,
                    elf::SHN_UNDEF,
                    0,
                    if zp { STO_MOS_ZEROPAGE } else { 0 },
                ),
            };
            w.write_symbol(&Sym {
                section,
                st_name: w.string_offset(sym_name[i]),
                st_info: elf::SymbolInfo::new(bind, elf::STT_NOTYPE),
                st_other: elf::SymbolOther(st_other),
                st_shndx,
                st_value,
                st_size: 0,
            });
        }
    }
    w.write_symtab_shndx();
    w.write_strtab();
    for (i, _) in &rela {
        w.write_align_relocation();
        for reloc in &out.sections[*i].relocs {
            let r_sym = target_index(reloc.target).unwrap_or(0);
            w.write_relocation(
                true,
                &Rel {
                    r_offset: u64::from(reloc.offset),
                    r_sym,
                    r_type: elf::RelocationType(reloc.r_type),
                    r_addend: reloc.addend,
                },
            );
        }
    }
    w.write_shstrtab();

    w.write_null_section_header();
    let symtab_index = w.symtab_index();
    for (i, section) in out.sections.iter().enumerate() {
        w.write_section_header(&SectionHeader {
            sh_name: w.section_name_offset(Some(section_name[i])),
            sh_type: if section.nobits {
                elf::SHT_NOBITS
            } else {
                elf::SHT_PROGBITS
            },
            sh_flags: elf::SectionFlags(section_flags(&section.name, section.zp)),
            sh_addr: 0,
            sh_offset: data_offset[i],
            sh_size: u64::from(section.size),
            sh_link: 0,
            sh_info: 0,
            sh_addralign: u64::from(section.align.max(1)),
            sh_entsize: 0,
        });
    }
    for ((i, name), offset) in rela.iter().zip(&rela_offset) {
        w.write_relocation_section_header(
            *name,
            section_index[*i],
            symtab_index,
            *offset,
            out.sections[*i].relocs.len(),
            true,
        );
    }
    let metadata = |w: &mut Writer<'_>, name, offset: u64, size: usize| {
        w.write_section_header(&SectionHeader {
            sh_name: w.section_name_offset(Some(name)),
            sh_type: elf::SHT_PROGBITS,
            sh_flags: elf::SectionFlags(0),
            sh_addr: 0,
            sh_offset: offset,
            sh_size: size as u64,
            sh_link: 0,
            sh_info: 0,
            sh_addralign: 1,
            sh_entsize: 0,
        });
    };
    metadata(&mut w, srcmap_name, srcmap_offset, srcmap.len());
    if let Some((_, name)) = assert_section {
        metadata(&mut w, name, assert_offset, assert_bytes.len());
    }
    if let Some(name) = fill_section {
        metadata(&mut w, name, fill_offset, fill_bytes.len());
    }
    w.write_symtab_section_header(num_local);
    w.write_symtab_shndx_section_header();
    w.write_strtab_section_header();
    w.write_shstrtab_section_header();
    drop(w);
    Ok(buffer)
}
