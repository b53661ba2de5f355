//! What a breakpoint displaces: the whole instructions under the three
//! bytes of its `JSR`, laid out in a trampoline that ends `JMP` back, and
//! the refusals where that would change what the code does. A displaced
//! branch reads the PC, so in the trampoline it becomes the opposite
//! branch over a `JMP` to its target. And where a step can go next, from
//! the instruction table.

use isa::{AddressingMode, Instruction, Mnemonic};

use super::error::{StubError, StubResult};
use super::link::TRAMPOLINE_LEN;
use crate::image::UploadImage;

/// `JSR abs`.
pub const JSR: u8 = 0x20;
/// `JMP abs`.
pub const JMP: u8 = 0x4C;

/// What turns a branch into its opposite (`BNE` into `BEQ`, `BCC` into
/// `BCS`, ...): the condition's sense is bit 5 of every branch opcode.
const OPPOSITE: u8 = 0x20;

/// A relocated branch in a trampoline: the opposite branch over the
/// `JMP` to the target (`Bxx` + 3, then `JMP target`).
const RELOCATED_LEN: u16 = 5;

/// One displaced instruction's place in its trampoline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Piece {
    /// Its offset among the displaced bytes (from the breakpoint).
    pub program: u16,
    /// Its offset in the trampoline.
    pub trampoline: u16,
    /// A branch, laid out as the opposite branch over a `JMP` to its target.
    pub relocated: bool,
}

/// A breakpoint's patch: where, the bytes it replaces, the trampoline.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Patch {
    /// The instruction it stops before.
    pub address: u16,
    /// The image's bytes of the displaced instructions (3 to 5).
    pub displaced: Vec<u8>,
    /// The trampoline: the displaced instructions (a branch relocated),
    /// then `JMP` past them.
    pub trampoline: Vec<u8>,
    /// Where each displaced instruction is in the trampoline, in order.
    pub pieces: Vec<Piece>,
}

impl Patch {
    /// The three bytes the image has where the `JSR` goes.
    #[must_use]
    pub fn original(&self) -> [u8; 3] {
        [self.displaced[0], self.displaced[1], self.displaced[2]]
    }

    /// Where `address` is among the displaced bytes: its offset from the
    /// first, if it is one.
    #[must_use]
    pub fn offset_of(&self, address: u16) -> Option<u16> {
        let offset = address.checked_sub(self.address)?;
        (usize::from(offset) < self.displaced.len()).then_some(offset)
    }

    /// Where the program's instruction at `offset` (from the breakpoint)
    /// is in the trampoline; the offset just past the displaced bytes is
    /// the `JMP` back.
    #[must_use]
    pub fn trampoline_offset(&self, offset: u16) -> Option<u16> {
        if usize::from(offset) == self.displaced.len() {
            return Some(self.back());
        }
        self.pieces
            .iter()
            .find(|piece| piece.program == offset)
            .map(|piece| piece.trampoline)
    }

    /// The program's offset (from the breakpoint) that the trampoline's
    /// instruction at `offset` stands for; the `JMP` back stands for the
    /// instruction after the displaced ones.
    #[must_use]
    pub fn program_offset(&self, offset: u16) -> Option<u16> {
        if offset == self.back() {
            return Some(self.displaced.len() as u16);
        }
        self.pieces
            .iter()
            .find(|piece| piece.trampoline == offset)
            .map(|piece| piece.program)
    }

    /// The offset of the trampoline's `JMP` back.
    #[must_use]
    pub fn back(&self) -> u16 {
        self.trampoline.len() as u16 - 3
    }

    /// The program's byte at `address`, if it is one the patch displaced.
    #[must_use]
    pub fn displaced_at(&self, address: u16) -> Option<u8> {
        self.offset_of(address)
            .map(|offset| self.displaced[usize::from(offset)])
    }

    /// The patch with the program's byte at `address` (one it displaced)
    /// changed to `value`, its trampoline laid out again, or why the
    /// bytes could no longer run in the trampoline: an instruction that
    /// would run past them into the `JMP` back, or a branch into them.
    ///
    /// # Errors
    /// The reason, for a refusal.
    pub fn with_byte(&self, address: u16, value: u8) -> Result<Patch, String> {
        let offset = usize::from(
            self.offset_of(address)
                .ok_or_else(|| format!("${address:04X} is not among its bytes"))?,
        );
        let mut displaced = self.displaced.clone();
        displaced[offset] = value;
        lay_out(self.address, displaced)
    }

