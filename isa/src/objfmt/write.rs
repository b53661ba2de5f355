//! The one writer of 6502 ELF relocatable objects (docs/ARCHITECTURE.md,
//! "The object format"), over `object`'s low-level ELF writer, which takes
//! any `e_machine` (its high-level `write::Object` refuses `EM_MOS`).
//!
//! A [`RelObject`] describes the object: its sections with their bytes and
//! relocations, its symbols, and our metadata sections. The assembler fills
//! one from its output; [`ObjectBuilder`](super::ObjectBuilder) fills one
//! for tests, including the invalid objects other producers could write
//! (any machine, flags, section types, `SHT_REL`). [`RelObject::write`]
//! lays it out the same way for both:
//!
//! - section headers: null, the sections in order (section `i` is ELF
//!   section `i + 1`), a `.rela<name>` (or `.rel<name>`) per section with
//!   relocations, `.scorpion.srcmap`, `.scorpion.assert`,
//!   `.scorpion.fill` (each only when present), `.symtab`,
//!   `.symtab_shndx` (only when needed), `.strtab`, `.shstrtab`;
//! - symbols: null, the `STT_FILE` symbol (when named), one `STT_SECTION`
//!   symbol per section (when asked for), the local symbols, then the
//!   global and weak ones, each group in the order given
//!   ([`RelObject::numbering`] tells the caller the resulting indices, which
//!   the metadata refers to).

use object::elf;
use object::write::elf::{FileHeader, Rel, SectionHeader, SectionIndex, Sym, Writer};

use super::{
    ASSERT_SECTION, Assertion, CONDES_SECTION, CondesEntry, EXPRS_SECTION, ExprField, ExprSymbol,
    FILL_SECTION, FillRun, SRCMAP_SECTION, SrcMap, VALUES_SECTION,
};
use crate::elf::{EF_MOS_ARCH_6502, EM_MOS, STO_MOS_ZEROPAGE};

/// A section of a [`RelObject`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjSection {
    /// The section's name (the ca65 segment's).
    pub name: String,
    /// `sh_type`: `SHT_PROGBITS`, `SHT_NOBITS` or (from a test) anything.
    pub sh_type: u32,
    /// `sh_flags`.
    pub sh_flags: u64,
    /// `sh_addralign`; the data is placed at a multiple of it in the file.
    pub align: u64,
    /// The bytes (empty for `SHT_NOBITS`).
    pub data: Vec<u8>,
    /// `sh_size`: the data's length, or the reserved size of `SHT_NOBITS`.
    pub size: u32,
    /// Its relocations.
    pub relocs: Vec<ObjReloc>,
}

impl ObjSection {
    /// Whether the file holds no bytes for it.
    #[must_use]
    pub fn is_nobits(&self) -> bool {
        self.sh_type == elf::SHT_NOBITS.0
    }
}

/// What a relocation refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RelocTarget {
    /// A symbol, by its index in [`RelObject::symbols`].
    Symbol(usize),
    /// The `STT_SECTION` symbol of a section, by index in
    /// [`RelObject::sections`] (needs [`RelObject::section_symbols`]).
    Section(usize),
    /// No symbol (`r_sym = 0`, `S = 0`).
    Absolute,
}

/// A relocation (`SHT_RELA`, or `SHT_REL` without the addend).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ObjReloc {
    /// `r_offset` in its section.
    pub offset: u32,
    /// `R_MOS_*` (`isa::elf`).
    pub r_type: u32,
    /// The symbol.
    pub target: RelocTarget,
    /// `r_addend`.
    pub addend: i64,
}

/// A symbol's binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// `STB_LOCAL`.
    Local,
    /// `STB_GLOBAL`: an export, or an import when undefined.
    Global,
    /// `STB_WEAK`.
    Weak,
}

/// Where a symbol is defined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Definition {
    /// At an offset in a section (index in [`RelObject::sections`]).
    Section(usize, u32),
    /// A constant (`SHN_ABS`).
    Absolute(u32),
    /// Not defined here (an import).
    Undefined,
    /// A section's own `STT_SECTION` symbol, placed among the locals (a
    /// test's way to write what other producers write).
    SectionSymbol(usize),
}

/// A symbol of a [`RelObject`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjSymbol {
    /// The name (`::` between scopes).
    pub name: String,
    /// Local, global or weak.
    pub binding: Binding,
    /// Where it is defined.
    pub def: Definition,
    /// `STO_MOS_ZEROPAGE` (`.importzp`).
    pub zeropage: bool,
}

