//! The hooks that count: every instruction's cycles by address, each
//! conditional branch taken and not taken, the shadow call stack, and each
//! robot command from its arrival to `CMD_DONE`.
//!
//! An instruction is counted when it has run ([`Hooks::after_instruction`],
//! which hands over the opcode the CPU fetched): its cycles are the cycle
//! counter's advance since the hooks' look before it, and the registers
//! say where it went (a branch taken or not, a call made) and what it left
//! S at. Nothing is read from memory per instruction.
//!
//! An idle loop the emulator skips is counted as if it had run: the probe
//! that found it ran one lap under these hooks, and
//! [`Hooks::idle_skipped`] says how many more laps the skip stands for,
//! so the last lap's instructions (kept in a ring of the last
//! [`RING`] instructions the probes ran: only theirs, so the run's other
//! instructions pay nothing for it) are counted that many times more, to
//! their addresses, lines, routines and branches.

use emulator::{Breakpoints, Bus, Control, Cpu, Hooks, Interrupt};

use crate::flow::{self, Flow};
use crate::stack::{Routine, Stack};

/// The longest idle loop the emulator skips is 32 instructions.
const RING: usize = 64;

/// Addresses of the ROM the profiler watches for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Places {
    /// Where a whole command has arrived and the ROM looks for its
    /// handler (the reference ROM's `dispatch`).
    pub arrival: Option<u16>,
    /// Where a command is done (`CMD_DONE`, and the ROM's own
    /// `cmd_done` its built-in commands jump to).
    pub done: Vec<u16>,
    /// The control loop's hook (`HOOK_LOOP`): a command that comes back
    /// to it without passing `CMD_DONE` (`/1R`) ends there.
    pub main_loop: Option<u16>,
    /// The command's length and buffer (`CMDLEN`, `CMDBUF`).
    pub command_length: u16,
    /// The command's letter and arguments.
    pub command_buffer: u16,
}

impl Places {
    /// The places of the ROM `robot` runs: its labels `dispatch`,
    /// `CMD_DONE` and `cmd_done`, its loop hook, and the reference ROM's
    /// command buffer.
    #[must_use]
    pub fn of(robot: &romlib::VirtualScorpion) -> Places {
        let labels = robot.labels();
        let find = |name: &str| labels.iter().find(|(_, n)| n == name).map(|(at, _)| *at);
        let mut done: Vec<u16> = ["CMD_DONE", "cmd_done"]
            .iter()
            .filter_map(|name| find(name))
            .collect();
        if done.is_empty() {
            done.push(romlib::symbols::CMD_DONE);
        }
        Places {
            arrival: find("dispatch"),
            done,
            main_loop: Some(robot.hook_address(isa::objfmt::HookKind::Loop)),
            command_length: romlib::symbols::CMDLEN,
            command_buffer: romlib::symbols::CMDBUF,
        }
    }
}

/// Names for addresses: which label each address is under.
#[derive(Debug, Clone)]
pub(crate) struct Labels {
    /// The index into `names` of the label at or below each address, or
    /// `u32::MAX` for none.
    by_address: Vec<u32>,
    pub(crate) names: Vec<(u16, String)>,
    /// The other labels of an address `names` names once (`rec:` on the
    /// line after `cmd_q:`): a budget may name a routine by any of them.
    pub(crate) aliases: Vec<(u16, String)>,
}

impl Labels {
    /// `labels`: (address, name), in any order; the first name at an
    /// address wins, names starting `__` (the toolchain's) last.
    pub(crate) fn new(labels: &[(u16, String)]) -> Labels {
        let mut names: Vec<(u16, String)> = labels.to_vec();
        names.sort_by_key(|(at, name)| (*at, name.starts_with("__"), name.clone()));
        let mut aliases: Vec<(u16, String)> = Vec::new();
        let mut first: Option<&(u16, String)> = None;
        for label in &names {
            match first {
                Some(kept) if kept.0 == label.0 => {
                    if kept.1 != label.1 && !aliases.contains(label) {
                        aliases.push(label.clone());
                    }
                }
                _ => first = Some(label),
            }
        }
        names.dedup_by_key(|(at, _)| *at);
        let mut by_address = vec![u32::MAX; 0x1_0000];
        for (index, window) in names.iter().enumerate() {
            let start = usize::from(window.0);
            let end = names
                .get(index + 1)
                .map_or(0x1_0000, |(next, _)| usize::from(*next));
            let index = u32::try_from(index).unwrap_or(u32::MAX);
            for slot in &mut by_address[start..end] {
                *slot = index;
            }
        }
        Labels {
            by_address,
            names,
            aliases,
        }
    }

