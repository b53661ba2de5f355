//! The undocumented opcodes, as "NMOS 6510 Unintended Opcodes" ("No More
//! Secrets") and 64doc describe the NMOS part. py65 does not run these, so
//! the expected values here were worked out by hand from those
//! descriptions, one case per behaviour worth pinning down.

use emulator::{Bus, Cpu, Ram, Step};

/// Runs `program` at $0200 after `setup`; returns the CPU and memory.
fn run(program: &[u8], setup: impl FnOnce(&mut Cpu, &mut Ram)) -> (Cpu, Ram) {
    let mut ram = Ram::new();
    ram.load(0x0200, program).expect("fits");
    let mut cpu = Cpu::new();
    cpu.pc = 0x0200;
    cpu.s = 0xFD;
    cpu.set_p(0x20);
    setup(&mut cpu, &mut ram);
    assert_eq!(cpu.step(&mut ram), Step::Instruction);
    (cpu, ram)
}

const N: u8 = 0x80;
const V: u8 = 0x40;
const D: u8 = 0x08;
const Z: u8 = 0x02;
const C: u8 = 0x01;

/// The flags N V Z C of P.
fn nvzc(cpu: &Cpu) -> u8 {
    cpu.p() & (N | V | Z | C)
}

#[test]
fn combined_read_modify_write_opcodes() {
    // SLO $40: M = M << 1, A |= M.
    let (cpu, ram) = run(&[0x07, 0x40], |cpu, ram| {
        cpu.a = 0x02;
        ram.bytes_mut()[0x40] = 0x81;
    });
    assert_eq!((ram.peek(0x40), cpu.a, nvzc(&cpu)), (0x02, 0x02, C));
    // RLA $40: M = ROL M, A &= M.
    let (cpu, ram) = run(&[0x27, 0x40], |cpu, ram| {
        cpu.a = 0xFF;
        cpu.set_p(0x20 | C);
        ram.bytes_mut()[0x40] = 0x81;
    });
    assert_eq!((ram.peek(0x40), cpu.a, nvzc(&cpu)), (0x03, 0x03, C));
    // SRE $40: M = LSR M, A ^= M.
    let (cpu, ram) = run(&[0x47, 0x40], |cpu, ram| {
        cpu.a = 0xFF;
        ram.bytes_mut()[0x40] = 0x03;
    });
    assert_eq!((ram.peek(0x40), cpu.a, nvzc(&cpu)), (0x01, 0xFE, N | C));
    // RRA $40: M = ROR M (C = old bit 0), then ADC with that carry.
    let (cpu, ram) = run(&[0x67, 0x40], |cpu, ram| {
        cpu.a = 0x10;
        ram.bytes_mut()[0x40] = 0x03;
    });
    assert_eq!((ram.peek(0x40), cpu.a, nvzc(&cpu)), (0x01, 0x12, 0));
    // DCP $40: M -= 1, CMP.
    let (cpu, ram) = run(&[0xC7, 0x40], |cpu, ram| {
        cpu.a = 0x10;
        ram.bytes_mut()[0x40] = 0x11;
    });
    assert_eq!((ram.peek(0x40), nvzc(&cpu)), (0x10, Z | C));
    // ISC $40: M += 1, SBC.
    let (cpu, ram) = run(&[0xE7, 0x40], |cpu, ram| {
        cpu.a = 0x20;
        cpu.set_p(0x20 | C);
        ram.bytes_mut()[0x40] = 0x0F;
    });
    assert_eq!((ram.peek(0x40), cpu.a, nvzc(&cpu)), (0x10, 0x10, C));
    // ISC in decimal mode subtracts in BCD: $20 - $10 after the increment.
    let (cpu, ram) = run(&[0xE7, 0x40], |cpu, ram| {
        cpu.a = 0x20;
        cpu.set_p(0x20 | D | C);
        ram.bytes_mut()[0x40] = 0x09;
    });
    assert_eq!((ram.peek(0x40), cpu.a), (0x0A, 0x10));
    // RRA in decimal mode adds in BCD: $19 + ($02 >> 1) + carry 0 = $20.
    let (cpu, _) = run(&[0x67, 0x40], |cpu, ram| {
        cpu.a = 0x19;
        cpu.set_p(0x20 | D);
        ram.bytes_mut()[0x40] = 0x02;
    });
    assert_eq!(cpu.a, 0x20);
}