/// A 6502 relocatable object, described.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RelObject {
    /// `e_machine` (`EM_MOS`).
    pub machine: u16,
    /// `e_flags`.
    pub flags: u32,
    /// `e_type` (`ET_REL`).
    pub e_type: u16,
    /// The `STT_FILE` symbol's name, if one is written.
    pub file_name: Option<String>,
    /// Whether every section gets an `STT_SECTION` symbol after the file
    /// symbol (what [`RelocTarget::Section`] refers to).
    pub section_symbols: bool,
    /// `SHT_RELA` (with addends, ours) or `SHT_REL`.
    pub rela: bool,
    /// The sections.
    pub sections: Vec<ObjSection>,
    /// The symbols; the table orders locals before globals.
    pub symbols: Vec<ObjSymbol>,
    /// `.scorpion.srcmap`, numbered by [`RelObject::numbering`].
    pub srcmap: Option<SrcMap>,
    /// `.scorpion.assert` (left out when empty), numbered the same way.
    pub asserts: Vec<Assertion>,
    /// `.scorpion.fill` (left out when empty); `section` is the ELF index.
    pub fills: Vec<FillRun>,
    /// `.scorpion.exprs` (left out when empty); `section` is the ELF index,
    /// symbols numbered by [`RelObject::numbering`].
    pub fields: Vec<ExprField>,
    /// `.scorpion.condes` (left out when empty), numbered the same way.
    pub condes: Vec<CondesEntry>,
    /// `.scorpion.values` (left out when empty), numbered the same way.
    pub values: Vec<ExprSymbol>,
}

impl Default for RelObject {
    fn default() -> RelObject {
        RelObject {
            machine: EM_MOS,
            flags: EF_MOS_ARCH_6502,
            e_type: elf::ET_REL.0,
            file_name: None,
            section_symbols: false,
            rela: true,
            sections: Vec::new(),
            symbols: Vec::new(),
            srcmap: None,
            asserts: Vec::new(),
            fills: Vec::new(),
            fields: Vec::new(),
            condes: Vec::new(),
            values: Vec::new(),
        }
    }
}

/// The `.symtab` indices a [`RelObject`] gets, for the metadata that
/// refers to symbols and sections by number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Numbering {
    /// `.symtab` index of each of [`RelObject::symbols`].
    pub symbols: Vec<u32>,
    /// `.symtab` index of each section's `STT_SECTION` symbol (0 without
    /// [`RelObject::section_symbols`]).
    pub section_symbols: Vec<u32>,
    /// How many symbols are local, the null symbol included (`sh_info`).
    pub locals: u32,
}

impl Numbering {
    /// The ELF section header index of section `index`.
    #[must_use]
    pub fn section(index: usize) -> u32 {
        u32::try_from(index + 1).unwrap_or(u32::MAX)
    }

    /// The `r_sym` of a relocation target.
    #[must_use]
    pub fn target(&self, target: RelocTarget) -> u32 {
        match target {
            RelocTarget::Symbol(symbol) => self.symbols.get(symbol).copied().unwrap_or(0),
            RelocTarget::Section(section) => {
                self.section_symbols.get(section).copied().unwrap_or(0)
            }
            RelocTarget::Absolute => 0,
        }
    }
}

fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

impl RelObject {
    /// The `.symtab` index every symbol and section symbol will have.
    #[must_use]
    pub fn numbering(&self) -> Numbering {
        let mut next = 1 + u32::from(self.file_name.is_some());
        let section_symbols = if self.section_symbols {
            let numbers = (next..next + count(self.sections.len())).collect();
            next += count(self.sections.len());
            numbers
        } else {
            vec![0; self.sections.len()]
        };
        let mut symbols = vec![0; self.symbols.len()];
        for global in [false, true] {
            for (number, symbol) in symbols.iter_mut().zip(&self.symbols) {
                if (symbol.binding != Binding::Local) == global {
                    *number = next;
                    next += 1;
                }
            }
        }
        let locals = 1
            + u32::from(self.file_name.is_some())
            + if self.section_symbols {
                count(self.sections.len())
            } else {
                0
            }
            + count(
                self.symbols
                    .iter()
                    .filter(|s| s.binding == Binding::Local)
                    .count(),
            );
        Numbering {
            symbols,
            section_symbols,
            locals,
        }
    }