    #[inline(always)]
    pub(crate) fn of(&self, address: u16) -> u32 {
        self.by_address[usize::from(address)]
    }

    /// The addresses `label` (an index, or `u32::MAX` for none) names: its
    /// first and how many (up to the next label).
    pub(crate) fn span(&self, label: u32) -> (u16, u32) {
        let first = self.names.get(label as usize).map_or(0, |(at, _)| *at);
        let next = label.wrapping_add(1) as usize;
        let end = self
            .names
            .get(next)
            .map_or(0x1_0000, |(at, _)| u32::from(*at));
        (first, end.saturating_sub(u32::from(first)))
    }

    /// `address` named: `label`, `label+$offset`, or `$ADDR`.
    pub(crate) fn name(&self, address: u16) -> String {
        match self.names.get(self.of(address) as usize) {
            Some((at, name)) if *at == address => name.clone(),
            Some((at, name)) => format!("{name}+${:X}", address - at),
            None => format!("${address:04X}"),
        }
    }

    /// The label with index `label`.
    pub(crate) fn label(&self, label: u32) -> Option<&str> {
        self.names
            .get(label as usize)
            .map(|(_, name)| name.as_str())
    }
}

/// One robot command, from its arrival.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandRun {
    /// As sent: `/2A1`.
    pub text: String,
    /// The cycle it arrived at (the robot's time).
    pub arrival: u64,
    /// Cycles from its arrival to `CMD_DONE`; `None` if it never got
    /// there (`/1R`, or the run ended first).
    pub cycles: Option<u64>,
    /// Where it came from (a transcript's `file:line`), if the host said.
    pub origin: Option<String>,
}

/// An instruction that ran, as the ring keeps it.
#[derive(Debug, Clone, Copy, Default)]
struct Ran {
    /// Its cycles, saturated (an idle loop's instruction has a few).
    cycles: u32,
    pc: u16,
    next_pc: u16,
    opcode: u8,
    /// S as it left it (S before it follows for the instructions that
    /// push: `JSR` two bytes, `BRK` three).
    s_after: u8,
}

/// The profiler: [`Hooks`] that never stop a run and let idle loops be
/// skipped, counting everything. Turn it into a [`crate::Profile`] with
/// [`Profiler::finish`].
#[derive(Debug, Clone)]
pub struct Profiler {
    flows: [Flow; 256],
    /// Executions and cycles by address, side by side: one cache line
    /// for both at each instruction.
    pub(crate) by_address: Vec<[u64; 2]>,
    /// Conditional branches taken, by address.
    pub(crate) taken: Vec<u64>,
    /// Conditional branches not taken, by address.
    pub(crate) not_taken: Vec<u64>,
    /// The cycle the instruction about to run began at (the hooks' look
    /// before it).
    start: u64,
    /// The last look at a watched address: the instructions run before
    /// it and the PC. A look asked again for the same instruction (the
    /// idle probe's at a lap's end, then the run's) is not made twice.
    looked: Option<(u64, u16)>,
    ring: [Ran; RING],
    ring_next: usize,
    ring_len: usize,
    pub(crate) stack: Stack,
    pub(crate) labels: Labels,
    places: Places,
    /// Every address of `places`: one bit test per instruction.
    watched: Breakpoints,
    /// Calls, commands and stacks counted too (not for coverage alone).
    calls: bool,
    pub(crate) commands: Vec<CommandRun>,
    /// Laps of idle loops counted without running.
    pub(crate) skipped_laps: u64,
    /// The cycle the last instruction or interrupt sequence counted ended
    /// at (`u64::MAX` before any): frames still open at the end close
    /// there, not at a later time the machine idled or was stuck through
    /// without being counted.
    last_end: u64,
}

