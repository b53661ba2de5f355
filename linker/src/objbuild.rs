//! Writing 6502 ELF relocatable objects from a description, with `object`'s
//! low-level ELF writer.
//!
//! Tests build the objects they link with this (so the linker is tested
//! without the assembler), and it shows what another producer's object
//! looks like to the linker: any machine, flags, section types and
//! relocation numbers can be written, valid or not.
//!
//! ```
//! use linker::objbuild::{ObjectBuilder, SymbolDef};
//! use isa::elf::R_MOS_ADDR16;
//!
//! let mut obj = ObjectBuilder::new();
//! let code = obj.code("CODE", &[0x4C, 0x00, 0x00]); // JMP target
//! let target = obj.import("target", false);
//! obj.reloc(code, 1, R_MOS_ADDR16, target, 0);
//! obj.global("start", SymbolDef::Section(code, 0));
//! let bytes = obj.build();
//! assert_eq!(&bytes[..4], b"\x7fELF");
//! ```

use isa::elf as mos;
use isa::objfmt::{
    ASSERT_SECTION, Assertion, Expr, ExprOp, SRCMAP_SECTION, SourceLoc, SrcMap, SrcMapEntry,
    SymbolLoc,
};
use object::elf;
use object::write::elf::{FileHeader, Rel, SectionHeader, SectionIndex, Sym, Writer};

/// A section of the object being built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SectionId(pub usize);

/// A symbol of the object being built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SymbolId(pub usize);

/// Where a symbol is defined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SymbolDef {
    /// At an offset in a section.
    Section(SectionId, u32),
    /// A constant (`SHN_ABS`).
    Absolute(u32),
    /// Not defined here (an import).
    Undefined,
}

#[derive(Debug, Clone)]
struct BuiltSection {
    name: String,
    data: Vec<u8>,
    size: u32,
    nobits: bool,
    flags: u64,
    align: u64,
    sh_type: u32,
    relocs: Vec<(u32, u32, SymbolId, i64)>,
}

#[derive(Debug, Clone)]
struct BuiltSymbol {
    name: String,
    global: bool,
    weak: bool,
    def: SymbolDef,
    zeropage: bool,
    section_symbol: bool,
}

/// Builds an ELF32 relocatable object.
#[derive(Debug, Clone)]
pub struct ObjectBuilder {
    machine: u16,
    flags: u32,
    e_type: u16,
    sections: Vec<BuiltSection>,
    symbols: Vec<BuiltSymbol>,
    files: Vec<String>,
    items: Vec<(SectionId, u32, u32, u32, u32)>,
    symbol_locs: Vec<(SymbolId, u32, u32, u32)>,
    asserts: Vec<Assertion>,
    rel_instead_of_rela: bool,
}

impl Default for ObjectBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl ObjectBuilder {
    /// An empty NMOS 6502 object (`EM_MOS`, `EF_MOS_ARCH_6502`).
    #[must_use]
    pub fn new() -> ObjectBuilder {
        ObjectBuilder {
            machine: mos::EM_MOS,
            flags: mos::EF_MOS_ARCH_6502,
            e_type: elf::ET_REL.0,
            sections: Vec::new(),
            symbols: Vec::new(),
            files: Vec::new(),
            items: Vec::new(),
            symbol_locs: Vec::new(),
            asserts: Vec::new(),
            rel_instead_of_rela: false,
        }
    }

    /// Sets `e_machine` (to test other producers).
    pub fn machine(&mut self, machine: u16) -> &mut Self {
        self.machine = machine;
        self
    }

    /// Sets `e_flags`.
    pub fn flags(&mut self, flags: u32) -> &mut Self {
        self.flags = flags;
        self
    }

    /// Sets `e_type` (`ET_REL` = 1 by default).
    pub fn file_type(&mut self, e_type: u16) -> &mut Self {
        self.e_type = e_type;
        self
    }

    /// Writes `SHT_REL` relocation sections instead of `SHT_RELA`.
    pub fn use_rel(&mut self) -> &mut Self {
        self.rel_instead_of_rela = true;
        self
    }

    fn add(&mut self, section: BuiltSection) -> SectionId {
        self.sections.push(section);
        SectionId(self.sections.len() - 1)
    }

    /// An executable `SHT_PROGBITS` section.
    pub fn code(&mut self, name: &str, data: &[u8]) -> SectionId {
        self.progbits(name, data, (elf::SHF_ALLOC.0 | elf::SHF_EXECINSTR.0) as u32)
    }

