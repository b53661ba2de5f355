//! Decoding and disassembly of NMOS 6502 machine code, in the syntax ca65
//! reads back (`LDA $1234,X`, `LDA ($12),Y`, `ASL A`, `BNE $1234`).

use core::fmt;

use crate::{AddressingMode, Opcode, opcode};

/// One decoded instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Instruction {
    /// Where the opcode byte sits.
    pub address: u16,
    /// The opcode table entry.
    pub opcode: &'static Opcode,
    /// The operand bytes as a little-endian number (0 when there are none).
    pub operand: u16,
}

impl Instruction {
    /// Decodes the instruction at the start of `bytes`, which sit at
    /// `address`. `None` if `bytes` is shorter than the instruction.
    #[must_use]
    pub fn decode(bytes: &[u8], address: u16) -> Option<Instruction> {
        let opcode = opcode(*bytes.first()?);
        let operand = match opcode.mode.operand_len() {
            0 => 0,
            1 => u16::from(*bytes.get(1)?),
            _ => u16::from_le_bytes([*bytes.get(1)?, *bytes.get(2)?]),
        };
        Some(Instruction {
            address,
            opcode,
            operand,
        })
    }

    /// Decodes the instruction at `address` from a function that reads memory
    /// (wrapping at `$FFFF` as the CPU does).
    pub fn decode_with(address: u16, mut read: impl FnMut(u16) -> u8) -> Instruction {
        let opcode = opcode(read(address));
        let operand = match opcode.mode.operand_len() {
            0 => 0,
            1 => u16::from(read(address.wrapping_add(1))),
            _ => u16::from_le_bytes([read(address.wrapping_add(1)), read(address.wrapping_add(2))]),
        };
        Instruction {
            address,
            opcode,
            operand,
        }
    }

    /// Length in bytes.
    #[must_use]
    pub fn len(&self) -> u8 {
        self.opcode.len()
    }

    /// The address of the next instruction in sequence.
    #[must_use]
    pub fn next_address(&self) -> u16 {
        self.address.wrapping_add(u16::from(self.len()))
    }

    /// The address the operand names, where it names one statically: the
    /// branch target for relative mode, the operand address for the
    /// zero-page, absolute and indirect modes (before indexing).
    #[must_use]
    pub fn target(&self) -> Option<u16> {
        match self.opcode.mode {
            AddressingMode::Implied | AddressingMode::Accumulator | AddressingMode::Immediate => {
                None
            }
            AddressingMode::Relative => {
                let displacement = i16::from(self.operand as u8 as i8);
                Some(self.next_address().wrapping_add_signed(displacement))
            }
            _ => Some(self.operand),
        }
    }

    /// Formats the instruction, naming addresses through `label` where it
    /// knows them (`JSR PUTCH` instead of `JSR $FFE0`).
    pub fn display_with<'a, F>(&'a self, label: F) -> impl fmt::Display + 'a
    where
        F: Fn(u16) -> Option<&'a str> + 'a,
    {
        Formatted { insn: self, label }
    }
}

impl fmt::Display for Instruction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_insn(f, self, &|_| None)
    }
}

struct Formatted<'a, F> {
    insn: &'a Instruction,
    label: F,
}

impl<'a, F> fmt::Display for Formatted<'a, F>
where
    F: Fn(u16) -> Option<&'a str>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_insn(f, self.insn, &self.label)
    }
}

