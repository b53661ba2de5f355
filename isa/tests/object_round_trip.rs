//! The one object writer, read back by an ELF reader nobody here wrote
//! (`object`'s): every field a [`RelObject`] describes comes back as
//! written, in the documented table order, and the metadata decodes to
//! what was given.

use isa::elf::{EF_MOS_ARCH_6502, EM_MOS, R_MOS_ADDR16, R_MOS_PCREL_8, STO_MOS_ZEROPAGE};
use isa::objfmt::{
    ASSERT_SECTION, AssertAction, Assertion, Binding, Definition, Expr, ExprOp, FILL_SECTION,
    FillRun, Numbering, ObjReloc, ObjSection, ObjSymbol, ObjectBuilder, RelObject, RelocTarget,
    SRCMAP_SECTION, SourceLoc, SrcMap, SrcMapEntry, SymbolDef,
};
use object::elf;
use object::read::elf::{ElfFile32, FileHeader as _, SectionHeader as _, Sym as _};
use object::{LittleEndian as LE, Object, ObjectSection, ObjectSymbol, RelocationTarget};
use proptest::prelude::*;

fn symbol(name: &str, binding: Binding, def: Definition) -> ObjSymbol {
    ObjSymbol {
        name: name.to_owned(),
        binding,
        def,
        zeropage: false,
    }
}

/// Two sections (one `SHT_NOBITS`), every kind of symbol and relocation
/// target, and all three metadata sections.
fn sample() -> RelObject {
    let mut object = RelObject {
        file_name: Some("main.s".into()),
        section_symbols: true,
        ..RelObject::default()
    };
    object.sections = vec![
        ObjSection {
            name: "CODE".into(),
            sh_type: elf::SHT_PROGBITS.0,
            sh_flags: elf::SHF_ALLOC.0 | elf::SHF_EXECINSTR.0,
            align: 4,
            data: vec![0x20, 0, 0, 0xD0, 0, 0x60],
            size: 6,
            relocs: vec![
                ObjReloc {
                    offset: 1,
                    r_type: R_MOS_ADDR16,
                    target: RelocTarget::Symbol(2),
                    addend: 3,
                },
                ObjReloc {
                    offset: 4,
                    r_type: R_MOS_PCREL_8,
                    target: RelocTarget::Section(0),
                    addend: 5,
                },
            ],
        },
        ObjSection {
            name: "BSS".into(),
            sh_type: elf::SHT_NOBITS.0,
            sh_flags: elf::SHF_ALLOC.0 | elf::SHF_WRITE.0,
            align: 1,
            data: Vec::new(),
            size: 32,
            relocs: Vec::new(),
        },
    ];
    object.symbols = vec![
        symbol("start", Binding::Global, Definition::Section(0, 0)),
        symbol("loop", Binding::Local, Definition::Section(0, 3)),
        ObjSymbol {
            zeropage: true,
            ..symbol("ptr", Binding::Global, Definition::Undefined)
        },
        symbol("SIZE", Binding::Local, Definition::Absolute(0x1234)),
        symbol("maybe", Binding::Weak, Definition::Undefined),
    ];
    let numbering = object.numbering();
    object.srcmap = Some(SrcMap {
        files: vec!["main.s".into()],
        entries: vec![SrcMapEntry {
            section: Numbering::section(0),
            offset: 3,
            loc: SourceLoc {
                file: 0,
                line: 7,
                column: 9,
            },
        }],
        symbols: Vec::new(),
        calls: vec![SrcMapEntry {
            section: Numbering::section(0),
            offset: 3,
            loc: SourceLoc {
                file: 0,
                line: 2,
                column: 9,
            },
        }],
    });
    object.asserts = vec![Assertion {
        action: AssertAction::Error,
        file: "main.s".into(),
        line: 4,
        column: 1,
        message: "fits".into(),
        expr: Expr {
            ops: vec![ExprOp::Symbol(numbering.symbols[0])],
        },
    }];
    object.fills = vec![FillRun {
        section: Numbering::section(1),
        offset: 0,
        length: 32,
    }];
    object
}

