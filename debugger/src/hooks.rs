//! The CPU hooks that find where to stop, and the bus that watches memory.
//!
//! A watchpoint is found by [`WatchBus`], which passes every access on to
//! the board and notes the first one a watchpoint covers, and has the
//! board end the run at that instruction's end
//! ([`Board::request_stop`]): a watch stops just after the instruction
//! that made the access, with its effect seen, and no hook looks for it
//! before every instruction.
//!
//! Nothing that never stops costs more than a bit test where it could:
//! breakpoints are a bitmap of the PCs they may stop at, tested once per
//! instruction (the breakpoint itself, its command or a condition, is
//! looked at only there); watchpoints are two bitmaps of the addresses
//! read or written that they cover, tested on reads only if some watch
//! reads, on writes only if some watch writes. Both answer from the PC,
//! registers and memory alone, so an idle loop that passes no breakpoint
//! and touches no watched byte is still skipped as the plain run skips it
//! ([`emulator::Hooks::may_skip_idle`]).

use std::cell::Cell;

use emulator::board::Board;
use emulator::{Breakpoints, Bus, Control, Cpu, Hooks, Interrupts};

use crate::points::Watch;

/// The addresses watchpoints cover, by kind of access: a bit per address.
pub(crate) struct Watched {
    /// Addresses some watch stops reads of.
    reads: Breakpoints,
    /// Addresses some watch stops writes of.
    writes: Breakpoints,
    /// The blocks of `reads` ([`block`]).
    read_blocks: u64,
    /// The blocks of `writes`.
    write_blocks: u64,
}

/// The 1 KiB block of `address`, as a bit of a block mask: a mask of the
/// blocks that hold a marked address is tested (in a register) before the
/// bitmap itself, so that an address far from every point costs a shift
/// and a test, no load.
#[inline(always)]
pub(crate) fn block(address: u16) -> u64 {
    1 << (address >> 10)
}

/// Whether `address`'s block is in `blocks`.
#[inline(always)]
pub(crate) fn in_blocks(blocks: u64, address: u16) -> bool {
    blocks & (1 << (address >> 10)) != 0
}

impl Watched {
    /// The blocks of the addresses watched for reads, and for writes.
    pub(crate) fn blocks(&self) -> (u64, u64) {
        (self.read_blocks, self.write_blocks)
    }

    /// The tables of `watches`.
    pub(crate) fn new(watches: &[Option<Watch>]) -> Watched {
        let mut table = Watched {
            reads: Breakpoints::new(),
            writes: Breakpoints::new(),
            read_blocks: 0,
            write_blocks: 0,
        };
        for watch in watches.iter().flatten() {
            for address in watch.start..=watch.end {
                if watch.kind.covers(false) {
                    table.reads.insert(address);
                    table.read_blocks |= block(address);
                }
                if watch.kind.covers(true) {
                    table.writes.insert(address);
                    table.write_blocks |= block(address);
                }
            }
        }
        table
    }

    /// Whether some watch covers reads, and whether some covers writes.
    pub(crate) fn kinds(&self) -> (bool, bool) {
        (self.reads.len() > 0, self.writes.len() > 0)
    }
}

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
    /// Where they are: only an access the tables mark looks further.
    pub(crate) watched: &'a Watched,
    pub(crate) hit: &'a Cell<Option<Access>>,
    /// The blocks holding an address watched for reads ([`blocks`]).
    pub(crate) read_blocks: u64,
    /// The blocks holding an address watched for writes.
    pub(crate) write_blocks: u64,
}

impl WatchBus<'_> {
    #[inline(always)]
    fn read_seen(&mut self, address: u16, value: u8) {
        if in_blocks(self.read_blocks, address) && self.watched.reads.contains(address) {
            self.note(address, value, false);
        }
    }

    #[inline(always)]
    fn write_seen(&mut self, address: u16, value: u8) {
        if in_blocks(self.write_blocks, address) && self.watched.writes.contains(address) {
            self.note(address, value, true);
        }
    }

    /// Notes the first access a watch covers, and has the board end the
    /// run at this instruction's end ([`Board::request_stop`]): the hooks
    /// need not look for it before every instruction.
    #[cold]
    #[inline(never)]
    fn note(&mut self, address: u16, value: u8, write: bool) {
        if let Some(hit) = self.hit.get() {
            // A read-modify-write instruction (INC, ASL...) writes the byte
            // it read, then the result: the byte it leaves is the one to
            // tell, not the NMOS 6502's dummy first write.
            if write && hit.write && hit.address == address {
                self.hit.set(Some(Access { value, ..hit }));
            }
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
            self.board.request_stop();
        }
    }
}