    /// Whether `address` is one of the displaced bytes after the first.
    #[must_use]
    pub fn covers_inside(&self, address: u16) -> bool {
        self.offset_of(address).is_some_and(|offset| offset > 0)
    }
}

/// The patch of `displaced` (whole instructions) at `address`: each
/// instruction copied into the trampoline, a branch as the opposite
/// branch over a `JMP` to its target, then `JMP` past them; or why not.
///
/// # Errors
/// The reason: an instruction that runs past `displaced`, or a branch to
/// one of the bytes the `JSR` covers after the first (it would land
/// inside the `JSR`).
pub fn lay_out(address: u16, displaced: Vec<u8>) -> Result<Patch, String> {
    let end = address.wrapping_add(displaced.len() as u16);
    let mut trampoline = Vec::new();
    let mut pieces = Vec::new();
    let mut at = 0;
    while at < displaced.len() {
        let here = address.wrapping_add(at as u16);
        let instruction = Instruction::decode(&displaced[at..], here).ok_or_else(|| {
            format!("the instruction at ${here:04X} would run past the bytes its trampoline holds")
        })?;
        let len = usize::from(instruction.len());
        let relocated = instruction.opcode.mode == AddressingMode::Relative;
        pieces.push(Piece {
            program: at as u16,
            trampoline: trampoline.len() as u16,
            relocated,
        });
        if relocated {
            let target = instruction.target().unwrap_or(here);
            if target != address && (address..end).contains(&target) {
                return Err(format!(
                    "the branch at ${here:04X} ({instruction}) goes to ${target:04X}, among the bytes the JSR covers"
                ));
            }
            let [low, high] = target.to_le_bytes();
            trampoline.extend_from_slice(&[displaced[at] ^ OPPOSITE, 3, JMP, low, high]);
        } else {
            trampoline.extend_from_slice(&displaced[at..at + len]);
        }
        at += len;
    }
    trampoline.push(JMP);
    trampoline.extend_from_slice(&end.to_le_bytes());
    debug_assert!(trampoline.len() <= usize::from(TRAMPOLINE_LEN));
    Ok(Patch {
        address,
        displaced,
        trampoline,
        pieces,
    })
}

/// What a trampoline in the robot's memory (`copy`, one slot's bytes, of
/// the stub whose breakpoints call `entry`) holds, read back into the
/// breakpoint it was laid out for: its address and the program's bytes
/// it displaced. `None` when the bytes are not a trampoline as
/// [`lay_out`] makes them: an older layout's, none at all, or a step's
/// ([`alone`]), whose `JSR` into the stub no breakpoint displaces (a
/// breakpoint is refused over another's `JSR`) but whose `JMP` after it
/// reads as a breakpoint's way back.
#[must_use]
pub fn read_trampoline(copy: &[u8], entry: u16) -> Option<(u16, Vec<u8>)> {
    // The program's bytes, a relocated branch's as (opcode, target).
    let mut program: Vec<(Vec<u8>, Option<u16>)> = Vec::new();
    let mut length = 0usize;
    let mut at = 0usize;
    while length < 3 {
        let rest = copy.get(at..)?;
        let instruction = Instruction::decode(rest, 0)?;
        if instruction.opcode.mode == AddressingMode::Relative {
            let bytes = copy.get(at..at + usize::from(RELOCATED_LEN))?;
            if bytes[1] != 3 || bytes[2] != JMP {
                return None;
            }
            let target = u16::from_le_bytes([bytes[3], bytes[4]]);
            program.push((vec![bytes[0] ^ OPPOSITE], Some(target)));
            length += 2;
            at += usize::from(RELOCATED_LEN);
        } else {
            let len = usize::from(instruction.len());
            program.push((copy[at..at + len].to_vec(), None));
            length += len;
            at += len;
        }
    }
    let back = copy.get(at..at + 3)?;
    if back[0] != JMP {
        return None;
    }
    let address = u16::from_le_bytes([back[1], back[2]]).wrapping_sub(length as u16);
    let mut displaced = Vec::new();
    for (bytes, target) in program {
        displaced.extend_from_slice(&bytes);
        if let Some(target) = target {
            let next = address.wrapping_add(displaced.len() as u16 + 1);
            let offset = i8::try_from(i32::from(target) - i32::from(next)).ok()?;
            displaced.push(offset as u8);
        }
    }
    // Laid out again, it must be the very bytes read.
    let patch = lay_out(address, displaced).ok()?;
    let [low, high] = entry.to_le_bytes();
    let calls_the_stub = patch.displaced.windows(3).any(|w| w == [JSR, low, high]);
    (copy.get(..patch.trampoline.len())? == patch.trampoline.as_slice() && !calls_the_stub)
        .then_some((address, patch.displaced))
}