    /// A writable `SHT_PROGBITS` section.
    pub fn data(&mut self, name: &str, data: &[u8]) -> SectionId {
        self.progbits(name, data, (elf::SHF_ALLOC.0 | elf::SHF_WRITE.0) as u32)
    }

    /// An `SHT_PROGBITS` section with explicit `sh_flags`.
    pub fn progbits(&mut self, name: &str, data: &[u8], flags: u32) -> SectionId {
        self.add(BuiltSection {
            name: name.to_owned(),
            data: data.to_vec(),
            size: data.len() as u32,
            nobits: false,
            flags: u64::from(flags),
            align: 1,
            sh_type: elf::SHT_PROGBITS.0,
            relocs: Vec::new(),
        })
    }

    /// An `SHT_NOBITS` section (`.res` only).
    pub fn bss(&mut self, name: &str, size: u32) -> SectionId {
        self.add(BuiltSection {
            name: name.to_owned(),
            data: Vec::new(),
            size,
            nobits: true,
            flags: elf::SHF_ALLOC.0 | elf::SHF_WRITE.0,
            align: 1,
            sh_type: elf::SHT_NOBITS.0,
            relocs: Vec::new(),
        })
    }

    /// A zero-page `SHT_NOBITS` section (`SHF_MOS_ZEROPAGE`).
    pub fn zeropage(&mut self, name: &str, size: u32) -> SectionId {
        let id = self.bss(name, size);
        self.sections[id.0].flags |= u64::from(mos::SHF_MOS_ZEROPAGE);
        id
    }

    /// Sets a section's `sh_addralign`.
    pub fn align(&mut self, section: SectionId, align: u64) -> &mut Self {
        self.sections[section.0].align = align;
        self
    }

    /// Sets a section's `sh_type` (to test other producers).
    pub fn section_type(&mut self, section: SectionId, sh_type: u32) -> &mut Self {
        self.sections[section.0].sh_type = sh_type;
        self
    }

    fn symbol(&mut self, symbol: BuiltSymbol) -> SymbolId {
        self.symbols.push(symbol);
        SymbolId(self.symbols.len() - 1)
    }

    /// A local symbol.
    pub fn local(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(BuiltSymbol {
            name: name.to_owned(),
            global: false,
            weak: false,
            def,
            zeropage: false,
            section_symbol: false,
        })
    }

    /// An exported symbol.
    pub fn global(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(BuiltSymbol {
            name: name.to_owned(),
            global: true,
            weak: false,
            def,
            zeropage: false,
            section_symbol: false,
        })
    }

    /// A weak symbol (defined, or an undefined weak reference).
    pub fn weak(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(BuiltSymbol {
            name: name.to_owned(),
            global: true,
            weak: true,
            def,
            zeropage: false,
            section_symbol: false,
        })
    }

    /// An import; `zeropage` marks it `STO_MOS_ZEROPAGE` (`.importzp`).
    pub fn import(&mut self, name: &str, zeropage: bool) -> SymbolId {
        self.symbol(BuiltSymbol {
            name: name.to_owned(),
            global: true,
            weak: false,
            def: SymbolDef::Undefined,
            zeropage,
            section_symbol: false,
        })
    }

    /// The `STT_SECTION` symbol of a section (for relocations against it).
    pub fn section_symbol(&mut self, section: SectionId) -> SymbolId {
        self.symbol(BuiltSymbol {
            name: String::new(),
            global: false,
            weak: false,
            def: SymbolDef::Section(section, 0),
            zeropage: false,
            section_symbol: true,
        })
    }

    /// A relocation at `offset` in `section`.
    pub fn reloc(
        &mut self,
        section: SectionId,
        offset: u32,
        r_type: u32,
        symbol: SymbolId,
        addend: i64,
    ) -> &mut Self {
        self.sections[section.0]
            .relocs
            .push((offset, r_type, symbol, addend));
        self
    }

    fn file_index(&mut self, file: &str) -> u32 {
        match self.files.iter().position(|f| f == file) {
            Some(index) => index as u32,
            None => {
                self.files.push(file.to_owned());
                (self.files.len() - 1) as u32
            }
        }
    }

    /// Source-map entry: the bytes of `section` from `offset` came from
    /// `file:line:column`.
    pub fn source(
        &mut self,
        section: SectionId,
        offset: u32,
        file: &str,
        line: u32,
        column: u32,
    ) -> &mut Self {
        let file = self.file_index(file);
        self.items.push((section, offset, file, line, column));
        self
    }