impl Profiler {
    /// A profiler for a robot whose ROM and images have `labels`
    /// ([`romlib::VirtualScorpion::labels`]) and whose ROM has `places`.
    #[must_use]
    pub fn new(labels: &[(u16, String)], places: Places) -> Profiler {
        let mut watched = Breakpoints::new();
        for &at in places
            .arrival
            .iter()
            .chain(&places.done)
            .chain(places.main_loop.iter())
        {
            watched.insert(at);
        }
        Profiler {
            watched,
            calls: true,
            flows: flow::table(),
            by_address: vec![[0; 2]; 0x1_0000],
            taken: vec![0; 0x1_0000],
            not_taken: vec![0; 0x1_0000],
            start: 0,
            looked: None,
            ring: [Ran::default(); RING],
            ring_next: 0,
            ring_len: 0,
            stack: Stack::new(),
            labels: Labels::new(labels),
            places,
            commands: Vec::new(),
            skipped_laps: 0,
            last_end: u64::MAX,
        }
    }

    /// A profiler for `robot` as it is now (its ROM and loaded images).
    #[must_use]
    pub fn for_robot(robot: &romlib::VirtualScorpion) -> Profiler {
        Profiler::new(&robot.labels(), Places::of(robot))
    }

    /// Counts executions by address and branches only, for coverage: no
    /// cycles, no call stack, no commands (faster; the profile's cycles
    /// and total stay 0).
    #[must_use]
    pub fn coverage_only(mut self) -> Profiler {
        self.calls = false;
        self.watched = Breakpoints::new();
        self
    }

    /// The end of a run of the CPU the hooks saw (the runner calls it).
    /// Every instruction is counted as it ends, so nothing is left to
    /// count: kept so that a caller need not know.
    pub fn end_run(&mut self, cpu: &Cpu) {
        let _ = cpu;
    }

    /// The host entered the routine at `target` as a `JSR` does, at cycle
    /// `now`, S at `s_before` before the return address was pushed (a
    /// routine-level test's call): its frame begins, a root of its own
    /// (no code of the robot's called it), and ends at its `RTS`.
    pub fn entered(&mut self, target: u16, s_before: u8, now: u64) {
        if self.calls {
            self.stack.entered(target, s_before, now);
        }
    }

    /// Says where the `index`th command seen came from (a transcript's
    /// `file:line`).
    pub fn set_origin(&mut self, index: usize, origin: String) {
        if let Some(run) = self.commands.get_mut(index) {
            run.origin = Some(origin);
        }
    }

    /// The commands seen so far.
    #[must_use]
    pub fn commands(&self) -> &[CommandRun] {
        &self.commands
    }

    /// Cycles counted so far.
    #[must_use]
    pub fn total_cycles(&self) -> u64 {
        // Every cycle counted is counted at an address: the sum is the
        // total (kept out of the per-instruction count).
        self.by_address.iter().map(|place| place[1]).sum()
    }

    /// Executions by address.
    pub(crate) fn counts(&self) -> Vec<u64> {
        self.by_address.iter().map(|place| place[0]).collect()
    }

    /// Cycles by address.
    pub(crate) fn cycles(&self) -> Vec<u64> {
        self.by_address.iter().map(|place| place[1]).collect()
    }

