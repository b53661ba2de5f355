//! The opcode table against the datasheet's facts and an independent table
//! (the `mos6502` crate's NMOS decoder).

use isa::{AddressingMode as Mode, Mnemonic, OPCODES, OpcodeKind, encode, opcode};
use mos6502::Variant;

#[test]
fn the_table_is_indexed_by_opcode_byte() {
    for (index, entry) in OPCODES.iter().enumerate() {
        assert_eq!(usize::from(entry.code), index);
    }
}

#[test]
fn counts_match_the_datasheet() {
    let documented = OPCODES.iter().filter(|o| o.is_documented()).count();
    assert_eq!(documented, 151);
    let jams: Vec<u8> = OPCODES
        .iter()
        .filter(|o| o.kind == OpcodeKind::Jam)
        .map(|o| o.code)
        .collect();
    assert_eq!(
        jams,
        [
            0x02, 0x12, 0x22, 0x32, 0x42, 0x52, 0x62, 0x72, 0x92, 0xB2, 0xD2, 0xF2
        ]
    );
    let documented_mnemonics: std::collections::BTreeSet<_> = OPCODES
        .iter()
        .filter(|o| o.is_documented())
        .map(|o| o.mnemonic)
        .collect();
    assert_eq!(documented_mnemonics.len(), 56);
    assert!(documented_mnemonics.iter().all(|m| m.is_documented()));
}

#[test]
fn datasheet_spot_checks() {
    // (opcode, mnemonic, mode, cycles, page penalty)
    let cases = [
        (0x00, Mnemonic::Brk, Mode::Implied, 7, false),
        (0x6C, Mnemonic::Jmp, Mode::Indirect, 5, false),
        (0xCE, Mnemonic::Dec, Mode::Absolute, 6, false),
        (0x3E, Mnemonic::Rol, Mode::AbsoluteX, 7, false),
        (0xBD, Mnemonic::Lda, Mode::AbsoluteX, 4, true),
        (0x9D, Mnemonic::Sta, Mode::AbsoluteX, 5, false),
        (0x91, Mnemonic::Sta, Mode::IndirectY, 6, false),
        (0xB1, Mnemonic::Lda, Mode::IndirectY, 5, true),
        (0xBE, Mnemonic::Ldx, Mode::AbsoluteY, 4, true),
        (0x96, Mnemonic::Stx, Mode::ZeroPageY, 4, false),
        (0x20, Mnemonic::Jsr, Mode::Absolute, 6, false),
        (0x40, Mnemonic::Rti, Mode::Implied, 6, false),
        (0x28, Mnemonic::Plp, Mode::Implied, 4, false),
        (0xD0, Mnemonic::Bne, Mode::Relative, 2, false),
        (0xB3, Mnemonic::Lax, Mode::IndirectY, 5, true),
        (0xDB, Mnemonic::Dcp, Mode::AbsoluteY, 7, false),
        (0xCB, Mnemonic::Sbx, Mode::Immediate, 2, false),
    ];
    for (code, mnemonic, mode, cycles, penalty) in cases {
        let entry = opcode(code);
        assert_eq!(
            (entry.mnemonic, entry.mode, entry.cycles, entry.page_penalty),
            (mnemonic, mode, cycles, penalty),
            "opcode {code:02X}"
        );
    }
    let bne = opcode(0xD0);
    assert_eq!(bne.cycles_for(false, false), 2);
    assert_eq!(bne.cycles_for(false, true), 3);
    assert_eq!(bne.cycles_for(true, true), 4);
    assert_eq!(opcode(0xBD).cycles_for(true, false), 5);
    assert_eq!(opcode(0x9D).cycles_for(true, false), 5);
}

#[test]
fn encode_is_the_inverse_of_decode() {
    for entry in &OPCODES {
        let code = encode(entry.mnemonic, entry.mode).expect("every entry encodes");
        let back = opcode(code);
        assert_eq!((back.mnemonic, back.mode), (entry.mnemonic, entry.mode));
        if entry.is_documented() {
            assert_eq!(code, entry.code, "documented opcodes encode to themselves");
        }
    }
    assert_eq!(encode(Mnemonic::Nop, Mode::Implied), Some(0xEA));
    assert_eq!(encode(Mnemonic::Sbc, Mode::Immediate), Some(0xE9));
    assert_eq!(encode(Mnemonic::Nop, Mode::Immediate), Some(0x80));
    assert_eq!(encode(Mnemonic::Jam, Mode::Implied), Some(0x02));
    assert_eq!(encode(Mnemonic::Lda, Mode::Indirect), None);
    assert_eq!(encode(Mnemonic::Stx, Mode::AbsoluteY), None);
}

#[test]
fn mnemonic_names_and_aliases() {
    for mnemonic in Mnemonic::ALL {
        assert_eq!(Mnemonic::from_name(mnemonic.name()), Some(*mnemonic));
        assert_eq!(
            Mnemonic::from_name(&mnemonic.name().to_ascii_lowercase()),
            Some(*mnemonic)
        );
    }
    assert_eq!(Mnemonic::from_name("axs"), Some(Mnemonic::Sbx));
    assert_eq!(Mnemonic::from_name("ISB"), Some(Mnemonic::Isc));
    assert_eq!(Mnemonic::from_name("lda "), None);
    assert_eq!(Mnemonic::from_name("ldaa"), None);
    assert_eq!(Mnemonic::from_name("é"), None);
}

fn their_mode(mode: mos6502::instruction::AddressingMode) -> Mode {
    use mos6502::instruction::AddressingMode as Theirs;
    match mode {
        Theirs::Accumulator => Mode::Accumulator,
        Theirs::Implied => Mode::Implied,
        Theirs::Immediate => Mode::Immediate,
        Theirs::ZeroPage => Mode::ZeroPage,
        Theirs::ZeroPageX => Mode::ZeroPageX,
        Theirs::ZeroPageY => Mode::ZeroPageY,
        Theirs::Relative => Mode::Relative,
        Theirs::Absolute => Mode::Absolute,
        Theirs::AbsoluteX => Mode::AbsoluteX,
        Theirs::AbsoluteY => Mode::AbsoluteY,
        Theirs::BuggyIndirect | Theirs::Indirect => Mode::Indirect,
        Theirs::IndexedIndirectX => Mode::IndirectX,
        Theirs::IndirectIndexedY => Mode::IndirectY,
        other => panic!("mos6502 gave a non-NMOS mode {other:?}"),
    }
}

/// Their names: NOP forms carry a suffix, `USBC` is `SBC #` at $EB, `XAA` is `ANE`.
fn their_name(instruction: mos6502::instruction::Instruction) -> String {
    let name = format!("{instruction:?}");
    match name.as_str() {
        "USBC" => "SBC".into(),
        "XAA" => "ANE".into(),
        other if other.starts_with("NOP") => "NOP".into(),
        other => other.into(),
    }
}

#[test]
fn agrees_with_the_mos6502_crates_decoder() {
    let mut compared = 0;
    for entry in &OPCODES {
        let Some((instruction, mode)) = mos6502::instruction::Nmos6502::decode(entry.code) else {
            // The crate leaves the unstable $93 $9B $9C $9E $9F $AB undecoded.
            assert_eq!(
                entry.kind,
                OpcodeKind::Unstable,
                "opcode {:02X}",
                entry.code
            );
            continue;
        };
        assert_eq!(
            (their_name(instruction).as_str(), their_mode(mode)),
            (entry.mnemonic.name(), entry.mode),
            "opcode {:02X}",
            entry.code
        );
        compared += 1;
    }
    assert_eq!(compared, 250);
}
