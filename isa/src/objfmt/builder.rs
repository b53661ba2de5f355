//! Building 6502 ELF relocatable objects from a description, for tests:
//! the linker is tested without the assembler, and any machine, flags,
//! section types and relocation numbers can be written, valid or not, to
//! show what another producer's object looks like to the linker. It fills
//! a [`RelObject`] and writes it with the same writer as the assembler.
//!
//! ```
//! use isa::objfmt::{ObjectBuilder, SymbolDef};
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

use object::elf;

use super::write::{Binding, Definition, ObjReloc, ObjSection, ObjSymbol, RelObject, RelocTarget};
use super::{Assertion, Expr, ExprOp, SourceLoc, SrcMap, SrcMapEntry, SymbolLoc};
use crate::elf as mos;

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

/// Builds an ELF32 relocatable object.
#[derive(Debug, Clone)]
pub struct ObjectBuilder {
    object: RelObject,
    files: Vec<String>,
    items: Vec<(SectionId, u32, u32, u32, u32)>,
    symbol_locs: Vec<(SymbolId, u32, u32, u32)>,
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
            object: RelObject::default(),
            files: Vec::new(),
            items: Vec::new(),
            symbol_locs: Vec::new(),
        }
    }

    /// Sets `e_machine` (to test other producers).
    pub fn machine(&mut self, machine: u16) -> &mut Self {
        self.object.machine = machine;
        self
    }

    /// Sets `e_flags`.
    pub fn flags(&mut self, flags: u32) -> &mut Self {
        self.object.flags = flags;
        self
    }

    /// Sets `e_type` (`ET_REL` = 1 by default).
    pub fn file_type(&mut self, e_type: u16) -> &mut Self {
        self.object.e_type = e_type;
        self
    }

    /// Writes `SHT_REL` relocation sections instead of `SHT_RELA`.
    pub fn use_rel(&mut self) -> &mut Self {
        self.object.rela = false;
        self
    }

    fn add(&mut self, section: ObjSection) -> SectionId {
        self.object.sections.push(section);
        SectionId(self.object.sections.len() - 1)
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
        self.add(ObjSection {
            name: name.to_owned(),
            sh_type: elf::SHT_PROGBITS.0,
            sh_flags: u64::from(flags),
            align: 1,
            data: data.to_vec(),
            size: u32::try_from(data.len()).unwrap_or(u32::MAX),
            relocs: Vec::new(),
        })
    }

    /// An `SHT_NOBITS` section (`.res` only).
    pub fn bss(&mut self, name: &str, size: u32) -> SectionId {
        self.add(ObjSection {
            name: name.to_owned(),
            sh_type: elf::SHT_NOBITS.0,
            sh_flags: elf::SHF_ALLOC.0 | elf::SHF_WRITE.0,
            align: 1,
            data: Vec::new(),
            size,
            relocs: Vec::new(),
        })
    }

    /// A zero-page `SHT_NOBITS` section (`SHF_MOS_ZEROPAGE`).
    pub fn zeropage(&mut self, name: &str, size: u32) -> SectionId {
        let id = self.bss(name, size);
        self.object.sections[id.0].sh_flags |= u64::from(mos::SHF_MOS_ZEROPAGE);
        id
    }

    /// Sets a section's `sh_addralign`.
    pub fn align(&mut self, section: SectionId, align: u64) -> &mut Self {
        self.object.sections[section.0].align = align;
        self
    }

    /// Sets a section's `sh_type` (to test other producers).
    pub fn section_type(&mut self, section: SectionId, sh_type: u32) -> &mut Self {
        self.object.sections[section.0].sh_type = sh_type;
        self
    }

    fn symbol(
        &mut self,
        name: &str,
        binding: Binding,
        def: Definition,
        zeropage: bool,
    ) -> SymbolId {
        self.object.symbols.push(ObjSymbol {
            name: name.to_owned(),
            binding,
            def,
            zeropage,
        });
        SymbolId(self.object.symbols.len() - 1)
    }

    fn definition(def: SymbolDef) -> Definition {
        match def {
            SymbolDef::Section(section, offset) => Definition::Section(section.0, offset),
            SymbolDef::Absolute(value) => Definition::Absolute(value),
            SymbolDef::Undefined => Definition::Undefined,
        }
    }

    /// A local symbol.
    pub fn local(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(name, Binding::Local, Self::definition(def), false)
    }

    /// An exported symbol.
    pub fn global(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(name, Binding::Global, Self::definition(def), false)
    }

    /// A weak symbol (defined, or an undefined weak reference).
    pub fn weak(&mut self, name: &str, def: SymbolDef) -> SymbolId {
        self.symbol(name, Binding::Weak, Self::definition(def), false)
    }

    /// An import; `zeropage` marks it `STO_MOS_ZEROPAGE` (`.importzp`).
    pub fn import(&mut self, name: &str, zeropage: bool) -> SymbolId {
        self.symbol(name, Binding::Global, Definition::Undefined, zeropage)
    }

    /// The `STT_SECTION` symbol of a section (for relocations against it).
    pub fn section_symbol(&mut self, section: SectionId) -> SymbolId {
        self.symbol(
            "",
            Binding::Local,
            Definition::SectionSymbol(section.0),
            false,
        )
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
        self.object.sections[section.0].relocs.push(ObjReloc {
            offset,
            r_type,
            target: RelocTarget::Symbol(symbol.0),
            addend,
        });
        self
    }

    fn file_index(&mut self, file: &str) -> u32 {
        let index = match self.files.iter().position(|f| f == file) {
            Some(index) => index,
            None => {
                self.files.push(file.to_owned());
                self.files.len() - 1
            }
        };
        u32::try_from(index).unwrap_or(u32::MAX)
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
        self.object.asserts.push(assertion);
        self
    }

    /// Writes the object.
    #[must_use]
    pub fn build(&self) -> Vec<u8> {
        let mut object = self.object.clone();
        let numbering = object.numbering();
        if !self.items.is_empty() || !self.symbol_locs.is_empty() {
            let mut entries: Vec<SrcMapEntry> = self
                .items
                .iter()
                .map(|&(section, offset, file, line, column)| SrcMapEntry {
                    section: super::Numbering::section(section.0),
                    offset,
                    loc: SourceLoc { file, line, column },
                })
                .collect();
            entries.sort_unstable();
            object.srcmap = Some(SrcMap {
                files: self.files.clone(),
                entries,
                symbols: self
                    .symbol_locs
                    .iter()
                    .map(|&(symbol, file, line, column)| SymbolLoc {
                        symbol: numbering.symbols[symbol.0],
                        loc: SourceLoc { file, line, column },
                        expanded_at: None,
                    })
                    .collect(),
                calls: Vec::new(),
            });
        }
        for assertion in &mut object.asserts {
            *assertion = Assertion {
                expr: Expr {
                    ops: assertion
                        .expr
                        .ops
                        .iter()
                        .map(|op| match op {
                            ExprOp::Symbol(id) => ExprOp::Symbol(
                                numbering.symbols.get(*id as usize).copied().unwrap_or(*id),
                            ),
                            other => *other,
                        })
                        .collect(),
                },
                ..assertion.clone()
            };
        }
        // Nothing a test builds exceeds ELF32's tables.
        object.write().unwrap_or_default()
    }
}
