//! The code a way's steps reach without running it: every instruction on
//! either side of a branch and behind a call, as far as `JMP`s go and no
//! further than a return, an indirect jump, code that stops the CPU or
//! memory an extension may not hold. A run on the host sees the one path
//! the robot's memory took that time; a backup that witnessed only that
//! left the other arm unchecked (hostile28 F3, D1: a branch taken every
//! 256th pass).

use std::collections::BTreeSet;

use isa::disasm::Instruction;
use isa::{AddressingMode, Mnemonic};

use super::{ChainBus, readable};
use crate::Result;
use crate::transport::Transport;

/// Instructions looked at before the walk stops: more than any handler a
/// hook's way runs outside its extension.
const MOST_INSTRUCTIONS: usize = 4096;

/// Adds to `bus`'s touched set every byte of each instruction reachable
/// from `starts`, leaving out what `listed` says (an extension's code,
/// checked by its own entry).
///
/// # Errors
/// The line's errors.
pub(super) fn reach<T: Transport>(
    bus: &mut ChainBus<'_, T>,
    starts: &[u16],
    listed: &dyn Fn(u16) -> bool,
) -> Result<()> {
    let mut todo: Vec<u16> = starts.to_vec();
    let mut looked = BTreeSet::new();
    while let Some(pc) = todo.pop() {
        if looked.len() >= MOST_INSTRUCTIONS {
            break;
        }
        if !readable(bus.profile, pc) || listed(pc) || !looked.insert(pc) {
            continue;
        }
        let instruction = Instruction::decode_with(pc, |at| bus.byte(at));
        if let Some(error) = bus.failed.take() {
            return Err(error);
        }
        bus.outside = false;
        for i in 0..u16::from(instruction.len()) {
            let at = pc.wrapping_add(i);
            if readable(bus.profile, at) && !listed(at) {
                bus.touched.insert(at);
            }
        }
        let indirect = instruction.opcode.mnemonic == Mnemonic::Jmp
            && instruction.opcode.mode == AddressingMode::Indirect;
        if indirect {
            bus.computed.get_or_insert(pc);
        }
        todo.extend(successors(&instruction));
    }
    Ok(())
}

/// Where `instruction` can go next, read from its bytes alone.
fn successors(instruction: &Instruction) -> Vec<u16> {
    let next = instruction.next_address();
    let opcode = instruction.opcode;
    match opcode.mnemonic {
        // Where an indirect jump goes is data: the host run follows it.
        Mnemonic::Jmp if opcode.mode == AddressingMode::Indirect => Vec::new(),
        Mnemonic::Jmp => vec![instruction.operand],
        Mnemonic::Jsr => vec![instruction.operand, next],
        Mnemonic::Rts | Mnemonic::Rti | Mnemonic::Brk => Vec::new(),
        _ if opcode.cycles == 0 => Vec::new(),
        _ if opcode.mode == AddressingMode::Relative => {
            vec![next, instruction.target().unwrap_or(next)]
        }
        _ => vec![next],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(bytes: &[u8], address: u16) -> Vec<u16> {
        successors(&Instruction::decode(bytes, address).expect("whole"))
    }

    #[test]
    fn each_kind_of_instruction_goes_where_its_bytes_say() {
        assert_eq!(at(&[0xD0, 0x10], 0x1000), vec![0x1002, 0x1012]); // BNE
        assert_eq!(at(&[0xD0, 0xFE], 0x1000), vec![0x1002, 0x1000]); // to itself
        assert_eq!(at(&[0x4C, 0x00, 0x20], 0x1000), vec![0x2000]); // JMP
        assert_eq!(at(&[0x20, 0x00, 0x20], 0x1000), vec![0x2000, 0x1003]); // JSR
        assert!(at(&[0x6C, 0x00, 0x20], 0x1000).is_empty()); // JMP (ind)
        assert!(at(&[0x60], 0x1000).is_empty()); // RTS
        assert!(at(&[0x02], 0x1000).is_empty()); // JAM
        assert_eq!(at(&[0xEE, 0x00, 0x0F], 0x1000), vec![0x1003]); // INC abs
    }
}