#[test]
fn loads_and_stores_of_a_and_x_together() {
    // LAX $1234: A = X = M.
    let (cpu, _) = run(&[0xAF, 0x34, 0x12], |_, ram| ram.bytes_mut()[0x1234] = 0x80);
    assert_eq!((cpu.a, cpu.x, nvzc(&cpu)), (0x80, 0x80, N));
    // SAX $40: M = A & X, no flags.
    let (cpu, ram) = run(&[0x87, 0x40], |cpu, _| {
        cpu.a = 0xF3;
        cpu.x = 0x5F;
    });
    assert_eq!((ram.peek(0x40), nvzc(&cpu)), (0x53, 0));
    // LAS $1234,Y: A = X = S = M & S.
    let (cpu, _) = run(&[0xBB, 0x34, 0x12], |cpu, ram| {
        cpu.s = 0xF3;
        ram.bytes_mut()[0x1234] = 0x5F;
    });
    assert_eq!((cpu.a, cpu.x, cpu.s), (0x53, 0x53, 0x53));
}

#[test]
fn immediate_opcodes() {
    // ANC #$80: AND, then C = N.
    let (cpu, _) = run(&[0x0B, 0x80], |cpu, _| cpu.a = 0xFF);
    assert_eq!((cpu.a, nvzc(&cpu)), (0x80, N | C));
    // ALR #$03: AND, then LSR A.
    let (cpu, _) = run(&[0x4B, 0x03], |cpu, _| cpu.a = 0xFF);
    assert_eq!((cpu.a, nvzc(&cpu)), (0x01, C));
    // SBX #$10: X = (A & X) - operand, C as CMP, D ignored.
    let (cpu, _) = run(&[0xCB, 0x10], |cpu, _| {
        cpu.a = 0xF0;
        cpu.x = 0x3C;
        cpu.set_p(0x20 | D);
    });
    assert_eq!((cpu.x, nvzc(&cpu)), (0x20, C));
    let (cpu, _) = run(&[0xCB, 0x31], |cpu, _| {
        cpu.a = 0xF0;
        cpu.x = 0x3C;
        cpu.set_p(0x20 | C);
    });
    assert_eq!((cpu.x, nvzc(&cpu)), (0xFF, N));
    // ANE #$FF: A = (A | $EE) & X & operand.
    let (cpu, _) = run(&[0x8B, 0xFF], |cpu, _| {
        cpu.a = 0x01;
        cpu.x = 0xFF;
    });
    assert_eq!((cpu.a, nvzc(&cpu)), (0xEF, N));
    // LXA #$5A: A = X = (A | $EE) & operand.
    let (cpu, _) = run(&[0xAB, 0x5A], |cpu, _| cpu.a = 0x00);
    assert_eq!((cpu.a, cpu.x), (0x4A, 0x4A));
    // SBC #imm's twin at $EB.
    let (cpu, _) = run(&[0xEB, 0x01], |cpu, _| {
        cpu.a = 0x00;
        cpu.set_p(0x20 | C);
    });
    assert_eq!((cpu.a, nvzc(&cpu)), (0xFF, N));
}

#[test]
fn arr_in_binary_mode_takes_c_and_v_from_bits_6_and_5() {
    // (A & operand) ROR 1 with the old carry in bit 7; C = bit 6, V = bit 6
    // XOR bit 5 of the result.
    let cases = [
        // A, carry in, result, N V Z C
        (0xFF, true, 0xFF, N | C),
        (0xC0, false, 0x60, C),
        (0x80, false, 0x40, V | C),
        (0x40, false, 0x20, V),
        (0x01, false, 0x00, Z),
    ];
    for (a, carry, result, flags) in cases {
        let (cpu, _) = run(&[0x6B, 0xFF], |cpu, _| {
            cpu.a = a;
            cpu.set_p(0x20 | if carry { C } else { 0 });
        });
        assert_eq!((cpu.a, nvzc(&cpu)), (result, flags), "ARR with A=${a:02X}");
    }
}

