//! `scorpion asm`, run as a process: objects and listings written,
//! diagnostics on stderr (file:line:col, the marked line, backtraces),
//! `-D`, `-I`, the built-in `scorpion.inc`, `.out` on stdout; and the
//! process-level ld65 check: `scorpion build --target flat --start ADDR
//! --format bin` on a generated program equals ca65 + ld65 byte for byte.

#[path = "../tests/asm_gen/mod.rs"]
mod asm_gen;

use std::path::Path;
use std::process::Command;

use crate::{scorpion, transcript};

/// The temporary directory's path is not stable across runs.
fn stable(dir: &Path, text: String) -> String {
    text.replace(&dir.display().to_string(), "[DIR]")
}

#[test]
fn assembles_with_a_listing_and_default_output_name() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("prog.s"),
        "; a small extension\n        .include \"defs.inc\"\n        .code\nstart:  lda #VALUE\n        sta $0400\n        .out \"assembled\"\n        rts\n",
    )
    .expect("write the source");
    std::fs::create_dir(dir.path().join("inc")).expect("make the include directory");
    std::fs::write(dir.path().join("inc/defs.inc"), "VALUE = DEPTH * 2\n")
        .expect("write the include");
    let output = scorpion(
        dir.path(),
        &[
            "asm",
            "prog.s",
            "-l",
            "prog.lst",
            "-I",
            "inc",
            "-D",
            "DEPTH=$10",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    insta::assert_snapshot!("asm_success", transcript(&output));
    let listing =
        std::fs::read_to_string(dir.path().join("prog.lst")).expect("the listing is written");
    insta::assert_snapshot!("asm_listing", listing);
    let object = std::fs::read(dir.path().join("prog.o")).expect("prog.o is the default output");
    assert_eq!(&object[..4], b"\x7FELF");
    assert_eq!(
        u16::from_le_bytes([object[18], object[19]]),
        isa::elf::EM_MOS
    );
}

#[test]
fn errors_are_all_reported_with_places_and_backtraces() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("bad.s"),
        ".macro put value\n        lda #value\n.endmacro\n        put 300\n        jmp nowhere\n        sta #1\n        bne far\n        .res 200\nfar:    rts\n",
    )
    .expect("write the source");
    let output = scorpion(dir.path(), &["asm", "bad.s", "-o", "bad.o"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(!dir.path().join("bad.o").exists(), "no object after errors");
    insta::assert_snapshot!("asm_errors", stable(dir.path(), transcript(&output)));
}

#[test]
fn warnings_do_not_stop_the_object() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("warn.s"),
        "        jmp ($02FF)\n        .warning \"check this\"\n",
    )
    .expect("write");
    let output = scorpion(dir.path(), &["asm", "warn.s", "-o", "warn.o"]);
    assert_eq!(output.status.code(), Some(0));
    assert!(dir.path().join("warn.o").exists());
    insta::assert_snapshot!("asm_warnings", transcript(&output));
}

#[test]
fn bad_invocations_are_clear() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let missing = scorpion(dir.path(), &["asm", "nope.s"]);
    assert_eq!(missing.status.code(), Some(1));
    insta::assert_snapshot!("asm_missing_file", transcript(&missing));
    let bad_define = scorpion(dir.path(), &["asm", "nope.s", "-D", "9X=1"]);
    assert_eq!(bad_define.status.code(), Some(2));
    insta::assert_snapshot!("asm_bad_define", transcript(&bad_define));
}

