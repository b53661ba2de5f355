//! Differential test against py65 (PyPI), an independent NMOS 6502 written
//! in Python: seeded random instruction streams covering every documented
//! opcode, decimal mode included, compared after every instruction
//! (registers, flags, every byte written) and over all memory at the end of
//! each stream; then decimal-mode ADC and SBC for every operand pair and
//! carry. Cycles are checked against the `isa` table, not py65 (whose
//! `DEC abs` costs 3 cycles instead of 6).
//!
//! How a stream goes: before each step the generator writes a random
//! documented instruction at the current PC (in both memories), so
//! execution wanders over random memory, stack and vectors but never meets
//! an undocumented opcode (py65 runs those as 1-byte NOPs). Now and then an
//! IRQ or NMI is raised instead. The whole run is one Python process
//! (`py65_driver.py`). `SCORPION_PY65_SEED` and `SCORPION_PY65_STEPS`
//! change the seed and the length for longer runs by hand.

use std::collections::BTreeMap;
use std::io::Write;
use std::process::{Command, Stdio};

use emulator::{Bus, Cpu, Interrupt, Ram, Step};
use isa::{AddressingMode, Instruction, Mnemonic, OPCODES, Opcode};
use scorpion_tests::tools::require_python_module;

/// SplitMix64: small, seeded, good enough to pick instructions.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn byte(&mut self) -> u8 {
        self.next() as u8
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// RAM that keeps the last value written to each address since `clear`.
#[derive(Debug)]
struct WriteLog {
    ram: Ram,
    written: BTreeMap<u16, u8>,
}

impl Bus for WriteLog {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        self.ram.read(address, cycle)
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.ram.write(address, value, cycle);
        self.written.insert(address, value);
    }

    fn peek(&self, address: u16) -> u8 {
        self.ram.peek(address)
    }
}

/// One step's outcome in the driver's output format.
#[derive(Debug, Clone, PartialEq, Eq)]
struct State {
    pc: u16,
    a: u8,
    x: u8,
    y: u8,
    s: u8,
    /// P with bits 4 and 5 masked out (py65 keeps a B bit in its register).
    p: u8,
    written: Vec<(u16, u8)>,
}

impl State {
    fn of(cpu: &Cpu, bus: &WriteLog) -> State {
        State {
            pc: cpu.pc,
            a: cpu.a,
            x: cpu.x,
            y: cpu.y,
            s: cpu.s,
            p: cpu.p() & 0xCF,
            written: bus.written.iter().map(|(&a, &v)| (a, v)).collect(),
        }
    }

    fn parse(line: &str) -> State {
        let fields: Vec<&str> = line.split(' ').collect();
        assert_eq!(fields.len(), 7, "bad driver line {line:?}");
        let hex = |text: &str| u16::from_str_radix(text, 16).expect("driver hex");
        let written = if fields[6] == "-" {
            Vec::new()
        } else {
            fields[6]
                .split(',')
                .map(|pair| {
                    let (address, value) = pair.split_once('=').expect("ADDR=VAL");
                    (hex(address), hex(value) as u8)
                })
                .collect()
        };
        State {
            pc: hex(fields[0]),
            a: hex(fields[1]) as u8,
            x: hex(fields[2]) as u8,
            y: hex(fields[3]) as u8,
            s: hex(fields[4]) as u8,
            p: hex(fields[5]) as u8 & 0xCF,
            written,
        }
    }
}

/// The cycles `isa` says the instruction at PC takes in this state, with
/// the page-cross and branch conditions worked out from the operands.
fn expected_cycles(cpu: &Cpu, bus: &WriteLog, insn: &Instruction) -> u8 {
    let opcode: &Opcode = insn.opcode;
    let crosses = |base: u16, index: u8| (base & 0xFF) + u16::from(index) > 0xFF;
    let p = cpu.p();
    let (crossed, taken) = match opcode.mode {
        AddressingMode::AbsoluteX => (crosses(insn.operand, cpu.x), false),
        AddressingMode::AbsoluteY => (crosses(insn.operand, cpu.y), false),
        AddressingMode::IndirectY => {
            let pointer_lo = bus.peek(insn.operand);
            (crosses(u16::from(pointer_lo), cpu.y), false)
        }
        AddressingMode::Relative => {
            let taken = match opcode.mnemonic {
                Mnemonic::Bpl => p & 0x80 == 0,
                Mnemonic::Bmi => p & 0x80 != 0,
                Mnemonic::Bvc => p & 0x40 == 0,
                Mnemonic::Bvs => p & 0x40 != 0,
                Mnemonic::Bcc => p & 0x01 == 0,
                Mnemonic::Bcs => p & 0x01 != 0,
                Mnemonic::Bne => p & 0x02 == 0,
                _ => p & 0x02 != 0,
            };
            let target = insn.target().expect("branches have targets");
            ((target ^ insn.next_address()) & 0xFF00 != 0, taken)
        }
        _ => (false, false),
    };
    opcode.cycles_for(crossed, taken)
}

