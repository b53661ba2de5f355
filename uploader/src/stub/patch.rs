//! What a breakpoint displaces: the whole instructions under the three
//! bytes of its `JSR`, copied to a trampoline that ends `JMP` back, and
//! the refusals where that would change what the code does. And where a
//! step can go next, from the instruction table.

use isa::{AddressingMode, Instruction, Mnemonic};

use super::error::{StubError, StubResult};
use crate::image::UploadImage;

/// `JSR abs`.
pub const JSR: u8 = 0x20;
/// `JMP abs`.
pub const JMP: u8 = 0x4C;

/// A breakpoint's patch: where, the bytes it replaces, the trampoline.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Patch {
    /// The instruction it stops before.
    pub address: u16,
    /// The image's bytes of the displaced instructions (3 to 5).
    pub displaced: Vec<u8>,
    /// The trampoline: the displaced bytes, then `JMP` past them.
    pub trampoline: Vec<u8>,
}

impl Patch {
    /// The three bytes the image has where the `JSR` goes.
    #[must_use]
    pub fn original(&self) -> [u8; 3] {
        [self.displaced[0], self.displaced[1], self.displaced[2]]
    }

    /// Where `address` is among the displaced bytes: its offset from the
    /// first (the trampoline holds them in the same order), if it is one.
    #[must_use]
    pub fn offset_of(&self, address: u16) -> Option<u16> {
        let offset = address.checked_sub(self.address)?;
        (usize::from(offset) < self.displaced.len()).then_some(offset)
    }

    /// The program's byte at `address`, if it is one the patch displaced.
    #[must_use]
    pub fn displaced_at(&self, address: u16) -> Option<u8> {
        self.offset_of(address)
            .map(|offset| self.displaced[usize::from(offset)])
    }

    /// The patch with the program's byte at `address` (one it displaced)
    /// changed to `value`, in its record and its trampoline's copy, or why
    /// the copy could no longer run in the trampoline: an instruction
    /// that would run past its bytes into the `JMP` back, or a branch
    /// (which reads the PC).
    ///
    /// # Errors
    /// The reason, for a refusal.
    pub fn with_byte(&self, address: u16, value: u8) -> Result<Patch, String> {
        let offset = usize::from(
            self.offset_of(address)
                .ok_or_else(|| format!("${address:04X} is not among its bytes"))?,
        );
        let mut changed = self.clone();
        changed.displaced[offset] = value;
        changed.trampoline[offset] = value;
        let mut at = 0;
        while at < changed.displaced.len() {
            let here = self.address.wrapping_add(at as u16);
            let instruction = Instruction::decode(&changed.displaced[at..], here)
                .ok_or_else(|| {
                    format!(
                        "the instruction at ${here:04X} would then run past the bytes its trampoline holds"
                    )
                })?;
            if instruction.opcode.mode == AddressingMode::Relative {
                return Err(format!(
                    "the instruction at ${here:04X} would then be a branch ({instruction}), which cannot run from a trampoline"
                ));
            }
            at += usize::from(instruction.len());
        }
        Ok(changed)
    }

    /// Whether `address` is one of the displaced bytes after the first.
    #[must_use]
    pub fn covers_inside(&self, address: u16) -> bool {
        self.offset_of(address).is_some_and(|offset| offset > 0)
    }
}

/// The patch for a breakpoint at `address` in `image`, or why not:
/// outside the image (the ROM cannot be patched), an instruction that
/// reads the PC (a relative branch) among those displaced, or a displaced
/// instruction after the first that code may jump to (`entries`: the
/// image's labels and the targets of its branches, jumps and calls).
///
/// # Errors
/// [`StubError::Refused`] with the reason.
pub fn plan(address: u16, image: &UploadImage, entries: &[u16]) -> StubResult<Patch> {
    let refuse = |reason: String| StubError::Refused {
        what: format!("a breakpoint at ${address:04X}"),
        reason,
    };
    if !image.contains(address) {
        return Err(refuse(
            "it is not in the uploaded code: the ROM cannot be patched, and only the image's bytes are known"
                .into(),
        ));
    }
    let mut displaced = Vec::new();
    let mut at = address;
    while displaced.len() < 3 {
        let bytes: Option<Vec<u8>> = (0..3).map(|i| image.byte(at.wrapping_add(i))).collect();
        let instruction = Instruction::decode(&bytes.unwrap_or_default(), at)
            .or_else(|| {
                let first = image.byte(at)?;
                Instruction::decode(&[first, image.byte(at + 1)?], at)
                    .or_else(|| Instruction::decode(&[first], at))
            })
            .ok_or_else(|| {
                refuse(format!(
                    "the instruction at ${at:04X} runs past the end of the uploaded code"
                ))
            })?;
        if instruction.opcode.mode == AddressingMode::Relative {
            return Err(refuse(format!(
                "the branch at ${at:04X} ({}) would be displaced, and a branch reads the PC; put the breakpoint on the instruction after it or at its target",
                instruction
            )));
        }
        if at != address && entries.contains(&at) {
            return Err(refuse(format!(
                "the JSR would cover ${at:04X}, an instruction some code may jump to (a label is there, or a branch, jump or call goes there); put the breakpoint there instead"
            )));
        }
        for i in 0..u16::from(instruction.len()) {
            let byte = image.byte(at.wrapping_add(i)).ok_or_else(|| {
                refuse(format!(
                    "the instruction at ${at:04X} runs past the uploaded code"
                ))
            })?;
            displaced.push(byte);
        }
        at = instruction.next_address();
    }
    let mut trampoline = displaced.clone();
    trampoline.push(JMP);
    trampoline.extend_from_slice(&at.to_le_bytes());
    Ok(Patch {
        address,
        displaced,
        trampoline,
    })
}

