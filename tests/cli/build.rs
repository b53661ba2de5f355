//! `scorpion build`: sources to images in one step.

use std::path::Path;

use linker::Image;

use crate::{scorpion, transcript};

const MAIN_S: &str = "\
; The entry point: prints the library's greeting.
.import print, greeting
.importzp text
.export start

.macro point_at pointer, address
        lda #<address
        sta pointer
        lda #>address
        sta pointer+1
.endmacro

.code
start:  point_at text, greeting
        jsr print
done:   jmp done
";

const LIB_S: &str = "\
; Sends the zero-terminated string at (text) to $C000.
.exportzp text
.export print, greeting

.zeropage
text:   .res 2

.code
print:  ldy #0
@next:  lda (text),y
        beq @end
        sta $C000
        iny
        bne @next
@end:   rts

.rodata
greeting: .byte \"HELLO\", 0
";

fn write_sources(dir: &Path) {
    std::fs::write(dir.join("main.s"), MAIN_S).expect("write main.s");
    std::fs::write(dir.join("lib.s"), LIB_S).expect("write lib.s");
}

#[test]
fn builds_a_multi_file_program_into_every_format() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_sources(dir.path());
    let mut all = String::new();
    for format in ["elf", "bin", "ihex", "srec", "kim"] {
        let out = format!("hello.{format}");
        let output = scorpion(
            dir.path(),
            &[
                "build",
                "main.s",
                "lib.s",
                "-o",
                &out,
                "--target",
                "flat",
                "--start",
                "$0800",
                "--format",
                format,
                "--map",
                "hello.map",
                "--labels",
                "hello.lbl",
            ],
        );
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
        all.push_str(&transcript(&output));
    }
    insta::assert_snapshot!("build_every_format", all);
    let bin = std::fs::read(dir.path().join("hello.bin")).expect("bin written");
    let image = Image::parse(
        "hello.elf",
        &std::fs::read(dir.path().join("hello.elf")).expect("elf written"),
    )
    .expect("reads back");
    assert_eq!(linker::output::write_bin(&image), bin);
    assert_eq!(image.symbol("text"), Some(0));
    assert_eq!(
        &bin[..4],
        [0xA9, 0x1B, 0x85, 0x00],
        "lda #<greeting / sta text"
    );
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).expect("written");
    insta::assert_snapshot!("build_map", read("hello.map"));
    assert!(read("hello.lbl").contains("al 000800 .start"));
    // No object files were written.
    assert!(!dir.path().join("main.o").exists());
}

#[test]
fn assembler_and_linker_errors_point_at_the_source() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_sources(dir.path());
    std::fs::write(
        dir.path().join("typo.s"),
        ".import prnt\n.code\n        jsr prnt\n        lda #300\n",
    )
    .expect("write typo.s");
    std::fs::write(
        dir.path().join("far.s"),
        ".import print\n.code\n        bne print\n        .res 200\n",
    )
    .expect("write far.s");
    let asm_error = scorpion(
        dir.path(),
        &[
            "build", "typo.s", "-o", "t.bin", "--target", "flat", "--start", "$1000",
        ],
    );
    assert_eq!(asm_error.status.code(), Some(1));
    std::fs::write(
        dir.path().join("typo.s"),
        ".import prnt\n.code\n        jsr prnt\n",
    )
    .expect("rewrite typo.s");
    let link_error = scorpion(
        dir.path(),
        &[
            "build", "typo.s", "far.s", "lib.s", "-o", "t.bin", "--target", "flat", "--start",
            "$1000",
        ],
    );
    assert_eq!(link_error.status.code(), Some(1));
    // The assembler's own wording is its snapshots' business; here, only
    // that its error stops the build and names the line.
    let asm_stderr = String::from_utf8_lossy(&asm_error.stderr);
    assert!(asm_stderr.contains("typo.s:4:"), "{asm_stderr}");
    insta::assert_snapshot!("build_errors", transcript(&link_error));
}

#[test]
fn an_extension_builds_with_no_options_against_the_built_in_rom() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("ext.s"),
        ".include \"scorpion.inc\"\n.code\nSCORPION_UNKNOWN_HANDLER\n        cmp #'Q'\n        bne @not_mine\n        jsr PUTEOL\n        jmp CMD_DONE\n@not_mine:\nSCORPION_CHAIN_UNKNOWN\n",
    )
    .expect("write ext.s");
    let output = scorpion(dir.path(), &["build", "ext.s", "-o", "ext.elf"]);
    insta::assert_snapshot!("build_extension", transcript(&output));
    let image = Image::parse(
        "ext.elf",
        &std::fs::read(dir.path().join("ext.elf")).expect("written"),
    )
    .expect("reads back");
    let hook = image.hooks.records[0];
    assert_eq!(hook.handler, 0x0400);
    assert_eq!(
        image.byte_at(u32::from(hook.chain.expect("chain")) - 1),
        Some(0x4C)
    );
}

#[test]
fn two_extensions_in_one_link_name_the_users_lines_that_took_the_hook() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let one = ".include \"scorpion.inc\"\n\n; the first\nSCORPION_UNKNOWN_HANDLER\n        SCORPION_CHAIN_UNKNOWN\n";
    let two =
        ".include \"scorpion.inc\"\nSCORPION_UNKNOWN_HANDLER\n        SCORPION_CHAIN_UNKNOWN\n";
    std::fs::write(dir.path().join("one.s"), one).expect("write");
    std::fs::write(dir.path().join("two.s"), two).expect("write");
    let output = scorpion(dir.path(), &["build", "one.s", "two.s", "-o", "both.elf"]);
    let stderr = String::from_utf8_lossy(&output.stderr).replace('\n', " ");
    assert!(!output.status.success(), "{stderr}");
    // The macro's own line is the same for both; the user's lines are not.
    for wanted in [
        "`__scorpion_hook_unknown` is defined twice",
        "one.s:4:1",
        "two.s:2:1",
        "one.s:5:9",
        "two.s:3:9",
    ] {
        assert!(stderr.contains(wanted), "`{wanted}` missing from: {stderr}");
    }
}

/// N3 (issue 27): an output that cannot be written is refused before any
/// is written (the image stays unwritten when the map's directory is
/// missing); a missing directory for the image is worded as every other
/// command words it (`hostfs::write`), its cause said once.
#[test]
fn outputs_are_checked_before_any_is_written_and_worded_once() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_sources(dir.path());
    let output = scorpion(
        dir.path(),
        &[
            "build",
            "main.s",
            "lib.s",
            "-o",
            "e.elf",
            "--target",
            "flat",
            "--start",
            "$0800",
            "--map",
            "nodir/e.map",
        ],
    );
    let text = transcript(&output);
    assert!(!output.status.success(), "{text}");
    assert!(text.contains("nodir/e.map"), "{text}");
    assert!(!dir.path().join("e.elf").exists(), "e.elf written: {text}");

    let output = scorpion(
        dir.path(),
        &[
            "build",
            "main.s",
            "lib.s",
            "-o",
            "nodir/e.elf",
            "--target",
            "flat",
            "--start",
            "$0800",
        ],
    );
    let text = transcript(&output);
    assert!(!output.status.success(), "{text}");
    assert!(text.contains("hostfs::write"), "{text}");
    assert_eq!(
        text.matches("the directory nodir does not exist").count(),
        1,
        "the cause once: {text}"
    );
}
