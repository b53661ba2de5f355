//! The NMOS 6502 core: registers, the run loop, interrupt polling and the
//! BRK/IRQ/NMI/RESET sequences. The opcode dispatch is in `execute`, the
//! addressing modes and bus accesses in `access`, the arithmetic in `alu`.
//!
//! # Timing model
//!
//! Every bus cycle is one [`Bus`] call made with the exact cycle number
//! (see [`crate::bus`]); the cycle counter advances by one per call, so an
//! instruction's cycle count *is* the number of accesses it makes, dummy
//! accesses included. A test checks every opcode's count against
//! [`isa::OPCODES`] (base cycles plus page-cross and branch penalties).
//!
//! Interrupts follow the datasheet: the inputs are polled once per
//! instruction at its second-to-last cycle (one earlier for a taken branch
//! that stays in its page), with the I flag as it was at that point, so CLI,
//! SEI and PLP act one instruction late while RTI acts at once. The
//! interrupt sequences do not poll at their end: at least one instruction of
//! a handler runs before the next interrupt. BRK and IRQ sequences check for
//! an NMI on their fourth cycle and take the NMI vector if one arrived
//! ("NMI hijacking"); the pushed B flag still tells BRK from IRQ.

mod access;
mod alu;
mod execute;
mod idle;

use crate::bus::Bus;
use crate::hooks::{Control, Hooks, NoHooks};
use idle::IdleSkip;

/// Bits of the processor status register P.
pub mod flag {
    /// Carry.
    pub const C: u8 = 0x01;
    /// Zero.
    pub const Z: u8 = 0x02;
    /// Interrupt disable.
    pub const I: u8 = 0x04;
    /// Decimal mode.
    pub const D: u8 = 0x08;
    /// Break: not a register bit; set in the copy of P that BRK and PHP push,
    /// clear in the copy IRQ and NMI push.
    pub const B: u8 = 0x10;
    /// Unused: always reads as 1.
    pub const U: u8 = 0x20;
    /// Overflow.
    pub const V: u8 = 0x40;
    /// Negative.
    pub const N: u8 = 0x80;
}

pub use isa::vectors::{IRQ as IRQ_VECTOR, NMI as NMI_VECTOR, RESET as RESET_VECTOR};

/// An interrupt sequence the CPU went through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Interrupt {
    /// A maskable interrupt request (vector `$FFFE`).
    Irq,
    /// A non-maskable interrupt (vector `$FFFA`), including one that hijacked
    /// an IRQ sequence.
    Nmi,
}

/// Why [`Cpu::run`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stop {
    /// The cycle counter reached the limit given to the run.
    Limit,
    /// The instruction at `pc` jumped or branched to itself (`JMP *`,
    /// `BNE *`), and the hooks asked to stop at traps.
    Trap {
        /// The trap's address, which is also the PC.
        pc: u16,
    },
    /// A JAM (KIL) opcode halted the processor. The PC stays on it and no
    /// cycle is counted for it; running again reports the same JAM.
    Jam {
        /// The address of the JAM opcode.
        pc: u16,
        /// The opcode byte.
        opcode: u8,
    },
    /// A hook (a breakpoint) asked to stop before the instruction at `pc`.
    Hook {
        /// The address of the instruction not yet executed.
        pc: u16,
    },
    /// The bus asked the run to end ([`Bus::stop_requested`], seen at an
    /// interrupt poll): on the board, a byte reached a host that watches
    /// its line. Running again goes on exactly as if the run had not ended.
    Bus,
}

/// What one [`Cpu::step`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Step {
    /// Executed one instruction.
    Instruction,
    /// Executed one instruction that jumped or branched to itself.
    Trap,
    /// Went through an interrupt sequence instead of an instruction.
    Interrupt(Interrupt),
    /// Hit a JAM opcode: nothing executed, the PC stays on it.
    Jam {
        /// The opcode byte.
        opcode: u8,
    },
}

// What an instruction tells the step about its interrupt poll and outcome.
/// Poll one cycle earlier (a taken branch that stays in its page).
const LATE_POLL: u8 = 1;
/// Poll with the I flag as it was before the instruction (CLI, SEI, PLP),
/// which `I_WAS_SET` gives.
const OLD_I: u8 = 2;
/// The instruction jumped or branched to its own address.
const TRAP: u8 = 4;
/// A JAM opcode: nothing executed.
const JAM: u8 = 8;
/// No poll at the end (BRK: the interrupt sequence has its own).
const NO_POLL: u8 = 16;
/// With `OLD_I`: I was set before the instruction.
const I_WAS_SET: u8 = 32;
/// The instruction's poll was made (not skipped as quiet).
const POLLED: u8 = 64;
/// RTI: the end of an interrupt handler, where an idle program goes back
/// to waiting (the run loop then looks for its idle loop at once).
const RETURNED: u8 = 128;

