//! Disassembly text and decoding edge cases.

use isa::{Disassembler, Instruction};

fn text(bytes: &[u8], address: u16) -> String {
    Instruction::decode(bytes, address)
        .expect("test bytes hold a whole instruction")
        .to_string()
}

#[test]
fn every_mode_formats_as_ca65_reads_it() {
    assert_eq!(text(&[0xEA], 0), "NOP");
    assert_eq!(text(&[0x0A], 0), "ASL A");
    assert_eq!(text(&[0xA9, 0x2E], 0), "LDA #$2E");
    assert_eq!(text(&[0xA5, 0x12], 0), "LDA $12");
    assert_eq!(text(&[0xB5, 0x12], 0), "LDA $12,X");
    assert_eq!(text(&[0xB6, 0x12], 0), "LDX $12,Y");
    assert_eq!(text(&[0xAD, 0x34, 0x12], 0), "LDA $1234");
    assert_eq!(text(&[0xBD, 0x34, 0x12], 0), "LDA $1234,X");
    assert_eq!(text(&[0xB9, 0x34, 0x12], 0), "LDA $1234,Y");
    assert_eq!(text(&[0x6C, 0xFF, 0x12], 0), "JMP ($12FF)");
    assert_eq!(text(&[0xA1, 0x12], 0), "LDA ($12,X)");
    assert_eq!(text(&[0xB1, 0x12], 0), "LDA ($12),Y");
    assert_eq!(text(&[0xD0, 0xFE], 0x1000), "BNE $1000");
    assert_eq!(text(&[0xD0, 0x7F], 0x1000), "BNE $1081");
    assert_eq!(text(&[0xD0, 0x80], 0x1000), "BNE $0F82");
    assert_eq!(text(&[0x10, 0x00], 0xFFFE), "BPL $0000");
    assert_eq!(text(&[0x02], 0), "JAM");
    assert_eq!(text(&[0xA7, 0x10], 0), "LAX $10");
}

#[test]
fn labels_replace_addresses() {
    let insn = Instruction::decode(&[0x20, 0xE0, 0xFF], 0x0400).unwrap();
    let named = insn
        .display_with(|address| (address == 0xFFE0).then_some("PUTCH"))
        .to_string();
    assert_eq!(named, "JSR PUTCH");
    let branch = Instruction::decode(&[0xD0, 0xFE], 0x0400).unwrap();
    let named = branch
        .display_with(|address| (address == 0x0400).then_some("loop"))
        .to_string();
    assert_eq!(named, "BNE loop");
}

#[test]
fn short_input_decodes_to_none_and_lists_as_bytes() {
    assert_eq!(Instruction::decode(&[], 0), None);
    assert_eq!(Instruction::decode(&[0xAD, 0x34], 0), None);
    let lines: Vec<String> = Disassembler::new(&[0xA9, 0x01, 0xAD, 0x34], 0xC000)
        .map(|line| line.to_string())
        .collect();
    assert_eq!(
        lines,
        ["C000  A9 01     LDA #$01", "C002  AD 34     .byte $AD,$34"]
    );
}

#[test]
fn decode_with_wraps_at_the_top_of_memory() {
    let memory = |address: u16| match address {
        0xFFFF => 0xAD,
        0x0000 => 0x34,
        0x0001 => 0x12,
        _ => 0,
    };
    let insn = Instruction::decode_with(0xFFFF, memory);
    assert_eq!(insn.to_string(), "LDA $1234");
    assert_eq!(insn.next_address(), 0x0002);
}
