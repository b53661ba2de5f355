//! Every opcode's cycles and length against `isa::OPCODES` (the one table of
//! the instruction set), and the bus contract: one access per cycle, with
//! the exact cycle number, in the datasheet's order.

use emulator::{Bus, Cpu, Ram, Step};
use isa::{AddressingMode, Mnemonic, OPCODES, OpcodeKind};

/// Every bus access an instruction made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Access {
    Read(u16, u8),
    Write(u16, u8),
}

/// RAM that records accesses and checks that their cycle numbers follow
/// one another without gaps.
#[derive(Debug)]
pub(crate) struct Recorder {
    pub(crate) ram: Ram,
    pub(crate) accesses: Vec<Access>,
    pub(crate) cycles: Vec<u64>,
}

impl Recorder {
    pub(crate) fn new(ram: Ram) -> Recorder {
        Recorder {
            ram,
            accesses: Vec::new(),
            cycles: Vec::new(),
        }
    }
}

impl Bus for Recorder {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        let value = self.ram.read(address, cycle);
        self.accesses.push(Access::Read(address, value));
        self.cycles.push(cycle);
        value
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.ram.write(address, value, cycle);
        self.accesses.push(Access::Write(address, value));
        self.cycles.push(cycle);
    }

    fn peek(&self, address: u16) -> u8 {
        self.ram.peek(address)
    }
}

/// Where the test instruction sits: late in a page, so that branches can
/// cross into the next one.
const AT: u16 = 0x10F0;
const X: u8 = 0x20;
const Y: u8 = 0x20;

/// Sets up `opcode` at [`AT`] with operands that make the indexed address
/// cross a page (or not) and branch conditions true or false; returns the
/// CPU and the bus, plus whether the table's page penalty and branch penalty
/// apply, worked out here from the addressing mode alone.
fn scenario(opcode: u8, cross: bool, flags_set: bool) -> (Cpu, Recorder, bool, bool) {
    let entry = &OPCODES[usize::from(opcode)];
    let mut ram = Ram::new();
    let low = if cross { 0xF0 } else { 0x10 };
    let operand: [u8; 2] = match entry.mode {
        AddressingMode::Relative => [if cross { 0x40 } else { 0x04 }, 0],
        AddressingMode::ZeroPage
        | AddressingMode::ZeroPageX
        | AddressingMode::ZeroPageY
        | AddressingMode::IndirectX
        | AddressingMode::IndirectY => [0x40, 0],
        _ => [low, 0x20],
    };
    ram.load(AT, &[opcode, operand[0], operand[1]])
        .expect("fits");
    // (zp),Y pointer at $40; (zp,X) pointer at $40 + X.
    ram.load(0x0040, &[low, 0x30]).expect("fits");
    ram.load(0x0040 + u16::from(X), &[0x00, 0x30])
        .expect("fits");
    let mut cpu = Cpu::new();
    cpu.pc = AT;
    cpu.x = X;
    cpu.y = Y;
    cpu.s = 0xF0;
    cpu.set_p(if flags_set { 0xFF } else { 0x00 });
    let p = cpu.p();
    let taken = match entry.mnemonic {
        Mnemonic::Bpl => p & 0x80 == 0,
        Mnemonic::Bmi => p & 0x80 != 0,
        Mnemonic::Bvc => p & 0x40 == 0,
        Mnemonic::Bvs => p & 0x40 != 0,
        Mnemonic::Bcc => p & 0x01 == 0,
        Mnemonic::Bcs => p & 0x01 != 0,
        Mnemonic::Bne => p & 0x02 == 0,
        Mnemonic::Beq => p & 0x02 != 0,
        _ => false,
    };
    let crossed = match entry.mode {
        AddressingMode::AbsoluteX | AddressingMode::AbsoluteY | AddressingMode::IndirectY => cross,
        AddressingMode::Relative => {
            let next = AT.wrapping_add(2);
            let target = next.wrapping_add_signed(i16::from(operand[0] as i8));
            (next ^ target) & 0xFF00 != 0
        }
        _ => false,
    };
    (cpu, Recorder::new(ram), crossed, taken)
}

#[test]
fn every_opcode_takes_the_cycles_and_length_of_the_isa_table() {
    let mut checked = 0;
    for entry in OPCODES.iter().filter(|entry| entry.kind != OpcodeKind::Jam) {
        for cross in [false, true] {
            for flags_set in [false, true] {
                let (mut cpu, mut bus, crossed, taken) = scenario(entry.code, cross, flags_set);
                let step = cpu.step(&mut bus);
                assert_eq!(
                    step,
                    Step::Instruction,
                    "${:02X} {}",
                    entry.code,
                    entry.mnemonic.name()
                );
                let expected = u64::from(entry.cycles_for(crossed, taken));
                assert_eq!(
                    cpu.cycles(),
                    expected,
                    "${:02X} {} {} (page crossed: {crossed}, branch taken: {taken})",
                    entry.code,
                    entry.mnemonic.name(),
                    entry.mode
                );
                assert_eq!(cpu.instructions(), 1);
                // One access per cycle, numbered from 0 without a gap.
                assert_eq!(
                    bus.cycles,
                    (0..expected).collect::<Vec<_>>(),
                    "${:02X}",
                    entry.code
                );
                let sequential = !matches!(
                    entry.mnemonic,
                    Mnemonic::Jmp | Mnemonic::Jsr | Mnemonic::Rts | Mnemonic::Rti | Mnemonic::Brk
                ) && !taken;
                if sequential {
                    assert_eq!(
                        cpu.pc,
                        AT + u16::from(entry.len()),
                        "${:02X} {} length",
                        entry.code,
                        entry.mnemonic.name()
                    );
                }
                checked += 1;
            }
        }
    }
    assert_eq!(
        checked,
        (256 - 12) * 4,
        "every opcode but the 12 JAMs, four ways"
    );
}