#[test]
fn scorpion_inc_is_built_in() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("ext.s"),
        "        .include \"scorpion.inc\"\n        SCORPION_UNKNOWN_HANDLER\n        cmp #'Q'\n        bne @not_mine\n        jsr PUTCH\n        jmp CMD_DONE\n@not_mine:\n        SCORPION_CHAIN_UNKNOWN\n",
    )
    .expect("write the source");
    let output = scorpion(dir.path(), &["asm", "ext.s"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let object = std::fs::read(dir.path().join("ext.o")).expect("ext.o");
    // `jsr PUTCH` is assembled against the ROM's jump table address.
    let putch = romlib::symbols::PUTCH.to_le_bytes();
    assert!(
        object.windows(3).any(|w| w == [0x20, putch[0], putch[1]]),
        "jsr PUTCH uses the ROM's address"
    );
}

/// The board's `hardware.inc` is built in beside `scorpion.inc`, and a file
/// of the same name on the search path comes first.
#[test]
fn hardware_inc_is_built_in_and_yields_to_the_users_own() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("card.s"),
        "        .include \"hardware.inc\"\n        lda SWITCHES\n        and #ST_RDRF\n",
    )
    .expect("write the source");
    let output = scorpion(dir.path(), &["asm", "card.s", "-l", "card.lst"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let listing = std::fs::read_to_string(dir.path().join("card.lst")).expect("the listing");
    let switches = platform::map::SWITCHES.to_le_bytes();
    let bytes = format!("AD {:02X} {:02X}", switches[0], switches[1]);
    assert!(listing.contains(&bytes), "lda SWITCHES:\n{listing}");
    assert!(listing.contains("29 08"), "and #ST_RDRF:\n{listing}");

    std::fs::write(
        dir.path().join("hardware.inc"),
        "SWITCHES = $1234\nST_RDRF = 1\n",
    )
    .expect("write the user's include");
    let output = scorpion(dir.path(), &["asm", "card.s", "-l", "card.lst"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let listing = std::fs::read_to_string(dir.path().join("card.lst")).expect("the listing");
    assert!(
        listing.contains("AD 34 12"),
        "the user's file wins:\n{listing}"
    );
}

/// `scorpion build --target flat --format bin` against ca65 + ld65.
#[test]
fn scorpion_build_flat_equals_ld65() {
    let test = "scorpion_build_flat_equals_ld65";
    let (Some(ca65), Some(ld65)) = (
        scorpion_tests::tools::require("ca65", test),
        scorpion_tests::tools::require("ld65", test),
    ) else {
        return;
    };
    for seed in [11, 12] {
        let dir = tempfile::tempdir().expect("temporary directory");
        let program = asm_gen::generate(seed, 1500, asm_gen::Flavor::Differential);
        let mut names = Vec::new();
        for (name, text) in &program.files {
            std::fs::write(dir.path().join(name), text).expect("write a source");
            names.push(name.as_str());
        }
        let mut args = vec!["build"];
        args.extend(&names);
        args.extend([
            "-o", "ours.bin", "--target", "flat", "--start", "$0800", "--format", "bin",
        ]);
        let output = scorpion(dir.path(), &args);
        assert_eq!(
            output.status.code(),
            Some(0),
            "seed {seed}: {}",
            transcript(&output)
        );
        let mut objects = Vec::new();
        for name in &names {
            let object = format!("{name}.o");
            let status = Command::new(&ca65)
                .current_dir(dir.path())
                .args([name, "-o", object.as_str()])
                .output()
                .expect("ca65 runs");
            assert!(
                status.status.success(),
                "ca65: {}",
                String::from_utf8_lossy(&status.stderr)
            );
            objects.push(object);
        }
        std::fs::write(
            dir.path().join("flat.cfg"),
            "MEMORY { ZP: start = $0000, size = $0100, type = rw; MAIN: start = $0800, size = $F800, file = %O; }\n\
             SEGMENTS { ZEROPAGE: load = ZP, type = zp; CODE: load = MAIN, type = ro; RODATA: load = MAIN, type = ro; DATA: load = MAIN, type = rw; BSS: load = MAIN, type = bss; }\n",
        )
        .expect("write the config");
        let status = Command::new(&ld65)
            .current_dir(dir.path())
            .args(["-C", "flat.cfg", "-o", "ld65.bin"])
            .args(&objects)
            .output()
            .expect("ld65 runs");
        assert!(
            status.status.success(),
            "ld65: {}",
            String::from_utf8_lossy(&status.stderr)
        );
        let ours = std::fs::read(dir.path().join("ours.bin")).expect("our binary");
        let theirs = std::fs::read(dir.path().join("ld65.bin")).expect("ld65's binary");
        assert!(
            ours == theirs,
            "seed {seed}: scorpion build and ld65 differ ({} vs {} bytes)",
            ours.len(),
            theirs.len()
        );
    }
}

/// `--feature NAME` switches a ca65 feature on from the first line; a name
/// that is not ca65's is refused with the list.
#[test]
fn features_from_the_command_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("f.s"), "        lda #-1\n").expect("write");
    let without = scorpion(dir.path(), &["asm", "f.s"]);
    assert_eq!(without.status.code(), Some(1), "{}", transcript(&without));
    let with = scorpion(dir.path(), &["asm", "f.s", "--feature", "force_range"]);
    assert_eq!(with.status.code(), Some(0), "{}", transcript(&with));
    std::fs::write(dir.path().join("c.s"), "        lda #1 /* a C comment */\n").expect("write");
    let plain = scorpion(dir.path(), &["asm", "c.s"]);
    assert_eq!(plain.status.code(), Some(1), "{}", transcript(&plain));
    let comments = scorpion(dir.path(), &["asm", "c.s", "--feature", "c_comments"]);
    assert_eq!(comments.status.code(), Some(0), "{}", transcript(&comments));
    // ca65's target systems translate strings; one with another CPU is
    // taken too (its symbols, its characters), and its CPU's instructions
    // are refused where they are used.
    std::fs::write(dir.path().join("t.s"), "        .byte \"Ab\"\n").expect("write");
    let c64 = scorpion(dir.path(), &["asm", "t.s", "-t", "c64", "-o", "t.o"]);
    assert_eq!(c64.status.code(), Some(0), "{}", transcript(&c64));
    let cx16 = scorpion(dir.path(), &["asm", "t.s", "-t", "cx16", "-o", "t.o"]);
    assert_eq!(cx16.status.code(), Some(0), "{}", transcript(&cx16));
    std::fs::write(dir.path().join("z.s"), "        stz $12\n").expect("write");
    let stz = scorpion(dir.path(), &["asm", "z.s", "-t", "apple2enh"]);
    assert_eq!(stz.status.code(), Some(1), "{}", transcript(&stz));
    assert!(transcript(&stz).contains("65C02"), "{}", transcript(&stz));
    let bogus_system = scorpion(dir.path(), &["asm", "t.s", "-t", "c65536"]);
    assert_eq!(
        bogus_system.status.code(),
        Some(2),
        "{}",
        transcript(&bogus_system)
    );
    let bogus = scorpion(dir.path(), &["asm", "f.s", "--feature", "bogus"]);
    assert_eq!(bogus.status.code(), Some(2), "{}", transcript(&bogus));
    assert!(
        transcript(&bogus).contains("underline_in_numbers"),
        "{}",
        transcript(&bogus)
    );
}
