//! Write-then-read: every linked image reads back as the same `Image`, and
//! the same inputs always give the same bytes.

use isa::elf::*;
use isa::objfmt::{HookKind, HookRecord};
use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::{Format, Image, MemorySources, SymbolFile, Target};

use crate::support::{fake_rom, link_with};

/// An extension in two objects: zero-page data, an import from the ROM,
/// a hook handler with a chain slot, code, read-only data and BSS.
pub(crate) fn extension() -> Vec<(&'static str, Vec<u8>)> {
    let mut main = ObjectBuilder::new();
    // handler: CMP #'Q' / BNE fall / JSR PUTCH / JMP CMD_DONE / fall: JMP $0000 (chain slot)
    let code = main.code(
        "CODE",
        &[0xC9, b'Q', 0xD0, 0x06, 0x20, 0, 0, 0x4C, 0, 0, 0x4C, 0, 0],
    );
    let putch = main.import("PUTCH", false);
    let done = main.import("CMD_DONE", false);
    let count = main.import("count", true);
    main.reloc(code, 5, R_MOS_ADDR16, putch, 0);
    main.reloc(code, 8, R_MOS_ADDR16, done, 0);
    main.global("__scorpion_hook_unknown", SymbolDef::Section(code, 0));
    main.global("__scorpion_chain_unknown", SymbolDef::Section(code, 11));
    let rodata = main.code("RODATA", &[0, 0]);
    let table = main.local("table", SymbolDef::Section(rodata, 0));
    main.reloc(rodata, 0, R_MOS_ADDR8, count, 0);
    main.reloc(rodata, 1, R_MOS_ADDR16_HI, table, 0);
    let mut data = ObjectBuilder::new();
    let zp = data.zeropage("ZEROPAGE", 2);
    data.global("count", SymbolDef::Section(zp, 1));
    data.bss("BSS", 16);
    let init = data.data("DATA", &[1, 2, 3]);
    data.local("initial", SymbolDef::Section(init, 0));
    vec![("main.o", main.build()), ("data.o", data.build())]
}

pub(crate) fn link_extension() -> linker::Linked {
    let rom = fake_rom(&[("PUTCH", 0xFF00), ("CMD_DONE", 0xF123)]);
    link_with(
        &extension(),
        &Target::ScorpionExt,
        &[SymbolFile {
            name: "rom.elf",
            image: &rom,
        }],
        &MemorySources::default(),
    )
    .expect("the extension links")
}

#[test]
fn elf_images_read_back_identically() {
    let linked = link_extension();
    let image = &linked.image;
    // CODE at USER_RAM_START, RODATA, DATA after it; BSS not loaded.
    assert_eq!(image.areas.len(), 1);
    assert_eq!(image.areas[0].load, 0x0400);
    assert_eq!(
        image.areas[0].bytes,
        [
            0xC9, b'Q', 0xD0, 0x06, 0x20, 0x00, 0xFF, 0x4C, 0x23, 0xF1, 0x4C, 0, 0, // CODE
            0x81, 0x04, // RODATA: count ($81), >table
            1, 2, 3, // DATA
        ]
    );
    assert_eq!(image.symbol("count"), Some(0x81));
    assert_eq!(
        image.hooks.get(HookKind::Unknown),
        Some(&HookRecord {
            kind: HookKind::Unknown,
            handler: 0x0400,
            chain: Some(0x040B),
        })
    );
    assert!(image.hooks.get(HookKind::Loop).is_none());
    let bytes = Format::Elf.write(image).expect("writes ELF");
    let read = Image::parse("ext.elf", &bytes).expect("reads back");
    assert_eq!(&read, image);
    // Referenced ROM symbols are in the image's symbol table, as constants.
    let putch = read
        .symbols
        .iter()
        .find(|s| s.name == "PUTCH")
        .expect("PUTCH");
    assert_eq!(
        (putch.value, putch.section, putch.global),
        (0xFF00, None, true)
    );
    // Locals keep their section.
    let table = read
        .symbols
        .iter()
        .find(|s| s.name == "table")
        .expect("table");
    assert_eq!(read.sections[table.section.expect("placed")].name, "RODATA");
}