fn write_insn<'a>(
    f: &mut fmt::Formatter<'_>,
    insn: &Instruction,
    label: &dyn Fn(u16) -> Option<&'a str>,
) -> fmt::Result {
    let mnemonic = insn.opcode.mnemonic;
    let value = insn.operand;
    let zp = |f: &mut fmt::Formatter<'_>| match label(value) {
        Some(name) => f.write_str(name),
        None => write!(f, "${value:02X}"),
    };
    let abs = |f: &mut fmt::Formatter<'_>, value: u16| match label(value) {
        Some(name) => f.write_str(name),
        None => write!(f, "${value:04X}"),
    };
    write!(f, "{mnemonic}")?;
    match insn.opcode.mode {
        AddressingMode::Implied => Ok(()),
        AddressingMode::Accumulator => f.write_str(" A"),
        AddressingMode::Immediate => write!(f, " #${value:02X}"),
        AddressingMode::ZeroPage => {
            f.write_str(" ")?;
            zp(f)
        }
        AddressingMode::ZeroPageX => {
            f.write_str(" ")?;
            zp(f)?;
            f.write_str(",X")
        }
        AddressingMode::ZeroPageY => {
            f.write_str(" ")?;
            zp(f)?;
            f.write_str(",Y")
        }
        AddressingMode::IndirectX => {
            f.write_str(" (")?;
            zp(f)?;
            f.write_str(",X)")
        }
        AddressingMode::IndirectY => {
            f.write_str(" (")?;
            zp(f)?;
            f.write_str("),Y")
        }
        AddressingMode::Absolute => {
            f.write_str(" ")?;
            abs(f, value)
        }
        AddressingMode::AbsoluteX => {
            f.write_str(" ")?;
            abs(f, value)?;
            f.write_str(",X")
        }
        AddressingMode::AbsoluteY => {
            f.write_str(" ")?;
            abs(f, value)?;
            f.write_str(",Y")
        }
        AddressingMode::Indirect => {
            f.write_str(" (")?;
            abs(f, value)?;
            f.write_str(")")
        }
        AddressingMode::Relative => {
            f.write_str(" ")?;
            abs(f, insn.target().unwrap_or(value))
        }
    }
}

/// One line of a disassembly listing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line<'a> {
    /// Address of the first byte.
    pub address: u16,
    /// The bytes the line covers.
    pub bytes: &'a [u8],
    /// The decoded instruction, or `None` for trailing bytes too few to
    /// hold the instruction their first byte starts (shown as `.byte`).
    pub instruction: Option<Instruction>,
}

impl fmt::Display for Line<'_> {
    /// `1000  A9 2E     LDA #$2E`: address, up to three bytes, text.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_line(f, self, &|_| None)
    }
}

impl Line<'_> {
    /// Formats the line as [`Line`]'s `Display` does, naming operand
    /// addresses through `label` where it knows them.
    pub fn display_with<'b, F>(&'b self, label: F) -> impl fmt::Display + 'b
    where
        F: Fn(u16) -> Option<&'b str> + 'b,
    {
        LabelledLine { line: self, label }
    }
}

struct LabelledLine<'a, F> {
    line: &'a Line<'a>,
    label: F,
}

impl<'a, F> fmt::Display for LabelledLine<'a, F>
where
    F: Fn(u16) -> Option<&'a str>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_line(f, self.line, &self.label)
    }
}

fn write_line<'a>(
    f: &mut fmt::Formatter<'_>,
    line: &Line<'_>,
    label: &dyn Fn(u16) -> Option<&'a str>,
) -> fmt::Result {
    write!(f, "{:04X} ", line.address)?;
    for slot in 0..3 {
        match line.bytes.get(slot) {
            Some(byte) => write!(f, " {byte:02X}")?,
            None => f.write_str("   ")?,
        }
    }
    f.write_str("  ")?;
    match &line.instruction {
        Some(insn) => write_insn(f, insn, label),
        None => {
            f.write_str(".byte ")?;
            for (index, byte) in line.bytes.iter().enumerate() {
                if index > 0 {
                    f.write_str(",")?;
                }
                write!(f, "${byte:02X}")?;
            }
            Ok(())
        }
    }
}

/// Disassembles `bytes`, which sit at `base`, one instruction at a time.
/// Addresses wrap at `$FFFF`.
#[derive(Debug, Clone)]
pub struct Disassembler<'a> {
    bytes: &'a [u8],
    offset: usize,
    base: u16,
}

impl<'a> Disassembler<'a> {
    /// Starts at the first byte of `bytes`, taken to sit at `base`.
    #[must_use]
    pub fn new(bytes: &'a [u8], base: u16) -> Disassembler<'a> {
        Disassembler {
            bytes,
            offset: 0,
            base,
        }
    }
}

impl<'a> Iterator for Disassembler<'a> {
    type Item = Line<'a>;

    fn next(&mut self) -> Option<Line<'a>> {
        let rest = self
            .bytes
            .get(self.offset..)
            .filter(|rest| !rest.is_empty())?;
        // Offsets beyond 64 KiB wrap, as addresses do on the 6502.
        let address = self.base.wrapping_add((self.offset & 0xFFFF) as u16);
        let (length, instruction) = match Instruction::decode(rest, address) {
            Some(insn) => (usize::from(insn.len()), Some(insn)),
            None => (rest.len(), None),
        };
        self.offset += length;
        Some(Line {
            address,
            bytes: &rest[..length],
            instruction,
        })
    }
}