#[test]
fn every_field_reads_back_as_written() {
    let object = sample();
    let bytes = object.write().expect("writes");
    let file = ElfFile32::<LE>::parse(bytes.as_slice()).expect("object reads it");
    let header = file.elf_header();
    assert_eq!(header.e_machine(LE).0, EM_MOS);
    assert_eq!(header.e_flags(LE).0, EF_MOS_ARCH_6502);
    assert_eq!(header.e_type(LE), elf::ET_REL);

    // Sections (after the null one, which the reader skips): ours first,
    // then the relocations and metadata.
    let names: Vec<&str> = file.sections().map(|s| s.name().expect("named")).collect();
    assert_eq!(
        &names[..5],
        ["CODE", "BSS", ".relaCODE", SRCMAP_SECTION, ASSERT_SECTION]
    );
    assert_eq!(names[5], FILL_SECTION);
    let code = file.section_by_name("CODE").expect("CODE");
    assert_eq!(code.index().0, 1);
    assert_eq!(code.data().expect("bytes"), object.sections[0].data);
    assert_eq!(code.align(), 4);
    assert_eq!(
        code.elf_section_header().sh_flags(LE).0,
        object.sections[0].sh_flags
    );
    let bss = file.section_by_name("BSS").expect("BSS");
    assert_eq!(bss.size(), 32);
    assert_eq!(bss.elf_section_header().sh_type(LE), elf::SHT_NOBITS);

    // Symbols: null, file, two section symbols, locals, then globals.
    let numbering = object.numbering();
    assert_eq!(numbering.section_symbols, vec![2, 3]);
    assert_eq!(numbering.symbols, vec![6, 4, 7, 5, 8]);
    assert_eq!(numbering.locals, 6);
    let table = file.elf_symbol_table();
    let by_index = |index: u32| {
        table
            .symbol(object::SymbolIndex(index as usize))
            .expect("there")
    };
    assert_eq!(by_index(1).st_type(), elf::STT_FILE);
    assert_eq!(by_index(2).st_type(), elf::STT_SECTION);
    for (symbol, &index) in object.symbols.iter().zip(&numbering.symbols) {
        let read = file
            .symbol_by_index(object::SymbolIndex(index as usize))
            .expect("numbered as said");
        assert_eq!(read.name().expect("named"), symbol.name);
        let bind = by_index(index).st_bind();
        let wanted = match symbol.binding {
            Binding::Local => elf::STB_LOCAL,
            Binding::Global => elf::STB_GLOBAL,
            Binding::Weak => elf::STB_WEAK,
        };
        assert_eq!(bind, wanted, "{}", symbol.name);
        assert_eq!(
            by_index(index).st_other().0 == STO_MOS_ZEROPAGE,
            symbol.zeropage,
            "{}",
            symbol.name
        );
        match symbol.def {
            Definition::Section(section, offset) => {
                assert_eq!(read.section_index().map(|i| i.0), Some(section + 1));
                assert_eq!(read.address(), u64::from(offset));
            }
            Definition::Absolute(value) => assert_eq!(read.address(), u64::from(value)),
            Definition::Undefined => assert!(read.is_undefined()),
            Definition::SectionSymbol(_) => unreachable!("none here"),
        }
    }

    // Relocations, with their symbols renumbered.
    let relocs: Vec<(u64, u32, usize, i64)> = code
        .relocations()
        .map(|(offset, reloc)| {
            let RelocationTarget::Symbol(symbol) = reloc.target() else {
                panic!("a symbol target")
            };
            let object::RelocationFlags::Elf { r_type } = reloc.flags() else {
                panic!("ELF flags")
            };
            (offset, r_type.0, symbol.0, reloc.addend())
        })
        .collect();
    assert_eq!(
        relocs,
        vec![(1, R_MOS_ADDR16, 7, 3), (4, R_MOS_PCREL_8, 2, 5)]
    );

    // The metadata decodes to what was given.
    let section = |name| {
        file.section_by_name(name)
            .expect("present")
            .data()
            .expect("bytes")
    };
    assert_eq!(
        SrcMap::decode(section(SRCMAP_SECTION)).expect("decodes"),
        object.srcmap.clone().expect("given")
    );
    assert_eq!(
        Assertion::decode_all(section(ASSERT_SECTION)).expect("decodes"),
        object.asserts
    );
    assert_eq!(
        FillRun::decode_all(section(FILL_SECTION)).expect("decodes"),
        object.fills
    );
}

#[test]
fn rel_sections_and_other_machines_are_written_for_tests() {
    let mut builder = ObjectBuilder::new();
    let code = builder.code("CODE", &[0x4C, 0, 0]);
    let target = builder.import("target", false);
    builder.reloc(code, 1, R_MOS_ADDR16, target, 0);
    builder.global("start", SymbolDef::Section(code, 0));
    builder.machine(0x3E).use_rel();
    let bytes = builder.build();
    let file = ElfFile32::<LE>::parse(bytes.as_slice()).expect("object reads it");
    assert_eq!(file.elf_header().e_machine(LE).0, 0x3E);
    assert!(file.section_by_name(".relCODE").is_some());
    assert!(file.section_by_name(".relaCODE").is_none());
    assert!(
        file.section_by_name(SRCMAP_SECTION).is_none(),
        "none asked for"
    );
}

proptest! {
    /// Any mix of locals and globals: the table puts every local first and
    /// `numbering` says where each went.
    #[test]
    fn numbering_is_the_table_order(globals in proptest::collection::vec(any::<bool>(), 0..20)) {
        let mut object = RelObject::default();
        object.sections.push(ObjSection {
            name: "CODE".into(),
            sh_type: elf::SHT_PROGBITS.0,
            sh_flags: elf::SHF_ALLOC.0,
            align: 1,
            data: vec![0xEA],
            size: 1,
            relocs: Vec::new(),
        });
        for (i, global) in globals.iter().enumerate() {
            let binding = if *global { Binding::Global } else { Binding::Local };
            object.symbols.push(symbol(&format!("s{i}"), binding, Definition::Section(0, 0)));
        }
        let numbering = object.numbering();
        let bytes = object.write().expect("writes");
        let file = ElfFile32::<LE>::parse(bytes.as_slice()).expect("reads");
        for (i, index) in numbering.symbols.iter().enumerate() {
            let read = file.symbol_by_index(object::SymbolIndex(*index as usize)).expect("there");
            prop_assert_eq!(read.name().expect("named"), format!("s{i}"));
            prop_assert_eq!(read.is_local(), !globals[i]);
        }
    }
}
