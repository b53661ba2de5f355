//! Reading relocatable objects (with `goblin`) into the linker's model.
//!
//! Everything is checked here, once: the ELF class, byte order, machine,
//! file type and CPU flags; every section, symbol and relocation index; that
//! each relocation is a supported `R_MOS_*` type and lies inside its
//! section. Later stages index freely.

use goblin::elf::{Elf, section_header as sh, sym};
use isa::elf as mos;
use isa::objfmt::{
    ASSERT_SECTION, Assertion, CONDES_SECTION, CondesEntry, EXPRS_SECTION, ExprField, ExprSymbol,
    FILL_SECTION, FieldKind, FillRun, SRCMAP_SECTION, SrcMap, VALUES_SECTION,
};

use crate::error::Error;
use crate::source::Place;

/// One input: a name for messages and the object's bytes.
#[derive(Debug, Clone, Copy)]
pub struct Input<'a> {
    /// The name diagnostics use (normally the file path).
    pub name: &'a str,
    /// The ELF object.
    pub bytes: &'a [u8],
}

/// A relocation, checked.
#[derive(Debug, Clone)]
pub(crate) struct Reloc {
    pub(crate) offset: u32,
    pub(crate) r_type: u32,
    pub(crate) symbol: usize,
    pub(crate) addend: i64,
}

/// An allocated section: a fragment of the segment of the same name.
#[derive(Debug, Clone)]
pub(crate) struct Section {
    /// ELF section header index.
    pub(crate) index: usize,
    pub(crate) name: String,
    /// Contents; empty for `SHT_NOBITS`.
    pub(crate) data: Vec<u8>,
    pub(crate) size: u32,
    pub(crate) align: u32,
    pub(crate) nobits: bool,
    pub(crate) zeropage: bool,
    /// `SHF_EXECINSTR`: holds code.
    pub(crate) exec: bool,
    pub(crate) relocs: Vec<Reloc>,
    /// Reserved byte ranges `(offset, length)` (`.scorpion.fill`): they
    /// take the fill value of the area the section is loaded into.
    pub(crate) fills: Vec<(u32, u32)>,
}

/// Where a symbol is defined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Definition {
    Undefined,
    Absolute(i64),
    /// Position of the section in [`Object::sections`], and the offset.
    Section(usize, u32),
    /// Computed by the linker: position in [`Object::values`].
    Computed(usize),
}

/// Symbol binding, reduced to what linking needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Binding {
    Local,
    Global,
    Weak,
}

/// A symbol-table entry.
#[derive(Debug, Clone)]
pub(crate) struct Symbol {
    pub(crate) name: String,
    pub(crate) binding: Binding,
    pub(crate) definition: Definition,
    /// `STT_SECTION` or `STT_FILE`: never exported or listed.
    pub(crate) is_section_or_file: bool,
    pub(crate) size: u32,
}

/// A checked relocatable object.
#[derive(Debug, Clone)]
pub(crate) struct Object {
    pub(crate) name: String,
    pub(crate) flags: u32,
    pub(crate) sections: Vec<Section>,
    /// By `.symtab` index (entry 0 is the null symbol).
    pub(crate) symbols: Vec<Symbol>,
    pub(crate) srcmap: Option<SrcMap>,
    pub(crate) asserts: Vec<Assertion>,
    /// Routines for the linker's tables (`.constructor` and the like).
    pub(crate) condes: Vec<CondesEntry>,
    /// Fields the linker computes from expressions (`.scorpion.exprs`).
    pub(crate) fields: Vec<Field>,
    /// Values of the symbols defined as [`Definition::Computed`]
    /// (`.scorpion.values`).
    pub(crate) values: Vec<isa::objfmt::Expr>,
}

/// A field of a section whose value the linker computes.
#[derive(Debug, Clone)]
pub(crate) struct Field {
    /// Position of the section in [`Object::sections`].
    pub(crate) section: usize,
    pub(crate) offset: u32,
    pub(crate) kind: FieldKind,
    pub(crate) expr: isa::objfmt::Expr,
}

impl Object {
    /// Where byte `offset` of section `section` (position in `sections`)
    /// came from.
    pub(crate) fn place_of_byte(&self, section: usize, offset: u32) -> Place {
        let sec = &self.sections[section];
        let found = self.srcmap.as_ref().and_then(|map| {
            let loc = map.lookup(sec.index as u32, offset)?;
            Some(Place::source(map.file_name(loc)?, loc.line, loc.column))
        });
        if let Some(place) = found {
            return place;
        }
        Place::bare(format!("{}({}+${offset:04X})", self.name, sec.name))
    }