    /// Counts the instruction at `pc` (`opcode`) that has just run, its
    /// registers as it left them: the per-instruction work, inlined into
    /// the CPU's run loop, with what is rare (calls, returns) out of line.
    /// Returns its cycles (0 for coverage alone, which counts none).
    #[inline(always)]
    fn ran(&mut self, cpu: &Cpu, pc: u16, opcode: u8) -> u64 {
        let at = usize::from(pc);
        let flow = self.flows[usize::from(opcode)];
        if flow == Flow::Branch {
            if cpu.pc == pc.wrapping_add(2) {
                self.not_taken[at] += 1;
            } else {
                self.taken[at] += 1;
            }
        }
        if !self.calls {
            self.by_address[at][0] += 1;
            return 0;
        }
        let end = cpu.cycles();
        let cycles = end.saturating_sub(self.start);
        self.last_end = end;
        let place = &mut self.by_address[at];
        place[0] += 1;
        place[1] += cycles;
        self.stack.charge(pc, cycles, &self.labels);
        if !matches!(flow, Flow::Plain | Flow::Branch) {
            self.flowed(flow, cpu.pc, cpu.s, 1, end);
        }
        cycles
    }

    /// Counts `ran`, which took `cycles`, `times` times over, the last
    /// one ending at `end` (a skipped idle loop's laps).
    fn count(&mut self, ran: Ran, cycles: u64, times: u64, end: u64) {
        let at = usize::from(ran.pc);
        let cycles = cycles * times;
        self.last_end = end;
        let place = &mut self.by_address[at];
        place[0] += times;
        place[1] += cycles;
        let flow = self.flows[usize::from(ran.opcode)];
        if flow == Flow::Branch {
            if ran.next_pc == ran.pc.wrapping_add(2) {
                self.not_taken[at] += times;
            } else {
                self.taken[at] += times;
            }
        }
        if !self.calls {
            return;
        }
        self.stack.charge(ran.pc, cycles, &self.labels);
        self.flowed(flow, ran.next_pc, ran.s_after, times, end);
    }

    /// What an instruction of kind `flow`, which went to `next_pc`
    /// leaving S at `s_after`, did to the call stack, `times` over, ending
    /// at `end`. Its cycles are charged already (a `JSR`'s to its caller,
    /// an `RTS`'s to the routine it leaves).
    #[inline(never)]
    fn flowed(&mut self, flow: Flow, next_pc: u16, s_after: u8, times: u64, end: u64) {
        match flow {
            Flow::Plain | Flow::Branch => {}
            Flow::Call => self
                .stack
                .call(next_pc, s_after.wrapping_add(2), end, times),
            Flow::Return => self.stack.unwind(s_after, false, end),
            Flow::ReturnFromInterrupt | Flow::SetStack => {
                self.stack.unwind(s_after, true, end);
            }
            Flow::Break => self
                .stack
                .interrupt(Routine::Brk, s_after.wrapping_add(3), end),
        }
    }

    /// The instruction at the PC, a watched address, is about to run:
    /// looks unless it looked already for this very instruction.
    #[cold]
    #[inline(never)]
    fn look_once<B: Bus>(&mut self, cpu: &Cpu, bus: &B) {
        let this = (cpu.instructions(), cpu.pc);
        if self.looked == Some(this) {
            return;
        }
        self.looked = Some(this);
        self.look(cpu.pc, cpu.cycles(), bus);
    }

    /// A new instruction at `pc` is about to run at cycle `now`: a
    /// command arriving or done.
    #[cold]
    #[inline(never)]
    fn look<B: Bus>(&mut self, pc: u16, now: u64, bus: &B) {
        if self.places.arrival == Some(pc) {
            self.arrive(now, bus);
        } else if self.places.done.contains(&pc) {
            self.done(now, true);
        } else if self.places.main_loop == Some(pc) && self.stack.command.is_some() {
            self.done(now, false);
        }
    }

    #[cold]
    fn arrive<B: Bus>(&mut self, now: u64, bus: &B) {
        self.done(now, false);
        let count = bus.peek(self.places.command_length);
        let mut text = format!("/{count}");
        for offset in 0..u16::from(count.min(9)) {
            let byte = bus.peek(self.places.command_buffer.wrapping_add(offset));
            text.push(if byte.is_ascii_graphic() {
                char::from(byte)
            } else {
                '?'
            });
        }
        let index = u32::try_from(self.commands.len()).unwrap_or(u32::MAX);
        self.stack.command_begins(&text, index, now);
        self.commands.push(CommandRun {
            text,
            arrival: now,
            cycles: None,
            origin: None,
        });
    }