/// An NMOS 6502. Registers are public fields; the status register is read
/// and written through [`Cpu::p`] and [`Cpu::set_p`] because the CPU keeps
/// its flags unpacked.
///
/// Two CPUs are equal when their registers, flags, counters and interrupt
/// state are; the idle-skip setting and schedule are not compared.
#[derive(Clone)]
pub struct Cpu {
    /// Accumulator.
    pub a: u8,
    /// Index register X.
    pub x: u8,
    /// Index register Y.
    pub y: u8,
    /// Stack pointer (the stack is page one, `$0100 + s`).
    pub s: u8,
    /// Program counter.
    pub pc: u16,
    // N is bit 7 of `n`; Z is set when `z` is 0 (the last result is kept
    // instead of computing the flags on every instruction).
    n: u8,
    z: u8,
    c: bool,
    // V, D and I in their P positions: one byte keeps a register free in
    // the run loop.
    vdi: u8,
    cycles: u64,
    instructions: u64,
    // The NMI level seen at the previous poll (edge detection).
    nmi_line: bool,
    nmi_pending: bool,
    // An IRQ was asserted with I clear at the last poll.
    irq_pending: bool,
    // Idle-loop skipping (see `idle`): not machine state.
    idle: IdleSkip,
}

impl PartialEq for Cpu {
    fn eq(&self, other: &Cpu) -> bool {
        (
            self.a,
            self.x,
            self.y,
            self.s,
            self.pc,
            self.n,
            self.z,
            self.c,
            self.vdi,
            self.cycles,
            self.instructions,
        ) == (
            other.a,
            other.x,
            other.y,
            other.s,
            other.pc,
            other.n,
            other.z,
            other.c,
            other.vdi,
            other.cycles,
            other.instructions,
        ) && (self.nmi_line, self.nmi_pending, self.irq_pending)
            == (other.nmi_line, other.nmi_pending, other.irq_pending)
    }
}

impl Eq for Cpu {}

impl Default for Cpu {
    fn default() -> Cpu {
        Cpu::new()
    }
}

impl core::fmt::Debug for Cpu {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "PC=${:04X} A=${:02X} X=${:02X} Y=${:02X} S=${:02X} P=${:02X} ({}) cycles={} instructions={}",
            self.pc,
            self.a,
            self.x,
            self.y,
            self.s,
            self.p(),
            flags_text(self.p()),
            self.cycles,
            self.instructions
        )
    }
}

/// The status register as `NV-BDIZC` letters, upper case when set
/// (`nv-bdIzc`).
#[must_use]
pub fn flags_text(p: u8) -> String {
    "NV-BDIZC"
        .chars()
        .enumerate()
        .map(|(index, letter)| {
            if letter == '-' {
                '-'
            } else if p & (0x80 >> index) != 0 {
                letter
            } else {
                letter.to_ascii_lowercase()
            }
        })
        .collect()
}

impl Cpu {
    /// The power-on state: A, X, Y, S and PC zero, only I (and the unused
    /// bit) set in P, no interrupt pending, cycle 0. Call [`Cpu::reset`]
    /// before running, as the hardware's reset line does.
    #[must_use]
    pub const fn new() -> Cpu {
        Cpu {
            a: 0,
            x: 0,
            y: 0,
            s: 0,
            pc: 0,
            n: 0,
            z: 1,
            c: false,
            vdi: flag::I,
            cycles: 0,
            instructions: 0,
            nmi_line: false,
            nmi_pending: false,
            irq_pending: false,
            idle: IdleSkip::new(),
        }
    }

    /// Allows or forbids idle-loop skipping in [`Cpu::run`] (allowed by
    /// default). When the program goes round a loop that changes no memory
    /// (its writes, if any, store what is there already) and reads only
    /// plain memory, with every register back as it was, the
    /// run advances whole iterations up to the next moment a device could
    /// act (the bus's [`Bus::quiet_until`]) or the run's limit, counting
    /// their cycles and instructions as if it had run them: the state
    /// afterwards is exactly the state running them would leave. It only
    /// happens with hooks that observe nothing ([`Hooks::PASSIVE`]) and a
    /// bus that vouches for its memory ([`Bus::is_plain_memory`]), or with
    /// hooks whose answers repeat with the loop's laps
    /// ([`Hooks::may_skip_idle`]: breakpoints), which then see the probe's
    /// instructions and stop it as they would the run.
    pub fn set_idle_skip(&mut self, allowed: bool) {
        self.idle.enabled = allowed;
    }

