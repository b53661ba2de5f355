//! What a run does besides executing: tracing, breakpoints, stopping at
//! traps.
//!
//! [`Cpu::run`] is generic over a [`Hooks`] value and calls it at fixed
//! points. Every method has an empty, inlined default, so [`NoHooks`]
//! compiles to a loop with no hook code at all, and each combination of hooks
//! gets its own instantiation: tracing and breakpoints cost nothing when off.
//! Hooks combine as tuples: `(StopAtTrap, Tracer::new(file))`.

use std::io::Write;

use crate::bus::Bus;
use crate::cpu::{Cpu, Interrupt, flags_text};

/// A hook's answer: go on, or end the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Control {
    /// Keep running.
    Continue,
    /// End the run (with [`crate::Stop::Hook`] or [`crate::Stop::Trap`]).
    Stop,
}

/// Called by [`Cpu::run`] around what it executes. Methods receive the CPU
/// and a shared view of the bus (read it with [`Bus::peek`] only).
pub trait Hooks {
    /// True for hooks whose methods do nothing and never stop the run
    /// ([`NoHooks`]): only then may [`Cpu::run`] skip iterations of an idle
    /// loop instead of running them ([`Cpu::set_idle_skip`]). Hooks that
    /// trace or stop must see every instruction, so the default is false.
    const PASSIVE: bool = false;

    /// True for hooks that, though they look at every instruction, let an
    /// idle loop be skipped ([`Cpu::set_idle_skip`]): their
    /// [`Hooks::before_instruction`] answers from the registers, the flags
    /// and memory alone (and from what the bus they watch noted), never
    /// from the cycle or instruction counters (beyond
    /// [`Hooks::instruction_bound`]) or a count of their own. A lap of the
    /// loop they let run would then be let run every time again, since
    /// every lap sees the same registers and memory: the probe that finds
    /// the loop runs under the hooks, asks them once more at the lap's end,
    /// and skips. Breakpoints and their conditions qualify; hit counts and
    /// tracing do not. Answered once per run.
    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        Self::PASSIVE
    }

    /// The instruction count a skip of idle-loop iterations must not pass
    /// (the hooks stop at a count): the skip leaves
    /// [`Cpu::instructions`] at most this.
    #[inline(always)]
    fn instruction_bound(&self) -> u64 {
        u64::MAX
    }

    /// Before each instruction, with the registers as the instruction will
    /// see them. [`Control::Stop`] ends the run before it executes.
    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        let _ = (cpu, bus);
        Control::Continue
    }

    /// After each instruction the run executed (not a JAM, which executes
    /// nothing), before any interrupt sequence that follows it: `pc` is its
    /// address and `opcode` the byte the CPU fetched there; the registers
    /// and counters are as it left them (the PC where it went). A profiler
    /// counts here what the instruction took, from the counters, without
    /// reading memory.
    #[inline(always)]
    fn after_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        let _ = (cpu, bus, pc, opcode);
    }

    /// [`Hooks::after_instruction`] for an instruction an idle probe ran
    /// (only with hooks that [`Hooks::may_skip_idle`]): the laps
    /// [`Hooks::idle_skipped`] tells of are made of such instructions, so
    /// hooks that replay them keep these, and only these.
    #[inline(always)]
    fn after_probed_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        self.after_instruction(cpu, bus, pc, opcode);
    }

    /// After an IRQ or NMI sequence (not BRK, which is an instruction), with
    /// the PC at the handler.
    #[inline(always)]
    fn interrupt<B: Bus>(&mut self, cpu: &Cpu, bus: &B, kind: Interrupt) {
        let _ = (cpu, bus, kind);
    }

    /// After the run skipped `laps` iterations of an idle loop instead of
    /// running them (only with hooks that [`Hooks::may_skip_idle`]): one
    /// lap is the last `instructions` instructions these hooks were shown
    /// (the probe ran it under them, and asked them once more at its start
    /// again, the PC now), and took `cycles` cycles. Hooks that count what
    /// runs (a profiler) count the skipped laps here, as if they had seen
    /// them; the CPU's counters have already moved past them.
    #[inline(always)]
    fn idle_skipped(&mut self, cpu: &Cpu, laps: u64, instructions: u64, cycles: u64) {
        let _ = (cpu, laps, instructions, cycles);
    }

    /// After an instruction that jumped or branched to itself (`JMP *`,
    /// `BNE *`, the way test programs and idle loops stop).
    /// [`Control::Stop`] ends the run with [`crate::Stop::Trap`].
    #[inline(always)]
    fn trap<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        let _ = (cpu, bus);
        Control::Continue
    }
}

/// No hooks: the fastest run.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoHooks;

impl Hooks for NoHooks {
    const PASSIVE: bool = true;
}