#[test]
fn arr_in_decimal_mode_fixes_each_nibble() {
    // A & operand = $FF, carry clear: rotated $7F (N from the old carry,
    // V from bit 6 changing), low nibble fixed to $75, high nibble fixed
    // with carry out: $D5, C set.
    let (cpu, _) = run(&[0x6B, 0xFF], |cpu, _| {
        cpu.a = 0xFF;
        cpu.set_p(0x20 | D);
    });
    assert_eq!((cpu.a, nvzc(&cpu)), (0xD5, C));
    // $18 with carry set: rotated $8C, low nibble 8 fixed ($82), high
    // nibble 1 left alone, C clear.
    let (cpu, _) = run(&[0x6B, 0xFF], |cpu, _| {
        cpu.a = 0x18;
        cpu.set_p(0x20 | D | C);
    });
    assert_eq!((cpu.a, nvzc(&cpu)), (0x82, N));
}

#[test]
fn unstable_stores_and_the_high_byte_plus_one() {
    // SHA $1200,Y (no page cross): M = A & X & ($12 + 1).
    let (_, ram) = run(&[0x9F, 0x00, 0x12], |cpu, _| {
        cpu.a = 0xFF;
        cpu.x = 0x0F;
        cpu.y = 0x10;
    });
    assert_eq!(ram.peek(0x1210), 0x03);
    // SHA $12F0,Y crossing into $13: the value also becomes the address's
    // high byte, so $03 lands at $0310.
    let (_, ram) = run(&[0x9F, 0xF0, 0x12], |cpu, _| {
        cpu.a = 0xFF;
        cpu.x = 0x0F;
        cpu.y = 0x20;
    });
    assert_eq!((ram.peek(0x0310), ram.peek(0x1310)), (0x03, 0x00));
    // SHA ($40),Y with the pointer at $12F0, the same way.
    let (_, ram) = run(&[0x93, 0x40], |cpu, ram| {
        cpu.a = 0xFF;
        cpu.x = 0x0F;
        cpu.y = 0x20;
        ram.load(0x40, &[0xF0, 0x12]).expect("fits");
    });
    assert_eq!((ram.peek(0x0310), ram.peek(0x1310)), (0x03, 0x00));
    // SHX $1200,Y: X & $13.
    let (_, ram) = run(&[0x9E, 0x00, 0x12], |cpu, _| {
        cpu.x = 0xFF;
        cpu.y = 0x01;
    });
    assert_eq!(ram.peek(0x1201), 0x13);
    // SHY $30F0,X crossing: Y & $31 = $01, written at $0110.
    let (_, ram) = run(&[0x9C, 0xF0, 0x30], |cpu, _| {
        cpu.y = 0x0F;
        cpu.x = 0x20;
    });
    assert_eq!((ram.peek(0x0110), ram.peek(0x3110)), (0x01, 0x00));
    // TAS $1200,Y: S = A & X, M = S & $13.
    let (cpu, ram) = run(&[0x9B, 0x00, 0x12], |cpu, _| {
        cpu.a = 0xF0;
        cpu.x = 0x3F;
        cpu.y = 0x00;
    });
    assert_eq!((cpu.s, ram.peek(0x1200)), (0x30, 0x10));
}

#[test]
fn nop_forms_skip_their_operands_and_touch_nothing() {
    for (program, len) in [
        (&[0x1A][..], 1),
        (&[0x80, 0xFF][..], 2),
        (&[0x04, 0x40][..], 2),
        (&[0x14, 0x40][..], 2),
        (&[0x0C, 0x34, 0x12][..], 3),
        (&[0x1C, 0x34, 0x12][..], 3),
    ] {
        let (cpu, ram) = run(program, |cpu, _| cpu.a = 0x42);
        assert_eq!(cpu.pc, 0x0200 + len, "{program:02X?}");
        assert_eq!(
            (cpu.a, cpu.x, cpu.y, cpu.s, cpu.p()),
            (0x42, 0, 0, 0xFD, 0x20)
        );
        let untouched = ram
            .bytes()
            .iter()
            .enumerate()
            .all(|(address, &byte)| (0x0200..0x0203).contains(&address) || byte == 0);
        assert!(untouched, "{program:02X?} wrote memory");
    }
}