    /// Whether idle-loop skipping is allowed (see [`Cpu::set_idle_skip`]).
    #[must_use]
    pub const fn idle_skip(&self) -> bool {
        self.idle.enabled
    }

    /// Cycles this CPU advanced by skipping idle-loop iterations rather
    /// than running them (included in [`Cpu::cycles`]).
    #[must_use]
    pub const fn skipped_cycles(&self) -> u64 {
        self.idle.skipped_cycles
    }

    /// The status register as PHP would push it without the B bit (bit 5
    /// always set, bit 4 clear).
    #[inline]
    #[must_use]
    pub fn p(&self) -> u8 {
        (self.n & flag::N)
            | self.vdi
            | flag::U
            | if self.z == 0 { flag::Z } else { 0 }
            | u8::from(self.c)
    }

    /// Sets the status register (bits 4 and 5 do not exist in the register
    /// and are ignored).
    #[inline]
    pub fn set_p(&mut self, p: u8) {
        self.n = p;
        self.vdi = p & (flag::V | flag::D | flag::I);
        self.z = u8::from(p & flag::Z == 0);
        self.c = p & flag::C != 0;
    }

    #[inline(always)]
    fn v(&self) -> bool {
        self.vdi & flag::V != 0
    }

    #[inline(always)]
    fn d(&self) -> bool {
        self.vdi & flag::D != 0
    }

    #[inline(always)]
    fn i(&self) -> bool {
        self.vdi & flag::I != 0
    }

    #[inline(always)]
    fn set_flag(&mut self, mask: u8, on: bool) {
        self.vdi = (self.vdi & !mask) | if on { mask } else { 0 };
    }

    #[inline(always)]
    fn set_v(&mut self, on: bool) {
        self.set_flag(flag::V, on);
    }

    #[inline(always)]
    fn set_d(&mut self, on: bool) {
        self.set_flag(flag::D, on);
    }

    #[inline(always)]
    fn set_i(&mut self, on: bool) {
        self.set_flag(flag::I, on);
    }

    /// Bus cycles since the CPU was created (every access is one cycle).
    #[inline]
    #[must_use]
    pub const fn cycles(&self) -> u64 {
        self.cycles
    }

    /// Instructions completed since the CPU was created (interrupt and reset
    /// sequences are not instructions).
    #[inline]
    #[must_use]
    pub const fn instructions(&self) -> u64 {
        self.instructions
    }

    /// True if an interrupt sequence will run before the next instruction.
    #[must_use]
    pub const fn interrupt_pending(&self) -> bool {
        self.nmi_pending || self.irq_pending
    }

    /// The RESET sequence (7 cycles): two reads at the PC, three stack reads
    /// while S decreases by 3 (the suppressed pushes of an interrupt), then
    /// the vector at `$FFFC`. Sets I; D is left alone, as on the NMOS part.
    /// Pending interrupts are forgotten.
    pub fn reset<B: Bus>(&mut self, bus: &mut B) {
        self.dummy_read(bus, self.pc);
        self.dummy_read(bus, self.pc);
        for _ in 0..3 {
            self.dummy_read(bus, 0x0100 | u16::from(self.s));
            self.s = self.s.wrapping_sub(1);
        }
        self.set_i(true);
        self.nmi_pending = false;
        self.irq_pending = false;
        let lo = self.read(bus, RESET_VECTOR);
        let hi = self.read(bus, RESET_VECTOR + 1);
        self.pc = u16::from_le_bytes([lo, hi]);
    }

    /// Runs an IRQ or NMI sequence now (7 cycles), as if the input had just
    /// been polled asserted; an IRQ runs even with I set. For tests and
    /// hosts that inject interrupts directly; devices use [`Bus::poll`].
    pub fn interrupt<B: Bus>(&mut self, bus: &mut B, kind: Interrupt) -> Interrupt {
        match kind {
            Interrupt::Irq => self.irq_pending = true,
            Interrupt::Nmi => self.nmi_pending = true,
        }
        self.interrupt_sequence(bus)
    }

    /// Executes one instruction, or the pending interrupt sequence.
    pub fn step<B: Bus>(&mut self, bus: &mut B) -> Step {
        if self.nmi_pending || self.irq_pending {
            return Step::Interrupt(self.interrupt_sequence(bus));
        }
        let (flow, _) = self.instruction(bus);
        if flow & JAM != 0 {
            Step::Jam {
                opcode: bus.peek(self.pc),
            }
        } else if flow & TRAP != 0 {
            Step::Trap
        } else {
            Step::Instruction
        }
    }

