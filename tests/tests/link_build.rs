//! Assembler and linker together: a multi-file program with imports,
//! exports, zero-page data and macros, assembled in memory, linked into every
//! output format, checked against ld65, srecord's decoders and the emulator.

use std::path::Path;
use std::process::Command;

use linker::{Format, Image, Input, LinkOptions, Linked, NoSources, SymbolFile, Target};
use scorpion_tests::tools;

const MAIN_S: &str = "\
; Copies the library's message into a buffer, then traps.
.import copy_bytes, message
.importzp src, dst, MSGLEN
.export start, buffer

.macro set16 pointer, value
        lda #<value
        sta pointer
        lda #>value
        sta pointer+1
.endmacro

.code
start:  set16 src, message
        set16 dst, buffer
        ldy #MSGLEN
        jsr copy_bytes
        inc runs
done:   jmp done

.data
runs:   .byte 0

.bss
buffer: .res 16
";

const LIB_S: &str = "\
; Y bytes from (src) to (dst), last first.
.exportzp src, dst, MSGLEN
.export copy_bytes, message

.zeropage
src:    .res 2
dst:    .res 2

.code
copy_bytes:
@loop:  dey
        lda (src),y
        sta (dst),y
        cpy #0
        bne @loop
        rts

.rodata
message: .byte \"SCORPION\"
MSGLEN = * - message
";

fn assemble(name: &str, text: &str) -> Vec<u8> {
    match assembler::assemble_str(name, text, &assembler::Options::default()) {
        Ok(assembly) => assembly.object,
        Err(error) => panic!("{name} does not assemble: {error:?}"),
    }
}

fn link(objects: &[(&str, Vec<u8>)], target: &Target, symbols: &[SymbolFile<'_>]) -> Linked {
    let inputs: Vec<Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| Input { name, bytes })
        .collect();
    linker::link(
        &inputs,
        &LinkOptions {
            target,
            just_symbols: symbols,
            sources: &NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("link failed: {error:?}"))
}

fn program() -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("main.s", assemble("main.s", MAIN_S)),
        ("lib.s", assemble("lib.s", LIB_S)),
    ]
}

/// Runs a linked image on the plain 64 KiB machine from its entry point to
/// the trap at `done`; returns the RAM.
fn run(image: &Image) -> Vec<u8> {
    let mut ram = emulator::Ram::new();
    for area in &image.areas {
        ram.load(area.load as u16, &area.bytes)
            .expect("fits in 64 KiB");
    }
    let mut machine = emulator::Machine::new(ram);
    machine.cpu.pc = image.entry as u16;
    let stop = machine.run_with(100_000, &mut emulator::StopAtTrap);
    let done = image.symbol("done").expect("done is a label");
    assert!(
        matches!(stop, emulator::Stop::Trap { pc } if u32::from(pc) == done),
        "stopped with {stop:?}"
    );
    machine.bus.bytes().to_vec()
}

