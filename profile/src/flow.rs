//! What an opcode does to the flow of control, for the shadow call stack
//! and the branch counts: read once from the ISA's opcode table.

use isa::{AddressingMode, Mnemonic};

/// An instruction's kind, as far as the profiler cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flow {
    /// Anything that goes on to the next instruction or jumps without a
    /// trace on the stack (`JMP`).
    Plain,
    /// A conditional branch (relative addressing): taken or not taken.
    Branch,
    /// `JSR`: a routine entered.
    Call,
    /// `RTS`: back to the caller.
    Return,
    /// `RTI`: the end of an interrupt handler.
    ReturnFromInterrupt,
    /// `BRK`: a software interrupt.
    Break,
    /// `TXS`: the stack pointer set outright (a reset unwinds everything).
    SetStack,
}

/// Every opcode's [`Flow`], undocumented ones included.
pub(crate) fn table() -> [Flow; 256] {
    let mut flows = [Flow::Plain; 256];
    for (code, flow) in flows.iter_mut().enumerate() {
        let Ok(code) = u8::try_from(code) else {
            continue;
        };
        let opcode = isa::opcode(code);
        *flow = match opcode.mnemonic {
            Mnemonic::Jsr => Flow::Call,
            Mnemonic::Rts => Flow::Return,
            Mnemonic::Rti => Flow::ReturnFromInterrupt,
            Mnemonic::Brk => Flow::Break,
            Mnemonic::Txs => Flow::SetStack,
            _ if opcode.mode == AddressingMode::Relative => Flow::Branch,
            _ => Flow::Plain,
        };
    }
    flows
}

/// Whether `code` is a conditional branch.
#[must_use]
pub fn is_branch(code: u8) -> bool {
    isa::opcode(code).mode == AddressingMode::Relative
}
