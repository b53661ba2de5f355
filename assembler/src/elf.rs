//! The assembler's output as a relocatable object (docs/ARCHITECTURE.md,
//! "The object format"): a section per segment with ca65's flags, the
//! symbols, the relocations, and our metadata (`.scorpion.srcmap`,
//! `.scorpion.assert`, `.scorpion.fill`), described as an
//! [`isa::objfmt::RelObject`] and written by its one writer.

use isa::elf::SHF_MOS_ZEROPAGE;
use isa::objfmt::{
    AssertAction, Assertion, Binding, CondesEntry, Definition, Expr, ExprField, ExprSymbol,
    FillRun, Numbering, ObjReloc, ObjSection, ObjSymbol, RelObject, RelocTarget, SourceLoc, SrcMap,
    SymbolLoc,
};
use object::elf;

use crate::diag::Files;
use crate::output::{OutSymKind, Output, Target, assert_ops};

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

fn reloc_target(target: Target) -> RelocTarget {
    match target {
        Target::Section(section) => RelocTarget::Section(section),
        Target::Symbol(symbol) => RelocTarget::Symbol(symbol),
        Target::Absolute => RelocTarget::Absolute,
    }
}

/// Serialises `out` as an ELF object. Its source map items are moved into
/// the object; the sections' bytes are lent to the writer and given back
/// (the listing is made from them afterwards).
pub(crate) fn write_object(
    out: &mut Output,
    files: &Files,
    file_name: &str,
    e_flags: u32,
) -> Result<Vec<u8>, object::write::Error> {
    let mut object = RelObject {
        flags: e_flags,
        file_name: Some(file_name.to_owned()),
        section_symbols: true,
        ..RelObject::default()
    };
    object.sections = out
        .sections
        .iter_mut()
        .map(|section| ObjSection {
            name: section.name.clone(),
            sh_type: if section.nobits {
                elf::SHT_NOBITS.0
            } else {
                elf::SHT_PROGBITS.0
            },
            sh_flags: section_flags(&section.name, section.zp),
            align: u64::from(section.align.max(1)),
            data: std::mem::take(&mut section.data),
            size: section.size,
            relocs: section
                .relocs
                .iter()
                .map(|reloc| ObjReloc {
                    offset: reloc.offset,
                    r_type: reloc.r_type,
                    target: reloc_target(reloc.target),
                    addend: reloc.addend,
                })
                .collect(),
        })
        .collect();
    object.symbols = out
        .symbols
        .iter()
        .map(|symbol| ObjSymbol {
            name: symbol.name.clone(),
            binding: if symbol.global {
                Binding::Global
            } else {
                Binding::Local
            },
            // Constants are stored as their low 32 bits, as ca65's are.
            def: match symbol.kind {
                OutSymKind::Abs(value) => Definition::Absolute(value as u32),
                OutSymKind::Sec(section, offset) => Definition::Section(section, offset),
                OutSymKind::Undef { .. } => Definition::Undefined,
            },
            zeropage: matches!(symbol.kind, OutSymKind::Undef { zp: true }),
        })
        .collect();

    // The metadata refers to symbols and sections by their numbers.
    let numbering = object.numbering();
    let mut entries = std::mem::take(&mut out.items);
    for entry in &mut entries {
        entry.section = Numbering::section(entry.section as usize);
    }
    // Sorted here, in place, so that encoding needs no sorted copy.
    entries.sort_unstable();
    let mut calls = std::mem::take(&mut out.calls);
    for call in &mut calls {
        call.section = Numbering::section(call.section as usize);
    }
    calls.sort_unstable();
    object.srcmap = Some(SrcMap {
        files: files.files.iter().map(|f| f.name.clone()).collect(),
        entries,
        symbols: out
            .symbols
            .iter()
            .enumerate()
            .filter_map(|(i, sym)| {
                let (file, line, column) = sym.place?;
                (line > 0).then_some(SymbolLoc {
                    symbol: numbering.symbols[i],
                    loc: SourceLoc { file, line, column },
                    expanded_at: sym.expanded_at.map(|(file, line, column)| SourceLoc {
                        file,
                        line,
                        column,
                    }),
                })
            })
            .collect(),
        calls,
    });
    object.asserts = out
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
                    ops: assert_ops(&a.ops, |target| {
                        Some(numbering.target(reloc_target(target)))
                    })?,
                },
            })
        })
        .collect();
    object.fields = out
        .fields
        .iter()
        .filter_map(|field| {
            Some(ExprField {
                section: Numbering::section(field.section),
                offset: field.offset,
                kind: field.kind.field()?,
                expr: Expr {
                    ops: assert_ops(&field.ops, |target| {
                        Some(numbering.target(reloc_target(target)))
                    })?,
                },
            })
        })
        .collect();
    object.values = out
        .values
        .iter()
        .filter_map(|(symbol, ops)| {
            Some(ExprSymbol {
                symbol: numbering.symbols[*symbol],
                expr: Expr {
                    ops: assert_ops(ops, |target| Some(numbering.target(reloc_target(target))))?,
                },
            })
        })
        .collect();
    object.condes = out
        .condes
        .iter()
        .map(|&(symbol, kind, priority)| CondesEntry {
            kind,
            priority,
            symbol: numbering.symbols[symbol],
        })
        .collect();
    object.fills = out
        .fills
        .iter()
        .filter(|run| (run.section as usize) < out.sections.len())
        .map(|run| FillRun {
            section: Numbering::section(run.section as usize),
            ..*run
        })
        .collect();

    let bytes = object.write();
    for (section, written) in out.sections.iter_mut().zip(&mut object.sections) {
        section.data = std::mem::take(&mut written.data);
    }
    bytes
}
