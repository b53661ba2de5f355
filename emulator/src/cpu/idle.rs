//! Idle-loop skipping: when the program goes round a loop that can only
//! repeat itself until a device acts, the run advances whole iterations at
//! once, counting their cycles and instructions as if it had run them.
//!
//! # Why it is exact
//!
//! A probe runs real instructions (nothing is executed twice or undone)
//! through [`ProbeBus`], which passes every call on and notes whether any of
//! them could have changed anything: a read of something other than plain
//! memory ([`Bus::is_plain_memory`]: no side effect, and a value only the
//! CPU's own writes change), or a write that is not a plain store
//! ([`Bus::is_plain_store`]) of the value already there. When the PC comes
//! back to where the probe started, with every register and flag
//! byte-for-byte as it was and nothing but plain reads and such stores in
//! between (a JSR's return address pushed where the last lap pushed it),
//! memory is as it was when the lap began, so the next iteration would
//! start from the same state and read the same memory, which nothing can
//! have changed; it would take the same path, the same accesses and the
//! same `C` cycles and `I` instructions; and so would every iteration after
//! it, as long as none of their interrupt polls could find anything. The
//! polls are the only way the outside world reaches the CPU, so the skip is
//! bounded by [`Bus::quiet_until`] (every instruction of the skipped
//! iterations ends at or before it, so each of their polls would have been
//! skipped too) and by the run's limit (every instruction of them ends
//! before it, so the run would not have stopped among them). The state
//! after `k` skipped iterations is then the state now with `k * C` more
//! cycles and `k * I` more instructions, which is what the skip produces.
//!
//! Skipping is off with any hook that is not [`Hooks::PASSIVE`] (tracing
//! sees every instruction) unless the hooks answer from the registers and
//! memory alone ([`Hooks::may_skip_idle`]: breakpoints, a debugger's
//! watchpoints). Such hooks are asked before every instruction the probe
//! runs, as the run would ask them, and once more at the lap's end (a
//! watchpoint the lap's last access hit stops there); a lap they let run
//! they would let run every time, since every lap sees the same registers
//! and memory, so skipping it changes nothing they would have seen. The
//! skip also stops short of the hooks' [`Hooks::instruction_bound`], and
//! is told to them ([`Hooks::idle_skipped`]: the laps skipped, each the
//! lap they just saw), so hooks that count (a profiler) count every lap.
//! It is
//! off in [`Cpu::step`],
//! off for a bus that does not vouch for its memory (the default), and can
//! be switched off with [`Cpu::set_idle_skip`] (the equivalence test runs a
//! whole session both ways and compares everything).
//!
//! # Cost
//!
//! A probe gives up at the first write that changes memory or device read
//! (the program is at work) or after [`BUDGET`] instructions; probes come [`MIN_GAP`] cycles
//! after a success and back off to every 64K cycles while the program is
//! busy, so code that never idles pays almost nothing. An RTI that goes
//! back into the loop last found (an interrupt-driven program returning to
//! its wait) probes at once, without slowing the schedule down if the
//! program has work first. The run loop itself only compares its cycle
//! counter with the earlier of the run's limit and the next probe, a
//! comparison it makes anyway, and leaves its inner loop at an RTI.

use super::{Cpu, JAM, NO_POLL, POLLED, Stop, TRAP};
use crate::bus::{Bus, Interrupts};
use crate::hooks::{Control, Hooks};

/// Cycles from a success (or a skip) to the next probe.
const MIN_GAP: u64 = 128;
/// The longest wait between probes while nothing is found.
const MAX_GAP: u64 = 1 << 16;
/// The longest loop a probe recognises, in instructions.
const MAX_LOOP: usize = 32;
/// Instructions one probe may run before giving up.
const BUDGET: usize = 2 * MAX_LOOP;
/// No skip carries the cycle counter past this: a host that runs "forever"
/// (a limit of `u64::MAX`) keeps room for the counter to go on counting.
const CYCLE_CAP: u64 = u64::MAX >> 2;

/// When to look for an idle loop next, and what skipping saved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct IdleSkip {
    /// Skipping is allowed (see [`Cpu::set_idle_skip`]).
    pub(super) enabled: bool,
    /// The cycle from which the next probe may run.
    pub(super) next_probe: u64,
    /// The wait after the next failed probe.
    gap: u64,
    /// Cycles advanced by skipping rather than by running.
    pub(super) skipped_cycles: u64,
    /// The addresses of the instructions of the idle loop last found.
    lap: [u16; MAX_LOOP],
    lap_len: usize,
    /// The coming probe is a look on the way back from a handler.
    woken: bool,
}

