//! `scorpion link`: objects built with `isa::objfmt::ObjectBuilder`, linked by the
//! binary, outputs read back.

use std::path::Path;

use isa::elf::{R_MOS_ADDR8, R_MOS_ADDR16, R_MOS_PCREL_8};
use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::Image;

use crate::{scorpion, transcript};

/// main.o calls `print` in util.o through an import, with a zero-page
/// pointer; util.o exports both.
fn write_program(dir: &Path) {
    let mut main = ObjectBuilder::new();
    let code = main.code("CODE", &[0x20, 0, 0, 0xA5, 0, 0x60]);
    let print = main.import("print", false);
    let ptr = main.import("ptr", true);
    main.reloc(code, 1, R_MOS_ADDR16, print, 0)
        .reloc(code, 4, R_MOS_ADDR8, ptr, 0);
    main.global("start", SymbolDef::Section(code, 0));
    main.source(code, 0, "main.s", 2, 9)
        .source(code, 3, "main.s", 3, 9);
    let mut util = ObjectBuilder::new();
    let code = util.code("CODE", &[0xEA, 0x60]);
    util.global("print", SymbolDef::Section(code, 0));
    let zp = util.zeropage("ZEROPAGE", 2);
    util.global("ptr", SymbolDef::Section(zp, 0));
    util.code("RODATA", b"HI\0");
    std::fs::write(dir.join("main.o"), main.build()).expect("write main.o");
    std::fs::write(dir.join("util.o"), util.build()).expect("write util.o");
}

#[test]
fn links_into_every_format_with_map_and_labels() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_program(dir.path());
    let mut outputs = String::new();
    for format in ["elf", "bin", "ihex", "srec", "kim"] {
        let out = format!("prog.{format}");
        let output = scorpion(
            dir.path(),
            &[
                "link", "main.o", "util.o", "-o", &out, "--target", "flat", "--start", "$0800",
                "--format", format, "--map", "prog.map", "--labels", "prog.lbl",
            ],
        );
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
        outputs.push_str(&transcript(&output));
    }
    insta::assert_snapshot!("link_every_format", outputs);
    let bin = std::fs::read(dir.path().join("prog.bin")).expect("bin written");
    assert_eq!(
        bin,
        [
            0x20, 0x06, 0x08, 0xA5, 0x00, 0x60, 0xEA, 0x60, b'H', b'I', 0
        ]
    );
    let elf = std::fs::read(dir.path().join("prog.elf")).expect("elf written");
    let image = Image::parse("prog.elf", &elf).expect("the ELF image reads back");
    assert_eq!(linker::output::write_bin(&image), bin);
    assert_eq!(image.entry, 0x0800);
    let text = |name: &str| std::fs::read_to_string(dir.path().join(name)).expect("written");
    assert!(text("prog.ihex").ends_with(":00000001FF\n"));
    assert!(text("prog.srec").starts_with("S0"));
    assert!(text("prog.kim").starts_with(";0B0800"));
    insta::assert_snapshot!("link_map", text("prog.map"));
    insta::assert_snapshot!("link_labels", text("prog.lbl"));
}

