//! A step done on the host: the instruction at a stopped robot's PC run
//! by the emulator against the robot's memory read through the stub, its
//! writes and registers given back to the robot through the stub.
//!
//! A step otherwise stops the robot with a breakpoint's three-byte `JSR`
//! on the next instruction, which cannot go where that instruction is one
//! or two bytes followed by a line or a branch target: most of a
//! handler's lines. Here nothing is patched, and the robot never runs the
//! instruction; what it would have done is done to it. Instructions that
//! push (`JSR`, `PHA`, `PHP`, `BRK`) are left to the patching step: the
//! stub serves the host on the stack below the robot's S, where a push
//! would go. So are instructions that read the stub's bytes or write
//! outside RAM. Either way the host has run the instruction first, so
//! the caller knows every byte it writes (and refuses a step that would
//! write over the stub or a breakpoint's `JSR`).

use std::collections::BTreeMap;

use emulator::{Bus, Cpu};
use isa::Mnemonic;

use super::error::StubResult;
use super::session::Registers;

/// What the instruction did: the registers after it (the PC where it
/// went) and the bytes it wrote, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Effects {
    /// The registers after the instruction.
    pub registers: Registers,
    /// Each write, in the order the CPU made them.
    pub writes: Vec<(u16, u8)>,
}

/// What became of a step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// The host did it: what it did, to be given back to the robot.
    Host(Effects),
    /// Left to the robot (the patching step): the bytes the instruction
    /// writes outside the stack, as far as the host ran it (none for a
    /// push, whose bytes go to the stack).
    Robot(Vec<(u16, u8)>),
}

/// The robot's memory as the instruction sees it: reads through `read`
/// (once per address), writes kept; what the host cannot do marked.
struct LineBus<'a> {
    read: &'a mut dyn FnMut(u16) -> StubResult<u8>,
    unreadable: &'a dyn Fn(u16) -> bool,
    unwritable: &'a dyn Fn(u16) -> bool,
    seen: BTreeMap<u16, u8>,
    writes: Vec<(u16, u8)>,
    /// The first read that failed, or an access the host cannot make.
    trouble: Option<Trouble>,
}

enum Trouble {
    Line(super::error::StubError),
    Refused,
}

impl LineBus<'_> {
    fn byte(&mut self, address: u16) -> u8 {
        if let Some(&byte) = self.seen.get(&address) {
            return byte;
        }
        if (self.unreadable)(address) {
            // Read all the same: a write after it goes where it says.
            self.trouble.get_or_insert(Trouble::Refused);
        }
        match (self.read)(address) {
            Ok(byte) => {
                self.seen.insert(address, byte);
                byte
            }
            Err(error) => {
                self.trouble.get_or_insert(Trouble::Line(error));
                0
            }
        }
    }
}

impl Bus for LineBus<'_> {
    fn read(&mut self, address: u16, _cycle: u64) -> u8 {
        self.byte(address)
    }

    fn write(&mut self, address: u16, value: u8, _cycle: u64) {
        if (0x0100..0x0200).contains(&address) || (self.unwritable)(address) {
            self.trouble.get_or_insert(Trouble::Refused);
        }
        self.seen.insert(address, value);
        self.writes.push((address, value));
    }

    // The CPU ignores what a dummy read returns; reading through the stub
    // for it would only cost a frame (and clear an I/O flag the program
    // did not read).
    fn dummy_read(&mut self, _address: u16, _cycle: u64) {}

    fn peek(&self, address: u16) -> u8 {
        self.seen.get(&address).copied().unwrap_or(0)
    }
}