impl IdleSkip {
    pub(super) const fn new() -> IdleSkip {
        IdleSkip {
            enabled: true,
            next_probe: 0,
            gap: MIN_GAP,
            skipped_cycles: 0,
            lap: [0; MAX_LOOP],
            lap_len: 0,
            woken: false,
        }
    }

    /// Whether `pc` is an instruction of the idle loop last found.
    fn returns_to_loop(&self, pc: u16) -> bool {
        self.lap[..self.lap_len].contains(&pc)
    }

    fn found(&mut self, now: u64) {
        self.woken = false;
        self.gap = MIN_GAP;
        self.next_probe = now.saturating_add(MIN_GAP);
    }

    fn missed(&mut self, now: u64) {
        if self.woken {
            // Back from a handler with work to do: the program goes back
            // to its loop when done, so look again soon.
            self.woken = false;
            self.gap = MIN_GAP;
        }
        self.next_probe = now.saturating_add(self.gap);
        self.gap = (self.gap * 2).min(MAX_GAP);
    }
}

/// Everything that decides what the next instruction does, apart from
/// memory: the registers and the flags as the CPU keeps them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct LoopState {
    a: u8,
    x: u8,
    y: u8,
    s: u8,
    pc: u16,
    n: u8,
    z: u8,
    c: bool,
    vdi: u8,
    nmi_line: bool,
}

/// A bus that passes everything on and notes whether an access could have
/// changed anything or read anything that can change.
struct ProbeBus<'a, B> {
    bus: &'a mut B,
    clean: bool,
}

impl<B: Bus> ProbeBus<'_, B> {
    /// A write that leaves memory as it was: plain RAM that holds `value`
    /// already.
    #[inline(always)]
    fn stores_nothing_new(&self, address: u16, value: u8) -> bool {
        self.bus.is_plain_store(address) && self.bus.peek(address) == value
    }
}

impl<B: Bus> Bus for ProbeBus<'_, B> {
    #[inline(always)]
    fn fetch(&mut self, address: u16, cycle: u64) -> u8 {
        self.clean &= self.bus.is_plain_memory(address);
        self.bus.fetch(address, cycle)
    }

    #[inline(always)]
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        self.clean &= self.bus.is_plain_memory(address);
        self.bus.read(address, cycle)
    }

    #[inline(always)]
    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.clean &= self.stores_nothing_new(address, value);
        self.bus.write(address, value, cycle);
    }

    #[inline(always)]
    fn write_zp_stack(&mut self, address: u16, value: u8, cycle: u64) {
        self.clean &= self.stores_nothing_new(address, value);
        self.bus.write_zp_stack(address, value, cycle);
    }

    #[inline(always)]
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        self.clean &= self.bus.is_plain_memory(address);
        self.bus.dummy_read(address, cycle);
    }

    #[inline(always)]
    fn peek(&self, address: u16) -> u8 {
        self.bus.peek(address)
    }

    #[inline(always)]
    fn poll(&mut self, cycle: u64) -> Interrupts {
        self.bus.poll(cycle)
    }

    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        self.bus.quiet_until()
    }

    #[inline(always)]
    fn is_plain_memory(&self, address: u16) -> bool {
        self.bus.is_plain_memory(address)
    }

    #[inline(always)]
    fn is_plain_store(&self, address: u16) -> bool {
        self.bus.is_plain_store(address)
    }

    #[inline(always)]
    fn stop_requested(&self) -> bool {
        self.bus.stop_requested()
    }
}

impl Cpu {
    fn loop_state(&self) -> LoopState {
        LoopState {
            a: self.a,
            x: self.x,
            y: self.y,
            s: self.s,
            pc: self.pc,
            n: self.n,
            z: self.z,
            c: self.c,
            vdi: self.vdi,
            nmi_line: self.nmi_line,
        }
    }

