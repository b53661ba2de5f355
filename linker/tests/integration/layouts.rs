//! The built-in targets and layout files: where segments land, the symbols
//! a layout defines, and the map that shows it.

use isa::elf::*;
use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::{Layout, MemorySources, SymbolFile, Target};

use crate::round_trip::link_extension;
use crate::support::{fake_rom, link_with};

/// CODE, RODATA, DATA, BSS and ZEROPAGE, one of each.
fn program() -> Vec<u8> {
    let mut obj = ObjectBuilder::new();
    let code = obj.code("CODE", &[0xA9, 0x00, 0x60]);
    obj.global("main", SymbolDef::Section(code, 0));
    let rodata = obj.code("RODATA", &[1, 2]);
    obj.global("consts", SymbolDef::Section(rodata, 0));
    let data = obj.data("DATA", &[3]);
    obj.global("var", SymbolDef::Section(data, 0));
    let bss = obj.bss("BSS", 4);
    obj.global("buffer", SymbolDef::Section(bss, 0));
    let zp = obj.zeropage("ZEROPAGE", 2);
    obj.global("ptr", SymbolDef::Section(zp, 0));
    obj.build()
}

fn with_rom(target: &Target) -> linker::Linked {
    let rom = fake_rom(&[]);
    link_with(
        &[("prog.o", program())],
        target,
        &[SymbolFile {
            name: "rom.elf",
            image: &rom,
        }],
        &MemorySources::default(),
    )
    .expect("links")
}

#[test]
fn scorpion_ext_uses_the_user_zero_page_and_ram() {
    let linked = with_rom(&Target::ScorpionExt);
    let image = &linked.image;
    assert_eq!(image.symbol("ptr"), Some(0x80));
    assert_eq!(image.symbol("main"), Some(0x0400));
    assert_eq!(image.symbol("consts"), Some(0x0403));
    assert_eq!(image.symbol("var"), Some(0x0405));
    assert_eq!(image.symbol("buffer"), Some(0x0406));
    assert_eq!(image.areas.len(), 1);
    assert_eq!(image.areas[0].bytes, [0xA9, 0x00, 0x60, 1, 2, 3]);
    assert_eq!(image.entry, 0x0400);
}

#[test]
fn scorpion_os_runs_from_kim_bus_ram() {
    let linked = with_rom(&Target::ScorpionOs);
    let image = &linked.image;
    assert_eq!(image.symbol("main"), Some(0x1000));
    assert_eq!(image.symbol("var"), Some(0x1005));
    assert_eq!(image.symbol("buffer"), Some(0x0400));
    assert_eq!(image.symbol("ptr"), Some(0x80));
    assert_eq!(image.areas[0].load, 0x1000);
}

#[test]
fn scorpion_rom_reads_its_bounds_from_its_own_exports() {
    let mut obj = ObjectBuilder::new();
    obj.global("USER_ZP_START", SymbolDef::Absolute(0x80));
    obj.global("USER_RAM_START", SymbolDef::Absolute(0x0400));
    let code = obj.code("CODE", &[0x78, 0x4C, 0, 0]);
    let reset = obj.global("reset", SymbolDef::Section(code, 0));
    obj.reloc(code, 2, R_MOS_ADDR16, reset, 0);
    let data = obj.data("DATA", &[0x55, 0x66]);
    obj.local("state", SymbolDef::Section(data, 0));
    obj.bss("BSS", 0x10);
    let zp = obj.zeropage("ZEROPAGE", 4);
    obj.local("zp0", SymbolDef::Section(zp, 0));
    let jump = obj.code("JUMPTABLE", &[0x4C, 0, 0]);
    obj.reloc(jump, 1, R_MOS_ADDR16, reset, 0);
    let vectors = obj.code("VECTORS", &[0; 6]);
    for offset in [0, 2, 4] {
        obj.reloc(vectors, offset, R_MOS_ADDR16, reset, 0);
    }
    let linked = link_with(
        &[("rom.o", obj.build())],
        &Target::ScorpionRom,
        &[],
        &MemorySources::default(),
    )
    .expect("the ROM links without --just-symbols");
    let image = &linked.image;
    let bin = linker::output::write_bin(image);
    assert_eq!(bin.len(), 0x1000);
    assert_eq!(&bin[..4], [0x78, 0x4C, 0x00, 0xF0]);
    // DATA is stored after CODE and runs at $0200.
    assert_eq!(&bin[4..6], [0x55, 0x66]);
    assert_eq!(image.symbol("state"), Some(0x0200));
    assert_eq!(image.symbol("__DATA_LOAD__"), Some(0xF004));
    assert_eq!(image.symbol("__DATA_RUN__"), Some(0x0200));
    assert_eq!(image.symbol("__DATA_SIZE__"), Some(2));
    assert_eq!(image.symbol("zp0"), Some(0x00));
    assert_eq!(&bin[0xF00..0xF03], [0x4C, 0x00, 0xF0]);
    assert_eq!(&bin[0xFFA..], [0x00, 0xF0, 0x00, 0xF0, 0x00, 0xF0]);
    assert_eq!(bin[0x10], 0xFF, "erased-EPROM fill");
    insta::assert_snapshot!("scorpion_rom_map", linked.map());
}