/// The patch for a breakpoint at `address` in `image`, or why not:
/// outside the image (the ROM cannot be patched), a displaced
/// instruction after the first that code may jump to (`entries`: the
/// image's labels and the targets of its branches, jumps and calls), or a
/// displaced branch into the bytes the `JSR` covers.
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
    lay_out(address, displaced).map_err(refuse)
}

/// A step run alone in a trampoline: the instruction's `bytes`, `JSR` into
/// the stub's `entry` (the stop right after it), then `JMP` to `next`,
/// the program's next instruction, which says where the program goes on
/// to a session that finds the robot stopped there ([`alone_next`]).
#[must_use]
pub fn alone(bytes: &[u8], entry: u16, next: u16) -> Vec<u8> {
    let [entry_low, entry_high] = entry.to_le_bytes();
    let [next_low, next_high] = next.to_le_bytes();
    let mut code = bytes.to_vec();
    code.extend_from_slice(&[JSR, entry_low, entry_high, JMP, next_low, next_high]);
    code
}

/// Where the program goes on after a step run alone ([`alone`]), from the
/// robot's bytes at the stop (its `JSR` into `entry`, then the `JMP`), if
/// they are such a step's.
#[must_use]
pub fn alone_next(code: &[u8], entry: u16) -> Option<u16> {
    let [entry_low, entry_high] = entry.to_le_bytes();
    match *code {
        [JSR, low, high, JMP, next_low, next_high, ..]
            if [low, high] == [entry_low, entry_high] =>
        {
            Some(u16::from_le_bytes([next_low, next_high]))
        }
        _ => None,
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shape a breakpoint can displace, laid out and read back from
    /// a slot's bytes (the rest of the slot left as garbage).
    #[test]
    fn a_trampoline_reads_back_as_the_breakpoint_it_was_laid_out_for() {
        for (address, displaced) in [
            (0x0403, vec![0xC9, b'Q', 0xD0, 0xF9]), // CMP #, BNE back
            (0x0409, vec![0xCA, 0xD0, 0xFD]),       // DEX, BNE to itself
            (0x0500, vec![0xD0, 0x10, 0xF0, 0x80]), // two branches
            (0x0600, vec![0x90, 0x7F, 0xAD, 0x00, 0x90]), // BCC, LDA abs
            (0x0700, vec![0x20, 0x00, 0xFF]),       // JSR
            (0x0800, vec![0xE8, 0x48, 0x68]),       // INX PHA PLA
        ] {
            let patch = lay_out(address, displaced.clone()).expect("laid out");
            assert!(patch.trampoline.len() <= usize::from(TRAMPOLINE_LEN));
            let mut slot = patch.trampoline.clone();
            slot.resize(usize::from(TRAMPOLINE_LEN), 0x4C);
            assert_eq!(
                read_trampoline(&slot, 0x0C40),
                Some((address, displaced)),
                "{patch:?}"
            );
            for piece in &patch.pieces {
                assert_eq!(patch.program_offset(piece.trampoline), Some(piece.program));
                assert_eq!(
                    patch.trampoline_offset(piece.program),
                    Some(piece.trampoline)
                );
            }
        }
        // A step's slot (an instruction, then JSR into the stub) is none.
        assert_eq!(
            read_trampoline(&[0xA9, 0x01, 0x20, 0x40, 0x0C, 0, 0, 0], 0x0C40),
            None
        );
        let step = alone(&[0x48], 0x0C40, 0x0406);
        assert_eq!(read_trampoline(&step, 0x0C40), None);
        assert_eq!(alone_next(&step[1..], 0x0C40), Some(0x0406));
        assert_eq!(alone_next(&step[1..], 0x0C41), None, "another stub's");
    }

    #[test]
    fn a_relocated_branch_is_its_opposite_over_a_jmp_to_its_target() {
        let patch = lay_out(0x0403, vec![0xC9, b'Q', 0xD0, 0xF9]).expect("laid out");
        assert_eq!(
            patch.trampoline,
            [0xC9, b'Q', 0xF0, 0x03, 0x4C, 0x00, 0x04, 0x4C, 0x07, 0x04]
        );
        assert_eq!(patch.program_offset(7), Some(4), "the JMP back");
        // A branch into the bytes after the first is refused.
        let refused = lay_out(0x0407, vec![0x90, 0x01, 0xA9, 0x00]).expect_err("refused");
        assert!(refused.contains("$040A"), "{refused}");
    }
}