    /// Where symbol `index` was defined.
    pub(crate) fn place_of_symbol(&self, index: usize) -> Place {
        let found = self.srcmap.as_ref().and_then(|map| {
            let entry = map.symbol_entry(index as u32)?;
            let own = Place::source(map.file_name(entry.loc)?, entry.loc.line, entry.loc.column);
            // A macro's definition is shown at the user's line that called
            // the macro, its place in the macro's body beside it.
            let Some(call) = entry.expanded_at else {
                return Some(own);
            };
            let mut place = Place::source(map.file_name(call)?, call.line, call.column);
            place.text = format!("{} (from the macro at {})", place.text, own.text);
            Some(place)
        });
        if let Some(place) = found {
            return place;
        }
        match self.symbols[index].definition {
            Definition::Section(section, offset) => self.place_of_byte(section, offset),
            _ => Place::bare(self.name.clone()),
        }
    }
}

/// Human names of the CPU bits in `e_flags` outside the NMOS set.
fn cpu_names(flags: u32) -> String {
    const NAMES: [(u32, &str); 13] = [
        (mos::EF_MOS_ARCH_65C02, "65C02"),
        (mos::EF_MOS_ARCH_R65C02, "R65C02"),
        (mos::EF_MOS_ARCH_W65C02, "W65C02"),
        (mos::EF_MOS_ARCH_W65816, "65816"),
        (0x200, "65EL02"),
        (0x400, "65CE02"),
        (0x800, "HuC6280"),
        (0x1000, "65DTV02"),
        (0x2000, "4510"),
        (0x4000, "45GS02"),
        (0x8000, "SPC700 (S)"),
        (0x1_0000, "SWEET16"),
        (0x2_0000, "SPC700"),
    ];
    let names: Vec<&str> = NAMES
        .iter()
        .filter(|(bit, _)| flags & bit != 0)
        .map(|(_, name)| *name)
        .collect();
    if names.is_empty() {
        "an unknown CPU".into()
    } else {
        names.join(" + ")
    }
}

/// The relocation types the linker applies.
pub(crate) fn supported(r_type: u32) -> bool {
    matches!(
        r_type,
        mos::R_MOS_NONE
            | mos::R_MOS_IMM8
            | mos::R_MOS_ADDR8
            | mos::R_MOS_ADDR16
            | mos::R_MOS_ADDR16_LO
            | mos::R_MOS_ADDR16_HI
            | mos::R_MOS_PCREL_8
            | mos::R_MOS_ADDR24
            | mos::R_MOS_ADDR24_BANK
            | mos::R_MOS_FK_DATA_4
            | mos::R_MOS_FK_DATA_8
    )
}

/// How many bytes a relocation writes.
pub(crate) fn width(r_type: u32) -> u32 {
    match r_type {
        mos::R_MOS_NONE => 0,
        mos::R_MOS_ADDR16 => 2,
        mos::R_MOS_ADDR24 => 3,
        mos::R_MOS_FK_DATA_4 => 4,
        mos::R_MOS_FK_DATA_8 => 8,
        _ => 1,
    }
}