#[test]
fn linking_is_deterministic() {
    let first = link_extension();
    let second = link_extension();
    for format in Format::ALL {
        assert_eq!(
            format.write(&first.image).expect("writes"),
            format.write(&second.image).expect("writes"),
            "{format}"
        );
    }
    assert_eq!(first.map(), second.map());
    assert_eq!(first.vice_labels(), second.vice_labels());
}

#[test]
fn load_and_run_addresses_survive_the_round_trip() {
    // A ROM-style layout: DATA stored in ROM, run in RAM.
    let layout = linker::Layout::from_toml(
        "rom.toml",
        r#"
            [[area]]
            name = "RAM"
            start = "$0200"
            size = "$200"
            output = false
            [[area]]
            name = "ROM"
            start = "$F000"
            size = "$1000"
            fill = true
            fill-value = "$FF"
            [[segment]]
            name = "CODE"
            load = "ROM"
            [[segment]]
            name = "DATA"
            load = "ROM"
            run = "RAM"
            kind = "rw"
            define = true
            [[segment]]
            name = "VECTORS"
            load = "ROM"
            start = "$FFFA"
        "#,
    )
    .expect("layout parses");
    let mut obj = ObjectBuilder::new();
    let code = obj.code("CODE", &[0xEA, 0xAD, 0, 0]);
    let data = obj.data("DATA", &[0x42]);
    let var = obj.local("var", SymbolDef::Section(data, 0));
    obj.reloc(code, 2, R_MOS_ADDR16, var, 0);
    let vectors = obj.code("VECTORS", &[0, 0, 0, 0, 0, 0]);
    let reset = obj.global("reset", SymbolDef::Section(code, 0));
    obj.reloc(vectors, 2, R_MOS_ADDR16, reset, 0);
    let linked = link_with(
        &[("rom.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    let image = &linked.image;
    // One area split in three: CODE (runs where it loads), DATA (runs in
    // RAM), then fill and VECTORS.
    let shape: Vec<(u32, u32, usize)> = image
        .areas
        .iter()
        .map(|a| (a.load, a.run, a.bytes.len()))
        .collect();
    assert_eq!(
        shape,
        [
            (0xF000, 0xF000, 4),
            (0xF004, 0x0200, 1),
            (0xF005, 0xF005, 0x0FFB)
        ]
    );
    assert_eq!(image.areas[0].bytes, [0xEA, 0xAD, 0x00, 0x02]);
    assert_eq!(image.byte_at(0xFFFC), Some(0x00));
    assert_eq!(image.byte_at(0xFFFD), Some(0xF0));
    assert_eq!(image.byte_at(0xF100), Some(0xFF));
    assert_eq!(image.run_byte(0x0200), Some(0x42));
    assert_eq!(image.symbol("__DATA_LOAD__"), Some(0xF004));
    assert_eq!(image.symbol("__DATA_RUN__"), Some(0x0200));
    assert_eq!(image.symbol("__DATA_SIZE__"), Some(1));
    assert_eq!(linker::output::write_bin(image).len(), 0x1000);
    let read =
        Image::parse("rom.elf", &Format::Elf.write(image).expect("writes")).expect("reads back");
    assert_eq!(&read, image);
    let data_section = read
        .sections
        .iter()
        .find(|s| s.name == "DATA")
        .expect("DATA");
    assert_eq!((data_section.run, data_section.load), (0x0200, 0xF004));
}

#[test]
fn empty_sections_and_labels_at_their_start_round_trip() {
    let mut obj = ObjectBuilder::new();
    let empty = obj.code("RODATA", &[]);
    obj.global("nothing", SymbolDef::Section(empty, 0));
    obj.code("CODE", &[0x60]);
    obj.bss("BSS", 0);
    let linked = crate::support::link_flat(&[("e.o", obj.build())], 0x3000).expect("links");
    assert_eq!(linked.image.symbol("nothing"), Some(0x3001));
    let read = Image::parse("e.elf", &Format::Elf.write(&linked.image).expect("writes"))
        .expect("reads back");
    assert_eq!(read, linked.image);
    assert_eq!(read.sections.len(), 1, "only CODE has bytes");
}