    /// Runs until the cycle counter reaches `until` (checked between
    /// instructions, so the run may end a few cycles past it), a JAM, or a
    /// stop asked by `hooks`. With [`NoHooks`] the loop has no hook code at
    /// all: tracing and breakpoints cost nothing when off.
    // Never inlined: each instantiation gets a function of its own, whose
    // loop keeps the registers in machine registers; inlined into a large
    // caller it loses them to spills (measured 2-3x slower).
    #[inline(never)]
    pub fn run<B: Bus, H: Hooks>(&mut self, bus: &mut B, until: u64, hooks: &mut H) -> Stop {
        // The loop runs on a local copy whose address never escapes, so the
        // compiler can keep the registers in machine registers.
        let mut cpu = self.clone();
        let stop = cpu.run_local(bus, until, hooks);
        *self = cpu;
        stop
    }

    #[inline(always)]
    fn run_local<B: Bus, H: Hooks>(&mut self, bus: &mut B, until: u64, hooks: &mut H) -> Stop {
        // A constant `false` unless the hooks observe nothing or say
        // their answers repeat with an idle loop's laps.
        let probing = self.idle.enabled && (H::PASSIVE || hooks.may_skip_idle());
        // The inner loop ended on an RTI (only with passive hooks).
        let mut returned = false;
        loop {
            if self.cycles >= until {
                return Stop::Limit;
            }
            // Only a poll can have raised it: the inner loop and the probe
            // come out at a poll that finds it.
            if bus.stop_requested() {
                return Stop::Bus;
            }
            if self.nmi_pending || self.irq_pending {
                let kind = self.interrupt_sequence(bus);
                hooks.interrupt(self, &*bus, kind);
                returned = false;
                continue;
            }
            if probing && (returned || self.cycles >= self.idle.next_probe) {
                // On a copy, so that this loop's CPU never has its address
                // taken and stays in machine registers.
                let mut cpu = self.clone();
                let stop = cpu.probe_idle(bus, until, returned, hooks);
                *self = cpu;
                returned = false;
                if let Some(stop) = stop {
                    return stop;
                }
                continue;
            }
            // The inner loop also ends at the next probe: the comparison it
            // makes anyway.
            let limit = if probing {
                until.min(self.idle.next_probe)
            } else {
                until
            };
            // Instructions back to back until a poll finds an interrupt or
            // the limit is reached. Nothing here reads P as a whole; the
            // pending flags can only change where a poll is made, and with
            // a bus that has no interrupt source the polls fold away.
            returned = loop {
                if let Control::Stop = hooks.before_instruction(self, &*bus) {
                    return Stop::Hook { pc: self.pc };
                }
                let pc = self.pc;
                let opcode = self.fetch(bus);
                // Passive hooks ignore traps: no trap comparisons then.
                let flow = if H::PASSIVE {
                    self.execute::<B, false>(bus, opcode, pc)
                } else {
                    self.execute::<B, true>(bus, opcode, pc)
                };
                let mut interrupted = false;
                if flow & (JAM | NO_POLL | RETURNED) != 0 {
                    if flow & JAM != 0 {
                        // The processor locks up on the opcode: leave it
                        // there, uncounted, so the fault is reported where
                        // it happened.
                        self.pc = pc;
                        self.cycles -= 1;
                        return Stop::Jam {
                            pc,
                            opcode: bus.peek(pc),
                        };
                    }
                    self.instructions += 1;
                    hooks.after_instruction(self, &*bus, pc, opcode);
                    // BRK's sequence polled (a stop the bus asked during
                    // it ends the run here); RTI polls as usual.
                    if flow & NO_POLL != 0 {
                        interrupted = bus.stop_requested();
                    }
                    if flow & RETURNED != 0 {
                        if self.cycles > bus.quiet_until() {
                            self.poll_after(bus, flow);
                            interrupted =
                                self.nmi_pending || self.irq_pending || bus.stop_requested();
                        }
                        if probing {
                            // Maybe back into the idle loop last found:
                            // the probe decides, out of this loop.
                            break true;
                        }
                    }
                } else {
                    self.instructions += 1;
                    hooks.after_instruction(self, &*bus, pc, opcode);
                    // One comparison while the bus is quiet (see
                    // `instruction`).
                    if self.cycles > bus.quiet_until() {
                        self.poll_after(bus, flow);
                        interrupted = self.nmi_pending || self.irq_pending || bus.stop_requested();
                    }
                }
                if flow & TRAP != 0 {
                    if let Control::Stop = hooks.trap(self, &*bus) {
                        return Stop::Trap { pc: self.pc };
                    }
                }
                if interrupted || self.cycles >= limit {
                    break false;
                }
            };
        }
    }