    /// The object's bytes.
    ///
    /// # Errors
    /// `object`'s, for tables past ELF32's limits.
    pub fn write(&self) -> Result<Vec<u8>, object::write::Error> {
        let numbering = self.numbering();
        let srcmap = self.srcmap.as_ref().map(SrcMap::encode);
        let asserts = (!self.asserts.is_empty()).then(|| Assertion::encode_all(&self.asserts));
        let fills = (!self.fills.is_empty()).then(|| FillRun::encode_all(&self.fills));
        let fields = (!self.fields.is_empty()).then(|| ExprField::encode_all(&self.fields));
        let condes = (!self.condes.is_empty()).then(|| CondesEntry::encode_all(&self.condes));
        let values = (!self.values.is_empty()).then(|| ExprSymbol::encode_all(&self.values));
        let metadata: Vec<(&str, Vec<u8>)> = [
            (SRCMAP_SECTION, srcmap),
            (ASSERT_SECTION, asserts),
            (FILL_SECTION, fills),
            (EXPRS_SECTION, fields),
            (CONDES_SECTION, condes),
            (VALUES_SECTION, values),
        ]
        .into_iter()
        .filter_map(|(name, bytes)| Some((name, bytes?)))
        .collect();
        let rel_prefix = if self.rela { ".rela" } else { ".rel" };

        let mut buffer = Vec::new();
        let mut w = Writer::new(object::Endianness::Little, false, &mut buffer);
        w.reserve_file_header();

        // Section header indices and names, in header order.
        let mut section_index = Vec::with_capacity(self.sections.len());
        let mut section_name = Vec::with_capacity(self.sections.len());
        for section in &self.sections {
            section_index.push(w.reserve_section_index());
            section_name.push(w.add_section_name(section.name.as_bytes()));
        }
        let rel_names: Vec<(usize, String)> = self
            .sections
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.relocs.is_empty())
            .map(|(i, s)| (i, format!("{rel_prefix}{}", s.name)))
            .collect();
        let mut rel = Vec::with_capacity(rel_names.len());
        for (i, name) in &rel_names {
            w.reserve_section_index();
            rel.push((*i, w.add_section_name(name.as_bytes())));
        }
        let mut meta = Vec::with_capacity(metadata.len());
        for (name, _) in &metadata {
            w.reserve_section_index();
            meta.push(w.add_section_name(name.as_bytes()));
        }

        // Symbols, in .symtab order.
        w.reserve_null_symbol_index();
        let file_name = self.file_name.as_ref().map(|name| {
            let id = w.add_string(name.as_bytes());
            w.reserve_symbol_index(None);
            id
        });
        if self.section_symbols {
            for index in &section_index {
                w.reserve_symbol_index(Some(*index));
            }
        }
        let mut order = Vec::with_capacity(self.symbols.len());
        for global in [false, true] {
            for (i, symbol) in self.symbols.iter().enumerate() {
                if (symbol.binding != Binding::Local) == global {
                    order.push(i);
                }
            }
        }
        let mut symbol_name = vec![None; self.symbols.len()];
        for &i in &order {
            let symbol = &self.symbols[i];
            let section = match symbol.def {
                Definition::Section(section, _) | Definition::SectionSymbol(section) => {
                    section_index.get(section).copied()
                }
                _ => None,
            };
            w.reserve_symbol_index(section);
            if !matches!(symbol.def, Definition::SectionSymbol(_)) {
                symbol_name[i] = Some(w.add_string(symbol.name.as_bytes()));
            }
        }
        w.reserve_symtab_section_index();
        w.reserve_strtab_section_index();

        // File layout: section data, metadata, tables, relocations.
        let mut data_offset = Vec::with_capacity(self.sections.len());
        for section in &self.sections {
            let len = if section.is_nobits() {
                0
            } else {
                section.data.len() as u64
            };
            data_offset.push(w.reserve(len, section.align.max(1)));
        }
        let meta_offset: Vec<u64> = metadata
            .iter()
            .map(|(_, bytes)| w.reserve(bytes.len() as u64, 1))
            .collect();
        w.reserve_symtab();
        w.reserve_symtab_shndx();
        w.reserve_strtab()?;
        let rel_offset: Vec<u64> = rel
            .iter()
            .map(|(i, _)| w.reserve_relocations(self.sections[*i].relocs.len(), self.rela))
            .collect();
        w.reserve_shstrtab_section_index();
        w.reserve_shstrtab()?;
        w.reserve_section_headers();

