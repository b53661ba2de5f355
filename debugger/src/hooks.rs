//! The CPU hooks that find where to stop, and the bus that watches memory.
//!
//! A watchpoint is found by [`WatchBus`], which passes every access on to
//! the board and notes the first one a watchpoint covers; the hooks see
//! the note before the next instruction and stop there, so a watch stops
//! just after the instruction that made the access, with its effect seen.

use std::cell::Cell;

use emulator::board::Board;
use emulator::{Bus, Control, Cpu, Hooks, Interrupts};

use crate::points::Watch;

/// An access a watchpoint covered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Access {
    /// The watchpoint's index.
    pub watch: usize,
    /// The address accessed.
    pub address: u16,
    /// The byte read or written.
    pub value: u8,
    /// A write, not a read.
    pub write: bool,
}

/// The board, with watchpoints on its accesses.
pub(crate) struct WatchBus<'a> {
    pub(crate) board: &'a mut Board,
    pub(crate) watches: &'a [Option<Watch>],
    pub(crate) hit: &'a Cell<Option<Access>>,
}

impl WatchBus<'_> {
    #[inline]
    fn note(&self, address: u16, value: u8, write: bool) {
        if self.hit.get().is_some() {
            return;
        }
        let found = self
            .watches
            .iter()
            .position(|w| w.is_some_and(|w| w.hits(address, write)));
        if let Some(watch) = found {
            self.hit.set(Some(Access {
                watch,
                address,
                value,
                write,
            }));
        }
    }
}

impl Bus for WatchBus<'_> {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        let value = self.board.read(address, cycle);
        self.note(address, value, false);
        value
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.board.write(address, value, cycle);
        self.note(address, value, true);
    }

    // A read whose value the CPU ignores is not the program reading: it
    // still reaches the devices, but stops nothing.
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        self.board.dummy_read(address, cycle);
    }

    fn peek(&self, address: u16) -> u8 {
        self.board.peek(address)
    }

    fn poll(&mut self, cycle: u64) -> Interrupts {
        self.board.poll(cycle)
    }

    fn quiet_until(&self) -> u64 {
        self.board.quiet_until()
    }

    fn is_plain_memory(&self, address: u16) -> bool {
        self.board.is_plain_memory(address)
    }

    fn is_plain_store(&self, address: u16) -> bool {
        self.board.is_plain_store(address)
    }

    fn stop_requested(&self) -> bool {
        self.board.stop_requested()
    }
}

/// Why the hooks stopped the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Found {
    /// The instruction count to stop at was reached.
    Count,
    /// Breakpoint `index` (into the debugger's list).
    Breakpoint(usize),
    /// A watchpoint: the access, made by the instruction at `pc`.
    Watch { access: Access, pc: u16 },
    /// `next` came back from the subroutine.
    Returned,
    /// `finish`: the routine returned.
    Finished,
}

/// What the hooks look for. Breakpoints are matched by the debugger's
/// `matches` function (given the PC and the bus, it says which breakpoint
/// if any stops here); the rest are plain conditions.
pub(crate) struct Look<'a, M: Fn(&Cpu, &dyn Fn(u16) -> u8) -> Option<usize>> {
    /// Every PC a breakpoint may stop at: one bit test per instruction,
    /// and `breakpoint` asked only there.
    pub(crate) places: &'a emulator::Breakpoints,
    /// Which breakpoint, if any, stops at this PC.
    pub(crate) breakpoint: M,
    /// Stop before the instruction with this count (instructions run so
    /// far equal to it).
    pub(crate) at_count: Option<u64>,
    /// `next` over a `JSR`: stop back at this PC with this S.
    pub(crate) returning_to: Option<(u16, u8)>,
    /// `finish`: stop once S has risen to at least this.
    pub(crate) finish_at: Option<u8>,
    /// The watchpoint hit the bus noted.
    pub(crate) hit: &'a Cell<Option<Access>>,
    /// The first instruction of a resumed run: its breakpoint is where
    /// the last stop was, so it does not stop again.
    pub(crate) first: bool,
    /// The PC of the instruction last let run.
    pub(crate) last_pc: u16,
    /// What was found.
    pub(crate) found: Option<Found>,
}

impl<M: Fn(&Cpu, &dyn Fn(u16) -> u8) -> Option<usize>> Hooks for Look<'_, M> {
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, bus: &B) -> Control {
        let first = std::mem::replace(&mut self.first, false);
        // The watch first: it is about the instruction already run.
        let found = if let Some(access) = self.hit.take() {
            Some(Found::Watch {
                access,
                pc: self.last_pc,
            })
        } else if self.at_count.is_some_and(|n| cpu.instructions() >= n) {
            Some(Found::Count)
        } else if self.returning_to == Some((cpu.pc, cpu.s)) {
            Some(Found::Returned)
        } else if !first && self.finish_at.is_some_and(|s| cpu.s >= s) {
            Some(Found::Finished)
        } else if first || !self.places.contains(cpu.pc) {
            None
        } else {
            (self.breakpoint)(cpu, &|address| bus.peek(address)).map(Found::Breakpoint)
        };
        self.last_pc = cpu.pc;
        match found {
            Some(found) => {
                self.found = Some(found);
                Control::Stop
            }
            None => Control::Continue,
        }
    }
}
