//! The `flat` target against ld65: real ca65 objects linked by ld65 with the
//! config `linker::layout` documents, and the equivalent ELF objects (what
//! our assembler writes for the same sources) linked by us, must give the
//! same bytes.

use std::path::Path;
use std::process::Command;

use isa::elf::*;
use isa::objfmt::{ObjectBuilder, SymbolDef};

use crate::support::link_flat;

/// The ld65 config equivalent to `--target flat --start START`.
fn flat_cfg(start: u16) -> String {
    format!(
        "MEMORY {{
    ZP:   start = $0000, size = $0100, type = rw, file = \"\";
    MAIN: start = ${start:04X}, size = $10000 - ${start:04X}, file = %O;
}}
SEGMENTS {{
    ZEROPAGE: load = ZP,   type = zp,  optional = yes;
    CODE:     load = MAIN, type = ro,  optional = yes;
    RODATA:   load = MAIN, type = ro,  optional = yes;
    DATA:     load = MAIN, type = rw,  optional = yes;
    BSS:      load = MAIN, type = bss, optional = yes;
}}
"
    )
}

const A_S: &str = "\
.export foo
.importzp zz
.code
foo:    lda zz
        nop
.rodata
        .byte 1, 2, 3
        .align 4
        .byte 9
.bss
        .res 3
.data
        .byte $AA
";

fn a_o() -> Vec<u8> {
    let mut obj = ObjectBuilder::new();
    let code = obj.code("CODE", &[0xA5, 0x00, 0xEA]);
    let rodata = obj.code("RODATA", &[1, 2, 3, 0, 9]);
    obj.align(rodata, 4);
    obj.bss("BSS", 3);
    obj.data("DATA", &[0xAA]);
    obj.global("foo", SymbolDef::Section(code, 0));
    let zz = obj.import("zz", true);
    obj.reloc(code, 1, R_MOS_ADDR8, zz, 0);
    obj.build()
}

const B_S: &str = "\
.import foo
.exportzp zz
.zeropage
        .res 5
zz:     .res 1
.code
        jsr foo
        .align 8
        rts
.data
        .byte $BB
.bss
        .res 2
";

fn b_o() -> Vec<u8> {
    let mut obj = ObjectBuilder::new();
    let zp = obj.zeropage("ZEROPAGE", 6);
    obj.global("zz", SymbolDef::Section(zp, 5));
    let code = obj.code("CODE", &[0x20, 0, 0, 0, 0, 0, 0, 0, 0x60]);
    obj.align(code, 8);
    let imported = obj.import("foo", false);
    obj.reloc(code, 1, R_MOS_ADDR16, imported, 0);
    obj.data("DATA", &[0xBB]);
    obj.bss("BSS", 2);
    obj.build()
}

const C_S: &str = "\
.import foo
.importzp zz
.export table
.code
start:  ldx #<table
        ldy #>table
loop:   dex
        bne loop
        sta zz+1
        jmp foo
.rodata
table:  .word start, foo+2
        .byte <(table+1), >foo
";

fn c_o() -> Vec<u8> {
    let mut obj = ObjectBuilder::new();
    let code = obj.code(
        "CODE",
        &[0xA2, 0, 0xA0, 0, 0xCA, 0xD0, 0, 0x85, 0, 0x4C, 0, 0],
    );
    let rodata = obj.code("RODATA", &[0, 0, 0, 0, 0, 0]);
    let start = obj.local("start", SymbolDef::Section(code, 0));
    let looping = obj.local("loop", SymbolDef::Section(code, 4));
    let table = obj.global("table", SymbolDef::Section(rodata, 0));
    let imported = obj.import("foo", false);
    let zz = obj.import("zz", true);
    obj.reloc(code, 1, R_MOS_ADDR16_LO, table, 0)
        .reloc(code, 3, R_MOS_ADDR16_HI, table, 0)
        .reloc(code, 6, R_MOS_PCREL_8, looping, 0)
        .reloc(code, 8, R_MOS_ADDR8, zz, 1)
        .reloc(code, 10, R_MOS_ADDR16, imported, 0)
        .reloc(rodata, 0, R_MOS_ADDR16, start, 0)
        .reloc(rodata, 2, R_MOS_ADDR16, imported, 2)
        .reloc(rodata, 4, R_MOS_ADDR16_LO, table, 1)
        .reloc(rodata, 5, R_MOS_ADDR16_HI, imported, 0);
    obj.build()
}

fn ld65_link(dir: &Path, ca65: &Path, ld65: &Path, start: u16) -> Vec<u8> {
    let mut objects = Vec::new();
    for (name, text) in [("a", A_S), ("b", B_S), ("c", C_S)] {
        let source = dir.join(format!("{name}.s"));
        std::fs::write(&source, text).expect("write source");
        let status = Command::new(ca65).arg(&source).status().expect("ca65 runs");
        assert!(status.success(), "ca65 {name}.s");
        objects.push(dir.join(format!("{name}.o")));
    }
    let cfg = dir.join("flat.cfg");
    std::fs::write(&cfg, flat_cfg(start)).expect("write config");
    let out = dir.join(format!("out-{start:04X}.bin"));
    let output = Command::new(ld65)
        .arg("-C")
        .arg(&cfg)
        .arg("-o")
        .arg(&out)
        .args(&objects)
        .output()
        .expect("ld65 runs");
    assert!(
        output.status.success(),
        "ld65: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(&out).expect("ld65 wrote the binary")
}

#[test]
fn flat_matches_ld65_byte_for_byte() {
    let test = "linker ld65::flat_matches_ld65_byte_for_byte";
    let (Some(ca65), Some(ld65)) = (
        scorpion_tests::tools::require("ca65", test),
        scorpion_tests::tools::require("ld65", test),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    for start in [0x1000u16, 0x0801, 0xC003] {
        let expected = ld65_link(dir.path(), &ca65, &ld65, start);
        let linked = link_flat(
            &[("a.o", a_o()), ("b.o", b_o()), ("c.o", c_o())],
            u64::from(start),
        )
        .expect("links");
        let ours = linker::output::write_bin(&linked.image);
        assert_eq!(
            ours,
            expected,
            "flat at ${start:04X} differs from ld65\n{}",
            linked.map()
        );
        // ld65 warns when a segment start is not aligned; so do we.
        assert!(!linked.warnings.is_empty() || start % 8 == 0);
    }
}

#[test]
fn a_ca65_object_is_recognised_and_refused() {
    let test = "linker ld65::a_ca65_object_is_recognised_and_refused";
    let Some(ca65) = scorpion_tests::tools::require("ca65", test) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("a.s"), A_S).expect("write source");
    let status = Command::new(ca65)
        .current_dir(dir.path())
        .arg("a.s")
        .status()
        .expect("ca65 runs");
    assert!(status.success());
    let xo65 = std::fs::read(dir.path().join("a.o")).expect("ca65 wrote a.o");
    let error = link_flat(&[("a.o", xo65)], 0x1000).expect_err("not ELF");
    let text = format!("{:?}", miette::Report::new(error));
    assert!(text.contains("ca65 (xo65) object"), "{text}");
}