    /// Source-map entry for a symbol's definition.
    pub fn symbol_source(
        &mut self,
        symbol: SymbolId,
        file: &str,
        line: u32,
        column: u32,
    ) -> &mut Self {
        let file = self.file_index(file);
        self.symbol_locs.push((symbol, file, line, column));
        self
    }

    /// A deferred assertion; `ExprOp::Symbol(n)` in `assertion.expr` means
    /// `SymbolId(n)` and is renumbered to the `.symtab` index.
    pub fn assert(&mut self, assertion: Assertion) -> &mut Self {
        self.asserts.push(assertion);
        self
    }

    /// Writes the object.
    #[must_use]
    pub fn build(&self) -> Vec<u8> {
        // .symtab order: null, locals, globals.
        let mut order: Vec<usize> = (0..self.symbols.len())
            .filter(|i| !self.symbols[*i].global)
            .collect();
        let num_local = order.len() as u32 + 1;
        order.extend((0..self.symbols.len()).filter(|i| self.symbols[*i].global));
        let mut symtab_index = vec![0u32; self.symbols.len()];
        for (position, symbol) in order.iter().enumerate() {
            symtab_index[*symbol] = position as u32 + 1;
        }

        let srcmap = (!self.items.is_empty() || !self.symbol_locs.is_empty()).then(|| {
            SrcMap {
                files: self.files.clone(),
                entries: self
                    .items
                    .iter()
                    .map(|(section, offset, file, line, column)| SrcMapEntry {
                        section: section.0 as u32 + 1,
                        offset: *offset,
                        loc: SourceLoc {
                            file: *file,
                            line: *line,
                            column: *column,
                        },
                    })
                    .collect(),
                symbols: self
                    .symbol_locs
                    .iter()
                    .map(|(symbol, file, line, column)| SymbolLoc {
                        symbol: symtab_index[symbol.0],
                        loc: SourceLoc {
                            file: *file,
                            line: *line,
                            column: *column,
                        },
                        expanded_at: None,
                    })
                    .collect(),
            }
            .encode()
        });
        let asserts = (!self.asserts.is_empty()).then(|| {
            let renumbered: Vec<Assertion> = self
                .asserts
                .iter()
                .map(|assertion| Assertion {
                    expr: Expr {
                        ops: assertion
                            .expr
                            .ops
                            .iter()
                            .map(|op| match op {
                                ExprOp::Symbol(id) => ExprOp::Symbol(
                                    symtab_index.get(*id as usize).copied().unwrap_or(*id),
                                ),
                                other => *other,
                            })
                            .collect(),
                    },
                    ..assertion.clone()
                })
                .collect();
            Assertion::encode_all(&renumbered)
        });

        let is_rela = !self.rel_instead_of_rela;
        let mut buffer = Vec::new();
        let mut writer = Writer::new(object::Endianness::Little, false, &mut buffer);
        writer.reserve_file_header();
        writer.reserve_null_section_index();
        let names: Vec<_> = self
            .sections
            .iter()
            .map(|s| writer.add_section_name(s.name.as_bytes()))
            .collect();
        let indices: Vec<SectionIndex> = self
            .sections
            .iter()
            .map(|_| writer.reserve_section_index())
            .collect();
        let offsets: Vec<u64> = self
            .sections
            .iter()
            .map(|s| {
                if s.nobits {
                    0
                } else {
                    writer.reserve(s.data.len() as u64, 1)
                }
            })
            .collect();
        let rela_names: Vec<String> = self
            .sections
            .iter()
            .map(|s| format!("{}{}", if is_rela { ".rela" } else { ".rel" }, s.name))
            .collect();
        let mut relas = Vec::new();
        for (index, section) in self.sections.iter().enumerate() {
            if section.relocs.is_empty() {
                continue;
            }
            let name = writer.add_section_name(rela_names[index].as_bytes());
            let section_index = writer.reserve_section_index();
            let offset = writer.reserve_relocations(section.relocs.len(), is_rela);
            relas.push((index, name, section_index, offset));
        }
        let meta: Vec<(&str, &Vec<u8>)> = [(SRCMAP_SECTION, &srcmap), (ASSERT_SECTION, &asserts)]
            .into_iter()
            .filter_map(|(name, data)| data.as_ref().map(|data| (name, data)))
            .collect();
        let meta_reserved: Vec<_> = meta
            .iter()
            .map(|(name, data)| {
                let name = writer.add_section_name(name.as_bytes());
                let index = writer.reserve_section_index();
                let offset = writer.reserve(data.len() as u64, 1);
                (name, index, offset)
            })
            .collect();
        writer.reserve_null_symbol_index();
        let symbol_names: Vec<_> = order
            .iter()
            .map(|i| writer.add_string(self.symbols[*i].name.as_bytes()))
            .collect();
        for symbol in &order {
            let section = match self.symbols[*symbol].def {
                SymbolDef::Section(section, _) => Some(indices[section.0]),
                _ => None,
            };
            writer.reserve_symbol_index(section);
        }
        let symtab = writer.reserve_symtab_section_index();
        writer.reserve_symtab();
        writer.reserve_strtab_section_index();
        // Nothing in the builder can exceed the writer's limits.
        let _ = writer.reserve_strtab();
        writer.reserve_shstrtab_section_index();
        let _ = writer.reserve_shstrtab();
        writer.reserve_section_headers();

        let _ = writer.write_file_header(&FileHeader {
            os_abi: elf::ELFOSABI_NONE,
            abi_version: 0,
            e_type: elf::FileType(self.e_type),
            e_machine: elf::Machine(self.machine),
            e_entry: 0,
            e_flags: elf::FileFlags(self.flags),
        });
        for section in &self.sections {
            if !section.nobits {
                writer.write(&section.data);
            }
        }
        for (index, _, _, _) in &relas {
            writer.write_align_relocation();
            for (offset, r_type, symbol, addend) in &self.sections[*index].relocs {
                writer.write_relocation(
                    is_rela,
                    &Rel {
                        r_offset: u64::from(*offset),
                        r_sym: symtab_index.get(symbol.0).copied().unwrap_or(0),
                        r_type: elf::RelocationType(*r_type),
                        r_addend: *addend,
                    },
                );
            }
        }
        for (_, data) in &meta {
            writer.write(data);
        }
        writer.write_null_symbol();
        for (symbol, name) in order.iter().zip(&symbol_names) {
            let built = &self.symbols[*symbol];
            let (section, shndx, value) = match built.def {
                SymbolDef::Section(section, offset) => {
                    (Some(indices[section.0].0), elf::SymbolSection(0), offset)
                }
                SymbolDef::Absolute(value) => (None, elf::SHN_ABS, value),
                SymbolDef::Undefined => (None, elf::SHN_UNDEF, 0),
            };
            let bind = match (built.global, built.weak) {
                (_, true) => elf::STB_WEAK,
                (true, false) => elf::STB_GLOBAL,
                (false, false) => elf::STB_LOCAL,
            };
            let kind = if built.section_symbol {
                elf::STT_SECTION
            } else {
                elf::STT_NOTYPE
            };
            writer.write_symbol(&Sym {
                section,
                st_name: if built.section_symbol {
                    0
                } else {
                    writer.string_offset(Some(*name))
                },
                st_info: elf::SymbolInfo::new(bind, kind),
                st_other: elf::SymbolOther(if built.zeropage {
                    mos::STO_MOS_ZEROPAGE
                } else {
                    0
                }),
                st_shndx: shndx,
                st_value: u64::from(value),
                st_size: 0,
            });
        }
        writer.write_strtab();
        writer.write_shstrtab();
        writer.write_null_section_header();
        for ((section, name), offset) in self.sections.iter().zip(&names).zip(&offsets) {
            writer.write_section_header(&SectionHeader {
                sh_name: writer.section_name_offset(Some(*name)),
                sh_type: elf::SectionType(section.sh_type),
                sh_flags: elf::SectionFlags(section.flags),
                sh_addr: 0,
                sh_offset: *offset,
                sh_size: u64::from(section.size),
                sh_link: 0,
                sh_info: 0,
                sh_addralign: section.align,
                sh_entsize: 0,
            });
        }
        for (index, name, _, offset) in &relas {
            writer.write_relocation_section_header(
                *name,
                indices[*index],
                symtab,
                *offset,
                self.sections[*index].relocs.len(),
                is_rela,
            );
        }
        for ((name, _, offset), (_, data)) in meta_reserved.iter().zip(&meta) {
            writer.write_section_header(&SectionHeader {
                sh_name: writer.section_name_offset(Some(*name)),
                sh_type: elf::SHT_PROGBITS,
                sh_flags: elf::SectionFlags(0),
                sh_addr: 0,
                sh_offset: *offset,
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
        buffer
    }
}