/// What the generator did at one step, for failure messages.
#[derive(Debug)]
struct Event {
    what: String,
    before: String,
}

fn seed() -> u64 {
    std::env::var("SCORPION_PY65_SEED")
        .ok()
        .and_then(|text| text.parse().ok())
        .unwrap_or(0x5C0F_1A65)
}

fn steps_per_stream() -> usize {
    std::env::var("SCORPION_PY65_STEPS")
        .ok()
        .and_then(|text| text.parse().ok())
        .unwrap_or(10_000)
}

const STREAMS: usize = 16;

#[test]
fn py65_agrees_on_random_streams_and_every_decimal_operand() {
    let Some(python) = require_python_module("py65", "py65::differential") else {
        return;
    };
    let documented: Vec<&Opcode> = OPCODES.iter().filter(|op| op.is_documented()).collect();
    assert_eq!(documented.len(), 151);
    let steps = steps_per_stream();
    let mut rng = Rng(seed());
    let mut input = String::new();
    let mut ours: Vec<(Vec<Event>, Vec<State>, Vec<u8>)> = Vec::new();
    let mut seen = [0u32; 256];
    let mut decimal_seen = 0u32;

    for _ in 0..STREAMS {
        let mut memory = vec![0u8; 0x1_0000];
        memory.iter_mut().for_each(|byte| *byte = rng.byte());
        let mut ram = Ram::new();
        ram.load(0, &memory).expect("64 KiB");
        let mut bus = WriteLog {
            ram,
            written: BTreeMap::new(),
        };
        let mut cpu = Cpu::new();
        cpu.a = rng.byte();
        cpu.x = rng.byte();
        cpu.y = rng.byte();
        cpu.s = rng.byte();
        cpu.set_p(rng.byte());
        cpu.pc = rng.next() as u16;
        input.push_str(&format!(
            "stream {:02X} {:02X} {:02X} {:02X} {:02X} {:04X}\nmem ",
            cpu.a,
            cpu.x,
            cpu.y,
            cpu.s,
            cpu.p(),
            cpu.pc
        ));
        for byte in &memory {
            input.push_str(&format!("{byte:02X}"));
        }
        input.push('\n');

        let mut events = Vec::with_capacity(steps);
        let mut states = Vec::with_capacity(steps);
        for _ in 0..steps {
            let before = format!("{cpu:?}");
            bus.written.clear();
            let roll = rng.below(1000);
            if roll < 6 && cpu.p() & 0x04 == 0 {
                cpu.interrupt(&mut bus, Interrupt::Irq);
                input.push_str("irq\n");
                events.push(Event {
                    what: "IRQ".into(),
                    before,
                });
            } else if roll < 9 {
                cpu.interrupt(&mut bus, Interrupt::Nmi);
                input.push_str("nmi\n");
                events.push(Event {
                    what: "NMI".into(),
                    before,
                });
            } else {
                let opcode = loop {
                    let opcode = documented[rng.below(documented.len())];
                    // JSR reads its low byte, pushes, then reads its high
                    // byte; py65 pushes before reading either. If the push
                    // lands on the low byte py65 jumps elsewhere than the
                    // real CPU: leave that case out (the high byte agrees).
                    let pushes = [
                        0x0100 | u16::from(cpu.s),
                        0x0100 | u16::from(cpu.s.wrapping_sub(1)),
                    ];
                    if opcode.mnemonic == Mnemonic::Jsr && pushes.contains(&cpu.pc.wrapping_add(1))
                    {
                        continue;
                    }
                    // py65 cannot fetch a word operand across $FFFF (its
                    // memory list has no index $10000).
                    if opcode.len() == 3 && cpu.pc == 0xFFFE {
                        continue;
                    }
                    break opcode;
                };
                let bytes = [opcode.code, rng.byte(), rng.byte()];
                let len = usize::from(opcode.len());
                for (offset, &byte) in bytes[..len].iter().enumerate() {
                    bus.ram.bytes_mut()[usize::from(cpu.pc.wrapping_add(offset as u16))] = byte;
                }
                let insn = Instruction::decode_with(cpu.pc, |address| bus.peek(address));
                let cycles = expected_cycles(&cpu, &bus, &insn);
                seen[usize::from(opcode.code)] += 1;
                if cpu.p() & 0x08 != 0 && matches!(opcode.mnemonic, Mnemonic::Adc | Mnemonic::Sbc) {
                    decimal_seen += 1;
                }
                input.push_str(&format!("i {:04X} ", cpu.pc));
                for byte in &bytes[..len] {
                    input.push_str(&format!("{byte:02X}"));
                }
                input.push('\n');
                let start = cpu.cycles();
                let step = cpu.step(&mut bus);
                assert!(
                    matches!(step, Step::Instruction | Step::Trap),
                    "{insn} at ${:04X}: {step:?}",
                    insn.address
                );
                assert_eq!(
                    cpu.cycles() - start,
                    u64::from(cycles),
                    "{insn} at ${:04X} took the wrong number of cycles; before: {before}",
                    insn.address
                );
                events.push(Event {
                    what: format!("${:04X}: {insn}", insn.address),
                    before,
                });
            }
            states.push(State::of(&cpu, &bus));
        }
        input.push_str("end\n");
        ours.push((events, states, bus.ram.bytes().to_vec()));
    }
    input.push_str("decimal\n");

    // Every documented opcode came up, and decimal arithmetic often.
    for op in &documented {
        assert!(
            seen[usize::from(op.code)] >= 100,
            "${:02X} ran only {} times",
            op.code,
            seen[usize::from(op.code)]
        );
    }
    assert!(
        decimal_seen > 500,
        "decimal ADC/SBC ran {decimal_seen} times"
    );

    let driver = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cpu/py65_driver.py");
    let mut child = Command::new(python)
        .arg(driver)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start python");
    // The driver reads all its input before writing: no deadlock.
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input.as_bytes())
        .expect("send the cases");
    let output = child.wait_with_output().expect("python runs");
    assert!(
        output.status.success(),
        "py65_driver.py failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout).expect("utf-8");
    let mut lines = text.lines();

    for (stream, (events, states, memory)) in ours.iter().enumerate() {
        for (step, (event, state)) in events.iter().zip(states).enumerate() {
            let theirs = State::parse(lines.next().expect("a line per step"));
            assert_eq!(
                state, &theirs,
                "stream {stream} step {step}: {} differs from py65 (left: ours, right: py65)\nbefore: {}",
                event.what, event.before
            );
        }
        let line = lines.next().expect("the stream's memory");
        let hex = line.strip_prefix("mem ").expect("mem line");
        let first_difference = (0..0x1_0000).find(|&address| {
            u8::from_str_radix(&hex[2 * address..2 * address + 2], 16).ok() != Some(memory[address])
        });
        assert_eq!(
            first_difference, None,
            "stream {stream}: memory differs at the end"
        );
    }

    // Decimal mode: ADC then SBC, carry 0 then 1, every A and operand.
    let line = lines.next().expect("the decimal line");
    let hex = line.strip_prefix("decimal ").expect("decimal line");
    let mut index = 0;
    for opcode in [0x69u8, 0xE9] {
        for carry in [0u8, 1] {
            for a in 0..=255u8 {
                for operand in 0..=255u8 {
                    let mut ram = Ram::new();
                    ram.load(0x0200, &[opcode, operand]).expect("fits");
                    let mut cpu = Cpu::new();
                    cpu.pc = 0x0200;
                    cpu.a = a;
                    cpu.set_p(0x08 | carry);
                    cpu.step(&mut ram);
                    let theirs_a = u8::from_str_radix(&hex[index..index + 2], 16).expect("hex");
                    let theirs_p = u8::from_str_radix(&hex[index + 2..index + 4], 16).expect("hex");
                    index += 4;
                    assert_eq!(
                        (cpu.a, cpu.p() & 0xCF),
                        (theirs_a, theirs_p & 0xCF),
                        "decimal {} ${a:02X} {} #${operand:02X} with C={carry}: (A, P) differ from py65",
                        if opcode == 0x69 { "A + " } else { "A - " },
                        if opcode == 0x69 { "ADC" } else { "SBC" },
                    );
                }
            }
        }
    }
    assert_eq!(index, hex.len());
}
