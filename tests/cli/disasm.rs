//! `scorpion disasm`.

use crate::{scorpion, transcript};

#[test]
fn disassembles_a_file_at_a_base_address() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // LDA #$01 / STA $C000 / BNE * / a lone JMP opcode at the end.
    std::fs::write(
        dir.path().join("prog.bin"),
        [0xA9, 0x01, 0x8D, 0x00, 0xC0, 0xD0, 0xFE, 0x4C],
    )
    .expect("write the program");
    let output = scorpion(dir.path(), &["disasm", "prog.bin", "--base", "$0400"]);
    insta::assert_snapshot!("disasm_whole_file", transcript(&output));
    let window = scorpion(
        dir.path(),
        &[
            "disasm", "prog.bin", "--base", "0x400", "--start", "1029", "--length", "2",
        ],
    );
    insta::assert_snapshot!("disasm_window", transcript(&window));
}

#[test]
fn bad_arguments_are_clear_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let missing = scorpion(dir.path(), &["disasm", "nope.bin"]);
    assert_eq!(missing.status.code(), Some(1));
    insta::assert_snapshot!("disasm_missing_file", transcript(&missing));
    let bad = scorpion(dir.path(), &["disasm", "nope.bin", "--base", "zz"]);
    assert_eq!(bad.status.code(), Some(2));
    insta::assert_snapshot!("disasm_bad_address", transcript(&bad));
    std::fs::write(dir.path().join("one.bin"), [0xEA]).expect("write");
    let outside = scorpion(
        dir.path(),
        &["disasm", "one.bin", "--base", "$1000", "--start", "$0FFF"],
    );
    assert_eq!(outside.status.code(), Some(1));
    insta::assert_snapshot!("disasm_start_outside_file", transcript(&outside));
}

/// `scorpion build`'s default output is an ELF image: it is disassembled at
/// its addresses with its symbols and the ROM's as labels, not as raw bytes
/// from its ELF header; an object shows its sections and relocations.
#[test]
fn disassembles_elf_images_and_objects_with_their_symbols() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let source = "\
        .include \"scorpion.inc\"
        .code
SCORPION_UNKNOWN_HANDLER
        cmp #'Q'
        bne pass
        lda message
        jsr PUTCH
        jmp CMD_DONE
pass:   SCORPION_CHAIN_UNKNOWN
        .rodata
message: .byte \"Q\", 0
";
    std::fs::write(dir.path().join("ext.s"), source).expect("write");
    let built = scorpion(dir.path(), &["build", "ext.s", "-o", "ext.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let image = scorpion(dir.path(), &["disasm", "ext.elf"]);
    assert_eq!(image.status.code(), Some(0), "{}", transcript(&image));
    let text = String::from_utf8_lossy(&image.stdout);
    assert!(
        !text.contains("7F 45 4C"),
        "the ELF header was disassembled:\n{text}"
    );
    insta::assert_snapshot!("disasm_elf_image", transcript(&image));
    let assembled = scorpion(dir.path(), &["asm", "ext.s", "-o", "ext.o"]);
    assert!(assembled.status.success(), "{}", transcript(&assembled));
    let object = scorpion(dir.path(), &["disasm", "ext.o"]);
    assert_eq!(object.status.code(), Some(0), "{}", transcript(&object));
    insta::assert_snapshot!("disasm_elf_object", transcript(&object));
    let window = scorpion(
        dir.path(),
        &["disasm", "ext.elf", "--start", "$0402", "--length", "5"],
    );
    insta::assert_snapshot!("disasm_elf_window", transcript(&window));
    let base = scorpion(dir.path(), &["disasm", "ext.elf", "--base", "$1000"]);
    assert_eq!(base.status.code(), Some(1));
    insta::assert_snapshot!("disasm_elf_with_base", transcript(&base));
}