/// Ends the run at the first trap (an instruction that jumps or branches to
/// itself).
#[derive(Debug, Clone, Copy, Default)]
pub struct StopAtTrap;

impl Hooks for StopAtTrap {
    #[inline(always)]
    fn trap<B: Bus>(&mut self, _cpu: &Cpu, _bus: &B) -> Control {
        Control::Stop
    }
}

impl<H: Hooks + ?Sized> Hooks for &mut H {
    const PASSIVE: bool = H::PASSIVE;

    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        (**self).may_skip_idle()
    }

    #[inline(always)]
    fn instruction_bound(&self) -> u64 {
        (**self).instruction_bound()
    }

    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        (**self).before_instruction(cpu, bus)
    }

    #[inline(always)]
    fn after_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        (**self).after_instruction(cpu, bus, pc, opcode);
    }

    #[inline(always)]
    fn after_probed_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        (**self).after_probed_instruction(cpu, bus, pc, opcode);
    }

    #[inline(always)]
    fn interrupt<B: Bus>(&mut self, cpu: &Cpu, bus: &B, kind: Interrupt) {
        (**self).interrupt(cpu, bus, kind);
    }

    #[inline(always)]
    fn idle_skipped(&mut self, cpu: &Cpu, laps: u64, instructions: u64, cycles: u64) {
        (**self).idle_skipped(cpu, laps, instructions, cycles);
    }

    #[inline(always)]
    fn trap<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        (**self).trap(cpu, bus)
    }
}

/// Both hooks, the first one first; either can stop the run.
impl<H1: Hooks, H2: Hooks> Hooks for (H1, H2) {
    const PASSIVE: bool = H1::PASSIVE && H2::PASSIVE;

    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        self.0.may_skip_idle() && self.1.may_skip_idle()
    }

    #[inline(always)]
    fn instruction_bound(&self) -> u64 {
        self.0.instruction_bound().min(self.1.instruction_bound())
    }

    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        match self.0.before_instruction(cpu, bus) {
            Control::Stop => Control::Stop,
            Control::Continue => self.1.before_instruction(cpu, bus),
        }
    }

    #[inline(always)]
    fn after_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        self.0.after_instruction(cpu, bus, pc, opcode);
        self.1.after_instruction(cpu, bus, pc, opcode);
    }

    #[inline(always)]
    fn after_probed_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B, pc: u16, opcode: u8) {
        self.0.after_probed_instruction(cpu, bus, pc, opcode);
        self.1.after_probed_instruction(cpu, bus, pc, opcode);
    }

    #[inline(always)]
    fn interrupt<B: Bus>(&mut self, cpu: &Cpu, bus: &B, kind: Interrupt) {
        self.0.interrupt(cpu, bus, kind);
        self.1.interrupt(cpu, bus, kind);
    }

    #[inline(always)]
    fn idle_skipped(&mut self, cpu: &Cpu, laps: u64, instructions: u64, cycles: u64) {
        self.0.idle_skipped(cpu, laps, instructions, cycles);
        self.1.idle_skipped(cpu, laps, instructions, cycles);
    }

    #[inline(always)]
    fn trap<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        // Both see the trap even if the first one stops.
        let first = self.0.trap(cpu, bus);
        let second = self.1.trap(cpu, bus);
        if first == Control::Stop || second == Control::Stop {
            Control::Stop
        } else {
            Control::Continue
        }
    }
}

/// Execution breakpoints: the run stops before an instruction at a marked
/// address. A bitmap of the whole address space (8 KiB), so the check is one
/// load and a bit test. To go on from a breakpoint, execute one
/// [`Cpu::step`] before running again.
#[derive(Clone, PartialEq, Eq)]
pub struct Breakpoints {
    bits: Box<[u64; 1024]>,
    count: usize,
}

impl Breakpoints {
    /// No breakpoint set.
    #[must_use]
    pub fn new() -> Breakpoints {
        Breakpoints {
            bits: Box::new([0; 1024]),
            count: 0,
        }
    }

    /// Marks `address`; returns false if it was already marked.
    pub fn insert(&mut self, address: u16) -> bool {
        let (word, bit) = Self::slot(address);
        let fresh = self.bits[word] & bit == 0;
        self.bits[word] |= bit;
        self.count += usize::from(fresh);
        fresh
    }

    /// Unmarks `address`; returns false if it was not marked.
    pub fn remove(&mut self, address: u16) -> bool {
        let (word, bit) = Self::slot(address);
        let present = self.bits[word] & bit != 0;
        self.bits[word] &= !bit;
        self.count -= usize::from(present);
        present
    }

    /// True if `address` is marked.
    #[inline(always)]
    #[must_use]
    pub fn contains(&self, address: u16) -> bool {
        let (word, bit) = Self::slot(address);
        self.bits[word] & bit != 0
    }

    /// How many addresses are marked.
    #[must_use]
    pub fn len(&self) -> usize {
        self.count
    }