#[test]
fn a_multi_file_program_runs_from_every_format() {
    let target = Target::builtin("flat", Some(0x0800)).expect("flat");
    let linked = link(&program(), &target, &[]);
    let image = &linked.image;
    assert!(linked.warnings.is_empty(), "{:?}", linked.warnings);

    let ram = run(image);
    let buffer = image.symbol("buffer").expect("buffer") as usize;
    assert_eq!(&ram[buffer..buffer + 8], b"SCORPION");
    let runs = image.symbol("runs").expect("runs") as usize;
    assert_eq!(ram[runs], 1);
    // The zero-page pointers sit at $00-$03 and point at the buffer.
    assert_eq!(image.symbol("src"), Some(0));
    assert_eq!(image.symbol("dst"), Some(2));
    assert_eq!(usize::from(ram[2]) | usize::from(ram[3]) << 8, buffer);

    // The ELF image reads back identically and runs the same.
    let elf = Format::Elf.write(image).expect("elf");
    let read = Image::parse("prog.elf", &elf).expect("reads back");
    assert_eq!(&read, image);
    assert_eq!(run(&read), ram);
    let exec = |name: &str| {
        read.sections
            .iter()
            .find(|s| s.name == name)
            .map(|s| s.exec)
    };
    assert_eq!((exec("CODE"), exec("RODATA")), (Some(true), Some(false)));

    // The record formats decode to the raw binary.
    let bin = Format::Bin.write(image).expect("bin");
    let test = "link_build::a_multi_file_program_runs_from_every_format (srecord)";
    if let Some(srec_cat) = tools::require("srec_cat", test) {
        let dir = tempfile::tempdir().expect("temporary directory");
        for (format, flag) in [
            (Format::Ihex, "-intel"),
            (Format::Srec, "-motorola"),
            (Format::Kim, "-mos_technologies"),
        ] {
            let text = format.write(image).expect("writes");
            assert_eq!(decode(&srec_cat, dir.path(), &text, flag), bin, "{format}");
        }
    }

    // ca65 + ld65 build the same binary from the same sources.
    let test = "link_build::a_multi_file_program_runs_from_every_format (ld65)";
    if let (Some(ca65), Some(ld65)) = (tools::require("ca65", test), tools::require("ld65", test)) {
        assert_eq!(
            ld65_build(&ca65, &ld65),
            bin,
            "ld65 disagrees\n{}",
            linked.map()
        );
    }
}

