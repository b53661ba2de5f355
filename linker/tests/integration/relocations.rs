//! Every supported relocation type, applied with lld's MOS semantics.

use isa::elf::*;
use isa::objfmt::{ObjectBuilder, SymbolDef};

use crate::support::link_flat;

/// One object: CODE holding `code`, a relocation of `r_type` at `offset`
/// against `target` (an absolute symbol with value `value`) plus `addend`.
fn patched(code: &[u8], offset: u32, r_type: u32, value: u32, addend: i64) -> Vec<u8> {
    let mut obj = ObjectBuilder::new();
    let section = obj.code("CODE", code);
    let target = obj.global("target", SymbolDef::Absolute(value));
    obj.reloc(section, offset, r_type, target, addend);
    let linked = link_flat(&[("t.o", obj.build())], 0x1000).expect("links");
    linker::output::write_bin(&linked.image)
}

#[test]
fn absolute_relocations() {
    assert_eq!(
        patched(&[0xAD, 0, 0], 1, R_MOS_ADDR16, 0x1234, 1),
        [0xAD, 0x35, 0x12]
    );
    assert_eq!(
        patched(&[0xA9, 0], 1, R_MOS_ADDR16_LO, 0x1234, 0),
        [0xA9, 0x34]
    );
    assert_eq!(
        patched(&[0xA9, 0], 1, R_MOS_ADDR16_HI, 0x1234, 0x100),
        [0xA9, 0x13]
    );
    assert_eq!(patched(&[0xA5, 0], 1, R_MOS_ADDR8, 0x80, 2), [0xA5, 0x82]);
    // ADDR8 ignores bits above 16, as lld does.
    assert_eq!(
        patched(&[0xA5, 0], 1, R_MOS_ADDR8, 0x1_0042, 0),
        [0xA5, 0x42]
    );
    assert_eq!(patched(&[0xA9, 0], 1, R_MOS_IMM8, 0xFF, 0), [0xA9, 0xFF]);
    assert_eq!(patched(&[0xA9, 0], 1, R_MOS_IMM8, 0, -128), [0xA9, 0x80]);
    assert_eq!(
        patched(&[0, 0, 0], 0, R_MOS_ADDR24, 0x12_3456, 0),
        [0x56, 0x34, 0x12]
    );
    assert_eq!(
        patched(&[0xA9, 0], 1, R_MOS_ADDR24_BANK, 0x12_3456, 0),
        [0xA9, 0x12]
    );
    assert_eq!(
        patched(&[0; 4], 0, R_MOS_FK_DATA_4, 0x1234_5678, 0),
        [0x78, 0x56, 0x34, 0x12]
    );
    assert_eq!(patched(&[9, 9], 0, R_MOS_NONE, 0x1234, 0), [9, 9]);
    // ADDR16 keeps the low 16 bits of wider values, unchecked.
    assert_eq!(patched(&[0, 0], 0, R_MOS_ADDR16, 0x1_2345, 0), [0x45, 0x23]);
}

#[test]
fn branches_are_relative_to_the_next_instruction() {
    // At $1000: BNE target; the operand byte is at $1001, so the
    // displacement is S + A - P - 1 = target - $1002.
    assert_eq!(
        patched(&[0xD0, 0], 1, R_MOS_PCREL_8, 0x1002 + 127, 0),
        [0xD0, 0x7F]
    );
    assert_eq!(
        patched(&[0xD0, 0], 1, R_MOS_PCREL_8, 0x1002 - 128, 0),
        [0xD0, 0x80]
    );
    assert_eq!(
        patched(&[0xD0, 0], 1, R_MOS_PCREL_8, 0x1000, 0),
        [0xD0, 0xFE]
    );
}

#[test]
fn section_symbols_and_cross_object_references() {
    // a.o: CODE = JSR helper / LDA table+1 (via the RODATA section symbol
    // with an addend) / BEQ back to its own start.
    let mut a = ObjectBuilder::new();
    let code = a.code("CODE", &[0x20, 0, 0, 0xAD, 0, 0, 0xF0, 0]);
    let rodata = a.code("RODATA", &[0x11, 0x22]);
    let helper = a.import("helper", false);
    let ro = a.section_symbol(rodata);
    let here = a.local("here", SymbolDef::Section(code, 0));
    a.reloc(code, 1, R_MOS_ADDR16, helper, 0);
    a.reloc(code, 4, R_MOS_ADDR16, ro, 1);
    a.reloc(code, 7, R_MOS_PCREL_8, here, 0);
    // b.o: CODE = helper: RTS.
    let mut b = ObjectBuilder::new();
    let code_b = b.code("CODE", &[0x60]);
    b.global("helper", SymbolDef::Section(code_b, 0));
    let linked = link_flat(&[("a.o", a.build()), ("b.o", b.build())], 0x2000).expect("links");
    // CODE: a's 8 bytes at $2000, b's RTS at $2008; RODATA at $2009.
    assert_eq!(
        linker::output::write_bin(&linked.image),
        [
            0x20, 0x08, 0x20, 0xAD, 0x0A, 0x20, 0xF0, 0xF8, 0x60, 0x11, 0x22
        ]
    );
    assert_eq!(linked.image.symbol("helper"), Some(0x2008));
    assert_eq!(linked.image.symbol("here"), Some(0x2000));
    assert_eq!(linked.image.entry, 0x2000);
}