/// Instructions looked at after a refused breakpoint for one that takes it.
const NEAREST_LOOK: usize = 16;

/// The first instruction after `address` in `image` where a breakpoint
/// would not be refused ([`plan`] with `entries`), a few instructions on
/// at most: what a refusal can offer instead of a place that would be
/// refused too (fresh10 F4: "the instruction after it" was a branch's
/// neighbour, refused in turn).
#[must_use]
pub fn nearest(address: u16, image: &UploadImage, entries: &[u16]) -> Option<u16> {
    let mut at = address;
    for _ in 0..NEAREST_LOOK {
        let bytes: Vec<u8> = (0..3)
            .map_while(|i| image.byte(at.wrapping_add(i)))
            .collect();
        at = Instruction::decode(&bytes, at)?.next_address();
        if plan(at, image, entries).is_ok() {
            return Some(at);
        }
    }
    None
}

/// Where the instruction at `pc` (decoded from `read`) can go next, for a
/// step: `Ok` the successors; the stack's bytes are read through `read`
/// too (`RTS`, `RTI`). A `JSR` whose target is not in `image` (the ROM),
/// or any `JSR` when `over`, is stepped over: its successor is the instruction after it.
///
/// # Errors
/// [`StubError::Refused`] for `BRK` (the ROM's interrupt handler returns
/// from it) and a `JAM`.
pub fn successors(
    pc: u16,
    s: u8,
    image: &UploadImage,
    over: bool,
    read: &mut dyn FnMut(u16) -> StubResult<u8>,
) -> StubResult<Vec<u16>> {
    let bytes = [
        read(pc)?,
        read(pc.wrapping_add(1))?,
        read(pc.wrapping_add(2))?,
    ];
    let Some(instruction) = Instruction::decode(&bytes, pc) else {
        return Ok(vec![pc.wrapping_add(1)]);
    };
    let next = instruction.next_address();
    let stack = |offset: u8| 0x0100 | u16::from(s.wrapping_add(offset));
    let word = |read: &mut dyn FnMut(u16) -> StubResult<u8>, at: u16, high: u16| {
        Ok::<u16, StubError>(u16::from_le_bytes([read(at)?, read(high)?]))
    };
    Ok(match instruction.opcode.mnemonic {
        Mnemonic::Jmp if instruction.opcode.mode == AddressingMode::Indirect => {
            let pointer = instruction.operand;
            // The NMOS part does not carry into the pointer's high byte.
            let high = (pointer & 0xFF00) | (pointer.wrapping_add(1) & 0x00FF);
            vec![word(read, pointer, high)?]
        }
        Mnemonic::Jmp => vec![instruction.operand],
        Mnemonic::Jsr if !over && image.contains(instruction.operand) => vec![instruction.operand],
        Mnemonic::Jsr => vec![next],
        Mnemonic::Rts => vec![word(read, stack(1), stack(2))?.wrapping_add(1)],
        Mnemonic::Rti => vec![word(read, stack(2), stack(3))?],
        Mnemonic::Brk => {
            return Err(StubError::Refused {
                what: format!("a step over the BRK at ${pc:04X}"),
                reason: "the ROM's interrupt handler returns from a BRK: set a breakpoint after it and continue".into(),
            });
        }
        _ if instruction.opcode.mode == AddressingMode::Relative => {
            let target = instruction.target().unwrap_or(next);
            if target == next {
                vec![next]
            } else {
                vec![next, target]
            }
        }
        _ if instruction.opcode.cycles == 0 => {
            return Err(StubError::Refused {
                what: format!("a step at ${pc:04X}"),
                reason: "the opcode there is a JAM, which stops the CPU".into(),
            });
        }
        _ => vec![next],
    })
}