#[test]
fn an_extension_links_against_the_rom_with_just_symbols() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // A miniature ROM: exports the user bounds and PUTCH, linked with the
    // scorpion-rom target (its bounds come from its own exports).
    let mut rom = ObjectBuilder::new();
    for (name, value) in [
        ("USER_ZP_START", 0x80),
        ("USER_ZP_END", 0xFF),
        ("USER_RAM_START", 0x0400),
        ("USER_RAM_END", 0x0FFF),
    ] {
        rom.global(name, SymbolDef::Absolute(value));
    }
    let code = rom.code("CODE", &[0x60]);
    rom.global("PUTCH", SymbolDef::Section(code, 0));
    rom.code("VECTORS", &[0; 6]);
    std::fs::write(dir.path().join("rom.o"), rom.build()).expect("write rom.o");
    let built = scorpion(
        dir.path(),
        &["link", "rom.o", "-o", "rom.elf", "--target", "scorpion-rom"],
    );
    assert_eq!(built.status.code(), Some(0), "{}", transcript(&built));
    // The extension: a handler that calls PUTCH and falls through.
    let mut ext = ObjectBuilder::new();
    let code = ext.code("CODE", &[0x20, 0, 0, 0x4C, 0, 0]);
    let putch = ext.import("PUTCH", false);
    ext.reloc(code, 1, R_MOS_ADDR16, putch, 0);
    ext.global("__scorpion_hook_unknown", SymbolDef::Section(code, 0));
    ext.global("__scorpion_chain_unknown", SymbolDef::Section(code, 4));
    std::fs::write(dir.path().join("ext.o"), ext.build()).expect("write ext.o");
    // Without --just-symbols, the built-in reference ROM's PUTCH ($FF00).
    let without = scorpion(dir.path(), &["link", "ext.o", "-o", "builtin.elf"]);
    assert_eq!(without.status.code(), Some(0), "{}", transcript(&without));
    let builtin = Image::parse(
        "builtin.elf",
        &std::fs::read(dir.path().join("builtin.elf")).expect("written"),
    )
    .expect("reads");
    assert_eq!(builtin.areas[0].bytes[..3], [0x20, 0x00, 0xFF]);
    let with = scorpion(
        dir.path(),
        &[
            "link",
            "ext.o",
            "-o",
            "ext.elf",
            "--just-symbols",
            "rom.elf",
        ],
    );
    insta::assert_snapshot!(
        "link_extension_against_rom",
        format!(
            "{}{}{}",
            transcript(&built),
            transcript(&without),
            transcript(&with)
        )
    );
    let image = Image::parse(
        "ext.elf",
        &std::fs::read(dir.path().join("ext.elf")).expect("written"),
    )
    .expect("reads");
    assert_eq!(image.areas[0].load, 0x0400);
    assert_eq!(image.areas[0].bytes[..3], [0x20, 0x00, 0xF0]);
    let hook = image.hooks.records[0];
    assert_eq!((hook.handler, hook.chain), (0x0400, Some(0x0404)));
}

#[test]
fn layout_files_and_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_program(dir.path());
    std::fs::write(
        dir.path().join("layout.toml"),
        "[[area]]\nname = \"ZP\"\nstart = \"$10\"\nsize = 16\noutput = false\n\
         [[area]]\nname = \"RAM\"\nstart = \"$2000\"\nsize = \"$100\"\n\
         [[segment]]\nname = \"ZEROPAGE\"\nload = \"ZP\"\nkind = \"zp\"\n\
         [[segment]]\nname = \"CODE\"\nload = \"RAM\"\n\
         [[segment]]\nname = \"RODATA\"\nload = \"RAM\"\n",
    )
    .expect("write layout");
    std::fs::write(dir.path().join("bad.toml"), "[[area]]\nname = 3\n").expect("write");
    let runs = [
        vec![
            "link",
            "main.o",
            "util.o",
            "-o",
            "p.bin",
            "--target",
            "layout.toml",
            "--format",
            "bin",
        ],
        vec![
            "link", "main.o", "util.o", "-o", "p.bin", "--target", "bad.toml",
        ],
        vec![
            "link",
            "main.o",
            "util.o",
            "-o",
            "p.bin",
            "--target",
            "layout.toml",
            "--start",
            "$1000",
        ],
        vec![
            "link", "main.o", "-o", "p.bin", "--target", "flat", "--start", "$1000",
        ],
        vec![
            "link", "main.o", "util.o", "-o", "p.bin", "--format", "coff",
        ],
        vec!["link", "main.o", "-o", "p.bin", "--target", "flat"],
        vec!["link", "nope.o", "-o", "p.bin"],
    ];
    let mut all = String::new();
    for args in &runs {
        let output = scorpion(dir.path(), args);
        all.push_str(&format!(
            "$ scorpion {}\n{}\n",
            args.join(" "),
            transcript(&output)
        ));
    }
    insta::assert_snapshot!("link_layouts_and_errors", all);
    let bin = std::fs::read(dir.path().join("p.bin")).expect("the layout link wrote p.bin");
    assert_eq!(bin[..6], [0x20, 0x06, 0x20, 0xA5, 0x10, 0x60]);
}