#[test]
fn weak_symbols_yield_to_strong_ones_and_default_to_zero() {
    let mut a = ObjectBuilder::new();
    let code = a.code("CODE", &[0xAD, 0, 0, 0xAD, 0, 0]);
    let hook = a.weak("hook", SymbolDef::Section(code, 0));
    let optional = a.weak("optional", SymbolDef::Undefined);
    a.reloc(code, 1, R_MOS_ADDR16, hook, 0);
    a.reloc(code, 4, R_MOS_ADDR16, optional, 0);
    let mut b = ObjectBuilder::new();
    b.global("hook", SymbolDef::Absolute(0xBEEF));
    let linked = link_flat(&[("a.o", a.build()), ("b.o", b.build())], 0x1000).expect("links");
    assert_eq!(
        linker::output::write_bin(&linked.image),
        [0xAD, 0xEF, 0xBE, 0xAD, 0x00, 0x00]
    );
}

/// An object laid out as llvm-mos writes them: `.text.*`/`.rodata.*`/
/// `.zp.*` sections, relocations against section symbols with addends,
/// debug sections with their own relocations, BCD in `e_flags`. The
/// built-in targets place llvm-mos section names with ca65's segments.
#[test]
fn llvm_mos_style_objects_link_with_the_built_in_targets() {
    let mut obj = ObjectBuilder::new();
    obj.flags(EF_MOS_ARCH_6502 | EF_MOS_ARCH_6502_BCD);
    // main: lda .rodata.str+1 / sta __rc0 / jmp helper
    let text = obj.code(".text.main", &[0xAD, 0, 0, 0x85, 0, 0x4C, 0, 0]);
    let helper = obj.code(".text.helper", &[0x60]);
    let rodata = obj.code(".rodata.str1.1", b"hi\0");
    let zp = obj.zeropage(".zp.bss", 2);
    obj.bss(".bss", 8);
    obj.data(".data", &[0x11]);
    obj.progbits(".comment", b"clang version 19\0", 0);
    let debug = obj.progbits(".debug_info", &[0; 8], 0);
    let text_sym = obj.section_symbol(text);
    let rodata_sym = obj.section_symbol(rodata);
    let helper_sym = obj.section_symbol(helper);
    let zp_sym = obj.section_symbol(zp);
    obj.reloc(text, 1, R_MOS_ADDR16, rodata_sym, 1)
        .reloc(text, 4, R_MOS_ADDR8, zp_sym, 0)
        .reloc(text, 6, R_MOS_ADDR16, helper_sym, 0)
        .reloc(debug, 0, R_MOS_FK_DATA_4, text_sym, 0)
        .reloc(debug, 4, R_MOS_FK_DATA_4, rodata_sym, 0);
    obj.global("main", SymbolDef::Section(text, 0));
    obj.global("__rc0", SymbolDef::Section(zp, 0));
    let rom = crate::support::fake_rom(&[]);
    let linked = crate::support::link_with(
        &[("main.c.o", obj.build())],
        &linker::Target::ScorpionExt,
        &[linker::SymbolFile {
            name: "rom.elf",
            image: &rom,
        }],
        &linker::MemorySources::default(),
    )
    .expect("links");
    let image = &linked.image;
    // CODE $0400: main (8 bytes), helper at $0408; RODATA "hi" at $0409;
    // DATA at $040C; __rc0 at the user zero page's start.
    assert_eq!(
        image.areas[0].bytes,
        [
            0xAD, 0x0A, 0x04, 0x85, 0x80, 0x4C, 0x08, 0x04, 0x60, b'h', b'i', 0, 0x11
        ]
    );
    assert_eq!(image.symbol("__rc0"), Some(0x80));
    assert_eq!(image.flags, EF_MOS_ARCH_6502 | EF_MOS_ARCH_6502_BCD);
    // Debug sections are not placed; their relocations go with them.
    assert!(image.sections.iter().all(|s| !s.name.starts_with(".debug")));
}