/// Runs the instruction at `registers.pc` on the host, reading the
/// robot's memory with `read` (which gives the instruction's own bytes as
/// the program has them, not a breakpoint's `JSR`). [`Step::Robot`] when
/// the host cannot do it (a push, a JAM, a read `unreadable` or a write
/// `unwritable` or in the stack page): the caller patches instead.
///
/// # Errors
/// The line's errors from `read`.
pub fn step(
    registers: Registers,
    read: &mut dyn FnMut(u16) -> StubResult<u8>,
    unreadable: &dyn Fn(u16) -> bool,
    unwritable: &dyn Fn(u16) -> bool,
) -> StubResult<Step> {
    let pc = registers.pc;
    let opcode = read(pc)?;
    let info = isa::opcode(opcode);
    if info.cycles == 0
        || matches!(
            info.mnemonic,
            Mnemonic::Jsr | Mnemonic::Pha | Mnemonic::Php | Mnemonic::Brk
        )
    {
        return Ok(Step::Robot(Vec::new()));
    }
    let mut bus = LineBus {
        read,
        unreadable,
        unwritable,
        seen: BTreeMap::from([(pc, opcode)]),
        writes: Vec::new(),
        trouble: None,
    };
    let mut cpu = Cpu::new();
    cpu.set_idle_skip(false);
    (cpu.a, cpu.x, cpu.y, cpu.s, cpu.pc) = (registers.a, registers.x, registers.y, registers.s, pc);
    cpu.set_p(registers.p);
    cpu.step(&mut bus);
    match bus.trouble {
        Some(Trouble::Line(error)) => return Err(error),
        Some(Trouble::Refused) => {
            let writes = bus
                .writes
                .into_iter()
                .filter(|(address, _)| !(0x0100..0x0200).contains(address))
                .collect();
            return Ok(Step::Robot(writes));
        }
        None => {}
    }
    Ok(Step::Host(Effects {
        registers: Registers {
            pc: cpu.pc,
            a: cpu.a,
            x: cpu.x,
            y: cpu.y,
            // B and the unused bit as the stub keeps them (PHP's).
            p: (cpu.p() & !0x30) | (registers.p & 0x30),
            s: cpu.s,
        },
        writes: bus.writes,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn registers(pc: u16) -> Registers {
        Registers {
            pc,
            a: 0x10,
            x: 0xFF,
            y: 0,
            p: 0x30,
            s: 0xF0,
        }
    }

    /// Steps the instruction `code` at $0400 in RAM holding `ram` pairs.
    fn run(code: &[u8], ram: &[(u16, u8)], at: Registers) -> Option<Effects> {
        match step_it(code, ram, at) {
            Step::Host(effects) => Some(effects),
            Step::Robot(_) => None,
        }
    }

    fn step_it(code: &[u8], ram: &[(u16, u8)], at: Registers) -> Step {
        let mut memory = [0u8; 0x10000];
        memory[0x0400..0x0400 + code.len()].copy_from_slice(code);
        for &(address, value) in ram {
            memory[usize::from(address)] = value;
        }
        let mut read = |address: u16| Ok(memory[usize::from(address)]);
        step(at, &mut read, &|address| address == 0x00F0, &|address| {
            address > 0x0FFF
        })
        .expect("no line here")
    }

    #[test]
    fn a_one_byte_instruction_is_done_for_the_robot() {
        let done = run(&[0xE8], &[], registers(0x0400)).expect("INX is the host's");
        assert_eq!(done.registers.x, 0x00);
        assert_eq!(done.registers.pc, 0x0401);
        assert_eq!(done.registers.p & 0x02, 0x02, "Z set");
        assert_eq!(
            done.registers.p & 0x30,
            0x30,
            "B and bit 5 as the stub keeps them"
        );
        assert!(done.writes.is_empty());
    }

    #[test]
    fn a_branch_goes_where_the_flags_say() {
        let taken = run(&[0xD0, 0x10], &[], registers(0x0400)).expect("BNE");
        assert_eq!(taken.registers.pc, 0x0412, "Z clear: taken");
        let mut zero = registers(0x0400);
        zero.p |= 0x02;
        let not = run(&[0xD0, 0x10], &[], zero).expect("BNE");
        assert_eq!(not.registers.pc, 0x0402);
    }

    #[test]
    fn reads_and_writes_go_through_the_line() {
        let done = run(&[0xA5, 0x80], &[(0x0080, 0x42)], registers(0x0400)).expect("LDA zp");
        assert_eq!(done.registers.a, 0x42);
        let done = run(&[0x85, 0x81], &[], registers(0x0400)).expect("STA zp");
        assert_eq!(done.writes, vec![(0x0081, 0x10)]);
        let done = run(&[0xEE, 0x00, 0x05], &[(0x0500, 7)], registers(0x0400)).expect("INC");
        assert_eq!(
            done.writes,
            vec![(0x0500, 7), (0x0500, 8)],
            "the NMOS read-modify-write writes twice"
        );
        let done = run(
            &[0x60],
            &[(0x01F1, 0x20), (0x01F2, 0x04)],
            registers(0x0400),
        )
        .expect("RTS reads the stack");
        assert_eq!((done.registers.pc, done.registers.s), (0x0421, 0xF2));
    }

    #[test]
    fn what_the_host_cannot_do_is_left_to_the_patch() {
        for (code, why) in [
            (&[0x48][..], "PHA pushes"),
            (&[0x08][..], "PHP pushes"),
            (&[0x20, 0x00, 0x05][..], "JSR pushes"),
            (&[0x00][..], "BRK"),
            (&[0x02][..], "a JAM"),
            (&[0xA5, 0xF0][..], "the stub's zero page"),
            (&[0x8D, 0x00, 0x90][..], "a write outside RAM"),
            (&[0x9D, 0x00, 0x01][..], "a write into the stack page"),
        ] {
            assert_eq!(run(code, &[], registers(0x0400)), None, "{why}");
        }
    }

    #[test]
    fn a_step_left_to_the_robot_says_what_it_writes() {
        // INC $F0 reads a byte it may not (the stub's, here): left to the
        // robot, with both of its writes named.
        assert_eq!(
            step_it(&[0xE6, 0xF0], &[(0x00F0, 4)], registers(0x0400)),
            Step::Robot(vec![(0x00F0, 4), (0x00F0, 5)])
        );
        // A write outside RAM too, and the stack's bytes are not named.
        assert_eq!(
            step_it(&[0x8D, 0x00, 0x90], &[], registers(0x0400)),
            Step::Robot(vec![(0x9000, 0x10)])
        );
        assert_eq!(
            step_it(&[0x48], &[], registers(0x0400)),
            Step::Robot(Vec::new())
        );
    }
}