#[test]
fn jam_opcodes_halt_without_executing() {
    for entry in OPCODES.iter().filter(|entry| entry.kind == OpcodeKind::Jam) {
        let (mut cpu, mut bus, _, _) = scenario(entry.code, false, false);
        let before = cpu.clone();
        assert_eq!(cpu.step(&mut bus), Step::Jam { opcode: entry.code });
        assert_eq!(
            cpu, before,
            "${:02X} must leave the CPU as it was",
            entry.code
        );
    }
}

/// Runs one instruction from `program` at $0200 and returns its accesses.
fn accesses(program: &[u8], setup: impl FnOnce(&mut Cpu, &mut Ram)) -> Vec<Access> {
    let mut ram = Ram::new();
    ram.load(0x0200, program).expect("fits");
    let mut cpu = Cpu::new();
    cpu.pc = 0x0200;
    cpu.s = 0xFD;
    setup(&mut cpu, &mut ram);
    let mut bus = Recorder::new(ram);
    cpu.step(&mut bus);
    bus.accesses
}

use Access::{Read as R, Write as W};

#[test]
fn read_modify_write_writes_the_old_value_then_the_new_one() {
    // INC $12F0,X with X = $20: the un-carried address $1210 is read first.
    let seen = accesses(&[0xFE, 0xF0, 0x12], |cpu, ram| {
        cpu.x = 0x20;
        ram.bytes_mut()[0x1310] = 0x41;
    });
    assert_eq!(
        seen,
        [
            R(0x0200, 0xFE),
            R(0x0201, 0xF0),
            R(0x0202, 0x12),
            R(0x1210, 0x00),
            R(0x1310, 0x41),
            W(0x1310, 0x41),
            W(0x1310, 0x42)
        ]
    );
}

#[test]
fn indexed_reads_touch_the_uncarried_address_only_on_a_page_cross() {
    // LDA $12F0,X crossing: dummy read of $1210, then $1310.
    let crossing = accesses(&[0xBD, 0xF0, 0x12], |cpu, _| cpu.x = 0x20);
    assert_eq!(crossing[3..], [R(0x1210, 0), R(0x1310, 0)]);
    // LDA $1200,X not crossing: one read.
    let straight = accesses(&[0xBD, 0x00, 0x12], |cpu, _| cpu.x = 0x20);
    assert_eq!(straight[3..], [R(0x1220, 0)]);
    // STA $1200,Y always makes the dummy read.
    let store = accesses(&[0x99, 0x00, 0x12], |cpu, _| {
        cpu.y = 0x20;
        cpu.a = 7;
    });
    assert_eq!(store[3..], [R(0x1220, 0), W(0x1220, 7)]);
    // LDA ($FF),Y takes the pointer's high byte from $00 (page zero wraps).
    let wrapped = accesses(&[0xB1, 0xFF], |cpu, ram| {
        cpu.y = 1;
        ram.bytes_mut()[0xFF] = 0x34;
        ram.bytes_mut()[0x00] = 0x12;
    });
    assert_eq!(
        wrapped[2..],
        [R(0x00FF, 0x34), R(0x0000, 0x12), R(0x1235, 0)]
    );
}

#[test]
fn one_byte_instructions_and_the_stack_make_their_dummy_reads() {
    // NOP reads the next byte; PLA reads it, then the stack top, then pulls.
    let nop = accesses(&[0xEA, 0x99], |_, _| {});
    assert_eq!(nop, [R(0x0200, 0xEA), R(0x0201, 0x99)]);
    let pla = accesses(&[0x68, 0x99], |cpu, ram| {
        cpu.s = 0x80;
        ram.bytes_mut()[0x0181] = 0x55;
    });
    assert_eq!(
        pla,
        [
            R(0x0200, 0x68),
            R(0x0201, 0x99),
            R(0x0180, 0),
            R(0x0181, 0x55)
        ]
    );
    // JSR $1234: low byte, stack read, push $02 $02, then the high byte.
    let jsr = accesses(&[0x20, 0x34, 0x12], |_, _| {});
    assert_eq!(
        jsr,
        [
            R(0x0200, 0x20),
            R(0x0201, 0x34),
            R(0x01FD, 0),
            W(0x01FD, 0x02),
            W(0x01FC, 0x02),
            R(0x0202, 0x12)
        ]
    );
    // JMP ($12FF) reads the high byte from $1200, not $1300.
    let jmp = accesses(&[0x6C, 0xFF, 0x12], |_, ram| {
        ram.bytes_mut()[0x12FF] = 0x78;
        ram.bytes_mut()[0x1200] = 0x56;
        ram.bytes_mut()[0x1300] = 0xEE;
    });
    assert_eq!(jmp[3..], [R(0x12FF, 0x78), R(0x1200, 0x56)]);
}

#[test]
fn taken_branches_make_their_dummy_reads() {
    // BNE +$10 from $0200 (taken, same page): reads the next opcode.
    let near = accesses(&[0xD0, 0x10], |cpu, _| cpu.set_p(0));
    assert_eq!(near[2..], [R(0x0202, 0)]);
    // BNE -$10 from $0200: crosses back into page $01; the old page's
    // $02F2 is read before the fix-up.
    let far = accesses(&[0xD0, 0xF0], |cpu, _| cpu.set_p(0));
    assert_eq!(far[2..], [R(0x0202, 0), R(0x02F2, 0)]);
}