    /// [`Cpu::run`] without hooks.
    #[inline]
    pub fn run_plain<B: Bus>(&mut self, bus: &mut B, until: u64) -> Stop {
        self.run(bus, until, &mut NoHooks)
    }

    /// One instruction and its interrupt poll, for [`Cpu::step`] and the
    /// idle probe (the run loop has its own copy). Returns the flow bits,
    /// with `POLLED` if the poll was made, and the opcode fetched.
    ///
    /// The poll is skipped when the bus says it would find nothing
    /// ([`Bus::quiet_until`]); a skipped poll changes nothing here either,
    /// since instructions only run with no interrupt pending and a bus only
    /// reports quiet while NMI rests released.
    #[inline(always)]
    fn instruction<B: Bus>(&mut self, bus: &mut B) -> (u8, u8) {
        let pc = self.pc;
        let opcode = self.fetch(bus);
        let flow = self.execute::<B, true>(bus, opcode, pc);
        if flow & (JAM | NO_POLL) != 0 {
            if flow & JAM != 0 {
                // The processor locks up on the opcode: leave it there,
                // uncounted, so the fault is reported where it happened.
                self.pc = pc;
                self.cycles -= 1;
                return (flow, opcode);
            }
            self.instructions += 1;
            return (flow, opcode);
        }
        self.instructions += 1;
        // Every poll point lies before the instruction's end (two cycles
        // or more before it): one comparison decides, and with a bus that
        // is always quiet (`u64::MAX`) it folds away.
        if self.cycles <= bus.quiet_until() {
            return (flow, opcode);
        }
        self.poll_after(bus, flow);
        (flow | POLLED, opcode)
    }

    /// The poll of the instruction that just ended with `flow`: at its
    /// second-to-last cycle (one earlier for `LATE_POLL`), with I as the
    /// instruction left it or, for `OLD_I`, as it was before.
    #[inline(always)]
    fn poll_after<B: Bus>(&mut self, bus: &mut B, flow: u8) {
        let poll_at = self.cycles - 2 - u64::from(flow & LATE_POLL);
        let i = if flow & OLD_I != 0 {
            flow & I_WAS_SET != 0
        } else {
            self.i()
        };
        self.poll(bus, poll_at, i);
    }

    /// The flow bits of CLI, SEI and PLP, taken before they change I: their
    /// poll sees I as it was.
    #[inline(always)]
    fn old_i(&self) -> u8 {
        if self.i() { OLD_I | I_WAS_SET } else { OLD_I }
    }

    /// Samples the interrupt inputs for bus cycle `cycle`, with I as it was
    /// then.
    #[inline(always)]
    fn poll<B: Bus>(&mut self, bus: &mut B, cycle: u64, i: bool) {
        let lines = bus.poll(cycle);
        self.nmi_pending |= lines.nmi & !self.nmi_line;
        self.nmi_line = lines.nmi;
        self.irq_pending = lines.irq & !i;
    }

    /// IRQ/NMI: two reads at the PC (the opcode fetch, suppressed), then the
    /// common tail with B clear.
    #[inline(always)]
    fn interrupt_sequence<B: Bus>(&mut self, bus: &mut B) -> Interrupt {
        self.dummy_read(bus, self.pc);
        self.dummy_read(bus, self.pc);
        self.interrupt_tail(bus, 0)
    }

    /// Cycles 3 to 7 of BRK, IRQ and NMI: push PC and P (with `b` as the B
    /// bit), set I, fetch the vector. An NMI seen by cycle 4 takes the NMI
    /// vector, whatever started the sequence.
    #[inline(always)]
    fn interrupt_tail<B: Bus>(&mut self, bus: &mut B, b: u8) -> Interrupt {
        let [pcl, pch] = self.pc.to_le_bytes();
        self.push(bus, pch);
        self.push(bus, pcl);
        let lines = bus.poll(self.cycles - 1);
        self.nmi_pending |= lines.nmi & !self.nmi_line;
        self.nmi_line = lines.nmi;
        let nmi = self.nmi_pending;
        self.nmi_pending = false;
        let p = self.p() | b;
        self.push(bus, p);
        self.set_i(true);
        self.irq_pending = false;
        let vector = if nmi { NMI_VECTOR } else { IRQ_VECTOR };
        let lo = self.read(bus, vector);
        let hi = self.read(bus, vector + 1);
        self.pc = u16::from_le_bytes([lo, hi]);
        if nmi { Interrupt::Nmi } else { Interrupt::Irq }
    }
}