    /// Runs instructions (at most [`BUDGET`], and not past `until` or an
    /// interrupt) looking for an idle loop, and skips the iterations it may
    /// when one is found. Returns the stop that ends the run (a JAM, or
    /// the hooks'), if any. Never inlined, and called on a copy of the
    /// run's CPU, so that the run loop keeps its registers.
    ///
    /// After an RTI (`returned`) it looks only if the RTI went back into
    /// the idle loop last found, where an interrupt-driven program waits
    /// again once its handler is done; a failure then does not slow the
    /// probes down.
    #[inline(never)]
    pub(super) fn probe_idle<B: Bus, H: Hooks>(
        &mut self,
        bus: &mut B,
        until: u64,
        returned: bool,
        hooks: &mut H,
    ) -> Option<Stop> {
        if returned {
            if !self.idle.returns_to_loop(self.pc) {
                return None;
            }
            self.idle.woken = true;
        }
        if !bus.is_plain_memory(self.pc) {
            // Code outside plain memory (or a bus that vouches for none):
            // no lap can be clean.
            self.idle.missed(self.cycles);
            return None;
        }
        let mut probe = ProbeBus { bus, clean: true };
        let mut start = (self.loop_state(), self.cycles, self.instructions);
        let mut lap = [0; MAX_LOOP];
        lap[0] = self.pc;
        let mut window = 0;
        for _ in 0..BUDGET {
            if self.cycles >= until || self.nmi_pending || self.irq_pending {
                break;
            }
            if !H::PASSIVE && hooks.before_instruction(self, &*probe.bus) == Control::Stop {
                return Some(Stop::Hook { pc: self.pc });
            }
            let pc = self.pc;
            let (flow, opcode) = self.instruction(&mut probe);
            if flow & JAM != 0 {
                return Some(Stop::Jam {
                    pc: self.pc,
                    opcode: probe.bus.peek(self.pc),
                });
            }
            if !H::PASSIVE {
                hooks.after_probed_instruction(self, &*probe.bus, pc, opcode);
            }
            if !H::PASSIVE && flow & TRAP != 0 && hooks.trap(self, &*probe.bus) == Control::Stop {
                return Some(Stop::Trap { pc: self.pc });
            }
            // BRK's sequence polled for itself (NO_POLL).
            if flow & (POLLED | NO_POLL) != 0
                && (self.nmi_pending || self.irq_pending || probe.bus.stop_requested())
            {
                break;
            }
            if !probe.clean {
                // A change to memory or a device read: the program is at work, not
                // idling. Cheap to find out, so the next probe comes soon.
                break;
            }
            window += 1;
            if self.pc == start.0.pc && self.loop_state() == start.0 {
                // The hooks once more, before the lap repeats: a watch the
                // lap's last access hit stops here, not laps later.
                if !H::PASSIVE && hooks.before_instruction(self, &*probe.bus) == Control::Stop {
                    return Some(Stop::Hook { pc: self.pc });
                }
                let cycles = self.cycles - start.1;
                let instructions = self.instructions - start.2;
                (self.idle.lap, self.idle.lap_len) = (lap, window);
                let until_count = hooks.instruction_bound();
                let laps =
                    self.skip_iterations(probe.bus, until, until_count, cycles, instructions);
                if !H::PASSIVE && laps > 0 {
                    hooks.idle_skipped(self, laps, instructions, cycles);
                }
                return None;
            }
            if self.pc == start.0.pc || window == MAX_LOOP {
                // Back with other registers (the first lap after entering
                // a loop), or no loop through here: look from here.
                start = (self.loop_state(), self.cycles, self.instructions);
                lap[0] = self.pc;
                window = 0;
            } else {
                lap[window] = self.pc;
            }
        }
        self.idle.missed(self.cycles);
        None
    }

    /// Advances as many whole `cycles`-long iterations as end before
    /// `until` and no later than the bus's quiet horizon, leaving the
    /// instruction count at most `until_count`. Returns how many it
    /// advanced.
    fn skip_iterations<B: Bus>(
        &mut self,
        bus: &B,
        until: u64,
        until_count: u64,
        cycles: u64,
        instructions: u64,
    ) -> u64 {
        let last_end = until
            .saturating_sub(1)
            .min(bus.quiet_until())
            .min(CYCLE_CAP);
        let by_count = until_count.saturating_sub(self.instructions) / instructions.max(1);
        let laps = (last_end.saturating_sub(self.cycles) / cycles).min(by_count);
        if laps == 0 {
            self.idle.missed(self.cycles);
            return 0;
        }
        self.cycles += laps * cycles;
        self.instructions += laps * instructions;
        self.idle.skipped_cycles += laps * cycles;
        self.idle.found(self.cycles);
        laps
    }
}
