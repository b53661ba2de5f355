//! Addressing modes of the NMOS 6502, named as in the MOS datasheet.

use core::fmt;

/// How an instruction finds its operand (MCS6500 Microcomputer Family
/// Programming Manual, appendix A).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AddressingMode {
    /// No operand (`CLC`, `RTS`).
    Implied,
    /// The accumulator is the operand (`ASL A`).
    Accumulator,
    /// An 8-bit constant follows the opcode (`LDA #$12`).
    Immediate,
    /// An address in page zero (`LDA $12`).
    ZeroPage,
    /// Page-zero address plus X, wrapping within page zero (`LDA $12,X`).
    ZeroPageX,
    /// Page-zero address plus Y, wrapping within page zero (`LDX $12,Y`).
    ZeroPageY,
    /// A 16-bit address (`LDA $1234`).
    Absolute,
    /// A 16-bit address plus X (`LDA $1234,X`).
    AbsoluteX,
    /// A 16-bit address plus Y (`LDA $1234,Y`).
    AbsoluteY,
    /// `JMP ($1234)`: the target is read from the pointer; the NMOS part does
    /// not carry into the high byte, so `($12FF)` reads `$12FF` and `$1200`.
    Indirect,
    /// Indexed indirect `($12,X)`: the pointer is at `$12+X` in page zero.
    IndirectX,
    /// Indirect indexed `($12),Y`: the pointer at `$12` in page zero, plus Y.
    IndirectY,
    /// A signed 8-bit displacement from the next instruction (branches).
    Relative,
}

impl AddressingMode {
    /// Every mode, in declaration order.
    pub const ALL: [AddressingMode; 13] = [
        AddressingMode::Implied,
        AddressingMode::Accumulator,
        AddressingMode::Immediate,
        AddressingMode::ZeroPage,
        AddressingMode::ZeroPageX,
        AddressingMode::ZeroPageY,
        AddressingMode::Absolute,
        AddressingMode::AbsoluteX,
        AddressingMode::AbsoluteY,
        AddressingMode::Indirect,
        AddressingMode::IndirectX,
        AddressingMode::IndirectY,
        AddressingMode::Relative,
    ];

    /// Number of operand bytes after the opcode (0, 1 or 2).
    #[must_use]
    pub const fn operand_len(self) -> u8 {
        match self {
            AddressingMode::Implied | AddressingMode::Accumulator => 0,
            AddressingMode::Immediate
            | AddressingMode::ZeroPage
            | AddressingMode::ZeroPageX
            | AddressingMode::ZeroPageY
            | AddressingMode::IndirectX
            | AddressingMode::IndirectY
            | AddressingMode::Relative => 1,
            AddressingMode::Absolute
            | AddressingMode::AbsoluteX
            | AddressingMode::AbsoluteY
            | AddressingMode::Indirect => 2,
        }
    }

    /// Total instruction length in bytes, opcode included.
    #[must_use]
    pub const fn len(self) -> u8 {
        1 + self.operand_len()
    }

    /// True for the modes whose operand is a page-zero address.
    #[must_use]
    pub const fn is_zero_page(self) -> bool {
        matches!(
            self,
            AddressingMode::ZeroPage
                | AddressingMode::ZeroPageX
                | AddressingMode::ZeroPageY
                | AddressingMode::IndirectX
                | AddressingMode::IndirectY
        )
    }

    /// The absolute-address mode that a zero-page mode widens to, if any
    /// (`ZeroPageX` to `AbsoluteX`...). `IndirectX`/`IndirectY` have none.
    #[must_use]
    pub const fn widened(self) -> Option<AddressingMode> {
        match self {
            AddressingMode::ZeroPage => Some(AddressingMode::Absolute),
            AddressingMode::ZeroPageX => Some(AddressingMode::AbsoluteX),
            AddressingMode::ZeroPageY => Some(AddressingMode::AbsoluteY),
            _ => None,
        }
    }

    /// The zero-page mode that an absolute mode narrows to, if any.
    #[must_use]
    pub const fn narrowed(self) -> Option<AddressingMode> {
        match self {
            AddressingMode::Absolute => Some(AddressingMode::ZeroPage),
            AddressingMode::AbsoluteX => Some(AddressingMode::ZeroPageX),
            AddressingMode::AbsoluteY => Some(AddressingMode::ZeroPageY),
            _ => None,
        }
    }
}

impl fmt::Display for AddressingMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self {
            AddressingMode::Implied => "implied",
            AddressingMode::Accumulator => "accumulator",
            AddressingMode::Immediate => "immediate",
            AddressingMode::ZeroPage => "zero page",
            AddressingMode::ZeroPageX => "zero page,X",
            AddressingMode::ZeroPageY => "zero page,Y",
            AddressingMode::Absolute => "absolute",
            AddressingMode::AbsoluteX => "absolute,X",
            AddressingMode::AbsoluteY => "absolute,Y",
            AddressingMode::Indirect => "(indirect)",
            AddressingMode::IndirectX => "(indirect,X)",
            AddressingMode::IndirectY => "(indirect),Y",
            AddressingMode::Relative => "relative",
        };
        f.write_str(text)
    }
}