fn decode(srec_cat: &Path, dir: &Path, text: &[u8], flag: &str) -> Vec<u8> {
    std::fs::write(dir.join("in.txt"), text).expect("write");
    let output = Command::new(srec_cat)
        .current_dir(dir)
        .args([
            "in.txt", flag, "-offset", "-0x0800", "-o", "out.bin", "-binary",
        ])
        .output()
        .expect("srec_cat runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(dir.join("out.bin")).expect("decoded")
}

fn ld65_build(ca65: &Path, ld65: &Path) -> Vec<u8> {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (name, text) in [("main.s", MAIN_S), ("lib.s", LIB_S)] {
        std::fs::write(dir.path().join(name), text).expect("write source");
        let status = Command::new(ca65)
            .current_dir(dir.path())
            .arg(name)
            .status()
            .expect("ca65 runs");
        assert!(status.success(), "ca65 {name}");
    }
    std::fs::write(
        dir.path().join("flat.cfg"),
        "MEMORY {
    ZP:   start = $0000, size = $0100, type = rw, file = \"\";
    MAIN: start = $0800, size = $10000 - $0800, file = %O;
}
SEGMENTS {
    ZEROPAGE: load = ZP,   type = zp,  optional = yes;
    CODE:     load = MAIN, type = ro,  optional = yes;
    RODATA:   load = MAIN, type = ro,  optional = yes;
    DATA:     load = MAIN, type = rw,  optional = yes;
    BSS:      load = MAIN, type = bss, optional = yes;
}
",
    )
    .expect("write config");
    let output = Command::new(ld65)
        .current_dir(dir.path())
        .args(["-C", "flat.cfg", "-o", "ld65.bin", "main.o", "lib.o"])
        .output()
        .expect("ld65 runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(dir.path().join("ld65.bin")).expect("ld65 wrote it")
}

const ROM_S: &str = "\
; A miniature ROM: the ABI's user bounds and one service.
.exportzp USER_ZP_START, USER_ZP_END
.export USER_RAM_START, USER_RAM_END, PUTCH
USER_ZP_START  = $30
USER_ZP_END    = $FF
USER_RAM_START = $0400
USER_RAM_END   = $0FFF

.segment \"CODE\"
reset:  jmp reset
putch:  rts

.segment \"JUMPTABLE\"
PUTCH:  jmp putch

.segment \"VECTORS\"
        .addr reset, reset, reset
";

const EXT_S: &str = "\
; An extension: answers /1Q with 'Q', passes anything else on.
.import PUTCH
.export __scorpion_hook_unknown, __scorpion_chain_unknown

.zeropage
calls:  .res 1

.code
__scorpion_hook_unknown:
        cmp #'Q'
        bne chain
        inc calls
        jsr PUTCH
        rts
chain:  jmp $0000
__scorpion_chain_unknown = chain + 1
";

#[test]
fn an_extension_links_against_a_rom_built_by_the_same_tools() {
    let rom = link(
        &[("rom.s", assemble("rom.s", ROM_S))],
        &Target::ScorpionRom,
        &[],
    );
    let rom_bin = Format::Bin.write(&rom.image).expect("bin");
    assert_eq!(rom_bin.len(), 0x1000);
    assert_eq!(
        &rom_bin[0xF00..0xF03],
        [0x4C, 0x03, 0xF0],
        "JMP putch at $FF00"
    );
    assert_eq!(&rom_bin[0xFFA..0xFFC], [0x00, 0xF0], "NMI vector");
    let rom_elf = Image::parse("rom.elf", &Format::Elf.write(&rom.image).expect("elf"))
        .expect("the ROM image reads back");

    let ext = link(
        &[("ext.s", assemble("ext.s", EXT_S))],
        &Target::ScorpionExt,
        &[SymbolFile {
            name: "rom.elf",
            image: &rom_elf,
        }],
    );
    let image = &ext.image;
    assert_eq!(image.symbol("calls"), Some(0x30), "the user zero page");
    assert_eq!(image.areas[0].load, 0x0400, "the user RAM");
    let hook = image.hooks.records[0];
    assert_eq!(hook.handler, 0x0400);
    let chain = hook.chain.expect("a chain slot");
    // The chain slot is the operand of the fallthrough JMP.
    assert_eq!(image.byte_at(u32::from(chain) - 1), Some(0x4C));
    // JSR PUTCH went to the ROM's jump table.
    let bytes = &image.areas[0].bytes;
    let jsr = bytes.iter().position(|b| *b == 0x20).expect("a JSR");
    assert_eq!(&bytes[jsr..jsr + 3], [0x20, 0x00, 0xFF]);
    insta::assert_snapshot!("extension_map", ext.map());
}

const QUERY_S: &str = "\
; Answers /1Q with how often it was asked, in hex; passes the rest on.
.include \"scorpion.inc\"

.zeropage
asked:  .res 1

.code
SCORPION_UNKNOWN_HANDLER
        cmp #'Q'
        bne @not_mine
        inc asked
        lda asked
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
@not_mine:
SCORPION_CHAIN_UNKNOWN
";

#[test]
fn a_linked_extension_answers_on_the_virtual_scorpion() {
    let options = assembler::Options {
        builtin_includes: [(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]
        .into(),
        ..assembler::Options::default()
    };
    let object = assembler::assemble_str("query.s", QUERY_S, &options)
        .unwrap_or_else(|error| panic!("query.s does not assemble: {error:?}"))
        .object;
    let rom = Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("romlib's ROM image");
    let linked = link(
        &[("query.s", object)],
        &Target::ScorpionExt,
        &[SymbolFile {
            name: "scorpion-rom.elf",
            image: &rom,
        }],
    );
    // Through the ELF file, as the uploader and `scorpion sim` get it.
    let image = Image::parse("query.elf", &Format::Elf.write(&linked.image).expect("elf"))
        .expect("reads back");
    let mut robot = romlib::sim::VirtualScorpion::new();
    let installed = robot.load_image(&image).expect("loads and hooks");
    assert_eq!(installed.len(), 1);
    for expected in [b"01\r", b"02\r"] {
        let answer = robot
            .transact(b"/1Q", 500_000)
            .expect("the extension answers");
        assert!(
            answer.ends_with(expected),
            "{}",
            romlib::sim::escape(&answer)
        );
    }
    // The ROM still answers its own questions past the extension.
    let busy = robot
        .transact(b"/1X", 500_000)
        .expect("the ROM answers /1X");
    assert!(busy.starts_with(b"X"), "{}", romlib::sim::escape(&busy));
}
