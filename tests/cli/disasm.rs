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