impl Bus for WatchBus<'_> {
    // The instruction stream is not the program reading data: a read
    // watch stops at a load from its bytes, not at running code there
    // (and the opcode fetch, every instruction's, costs no test).
    #[inline(always)]
    fn fetch(&mut self, address: u16, cycle: u64) -> u8 {
        self.board.fetch(address, cycle)
    }

    #[inline(always)]
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        let value = self.board.read(address, cycle);
        self.read_seen(address, value);
        value
    }

    #[inline(always)]
    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.board.write(address, value, cycle);
        self.write_seen(address, value);
    }

    // Page zero and the stack keep the board's fast path.
    #[inline(always)]
    fn read_zp_stack(&mut self, address: u16, cycle: u64) -> u8 {
        let value = self.board.read_zp_stack(address, cycle);
        self.read_seen(address, value);
        value
    }

    #[inline(always)]
    fn write_zp_stack(&mut self, address: u16, value: u8, cycle: u64) {
        self.board.write_zp_stack(address, value, cycle);
        self.write_seen(address, value);
    }

    // A read whose value the CPU ignores is not the program reading: it
    // still reaches the devices, but stops nothing.
    #[inline(always)]
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        self.board.dummy_read(address, cycle);
    }

    #[inline(always)]
    fn peek(&self, address: u16) -> u8 {
        self.board.peek(address)
    }

    #[inline(always)]
    fn poll(&mut self, cycle: u64) -> Interrupts {
        self.board.poll(cycle)
    }

    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        self.board.quiet_until()
    }

    #[inline(always)]
    fn is_plain_memory(&self, address: u16) -> bool {
        self.board.is_plain_memory(address)
    }

    #[inline(always)]
    fn is_plain_store(&self, address: u16) -> bool {
        self.board.is_plain_store(address)
    }

    #[inline(always)]
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

/// Why [`Lean`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LeanStop {
    /// At a PC a breakpoint may stop at: which one, if any, is asked
    /// there.
    Place,
    /// The count to stop at.
    Count,
    /// A watchpoint: the access, made by the instruction at `pc`.
    Watch { access: Access, pc: u16 },
}

/// The hooks of a run that only breakpoints, watchpoints (with `WATCH`)
/// and a count (with `COUNT`) can stop: a bit test of the PC per
/// instruction (and a comparison of the count, with `COUNT`, and the PC
/// noted, with `WATCH`: the watching bus ends the run itself, through the
/// board), nothing else. A run to a breakpoint,
/// a step back's re-run, a search for a hit all run here; `next`,
/// `finish` and tracing use [`Look`]. A run with no count to stop at
/// (`continue`) makes no comparison: its idle skip and its end are bound
/// by the cycle the run is given.
pub(crate) struct Lean<'a, const WATCH: bool, const COUNT: bool> {
    /// Every PC a breakpoint may stop at.
    pub(crate) places: &'a Breakpoints,
    /// The blocks that hold one ([`blocks`]): tested first.
    pub(crate) place_blocks: u64,
    /// The count of the run's first instruction: a breakpoint there is
    /// where the last stop was, so it does not stop again.
    pub(crate) start: u64,
    /// Stop before the instruction with this count.
    pub(crate) stop_at: u64,
    /// The PC of the instruction last let run (with `WATCH`).
    pub(crate) last_pc: u16,
    /// Why it stopped.
    pub(crate) stopped: Option<LeanStop>,
    /// No breakpoint counts its hits or logs: an idle loop may be skipped.
    pub(crate) skip_idle: bool,
}

impl<const WATCH: bool, const COUNT: bool> Hooks for Lean<'_, WATCH, COUNT> {
    // Every answer comes from the PC, memory and the bus's note, except
    // the count, which bounds the skip, and a breakpoint's hits, which
    // forbid it.
    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        self.skip_idle
    }

    #[inline(always)]
    fn instruction_bound(&self) -> u64 {
        if COUNT { self.stop_at } else { u64::MAX }
    }

    #[inline(always)]
    fn before_instruction<B: Bus>(&mut self, cpu: &Cpu, _bus: &B) -> Control {
        if WATCH {
            // A watch hit ends the run through the board, just after the
            // instruction: its PC is the last one noted here.
            self.last_pc = cpu.pc;
        }
        if COUNT && cpu.instructions() >= self.stop_at {
            self.stopped = Some(LeanStop::Count);
            return Control::Stop;
        }
        if in_blocks(self.place_blocks, cpu.pc)
            && self.places.contains(cpu.pc)
            && cpu.instructions() != self.start
        {
            self.stopped = Some(LeanStop::Place);
            return Control::Stop;
        }
        Control::Continue
    }
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
    /// No breakpoint counts its hits or logs: an idle loop may be skipped.
    pub(crate) skip_idle: bool,
}

impl<M: Fn(&Cpu, &dyn Fn(u16) -> u8) -> Option<usize>> Hooks for Look<'_, M> {
    // Every answer comes from the PC, S, memory and the watch the bus
    // noted (all the same on every lap of an idle loop), except the count
    // to stop at, which bounds the skip. A point with a count of its own
    // (a hit count, a log point) says no here.
    #[inline(always)]
    fn may_skip_idle(&self) -> bool {
        self.skip_idle
    }

    #[inline(always)]
    fn instruction_bound(&self) -> u64 {
        self.at_count.unwrap_or(u64::MAX)
    }

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