    #[inline(always)]
    fn slot(address: u16) -> (usize, u64) {
        (usize::from(address >> 6), 1 << (address & 63))
    }
}

impl Default for Breakpoints {
    fn default() -> Breakpoints {
        Breakpoints::new()
    }
}

impl core::fmt::Debug for Breakpoints {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let marked = (0..=u16::MAX).filter(|&address| self.contains(address));
        f.debug_set()
            .entries(marked.map(|address| format!("${address:04X}")))
            .finish()
    }
}

impl Hooks for Breakpoints {
    /// A bit test of the PC: an idle loop that passes no marked address
    /// may be skipped.
    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        true
    }

    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, _bus: &B) -> Control {
        if self.contains(cpu.pc) {
            Control::Stop
        } else {
            Control::Continue
        }
    }
}

/// Writes one line per instruction to `W`: address, bytes, disassembly,
/// registers before the instruction, and the cycle at which it starts:
///
/// ```text
/// 0400  A9 01     LDA #$01        A=00 X=00 Y=00 S=FD P=nv-bdIzc cycle=7
/// ```
///
/// Interrupt sequences get a line of their own (`IRQ   -> $F000 ...`, with the
/// registers after the sequence and the cycle it began at). The
/// first write error ends the run; [`Tracer::finish`] returns it.
#[derive(Debug)]
pub struct Tracer<W: Write> {
    out: W,
    error: Option<std::io::Error>,
}

impl<W: Write> Tracer<W> {
    /// Traces into `out` (wrap files in a `BufWriter`).
    pub fn new(out: W) -> Tracer<W> {
        Tracer { out, error: None }
    }

    /// Flushes what was traced so far (a debugger does as each run ends,
    /// so that a writer that cannot take it fails at that run, not at a
    /// later one or at [`Tracer::finish`]). A failure counts as the first
    /// write error: the trace's next instruction stops the run again.
    ///
    /// # Errors
    /// The first error `out` returned, now or before (its kind and text).
    pub fn flush(&mut self) -> std::io::Result<()> {
        if self.error.is_none()
            && let Err(error) = self.out.flush()
        {
            self.error = Some(error);
        }
        match &self.error {
            Some(error) => Err(std::io::Error::new(error.kind(), error.to_string())),
            None => Ok(()),
        }
    }

    /// Flushes and returns the writer, or the first write error.
    ///
    /// # Errors
    /// The first error `out` returned.
    pub fn finish(mut self) -> std::io::Result<W> {
        if let Some(error) = self.error.take() {
            return Err(error);
        }
        self.out.flush()?;
        Ok(self.out)
    }

    fn registers(cpu: &Cpu) -> String {
        format!(
            "A={:02X} X={:02X} Y={:02X} S={:02X} P={}",
            cpu.a,
            cpu.x,
            cpu.y,
            cpu.s,
            flags_text(cpu.p())
        )
    }

    fn emit(&mut self, line: core::fmt::Arguments<'_>) -> Control {
        if self.error.is_some() {
            return Control::Stop;
        }
        match writeln!(self.out, "{line}") {
            Ok(()) => Control::Continue,
            Err(error) => {
                self.error = Some(error);
                Control::Stop
            }
        }
    }
}

/// One trace line for the instruction at the CPU's PC (what [`Tracer`]
/// writes), for callers that trace by other means.
#[must_use]
pub fn trace_line<B: Bus>(cpu: &Cpu, bus: &B) -> String {
    let insn = isa::Instruction::decode_with(cpu.pc, |address| bus.peek(address));
    let bytes: Vec<String> = (0..u16::from(insn.len()))
        .map(|offset| format!("{:02X}", bus.peek(cpu.pc.wrapping_add(offset))))
        .collect();
    format!(
        "{:04X}  {:<8}  {:<14}  {} cycle={}",
        cpu.pc,
        bytes.join(" "),
        insn.to_string(),
        Tracer::<std::io::Sink>::registers(cpu),
        cpu.cycles()
    )
}

impl<W: Write> Hooks for Tracer<W> {
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        let line = trace_line(cpu, bus);
        self.emit(format_args!("{line}"))
    }

    fn interrupt<B: Bus>(&mut self, cpu: &Cpu, _bus: &B, kind: Interrupt) {
        let name = match kind {
            Interrupt::Irq => "IRQ",
            Interrupt::Nmi => "NMI",
        };
        let registers = Self::registers(cpu);
        // The run notices a failed write at the next instruction.
        // The cycle at which the 7-cycle sequence began, as instruction
        // lines give theirs.
        let _ = self.emit(format_args!(
            "{name:<4}  -> ${:04X}{:<18}{registers} cycle={}",
            cpu.pc,
            "",
            cpu.cycles() - 7
        ));
    }
}