    #[cold]
    fn done(&mut self, now: u64, finished: bool) {
        if let Some(index) = self.stack.command {
            if let Some(run) = self.commands.get_mut(index as usize) {
                if finished {
                    run.cycles = Some(now.saturating_sub(run.arrival));
                }
            }
            self.stack.command_ends(now);
        }
    }

    /// Counts `laps` more laps of the last `instructions` instructions.
    #[cold]
    fn replay(&mut self, cpu: &Cpu, laps: u64, instructions: u64) {
        let len = usize::try_from(instructions).unwrap_or(usize::MAX);
        // The look the probe asked at the lap's end stands for the
        // instruction the run asks about next, after the skipped laps.
        if let Some((count, pc)) = self.looked {
            let skipped = laps.saturating_mul(instructions);
            if pc == cpu.pc && count == cpu.instructions().wrapping_sub(skipped) {
                self.looked = Some((cpu.instructions(), pc));
            }
        }
        if len == 0 || len > self.ring_len {
            // Not a lap these hooks saw (cannot happen with the
            // emulator's probe).
            return;
        }
        let first = (self.ring_next + RING - len) % RING;
        let lap: Vec<Ran> = (0..len).map(|i| self.ring[(first + i) % RING]).collect();
        let lap_cycles: u64 = lap.iter().map(|ran| u64::from(ran.cycles)).sum();
        // Calls made and ended within the lap cost a lap's share; the
        // clock they see starts where the skipped laps began.
        let mut clock = cpu.cycles().saturating_sub(laps * lap_cycles);
        for ran in lap {
            clock += u64::from(ran.cycles);
            self.count(ran, u64::from(ran.cycles), laps, clock);
        }
        self.skipped_laps += laps;
    }

    /// Ends every frame still open and turns the counts into a profile.
    #[must_use]
    pub fn finish(mut self, now: u64) -> crate::Profile {
        let end = self.last_end.min(now);
        self.stack.close(end);
        crate::Profile::from_profiler(&self)
    }
}

impl Hooks for Profiler {
    // It never stops a run, and counts the laps of a skipped idle loop
    // when told of them.
    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        true
    }

    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        if self.calls {
            self.start = cpu.cycles();
            if self.watched.contains(cpu.pc) {
                self.look_once(cpu, bus);
            }
        }
        Control::Continue
    }

    #[inline(always)]
    fn after_instruction<B: Bus>(&mut self, cpu: &Cpu, _bus: &B, pc: u16, opcode: u8) {
        self.ran(cpu, pc, opcode);
    }

    fn after_probed_instruction<B: Bus>(&mut self, cpu: &Cpu, _bus: &B, pc: u16, opcode: u8) {
        let cycles = self.ran(cpu, pc, opcode);
        self.ring[self.ring_next] = Ran {
            cycles: u32::try_from(cycles).unwrap_or(u32::MAX),
            pc,
            next_pc: cpu.pc,
            opcode,
            s_after: cpu.s,
        };
        self.ring_next = (self.ring_next + 1) % RING;
        self.ring_len = (self.ring_len + 1).min(RING);
    }

    fn interrupt<B: Bus>(&mut self, cpu: &Cpu, _bus: &B, kind: Interrupt) {
        let began = cpu.cycles().saturating_sub(7);
        let s_before = cpu.s.wrapping_add(3);
        let routine = match kind {
            Interrupt::Irq => Routine::Irq,
            Interrupt::Nmi => Routine::Nmi,
        };
        if !self.calls {
            return;
        }
        // The sequence's own seven cycles are the handler's, counted at
        // its first instruction (its address, so its line and label):
        // cycles by address add up to the total, as routines' do.
        self.by_address[usize::from(cpu.pc)][1] += 7;
        self.last_end = began + 7;
        self.stack.interrupt(routine, s_before, began);
        self.stack.charge(cpu.pc, 7, &self.labels);
    }

    fn idle_skipped(&mut self, cpu: &Cpu, laps: u64, instructions: u64, _cycles: u64) {
        self.replay(cpu, laps, instructions);
    }
}