/// Reads and checks one relocatable object.
pub(crate) fn read_object(input: Input<'_>) -> Result<Object, Error> {
    let file = input.name;
    let malformed = |reason: String| Error::MalformedObject {
        file: file.to_owned(),
        reason,
    };
    let wrong = |reason: String| Error::WrongKind {
        file: file.to_owned(),
        reason,
    };
    if let Some(reason) = not_elf(input.bytes) {
        return Err(Error::NotElf {
            file: file.to_owned(),
            reason,
        });
    }
    let elf = Elf::parse(input.bytes).map_err(|error| Error::NotElf {
        file: file.to_owned(),
        reason: error.to_string(),
    })?;
    if elf.is_64 {
        return Err(wrong("is ELF64; 6502 objects are ELF32".into()));
    }
    if !elf.little_endian {
        return Err(wrong(
            "is big-endian; 6502 objects are little-endian".into(),
        ));
    }
    if elf.header.e_machine != mos::EM_MOS {
        return Err(wrong(format!(
            "is for machine {} ({}), not EM_MOS (6502)",
            elf.header.e_machine,
            goblin::elf::header::machine_to_str(elf.header.e_machine)
        )));
    }
    if elf.header.e_type != goblin::elf::header::ET_REL {
        return Err(wrong(format!(
            "is ET_{}, not a relocatable object (ET_REL)",
            goblin::elf::header::et_to_str(elf.header.e_type)
        )));
    }
    let flags = elf.header.e_flags;
    if flags & !mos::EF_MOS_NMOS_COMPATIBLE != 0 {
        return Err(Error::WrongCpu {
            file: file.to_owned(),
            flags,
            cpus: cpu_names(flags & !mos::EF_MOS_NMOS_COMPATIBLE),
        });
    }

    let section_name = |index: usize| -> String {
        elf.section_headers
            .get(index)
            .and_then(|header| elf.shdr_strtab.get_at(header.sh_name))
            .unwrap_or("?")
            .to_owned()
    };
    let section_bytes = |index: usize| -> Result<&[u8], Error> {
        let header = &elf.section_headers[index];
        let start = usize::try_from(header.sh_offset).unwrap_or(usize::MAX);
        let len = usize::try_from(header.sh_size).unwrap_or(usize::MAX);
        start
            .checked_add(len)
            .and_then(|end| input.bytes.get(start..end))
            .ok_or_else(|| {
                malformed(format!(
                    "section {} lies outside the file",
                    section_name(index)
                ))
            })
    };

    // Allocated sections, in header order.
    let mut sections = Vec::new();
    let mut position_of = vec![None; elf.section_headers.len()];
    let mut srcmap = None;
    let mut asserts = Vec::new();
    let mut fills = Vec::new();
    let mut raw_fields = Vec::new();
    let mut raw_values = Vec::new();
    let mut condes = Vec::new();
    for (index, header) in elf.section_headers.iter().enumerate() {
        let name = section_name(index);
        if header.sh_flags & u64::from(sh::SHF_ALLOC) == 0 {
            if name == SRCMAP_SECTION {
                let map = SrcMap::decode(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
                srcmap = Some(map);
            } else if name == ASSERT_SECTION {
                asserts = Assertion::decode_all(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
            } else if name == FILL_SECTION {
                fills = FillRun::decode_all(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
            } else if name == EXPRS_SECTION {
                raw_fields = ExprField::decode_all(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
            } else if name == VALUES_SECTION {
                raw_values = ExprSymbol::decode_all(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
            } else if name == CONDES_SECTION {
                condes = CondesEntry::decode_all(section_bytes(index)?)
                    .map_err(|error| malformed(error.to_string()))?;
            }
            continue;
        }
        let nobits = match header.sh_type {
            sh::SHT_NOBITS => true,
            sh::SHT_PROGBITS | sh::SHT_INIT_ARRAY | sh::SHT_FINI_ARRAY => false,
            other => {
                return Err(malformed(format!(
                    "allocated section {name} has type {}, not SHT_PROGBITS or SHT_NOBITS",
                    sh::sht_to_str(other)
                )));
            }
        };
        let size = u32::try_from(header.sh_size)
            .map_err(|_| malformed(format!("section {name} is larger than 4 GiB")))?;
        let data = if nobits {
            Vec::new()
        } else {
            section_bytes(index)?.to_vec()
        };
        let align = u32::try_from(header.sh_addralign.max(1))
            .ok()
            .filter(|align| align.is_power_of_two())
            .ok_or_else(|| {
                malformed(format!(
                    "section {name} has alignment {}, not a power of two",
                    header.sh_addralign
                ))
            })?;
        position_of[index] = Some(sections.len());
        sections.push(Section {
            index,
            name,
            data,
            size,
            align,
            nobits,
            zeropage: header.sh_flags & u64::from(mos::SHF_MOS_ZEROPAGE) != 0,
            exec: header.sh_flags & u64::from(sh::SHF_EXECINSTR) != 0,
            relocs: Vec::new(),
            fills: Vec::new(),
        });
    }

    // Symbols. Names are read from the string table directly: goblin's
    // lookup binary-searches an index, which dominates big links.
    let strtab = elf
        .section_headers
        .iter()
        .find(|header| header.sh_type == sh::SHT_SYMTAB)
        .and_then(|symtab| elf.section_headers.get(symtab.sh_link as usize))
        .and_then(|header| {
            let start = usize::try_from(header.sh_offset).ok()?;
            let len = usize::try_from(header.sh_size).ok()?;
            input.bytes.get(start..start.checked_add(len)?)
        })
        .unwrap_or(&[]);
    let mut symbols = Vec::with_capacity(elf.syms.len());
    for (index, entry) in elf.syms.iter().enumerate() {
        let name = string_at(strtab, entry.st_name).to_owned();
        let binding = match entry.st_bind() {
            sym::STB_LOCAL => Binding::Local,
            sym::STB_GLOBAL => Binding::Global,
            sym::STB_WEAK => Binding::Weak,
            other => {
                return Err(malformed(format!(
                    "symbol {index} ({name}) has unknown binding {other}"
                )));
            }
        };
        let shndx = entry.st_shndx;
        let definition = if index == 0 || shndx == sh::SHN_UNDEF as usize {
            Definition::Undefined
        } else if shndx == sh::SHN_ABS as usize {
            // Constants are 32-bit in ELF32; sign-extend so `-1` stays -1.
            Definition::Absolute(i64::from(entry.st_value as u32 as i32))
        } else if shndx == sh::SHN_COMMON as usize {
            return Err(malformed(format!(
                "symbol {name} is a common symbol; define it in a BSS segment instead"
            )));
        } else {
            match position_of.get(shndx).copied().flatten() {
                Some(position) => Definition::Section(position, entry.st_value as u32),
                None if entry.st_type() == sym::STT_SECTION
                    || entry.st_type() == sym::STT_FILE
                    || binding == Binding::Local =>
                {
                    // A local symbol of a section we do not place (debug info).
                    Definition::Absolute(0)
                }
                None => {
                    return Err(malformed(format!(
                        "symbol {name} is defined in section {shndx}, which is not an allocated section"
                    )));
                }
            }
        };
        symbols.push(Symbol {
            name,
            binding,
            definition,
            is_section_or_file: matches!(entry.st_type(), sym::STT_SECTION | sym::STT_FILE),
            size: entry.st_size as u32,
        });
    }
    if symbols.is_empty() {
        symbols.push(Symbol {
            name: String::new(),
            binding: Binding::Local,
            definition: Definition::Undefined,
            is_section_or_file: false,
            size: 0,
        });
    }

    // Relocations.
    for (index, relocs) in &elf.shdr_relocs {
        let header = &elf.section_headers[*index];
        let target = header.sh_info as usize;
        let Some(position) = position_of.get(target).copied().flatten() else {
            // Relocations of debug sections go with the sections we drop.
            continue;
        };
        let target_name = sections[position].name.clone();
        if header.sh_type == sh::SHT_REL {
            return Err(malformed(format!(
                "section {} holds SHT_REL relocations for {target_name}; only SHT_RELA is supported (as llvm-mos writes)",
                section_name(*index)
            )));
        }
        for reloc in relocs.iter() {
            if !supported(reloc.r_type) {
                return Err(Error::UnsupportedRelocation {
                    file: file.to_owned(),
                    section: target_name,
                    r_type: reloc.r_type,
                    name: mos::relocation_name(reloc.r_type)
                        .unwrap_or("unknown")
                        .to_owned(),
                });
            }
            if reloc.r_sym >= symbols.len() {
                return Err(malformed(format!(
                    "a relocation in {target_name} names symbol {}, past the end of the symbol table",
                    reloc.r_sym
                )));
            }
            let section = &sections[position];
            let end = reloc.r_offset.checked_add(u64::from(width(reloc.r_type)));
            if section.nobits || end.is_none_or(|end| end > u64::from(section.size)) {
                return Err(malformed(format!(
                    "a {} relocation at offset {:#x} lies outside section {target_name} ({} bytes{})",
                    mos::relocation_name(reloc.r_type).unwrap_or("?"),
                    reloc.r_offset,
                    section.size,
                    if section.nobits { ", no contents" } else { "" }
                )));
            }
            sections[position].relocs.push(Reloc {
                offset: reloc.r_offset as u32,
                r_type: reloc.r_type,
                symbol: reloc.r_sym,
                addend: reloc.r_addend.unwrap_or(0),
            });
        }
    }

    // Fill runs must lie in the bytes of an allocated section.
    for run in &fills {
        let section = position_of
            .get(run.section as usize)
            .copied()
            .flatten()
            .map(|position| &mut sections[position]);
        match section {
            Some(section) if !section.nobits && run.end() as usize <= section.data.len() => {
                section.fills.push((run.offset, run.length));
            }
            _ => {
                return Err(malformed(format!(
                    "{FILL_SECTION} names bytes {}..{} of section {}, which has no such bytes",
                    run.offset,
                    run.end(),
                    run.section
                )));
            }
        }
    }

    // Source-map and assertion symbol indices must exist.
    let bad_symbol = srcmap.as_ref().and_then(|map| {
        map.symbols
            .iter()
            .find(|entry| entry.symbol as usize >= symbols.len())
    });
    if let Some(bad) = bad_symbol {
        return Err(malformed(format!(
            "{SRCMAP_SECTION} names symbol {}, past the end of the symbol table",
            bad.symbol
        )));
    }
    for assertion in &asserts {
        if let Some(bad) = assertion
            .expr
            .symbols()
            .find(|s| *s as usize >= symbols.len())
        {
            return Err(malformed(format!(
                "{ASSERT_SECTION} names symbol {bad}, past the end of the symbol table"
            )));
        }
    }
    if let Some(bad) = condes.iter().find(|e| e.symbol as usize >= symbols.len()) {
        return Err(malformed(format!(
            "{CONDES_SECTION} names symbol {}, past the end of the symbol table",
            bad.symbol
        )));
    }
    let mut values = Vec::with_capacity(raw_values.len());
    for value in raw_values {
        let bad = value.expr.symbols().find(|s| *s as usize >= symbols.len());
        let target = symbols
            .get_mut(value.symbol as usize)
            .filter(|_| value.symbol != 0);
        match (target, bad) {
            (Some(symbol), None) if symbol.binding != Binding::Local => {
                symbol.definition = Definition::Computed(values.len());
                values.push(value.expr);
            }
            _ => {
                return Err(malformed(format!(
                    "{VALUES_SECTION} gives a value to symbol {} or names a symbol past the end of the symbol table",
                    value.symbol
                )));
            }
        }
    }
    let mut fields = Vec::with_capacity(raw_fields.len());
    for field in raw_fields {
        let position = position_of.get(field.section as usize).copied().flatten();
        let fits = position.is_some_and(|p| {
            let section: &Section = &sections[p];
            !section.nobits && field.offset as usize + field.kind.size() <= section.data.len()
        });
        let (Some(section), true) = (position, fits) else {
            return Err(malformed(format!(
                "{EXPRS_SECTION} names bytes {}..{} of section {}, which has no such bytes",
                field.offset,
                field.offset as usize + field.kind.size(),
                field.section
            )));
        };
        if let Some(bad) = field.expr.symbols().find(|s| *s as usize >= symbols.len()) {
            return Err(malformed(format!(
                "{EXPRS_SECTION} names symbol {bad}, past the end of the symbol table"
            )));
        }
        fields.push(Field {
            section,
            offset: field.offset,
            kind: field.kind,
            expr: field.expr,
        });
    }

    Ok(Object {
        name: file.to_owned(),
        flags,
        sections,
        symbols,
        srcmap,
        asserts,
        condes,
        fields,
        values,
    })
}

/// The NUL-terminated string at `offset` in a string table; empty when it
/// is out of bounds or not UTF-8 (a name is only ever shown to people).
fn string_at(table: &[u8], offset: usize) -> &str {
    let Some(rest) = table.get(offset..) else {
        return "";
    };
    let end = rest
        .iter()
        .position(|byte| *byte == 0)
        .unwrap_or(rest.len());
    std::str::from_utf8(&rest[..end]).unwrap_or("")
}

/// ca65's object files start with the magic $616E7A55, little-endian.
pub(crate) const XO65_MAGIC: [u8; 4] = [0x55, 0x7A, 0x6E, 0x61];
/// What to tell someone who gives the linker a ca65 object.
pub(crate) const XO65_REASON: &str =
    "this is a ca65 (xo65) object; assemble the source with `scorpion asm` for an ELF object";

/// Why `bytes` is plainly not an ELF file, naming what it looks like.
pub(crate) fn not_elf(bytes: &[u8]) -> Option<String> {
    if bytes.starts_with(b"\x7fELF") {
        return None;
    }
    if bytes.starts_with(&XO65_MAGIC) {
        return Some(XO65_REASON.into());
    }
    Some(format!(
        "it does not start with the ELF magic (7F 45 4C 46) but with {}",
        bytes
            .iter()
            .take(4)
            .map(|byte| format!("{byte:02X}"))
            .collect::<Vec<_>>()
            .join(" ")
    ))
}
