//! The NMOS 6502 as every Scorpion tool sees it: one table, one numbering.
//!
//! - [`OPCODES`]: all 256 opcode bytes with mnemonic, [`AddressingMode`],
//!   length, base cycles and the page-cross and branch penalties, documented
//!   and undocumented alike ([`OpcodeKind`]). [`encode`] is the reverse
//!   lookup the assembler uses.
//! - [`disasm`]: decoding and ca65-syntax disassembly.
//! - [`elf`]: llvm-mos's ELF numbering (`EM_MOS`, `R_MOS_*`,
//!   `SHF_MOS_ZEROPAGE`, `STO_MOS_ZEROPAGE`).
//! - [`vectors`]: where the CPU reads its NMI, reset and IRQ/BRK vectors.
//! - [`objfmt`]: our metadata sections (source map, deferred assertions, hook
//!   records) and the one definition of the expression operators.
//!
//! The assembler, linker and emulator take these from here and nowhere else.

pub mod disasm;
pub mod elf;
mod mnemonic;
mod mode;
pub mod objfmt;
mod opcode;

/// The addresses the 6502 reads its vectors from, low byte first.
pub mod vectors {
    /// The NMI vector, the first of the three.
    pub const NMI: u16 = 0xFFFA;
    /// The reset vector.
    pub const RESET: u16 = 0xFFFC;
    /// The IRQ/BRK vector.
    pub const IRQ: u16 = 0xFFFE;
}

pub use disasm::{Disassembler, Instruction};
pub use mnemonic::Mnemonic;
pub use mode::AddressingMode;
pub use opcode::{Access, OPCODES, Opcode, OpcodeKind, encode, has_mode, opcode};