#[test]
fn layout_files_align_define_and_match_section_patterns() {
    let layout = Layout::from_toml(
        "custom.toml",
        r#"
            name = "custom"
            [[area]]
            name = "RAM"
            start = 0x2001
            end = "$2FFF"
            fill-value = 0xEA
            define = true
            [[segment]]
            name = "CODE"
            load = "RAM"
            sections = ["CODE", ".text*"]
            [[segment]]
            name = "TABLES"
            load = "RAM"
            align = 256
            define = true
        "#,
    )
    .expect("parses");
    let mut a = ObjectBuilder::new();
    a.code(".text.main", &[0x60]);
    let code = a.code("CODE", &[0xEA, 0xEA]);
    a.align(code, 2);
    let tables = a.code("TABLES", &[7]);
    a.global("tables", SymbolDef::Section(tables, 0));
    let linked = link_with(
        &[("a.o", a.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    let image = &linked.image;
    // CODE: .text.main at $2001, then CODE aligned 2 at $2002 (the segment
    // itself starts aligned: $2002). TABLES at $2100; the gap is fill.
    assert_eq!(image.symbol("__CODE_RUN__"), None, "CODE has no define");
    assert_eq!(image.symbol("__TABLES_RUN__"), Some(0x2100));
    assert_eq!(image.symbol("__TABLES_SIZE__"), Some(1));
    assert_eq!(image.symbol("__RAM_START__"), Some(0x2001));
    assert_eq!(image.symbol("__RAM_SIZE__"), Some(0x0FFF));
    assert_eq!(image.symbol("__RAM_LAST__"), Some(0x2101));
    assert_eq!(image.symbol("tables"), Some(0x2100));
    let bin = linker::output::write_bin(image);
    assert_eq!(image.areas[0].load, 0x2001);
    assert_eq!(&bin[..5], [0xEA, 0x60, 0xEA, 0xEA, 0xEA]);
    assert_eq!(bin.len(), 0x100);
    assert_eq!(bin[0xFF], 7);
    insta::assert_snapshot!("custom_map", linked.map());
    insta::assert_snapshot!("custom_labels", linked.vice_labels());
}

#[test]
fn areas_may_be_larger_than_64k() {
    // ld65's `size = $1000000`: 100 KB of code assembled in .org chunks.
    let layout = Layout::from_toml(
        "bench.toml",
        "[[area]]\nname = \"MAIN\"\nstart = \"$1000\"\nsize = \"$1000000\"\n[[segment]]\nname = \"CODE\"\nload = \"MAIN\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    let chunk: Vec<u8> = (0..50_000u32).map(|i| i as u8).collect();
    let first = obj.code("CODE", &chunk);
    obj.global("first", SymbolDef::Section(first, 0));
    let mut second = ObjectBuilder::new();
    let code = second.code("CODE", &chunk);
    second.global("second", SymbolDef::Section(code, 0));
    let linked = link_with(
        &[("one.o", obj.build()), ("two.o", second.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    assert_eq!(linked.image.symbol("second"), Some(0x1000 + 50_000));
    assert_eq!(linker::output::write_bin(&linked.image).len(), 100_000);
}

#[test]
fn the_extension_map() {
    let linked = link_extension();
    insta::assert_snapshot!("extension_map", linked.map());
    insta::assert_snapshot!("extension_labels", linked.vice_labels());
}

#[test]
fn reserved_bytes_take_the_load_area_fill_value() {
    // CODE is section 1: `.res 3` (zeros in the object, listed in
    // `.scorpion.fill`) between two bytes, as ld65 fills with `fillval`.
    let object = |runs: &[isa::objfmt::FillRun]| {
        let mut obj = ObjectBuilder::new();
        obj.code("CODE", &[1, 0, 0, 0, 2]);
        obj.progbits(
            isa::objfmt::FILL_SECTION,
            &isa::objfmt::FillRun::encode_all(runs),
            0,
        );
        obj.build()
    };
    let run = |offset, length| isa::objfmt::FillRun {
        section: 1,
        offset,
        length,
    };
    let filled = |fill: &str| {
        Layout::from_toml(
            "filled.toml",
            &format!(
                "[[area]]\nname = \"ROM\"\nstart = \"$F000\"\nsize = \"$100\"\nfill-value = \"{fill}\"\n\
                 [[segment]]\nname = \"CODE\"\nload = \"ROM\"\n"
            ),
        )
        .expect("parses")
    };
    let bytes = |object: Vec<u8>, layout: Layout| {
        let linked = link_with(
            &[("a.o", object)],
            &Target::Custom(layout),
            &[],
            &MemorySources::default(),
        )
        .expect("links");
        linker::Format::Bin.write(&linked.image).expect("a binary")
    };
    assert_eq!(
        bytes(object(&[run(1, 3)]), filled("$FF")),
        [1, 0xFF, 0xFF, 0xFF, 2]
    );
    assert_eq!(
        bytes(object(&[run(1, 1), run(3, 1)]), filled("$EA")),
        [1, 0xEA, 0, 0xEA, 2]
    );
    assert_eq!(bytes(object(&[run(1, 3)]), filled("0")), [1, 0, 0, 0, 2]);
    // No runs: the object's bytes stand, whatever the fill.
    assert_eq!(bytes(object(&[]), filled("$FF")), [1, 0, 0, 0, 2]);

    // A run outside the section's bytes is a malformed object.
    let error = link_with(
        &[("a.o", object(&[run(3, 4)]))],
        &Target::Custom(filled("$FF")),
        &[],
        &MemorySources::default(),
    )
    .expect_err("a run past the end");
    assert!(
        format!("{error:?}").contains("has no such bytes"),
        "{error:?}"
    );
}