        w.write_file_header(&FileHeader {
            os_abi: elf::ELFOSABI_NONE,
            abi_version: 0,
            e_type: elf::FileType(self.e_type),
            e_machine: elf::Machine(self.machine),
            e_entry: 0,
            e_flags: elf::FileFlags(self.flags),
        })?;
        for section in &self.sections {
            w.write_align(section.align.max(1));
            if !section.is_nobits() {
                w.write(&section.data);
            }
        }
        for (_, bytes) in &metadata {
            w.write(bytes);
        }
        w.write_null_symbol();
        if let Some(name) = file_name {
            w.write_symbol(&Sym {
                section: None,
                st_name: w.string_offset(Some(name)),
                st_info: elf::SymbolInfo::new(elf::STB_LOCAL, elf::STT_FILE),
                st_other: elf::SymbolOther(0),
                st_shndx: elf::SHN_ABS,
                st_value: 0,
                st_size: 0,
            });
        }
        if self.section_symbols {
            for index in &section_index {
                w.write_symbol(&section_symbol(*index));
            }
        }
        for &i in &order {
            let symbol = &self.symbols[i];
            let (section, st_shndx, st_value) = match symbol.def {
                Definition::SectionSymbol(section) => {
                    let index = section_index.get(section).copied().unwrap_or_default();
                    w.write_symbol(&section_symbol(index));
                    continue;
                }
                Definition::Section(section, offset) => (
                    section_index.get(section).map(|index| index.0),
                    elf::SymbolSection(0),
                    offset,
                ),
                Definition::Absolute(value) => (None, elf::SHN_ABS, value),
                Definition::Undefined => (None, elf::SHN_UNDEF, 0),
            };
            let bind = match symbol.binding {
                Binding::Local => elf::STB_LOCAL,
                Binding::Global => elf::STB_GLOBAL,
                Binding::Weak => elf::STB_WEAK,
            };
            w.write_symbol(&Sym {
                section,
                st_name: w.string_offset(symbol_name[i]),
                st_info: elf::SymbolInfo::new(bind, elf::STT_NOTYPE),
                st_other: elf::SymbolOther(if symbol.zeropage { STO_MOS_ZEROPAGE } else { 0 }),
                st_shndx,
                st_value: u64::from(st_value),
                st_size: 0,
            });
        }
        w.write_symtab_shndx();
        w.write_strtab();
        for (i, _) in &rel {
            w.write_align_relocation();
            for reloc in &self.sections[*i].relocs {
                w.write_relocation(
                    self.rela,
                    &Rel {
                        r_offset: u64::from(reloc.offset),
                        r_sym: numbering.target(reloc.target),
                        r_type: elf::RelocationType(reloc.r_type),
                        r_addend: reloc.addend,
                    },
                );
            }
        }
        w.write_shstrtab();

        w.write_null_section_header();
        let symtab = w.symtab_index();
        for (i, section) in self.sections.iter().enumerate() {
            w.write_section_header(&SectionHeader {
                sh_name: w.section_name_offset(Some(section_name[i])),
                sh_type: elf::SectionType(section.sh_type),
                sh_flags: elf::SectionFlags(section.sh_flags),
                sh_addr: 0,
                sh_offset: data_offset[i],
                sh_size: u64::from(section.size),
                sh_link: 0,
                sh_info: 0,
                sh_addralign: section.align.max(1),
                sh_entsize: 0,
            });
        }
        for ((i, name), offset) in rel.iter().zip(&rel_offset) {
            w.write_relocation_section_header(
                *name,
                section_index[*i],
                symtab,
                *offset,
                self.sections[*i].relocs.len(),
                self.rela,
            );
        }
        for ((name, offset), (_, bytes)) in meta.iter().zip(&meta_offset).zip(&metadata) {
            w.write_section_header(&SectionHeader {
                sh_name: w.section_name_offset(Some(*name)),
                sh_type: elf::SHT_PROGBITS,
                sh_flags: elf::SectionFlags(0),
                sh_addr: 0,
                sh_offset: *offset,
                sh_size: bytes.len() as u64,
                sh_link: 0,
                sh_info: 0,
                sh_addralign: 1,
                sh_entsize: 0,
            });
        }
        w.write_symtab_section_header(numbering.locals);
        w.write_symtab_shndx_section_header();
        w.write_strtab_section_header();
        w.write_shstrtab_section_header();
        drop(w);
        Ok(buffer)
    }
}

fn section_symbol(index: SectionIndex) -> Sym {
    Sym {
        section: Some(index.0),
        st_name: 0,
        st_info: elf::SymbolInfo::new(elf::STB_LOCAL, elf::STT_SECTION),
        st_other: elf::SymbolOther(0),
        st_shndx: elf::SymbolSection(0),
        st_value: 0,
        st_size: 0,
    }
}