/// An ld65 configuration as the target: `%S` from `--start`, an area
/// that starts where another ends, a second output file; and mistakes in
/// configurations named at their line and column.
#[test]
fn ld65_configurations_and_their_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_program(dir.path());
    std::fs::write(
        dir.path().join("two.cfg"),
        "# main code at %S, read-only data in a second file\n\
         MEMORY {\n\
             ZP:   start = $10, size = $10, type = rw, file = \"\";\n\
             MAIN: start = %S, size = $100, define = yes;\n\
             DATA: start = __MAIN_LAST__, size = $10, file = \"%O.data\";\n\
         }\n\
         SEGMENTS {\n\
             ZEROPAGE: load = ZP, type = zp;\n\
             CODE:     load = MAIN;\n\
             RODATA:   load = DATA, type = ro;\n\
         }\n",
    )
    .expect("write the configuration");
    std::fs::write(
        dir.path().join("typo.cfg"),
        "MEMORY {\n    MAIN: start = $1000, size = $100;\n}\nSEGMENTS {\n    CODE: load = MIAN, type = ro;\n}\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("o65.cfg"),
        "MEMORY { M: start = 0, size = $100; }\nSEGMENTS { CODE: load = M; }\nFILES { %O: format = o65; }\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("unknown.cfg"),
        "MEMORY {\n    M: start = $1000, size = __HIMEM__ - $1000;\n}\nSEGMENTS { CODE: load = M; RODATA: load = M; ZEROPAGE: load = M, type = zp; }\n",
    )
    .expect("write");
    let link = |target: &str, extra: &[&str]| {
        let mut args = vec![
            "link", "main.o", "util.o", "-o", "p.bin", "--format", "bin", "--target", target,
        ];
        args.extend_from_slice(extra);
        let output = scorpion(dir.path(), &args);
        format!("$ scorpion {}\n{}\n", args.join(" "), transcript(&output))
    };
    let mut all = link("two.cfg", &["--start", "$2000"]);
    for bad in ["typo.cfg", "o65.cfg", "unknown.cfg"] {
        all.push_str(&link(bad, &[]));
    }
    insta::assert_snapshot!("link_ld65_configurations", all);
    let main = std::fs::read(dir.path().join("p.bin")).expect("the main file");
    assert_eq!(main, [0x20, 0x06, 0x20, 0xA5, 0x10, 0x60, 0xEA, 0x60]);
    let data = std::fs::read(dir.path().join("p.bin.data")).expect("the second file");
    assert_eq!(data, b"HI\0");
}

#[test]
fn out_of_range_branch_shows_the_source_line_from_disk() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut obj = ObjectBuilder::new();
    let mut bytes = vec![0xF0, 0x00];
    bytes.extend(std::iter::repeat_n(0xEA, 150));
    let code = obj.code("CODE", &bytes);
    let far = obj.local("far", SymbolDef::Section(code, 152));
    obj.reloc(code, 1, R_MOS_PCREL_8, far, 0);
    obj.source(code, 0, "loop.s", 2, 9);
    std::fs::write(dir.path().join("loop.o"), obj.build()).expect("write");
    std::fs::write(
        dir.path().join("loop.s"),
        "start:\n        beq far\n        .res 150, $EA\nfar:\n",
    )
    .expect("write source");
    let output = scorpion(
        dir.path(),
        &[
            "link", "loop.o", "-o", "loop.bin", "--target", "flat", "--start", "$C000",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!("link_branch_range", transcript(&output));
}
