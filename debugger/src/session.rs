//! The debugging session: the robot, the host's actions on it, and the
//! ways to run it.

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use emulator::{Cpu, Tracer};
use isa::objfmt::HookKind;
use romlib::VirtualScorpion;

use crate::Error;
use crate::checkpoints::{Checkpoint, Checkpoints};
use crate::expr::{Peeking, Register};
use crate::hooks::{Access, Found, Lean, LeanStop, Look, WatchBus, Watched};
use crate::points::{Breakpoint, PointOptions, Watch};
use crate::symbols::Symbols;

/// Builds the robot as it is at power-up with everything loaded: called
/// once, and again for a step back that no checkpoint serves (a robot
/// that cannot be copied, a target before the first checkpoint).
pub type MakeRobot = Box<dyn Fn() -> Result<VirtualScorpion, Error> + Send>;

/// Something the host did to the robot, kept to be done again.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// Bytes sent down the serial line.
    Send(Vec<u8>),
    /// The bumpers set (a bit per closed bumper).
    Bumpers(u8),
    /// A register or flag set by the user.
    Set(Register, u16),
    /// Bytes of RAM written by the user.
    Poke {
        /// Where the first goes.
        address: u16,
        /// The bytes.
        bytes: Vec<u8>,
    },
}

/// An event and where in the run it happened.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Done {
    /// Instructions run before it.
    instructions: u64,
    /// The robot's cycle then (checked on every re-run).
    cycle: u64,
    event: Event,
}

/// Why the robot stopped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Why {
    /// Breakpoint number `id` (from 1).
    Breakpoint {
        /// Its number.
        id: usize,
        /// What it is.
        point: Breakpoint,
    },
    /// Watchpoint number `id` saw an access, made by the instruction at
    /// `pc`.
    Watch {
        /// Its number.
        id: usize,
        /// The access.
        access: Access,
        /// The instruction that made it.
        pc: u16,
    },
    /// The steps asked for were done.
    Stepped,
    /// `finish`: the routine returned.
    Finished,
    /// The robot time given to the run ran out.
    Budget,
    /// Back in time, at the instruction asked for.
    Back,
    /// Paused by the user (Ctrl-C in the monitor) while it ran.
    Paused,
}

/// Where a run ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stopped {
    /// Why.
    pub why: Why,
    /// The PC (the next instruction to run).
    pub pc: u16,
    /// Robot cycles since the last stop.
    pub cycles: u64,
    /// Instructions since the last stop (negative after a step back).
    pub instructions: i64,
    /// What the robot sent the host meanwhile.
    pub received: Vec<u8>,
}

/// The debugger: the robot, the host's history, the points to stop at.
pub struct Debugger {
    make: MakeRobot,
    robot: VirtualScorpion,
    symbols: Symbols,
    /// The loaded images, for their source lines.
    images: Vec<linker::Image>,
    /// Where the images' source paths start: which files are the user's
    /// own, for the lines a user is shown ([`Debugger::source_of`]).
    source_root: std::path::PathBuf,
    breakpoints: Vec<Option<Breakpoint>>,
    /// Each breakpoint's condition, hit count and log message.
    options: Vec<PointOptions>,
    /// Each breakpoint's hits so far (where its condition held).
    hits: Vec<Cell<u64>>,
    /// What log points logged since the last look.
    logs: RefCell<Logs>,
    /// Set (by a signal handler) to pause a run between its slices.
    interrupt: Option<Arc<AtomicBool>>,
    watches: Vec<Option<Watch>>,
    /// What the host did, in order, up to now.
    done: Vec<Done>,
    /// After a step back: what the host had done further on, done again
    /// when the run gets there (until the host does something new).
    ahead: VecDeque<Done>,
    /// Where the last stop was: (cycle, instructions).
    last_stop: (u64, u64),
    /// Instructions run when the robot was handed over (no going back
    /// before them).
    power_up: u64,
    /// Copies of the robot taken as it ran, to re-run from.
    checkpoints: Checkpoints,
    trace: Option<Trace>,
}

/// The trace being written: the tracer, and what its writer saw go wrong.
struct Trace {
    /// Where it goes, as the user named it (for the error).
    name: String,
    tracer: Tracer<Box<dyn Write + Send>>,
    /// The first write error, noted by [`Noted`]: the tracer stops the run
    /// at it, and the run must say why instead of starting again.
    failed: Arc<Mutex<Option<String>>>,
}

/// A trace's writer that notes its first error where the debugger sees it.
struct Noted {
    out: Box<dyn Write + Send>,
    failed: Arc<Mutex<Option<String>>>,
}

impl Noted {
    fn note<T>(&self, result: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(error) = &result
            && let Ok(mut failed) = self.failed.lock()
        {
            failed.get_or_insert_with(|| error.to_string());
        }
        result
    }
}

impl Write for Noted {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let result = self.out.write(buf);
        self.note(result)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let result = self.out.flush();
        self.note(result)
    }
}

impl std::fmt::Debug for Debugger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Debugger")
            .field("robot", &self.robot)
            .field("breakpoints", &self.breakpoints)
            .field("watches", &self.watches)
            .field("done", &self.done.len())
            .field("checkpoints", &self.checkpoints.len())
            .finish_non_exhaustive()
    }
}

/// Expressions read the session's robot as it is now.
impl crate::expr::Machine for Debugger {
    fn cpu(&self) -> &Cpu {
        self.cpu()
    }

    fn peek(&self, address: u16) -> u8 {
        emulator::Bus::peek(&self.robot.robot().bus, address)
    }
}

/// A line of disassembly.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line {
    /// Where the instruction is.
    pub address: u16,
    /// Its bytes.
    pub bytes: Vec<u8>,
    /// The label at its address, if any.
    pub label: Option<String>,
    /// The source file and line its bytes came from, if an image says.
    pub source: Option<(String, u32)>,
    /// The instruction, its operand named by a label where one fits.
    pub text: String,
}

impl Debugger {
    /// A session on the robot `make` builds; `images` are the loaded
    /// images (for their symbols).
    ///
    /// # Errors
    /// The robot's own failure to build.
    pub fn new(make: MakeRobot, images: &[linker::Image]) -> Result<Debugger, Error> {
        let robot = make()?;
        let symbols = Symbols::new(&robot, images);
        let last_stop = (robot.cycles(), robot.robot().cpu.instructions());
        let mut checkpoints = Checkpoints::new();
        checkpoints.take(&robot, 0);
        Ok(Debugger {
            make,
            robot,
            symbols,
            images: images.to_vec(),
            source_root: std::path::PathBuf::from("."),
            breakpoints: Vec::new(),
            options: Vec::new(),
            hits: Vec::new(),
            logs: RefCell::new(Logs::default()),
            interrupt: None,
            watches: Vec::new(),
            done: Vec::new(),
            ahead: VecDeque::new(),
            last_stop,
            power_up: last_stop.1,
            checkpoints,
            trace: None,
        })
    }

    /// The robot.
    #[must_use]
    pub fn robot(&self) -> &VirtualScorpion {
        &self.robot
    }

    /// The CPU.
    #[must_use]
    pub fn cpu(&self) -> &Cpu {
        &self.robot.robot().cpu
    }

    /// The names known.
    #[must_use]
    pub fn symbols(&self) -> &Symbols {
        &self.symbols
    }

    /// `count` instructions from `address`, decoded from memory as the CPU
    /// sees it, labels beside them and jump targets named.
    #[must_use]
    pub fn disassemble(&self, address: u16, count: usize) -> Vec<Line> {
        let bus = &self.robot.robot().bus;
        let peek = |at: u16| emulator::Bus::peek(bus, at);
        let mut lines = Vec::with_capacity(count);
        let mut at = address;
        for _ in 0..count {
            let instruction = isa::Instruction::decode_with(at, peek);
            let len = u16::from(instruction.len());
            let mut text = instruction.to_string();
            if let Some(name) = instruction.target().and_then(|t| self.symbols.label(t)) {
                text = format!("{text:<14} ; {name}");
            }
            lines.push(Line {
                address: at,
                bytes: (0..len).map(|i| peek(at.wrapping_add(i))).collect(),
                label: self.symbols.label(at).map(str::to_owned),
                source: self.source_of(at),
                text,
            });
            at = at.wrapping_add(len);
        }
        lines
    }

    /// Says where the images' source paths start (the project's root, or
    /// the directory a front end reads them from; the current directory
    /// until told): the files there are the user's own.
    pub fn set_source_root(&mut self, root: std::path::PathBuf) {
        self.source_root = root;
    }

    /// The source file (as the assembler was given it) and line a user
    /// is shown for the byte at `address`, if a loaded image says: the
    /// line it came from, or for a built-in macro's code (`scorpion.inc`,
    /// not a file of the user's) the user's line that called the macro
    /// ([`isa::objfmt::user_place`], as the profile and the coverage
    /// count it).
    #[must_use]
    pub fn source_of(&self, address: u16) -> Option<(String, u32)> {
        let is_users = |file: &str| hostfs::is_users_source(&self.source_root, file);
        self.images.iter().find_map(|image| {
            let (file, line) = image.user_source_of(u32::from(address), &is_users)?;
            Some((file.to_owned(), line))
        })
    }

    /// The first address whose bytes came from `line` of `file` (a path,
    /// or its last components: `adc.s`), or that a macro called there
    /// made (`break myext.s:26` on `SCORPION_CHAIN_UNKNOWN`: its `JMP`).
    #[must_use]
    pub fn address_of_line(&self, file: &str, line: u32) -> Option<u16> {
        self.images
            .iter()
            .filter_map(|image| image.address_of_line(file, line))
            .min()
            .and_then(|address| u16::try_from(address).ok())
    }

    /// The PC, then the `JSR` of each call on the 6502 stack, innermost
    /// first: every pair of stack bytes above S that points at the last
    /// byte of a `JSR` (the stack has no frames to walk; this is how 6502
    /// monitors show a call chain). A caller's frame is where it called,
    /// as gdb and editors show it, not the line the call returns to.
    #[must_use]
    pub fn backtrace(&self) -> Vec<u16> {
        let bus = &self.robot.robot().bus;
        let peek = |at: u16| emulator::Bus::peek(bus, at);
        let mut frames = vec![self.cpu().pc];
        let mut s = u16::from(self.cpu().s) + 1;
        while s < 0xFF {
            let pushed = u16::from_le_bytes([peek(0x0100 + s), peek(0x0100 + s + 1)]);
            let call = pushed.wrapping_sub(2);
            if peek(call) == 0x20 {
                frames.push(call);
                s += 2;
            } else {
                s += 1;
            }
        }
        frames
    }

    /// Traces every instruction run from now on into `out` (`name` says
    /// where, for errors), ending the trace there was.
    ///
    /// # Errors
    /// [`Error::Trace`]: the trace there was could not be written out.
    pub fn trace(&mut self, name: &str, out: Box<dyn Write + Send>) -> Result<(), Error> {
        let ended = self.trace_off();
        let failed = Arc::new(Mutex::new(None));
        let out: Box<dyn Write + Send> = Box::new(Noted {
            out,
            failed: Arc::clone(&failed),
        });
        self.trace = Some(Trace {
            name: name.to_owned(),
            tracer: Tracer::new(out),
            failed,
        });
        ended
    }

    /// Ends the trace (if one is written), flushing it.
    ///
    /// # Errors
    /// [`Error::Trace`]: a write or the flush failed.
    pub fn trace_off(&mut self) -> Result<(), Error> {
        let Some(trace) = self.trace.take() else {
            return Ok(());
        };
        let name = trace.name;
        trace
            .tracer
            .finish()
            .map(drop)
            .map_err(|error| Error::Trace {
                name,
                message: error.to_string(),
            })
    }

    /// The trace's write error, if one stopped the run: the trace ends.
    fn trace_failure(&mut self) -> Option<Error> {
        let trace = self.trace.as_ref()?;
        let message = trace.failed.lock().ok()?.clone()?;
        let name = trace.name.clone();
        self.trace = None;
        Some(Error::Trace { name, message })
    }

    /// Adds a breakpoint; returns its number.
    pub fn add_breakpoint(&mut self, point: Breakpoint) -> usize {
        self.add_breakpoint_with(point, PointOptions::default())
    }

    /// Adds a breakpoint with a condition, a hit count or a log message;
    /// returns its number.
    pub fn add_breakpoint_with(&mut self, point: Breakpoint, options: PointOptions) -> usize {
        self.breakpoints.push(Some(point));
        self.options.push(options);
        self.hits.push(Cell::new(0));
        self.breakpoints.len()
    }

    /// Breakpoint `id`'s condition, hit count and log message, and its hits
    /// so far.
    #[must_use]
    pub fn breakpoint_options(&self, id: usize) -> Option<(&PointOptions, u64)> {
        let index = id.checked_sub(1)?;
        self.breakpoints.get(index)?.as_ref()?;
        Some((self.options.get(index)?, self.hits.get(index)?.get()))
    }

    /// What log points logged since the last call (the oldest first), and
    /// how many lines were dropped beyond [`MAX_LOGS`] kept.
    pub fn take_logs(&mut self) -> (Vec<Logged>, u64) {
        let logs = std::mem::take(self.logs.get_mut());
        (logs.lines, logs.dropped)
    }

    /// Pauses a run (`continue`, `next`, `finish`, `until`) between slices
    /// of [`SLICE`] robot cycles once `flag` is set: the run ends with
    /// [`Why::Paused`] and clears it. Safe to set from a signal handler.
    pub fn set_interrupt(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Some(flag);
    }

    /// Sets a register or flag, as a host action done again on every
    /// re-run from before now (so a step back and forward sees it).
    ///
    /// # Errors
    /// [`Error::Value`] for a value the register does not hold.
    pub fn set_register(&mut self, register: Register, value: i64) -> Result<(), Error> {
        let value = u16::try_from(value)
            .ok()
            .filter(|&v| v <= register.max())
            .ok_or_else(|| Error::Value {
                what: register.to_string(),
                value,
                max: register.max(),
            })?;
        self.act(Event::Set(register, value));
        Ok(())
    }

    /// Writes `bytes` into RAM from `address` (as a host action, done
    /// again on every re-run).
    ///
    /// # Errors
    /// [`Error::NotRam`]: a byte would land outside RAM (the ROM, the I/O
    /// page, a card's registers, past $FFFF); nothing is written.
    pub fn poke(&mut self, address: u16, bytes: &[u8]) -> Result<(), Error> {
        let bus = &self.robot.robot().bus;
        for offset in 0..bytes.len() {
            let at = u16::try_from(usize::from(address) + offset)
                .ok()
                .filter(|&at| bus.is_ram(at));
            if at.is_none() {
                return Err(Error::NotRam {
                    address: u16::try_from(usize::from(address) + offset).unwrap_or(0xFFFF),
                });
            }
        }
        self.act(Event::Poke {
            address,
            bytes: bytes.to_vec(),
        });
        Ok(())
    }

    /// Runs until the PC reaches `address` (or a breakpoint or watchpoint
    /// stops it first, or `budget` cycles run out).
    ///
    /// # Errors
    /// As [`Debugger::run`].
    pub fn until(&mut self, address: u16, budget: u64) -> Result<Stopped, Error> {
        let kept = self.breakpoints.len();
        let id = self.add_breakpoint(Breakpoint::At(address));
        let until = self.robot.cycles().saturating_add(budget);
        let stopped = self.go(until, Goal::default());
        self.breakpoints.truncate(kept);
        self.options.truncate(kept);
        self.hits.truncate(kept);
        let mut stopped = stopped?;
        if matches!(stopped.why, Why::Breakpoint { id: hit, .. } if hit == id) {
            stopped.why = Why::Stepped;
        }
        Ok(stopped)
    }

    /// Adds a watchpoint; returns its number.
    pub fn add_watch(&mut self, watch: Watch) -> usize {
        self.watches.push(Some(watch));
        self.watches.len()
    }

    /// Deletes breakpoint `id`; false if there was none.
    pub fn delete_breakpoint(&mut self, id: usize) -> bool {
        id.checked_sub(1)
            .and_then(|i| self.breakpoints.get_mut(i))
            .and_then(Option::take)
            .is_some()
    }

    /// Deletes watchpoint `id`; false if there was none.
    pub fn delete_watch(&mut self, id: usize) -> bool {
        id.checked_sub(1)
            .and_then(|i| self.watches.get_mut(i))
            .and_then(Option::take)
            .is_some()
    }

    /// The breakpoints, with their numbers.
    #[must_use]
    pub fn breakpoints(&self) -> Vec<(usize, Breakpoint)> {
        numbered(&self.breakpoints)
    }

    /// The watchpoints, with their numbers.
    #[must_use]
    pub fn watches(&self) -> Vec<(usize, Watch)> {
        numbered(&self.watches)
    }

    /// The host sends `bytes` down the line (now, at the robot's time).
    pub fn send(&mut self, bytes: &[u8]) {
        self.act(Event::Send(bytes.to_vec()));
    }

    /// The host closes the bumpers whose bits are set in `closed`.
    pub fn set_bumpers(&mut self, closed: u8) {
        self.act(Event::Bumpers(closed));
    }

    /// How many checkpoints of the robot the session keeps now (at most
    /// [`crate::MAX_CHECKPOINTS`]; none for a robot that cannot be copied).
    #[must_use]
    pub fn checkpoints(&self) -> usize {
        self.checkpoints.len()
    }

    fn act(&mut self, event: Event) {
        // Something new: what the host had done further on is not redone,
        // and the robot's copies from then on are of a future that will
        // not happen.
        self.ahead.clear();
        self.checkpoints
            .forget_after(self.robot.cycles(), self.cpu().instructions());
        let done = Done {
            instructions: self.cpu().instructions(),
            cycle: self.robot.cycles(),
            event,
        };
        apply(&mut self.robot, &done.event);
        self.done.push(done);
    }

    /// Runs until a breakpoint or watchpoint, or for `budget` cycles.
    ///
    /// # Errors
    /// The robot's failure (a JAM, a card's fault).
    pub fn run(&mut self, budget: u64) -> Result<Stopped, Error> {
        let until = self.robot.cycles().saturating_add(budget);
        self.go(until, Goal::default())
    }

    /// Runs `count` instructions (stopping earlier at a breakpoint or
    /// watchpoint).
    ///
    /// # Errors
    /// As [`Debugger::run`].
    pub fn step(&mut self, count: u64) -> Result<Stopped, Error> {
        let target = self.cpu().instructions().saturating_add(count.max(1));
        self.go(
            u64::MAX,
            Goal {
                at_count: Some(target),
                ..Goal::default()
            },
        )
    }

    /// One instruction, a `JSR` with the whole subroutine it calls.
    ///
    /// # Errors
    /// As [`Debugger::run`].
    pub fn next(&mut self, budget: u64) -> Result<Stopped, Error> {
        let cpu = self.cpu();
        let pc = cpu.pc;
        let is_jsr = emulator::Bus::peek(&self.robot.robot().bus, pc) == 0x20;
        if !is_jsr {
            return self.step(1);
        }
        let goal = Goal {
            returning_to: Some((pc.wrapping_add(3), cpu.s)),
            ..Goal::default()
        };
        let until = self.robot.cycles().saturating_add(budget);
        self.go(until, goal)
    }

    /// One source line, as a user sees lines ([`Debugger::source_of`]),
    /// each `JSR` with the whole subroutine it calls: instructions as
    /// [`Debugger::next`] runs them until the PC is on another line (or
    /// where no line is: the ROM), a stop that is not a step's comes, or
    /// `budget` cycles have run. A built-in macro's code is shown at the
    /// user's line that called it, so the call is one line. Where the PC
    /// has no line, one instruction.
    ///
    /// # Errors
    /// As [`Debugger::run`].
    pub fn next_line(&mut self, budget: u64) -> Result<Stopped, Error> {
        let Some(line) = self.source_of(self.cpu().pc) else {
            return self.next(budget);
        };
        let until = self.robot.cycles().saturating_add(budget);
        let mut stopped = self.next(budget)?;
        while stopped.why == Why::Stepped && self.source_of(self.cpu().pc).as_ref() == Some(&line) {
            let left = until.saturating_sub(self.robot.cycles());
            if left == 0 {
                stopped.why = Why::Budget;
                break;
            }
            let more = self.next(left)?;
            stopped.why = more.why;
            stopped.pc = more.pc;
            stopped.cycles += more.cycles;
            stopped.instructions += more.instructions;
            stopped.received.extend(more.received);
        }
        Ok(stopped)
    }

    /// Runs until the current subroutine returns (its `RTS` pops the
    /// return address it was called with).
    ///
    /// # Errors
    /// As [`Debugger::run`].
    pub fn finish(&mut self, budget: u64) -> Result<Stopped, Error> {
        let goal = Goal {
            finish_at: self.cpu().s.checked_add(2),
            ..Goal::default()
        };
        let until = self.robot.cycles().saturating_add(budget);
        self.go(until, goal)
    }

    fn go(&mut self, until: u64, goal: Goal) -> Result<Stopped, Error> {
        let mut received = Vec::new();
        // Only the run's first instruction is where the last stop was.
        let mut first = true;
        loop {
            // After a step back, the host's recorded actions are done
            // again when the run gets to them.
            while let Some(done) = self.ahead.front() {
                if self.robot.cycles() < done.cycle {
                    break;
                }
                check_place(&self.robot, done)?;
                apply(&mut self.robot, &done.event);
                if let Some(done) = self.ahead.pop_front() {
                    self.done.push(done);
                }
            }
            let slice = if self.interrupt.is_some() {
                self.robot.cycles().saturating_add(SLICE)
            } else {
                u64::MAX
            };
            let to = until
                .min(self.ahead.front().map_or(u64::MAX, |d| d.cycle))
                .min(self.checkpoints.next_due())
                .min(slice);
            let arrival = self.arrival();
            let found = run_hooked(
                &mut self.robot,
                self.trace.as_mut().map(|trace| &mut trace.tracer),
                Points {
                    breakpoints: &self.breakpoints,
                    options: &self.options,
                    live: Some((self.hits.as_slice(), &self.logs)),
                    watches: &self.watches,
                    arrival,
                },
                to,
                goal,
                std::mem::replace(&mut first, false),
            )?;
            received.extend(self.robot.receive());
            if let Some(trace) = self.trace.as_mut() {
                // What this run traced is written out before it answers:
                // a writer that cannot take it fails this run, not the
                // next (its error is noted for the check below).
                let _ = trace.tracer.flush();
            }
            // A failed write stops the tracer's run at once, each time.
            if let Some(error) = self.trace_failure() {
                return Err(error);
            }
            if self.robot.cycles() >= self.checkpoints.next_due() {
                self.checkpoints.take(&self.robot, self.done.len());
            }
            let paused = self
                .interrupt
                .as_ref()
                .is_some_and(|flag| flag.swap(false, Ordering::Relaxed));
            if found.is_none() && paused {
                return Ok(self.stopped(Why::Paused, received));
            }
            if found.is_none() && self.robot.cycles() < until {
                continue;
            }
            let why = self.why(found);
            return Ok(self.stopped(why, received));
        }
    }

    /// Why a run under the hooks ended (`None`: its robot time ran out).
    fn why(&self, found: Option<Found>) -> Why {
        match found {
            Some(Found::Breakpoint(index)) => Why::Breakpoint {
                id: index + 1,
                point: self.breakpoints[index]
                    .clone()
                    .unwrap_or(Breakpoint::UnknownHook),
            },
            Some(Found::Watch { access, pc }) => Why::Watch {
                id: access.watch + 1,
                access,
                pc,
            },
            Some(Found::Count | Found::Returned) => Why::Stepped,
            Some(Found::Finished) => Why::Finished,
            None => Why::Budget,
        }
    }

    fn stopped(&mut self, why: Why, received: Vec<u8>) -> Stopped {
        let now = (self.robot.cycles(), self.cpu().instructions());
        let (cycle, instructions) = std::mem::replace(&mut self.last_stop, now);
        Stopped {
            why,
            pc: self.cpu().pc,
            cycles: now.0.abs_diff(cycle),
            instructions: signed(now.1) - signed(instructions),
            received,
        }
    }

    /// Where a command breakpoint looks: the ROM's `dispatch` and the
    /// unknown-command hook.
    fn arrival(&self) -> Arrival {
        Arrival {
            dispatch: self.symbols.get("dispatch"),
            unknown: self.robot.hook_address(HookKind::Unknown),
        }
    }

    /// Goes back `count` instructions: the robot built again and run,
    /// with the host's actions replayed, to that point.
    ///
    /// # Errors
    /// [`Error::BeforePowerUp`] for more instructions than have run;
    /// [`Error::Diverged`] if the re-run does not retrace the run.
    pub fn back(&mut self, count: u64) -> Result<Stopped, Error> {
        let now = self.cpu().instructions();
        let target = now
            .checked_sub(count)
            .filter(|&t| t >= self.power_up)
            .ok_or(Error::BeforePowerUp {
                asked: count,
                ran: now - self.power_up,
            })?;
        self.rerun_to(target)?;
        Ok(self.stopped(Why::Back, Vec::new()))
    }

    /// Goes back to the last breakpoint or watchpoint hit before now.
    /// `None` (and nothing changed) if there was none.
    ///
    /// # Errors
    /// As [`Debugger::back`].
    pub fn reverse_continue(&mut self) -> Result<Option<Stopped>, Error> {
        let now = self.cpu().instructions();
        let arrival = self.arrival();
        // Conditions hold on a re-run as they did; counts and logs are
        // the live run's (a log point never stops).
        let points = Points {
            breakpoints: &self.breakpoints,
            options: &self.options,
            live: None,
            watches: &self.watches,
            arrival,
        };
        // Short of now: a hit at now is the stop the robot is at.
        let Some(Hit { count, found, .. }) = self.last_hit(points, now, now.saturating_sub(1))?
        else {
            return Ok(None);
        };
        self.rerun_to(count)?;
        // A re-run reports only breakpoint and watchpoint hits.
        let why = self.why(Some(found));
        Ok(Some(self.stopped(why, Vec::new())))
    }

    /// The last write to `address` before now: the writing instruction's
    /// count (instructions run before it), its PC and the byte written.
    /// `None` if no instruction has written it since the session began
    /// (an image's bytes are loaded before it).
    ///
    /// # Errors
    /// As [`Debugger::back`].
    pub fn who_wrote(&mut self, address: u16) -> Result<Option<LastWrite>, Error> {
        let now = self.cpu().instructions();
        let watches = [Some(Watch {
            start: address,
            end: address,
            kind: crate::WatchKind::Write,
        })];
        let points = Points {
            breakpoints: &[],
            options: &[],
            live: None,
            watches: &watches,
            arrival: self.arrival(),
        };
        // The write of the instruction just run counts.
        let last = self
            .last_hit(points, now, now)?
            .and_then(|hit| match hit.found {
                Found::Watch { access, pc } => Some(LastWrite {
                    instruction: hit.count - 1,
                    pc,
                    value: access.value,
                    cycle: hit.cycle,
                }),
                _ => None,
            });
        Ok(last)
    }

    /// The last hit of `points` at an instruction count up to `latest`
    /// before the robot's `now`: a re-run from the
    /// newest checkpoint before now to now, then from the one before it to
    /// that one, and so on back to power-up, until a stretch has one. It
    /// costs a re-run as long as the way back to the hit. A stretch from
    /// instruction `s` to `e` sees the breakpoints at `s` up to but not at
    /// `e` (the next stretch's), and the watches after `s` up to `e`.
    fn last_hit(&self, points: Points<'_>, now: u64, latest: u64) -> Result<Option<Hit>, Error> {
        let starts = self.checkpoints.all().iter().rev();
        let starts = starts.filter(|c| c.instructions < now).map(Some);
        let mut end = now;
        for start in starts.chain([None]) {
            let mut scout = match start.and_then(|c| self.replayer_at(c)) {
                Some(scout) => scout,
                None => self.replayer()?,
            };
            let from = scout.robot.robot().cpu.instructions();
            if from >= end {
                continue;
            }
            // From power-up, as the session began: not at its first PC.
            scout.resumed = start.is_none();
            let mut last = None;
            while let Some((count, found)) = scout.run_to(end, points)? {
                if count <= latest {
                    last = Some(Hit {
                        count,
                        found,
                        cycle: scout.robot.cycles(),
                    });
                }
            }
            if last.is_some() {
                return Ok(last);
            }
            end = from;
        }
        Ok(None)
    }

    /// The host's actions, done and ahead.
    fn events(&self) -> Vec<Done> {
        self.done.iter().chain(self.ahead.iter()).cloned().collect()
    }

    /// The robot built again at power-up, to replay from.
    fn replayer(&self) -> Result<Replayer, Error> {
        Ok(Replayer {
            robot: (self.make)()?,
            events: self.events(),
            next: 0,
            resumed: true,
        })
    }

    /// The robot as checkpoint `at` has it, to replay from (`None` if it
    /// cannot be copied again).
    fn replayer_at(&self, at: &Checkpoint) -> Option<Replayer> {
        Some(Replayer {
            robot: at.robot.snapshot()?,
            events: self.events(),
            next: at.events,
            resumed: true,
        })
    }

    /// Runs the robot to `target` instructions from the newest checkpoint
    /// before it (or from power-up).
    fn rerun_to(&mut self, target: u64) -> Result<(), Error> {
        let from = self.checkpoints.before(target);
        let mut replay = match from.and_then(|c| self.replayer_at(c)) {
            Some(replay) => replay,
            None => self.replayer()?,
        };
        let points = Points {
            breakpoints: &[],
            options: &[],
            live: None,
            watches: &[],
            arrival: self.arrival(),
        };
        while replay.run_to(target, points)?.is_some() {}
        replay.robot.receive();
        let mut events = replay.events;
        self.ahead = events.split_off(replay.next).into();
        self.done = events;
        self.robot = replay.robot;
        Ok(())
    }
}

/// A write found by [`Debugger::who_wrote`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LastWrite {
    /// Instructions run before the writing one.
    pub instruction: u64,
    /// The writing instruction's address.
    pub pc: u16,
    /// The byte written.
    pub value: u8,
    /// The robot's cycle after it.
    pub cycle: u64,
}

/// A hit found by a re-run: the instruction count and cycle at it.
struct Hit {
    count: u64,
    found: Found,
    cycle: u64,
}

/// The robot built again, and the host's actions to do again on it.
struct Replayer {
    robot: VirtualScorpion,
    events: Vec<Done>,
    /// The next event to do.
    next: usize,
    /// The next run resumes from a stop: no breakpoint at its first
    /// instruction.
    resumed: bool,
}

impl Replayer {
    /// Runs to `target` instructions, doing the host's actions at their
    /// cycles; `Some` at a breakpoint or watchpoint on the way (call again
    /// to go on), `None` at the target.
    fn run_to(&mut self, target: u64, points: Points<'_>) -> Result<Option<(u64, Found)>, Error> {
        loop {
            while let Some(done) = self.events.get(self.next) {
                if self.robot.cycles() < done.cycle || done.instructions > target {
                    break;
                }
                check_place(&self.robot, done)?;
                apply(&mut self.robot, &done.event);
                self.next += 1;
            }
            if self.robot.robot().cpu.instructions() >= target {
                return Ok(None);
            }
            let until = self
                .events
                .get(self.next)
                .filter(|d| d.instructions <= target)
                .map_or(u64::MAX, |d| d.cycle);
            let goal = Goal {
                at_count: Some(target),
                ..Goal::default()
            };
            let first = std::mem::replace(&mut self.resumed, false);
            match run_hooked(&mut self.robot, None, points, until, goal, first)? {
                None | Some(Found::Count) => {}
                Some(found) => {
                    self.resumed = true;
                    return Ok(Some((self.robot.robot().cpu.instructions(), found)));
                }
            }
        }
    }
}

/// Checks that a re-run reached a recorded action where the run did.
fn check_place(robot: &VirtualScorpion, done: &Done) -> Result<(), Error> {
    let (cycle, count) = (robot.cycles(), robot.robot().cpu.instructions());
    if cycle != done.cycle || count != done.instructions {
        return Err(Error::Diverged {
            instruction: done.instructions,
            expected: done.cycle,
            found: cycle,
        });
    }
    Ok(())
}

/// What the hooks stop at.
#[derive(Clone, Copy)]
struct Points<'a> {
    breakpoints: &'a [Option<Breakpoint>],
    /// Beside each breakpoint (none past the end: plain breakpoints).
    options: &'a [PointOptions],
    /// The live run's hit counts and logs; `None` on a re-run, which
    /// only tests conditions.
    live: Option<(&'a [Cell<u64>], &'a RefCell<Logs>)>,
    watches: &'a [Option<Watch>],
    arrival: Arrival,
}

impl Points<'_> {
    /// Whether a hit must be counted or logged (no idle loop skipped).
    fn counting(&self) -> bool {
        self.live.is_some()
            && self
                .breakpoints
                .iter()
                .zip(self.options)
                .any(|(point, options)| point.is_some() && options.counts())
    }

    /// Which breakpoint stops at `cpu`'s PC, if any: each one there is
    /// asked in turn (its place, its condition, its count; a log point
    /// logs and does not stop). Asked only where a PC bit is set.
    fn stop_at(&self, cpu: &Cpu, peek: &dyn Fn(u16) -> u8) -> Option<usize> {
        let mut stop = None;
        for (index, point) in self.breakpoints.iter().enumerate() {
            let Some(point) = point else { continue };
            if !breakpoint_hits(point, cpu.pc, &self.arrival, peek) {
                continue;
            }
            let Some(options) = self.options.get(index) else {
                stop = stop.or(Some(index));
                continue;
            };
            let machine = Peeking { cpu, peek };
            if let Some(condition) = &options.condition {
                match condition.eval(&machine) {
                    Ok(0) => continue,
                    Ok(_) => {}
                    // It stops, and says why, rather than stopping silently or
                    // never: the user fixes the condition from what is said.
                    Err(error) => {
                        if let Some((_, logs)) = self.live {
                            logs.borrow_mut().push(Logged {
                                id: index + 1,
                                pc: cpu.pc,
                                text: format!(
                                    "breakpoint {}: its condition cannot be evaluated here, so it stops: {error}",
                                    index + 1
                                ),
                            });
                        }
                        stop = stop.or(Some(index));
                        continue;
                    }
                }
            }
            let Some((hits, logs)) = self.live else {
                // A re-run: conditions only.
                if options.log.is_none() {
                    stop = stop.or(Some(index));
                }
                continue;
            };
            if let Some(hit_condition) = options.hits {
                let count = hits.get(index).map_or(1, |hits| {
                    let count = hits.get().saturating_add(1);
                    hits.set(count);
                    count
                });
                if !hit_condition.stops(count) {
                    continue;
                }
            }
            match &options.log {
                Some(template) => logs.borrow_mut().push(Logged {
                    id: index + 1,
                    pc: cpu.pc,
                    text: template.render(&machine),
                }),
                None => stop = stop.or(Some(index)),
            }
        }
        stop
    }
}

/// A run's slice when it may be paused: a tenth of a second of robot
/// time, well under a millisecond of ours.
pub const SLICE: u64 = 100_000;

/// Log lines kept between looks ([`Debugger::take_logs`]); more are
/// counted, not kept.
pub const MAX_LOGS: usize = 10_000;

/// A line a log point logged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Logged {
    /// The breakpoint's number.
    pub id: usize,
    /// The PC it logged at.
    pub pc: u16,
    /// Its message, values filled in.
    pub text: String,
}

/// The lines logged since the last look, bounded.
#[derive(Debug, Default)]
struct Logs {
    lines: Vec<Logged>,
    dropped: u64,
}

impl Logs {
    fn push(&mut self, line: Logged) {
        if self.lines.len() < MAX_LOGS {
            self.lines.push(line);
        } else {
            self.dropped += 1;
        }
    }
}

/// One run under the hooks, to `until` (a cycle) or a stop; `first`: no
/// breakpoint stops its first instruction (the run resumes from a stop
/// there).
fn run_hooked(
    robot: &mut VirtualScorpion,
    trace: Option<&mut Tracer<Box<dyn Write + Send>>>,
    points: Points<'_>,
    until: u64,
    goal: Goal,
    first: bool,
) -> Result<Option<Found>, Error> {
    let idle = goal.at_count.is_none()
        && goal.returning_to.is_none()
        && goal.finish_at.is_none()
        && trace.is_none()
        && points.breakpoints.iter().all(Option::is_none)
        && points.watches.iter().all(Option::is_none);
    if idle {
        // Nothing to look for: the robot's own run, idle loops skipped.
        robot.run_until_with(until, |robot, to| robot.run(to))?;
        return Ok(None);
    }
    let mut places = emulator::Breakpoints::new();
    let mut place_blocks = 0;
    for point in points.breakpoints.iter().flatten() {
        let at = match point {
            Breakpoint::At(address) => *address,
            Breakpoint::UnknownHook => points.arrival.unknown,
            Breakpoint::Command { .. } => points.arrival.dispatch.unwrap_or(points.arrival.unknown),
        };
        places.insert(at);
        place_blocks |= crate::hooks::block(at);
    }
    let hit = Cell::new(None);
    let watched = Watched::new(points.watches);
    if goal.returning_to.is_none() && goal.finish_at.is_none() && trace.is_none() {
        return run_lean(
            robot,
            points,
            until,
            goal.at_count,
            first,
            (&places, place_blocks),
            &watched,
        );
    }
    let matches = |cpu: &Cpu, peek: &dyn Fn(u16) -> u8| points.stop_at(cpu, peek);
    let mut look = Look {
        places: &places,
        breakpoint: matches,
        at_count: goal.at_count,
        returning_to: goal.returning_to,
        finish_at: goal.finish_at,
        hit: &hit,
        first,
        last_pc: 0,
        found: None,
        skip_idle: !points.counting(),
    };
    let (read_blocks, write_blocks) = watched.blocks();
    let mut trace = trace;
    robot.run_until_with(until, |robot, to| {
        let mut bus = WatchBus {
            board: &mut robot.bus,
            watches: points.watches,
            watched: &watched,
            hit: &hit,
            read_blocks,
            write_blocks,
        };
        let stop = match trace.as_deref_mut() {
            Some(tracer) => robot.cpu.run(&mut bus, to, &mut (&mut look, tracer)),
            None => robot.cpu.run(&mut bus, to, &mut look),
        };
        // A watch hit's stop is this run's: the next one goes on.
        robot.bus.clear_stop_request();
        stop
    })?;
    // A watch the run's last instruction hit, though the run ended before
    // the next one looked: it stops here, not in the next run.
    if look.found.is_none()
        && let Some(access) = hit.take()
    {
        look.found = Some(Found::Watch {
            access,
            pc: look.last_pc,
        });
    }
    Ok(look.found)
}

/// [`run_hooked`] for a run only breakpoints, watchpoints and a count
/// stop ([`Lean`]): on the board itself when nothing is watched. A
/// breakpoint's PC reached, the breakpoint itself (a command's count and
/// letter) is asked there, and the run goes on if it says no.
fn run_lean(
    robot: &mut VirtualScorpion,
    points: Points<'_>,
    until: u64,
    at_count: Option<u64>,
    first: bool,
    (places, place_blocks): (&emulator::Breakpoints, u64),
    watched: &Watched,
) -> Result<Option<Found>, Error> {
    let (reads, writes) = watched.kinds();
    let skip_idle = !points.counting();
    let mut start = if first {
        robot.robot().cpu.instructions()
    } else {
        u64::MAX
    };
    let stop_at = at_count.unwrap_or(u64::MAX);
    let lean = Leaning {
        points,
        until,
        stop_at,
        places,
        place_blocks,
        watched,
        skip_idle,
    };
    loop {
        // Four runs, one per kind: each tests only what it needs.
        let stopped = match (reads || writes, at_count.is_some()) {
            (true, true) => lean.run::<true, true>(robot, start)?,
            (true, false) => lean.run::<true, false>(robot, start)?,
            (false, true) => lean.run::<false, true>(robot, start)?,
            (false, false) => lean.run::<false, false>(robot, start)?,
        };
        match stopped {
            None => return Ok(None),
            Some(LeanStop::Count) => return Ok(Some(Found::Count)),
            Some(LeanStop::Watch { access, pc }) => return Ok(Some(Found::Watch { access, pc })),
            Some(LeanStop::Place) => {
                let (cpu, bus) = (&robot.robot().cpu, &robot.robot().bus);
                let peek = |address| emulator::Bus::peek(bus, address);
                let found = points.stop_at(cpu, &peek);
                if let Some(index) = found {
                    return Ok(Some(Found::Breakpoint(index)));
                }
                // Not this time (another command): on from here.
                start = cpu.instructions();
            }
        }
    }
}

/// What a lean run is given.
struct Leaning<'a> {
    points: Points<'a>,
    until: u64,
    stop_at: u64,
    places: &'a emulator::Breakpoints,
    place_blocks: u64,
    watched: &'a Watched,
    skip_idle: bool,
}

impl Leaning<'_> {
    /// One run under [`Lean`]: why it stopped (`None`: at `until`).
    fn run<const WATCH: bool, const COUNT: bool>(
        &self,
        robot: &mut VirtualScorpion,
        start: u64,
    ) -> Result<Option<LeanStop>, Error> {
        let hit = Cell::new(None);
        let mut lean = Lean::<WATCH, COUNT> {
            places: self.places,
            place_blocks: self.place_blocks,
            start,
            stop_at: self.stop_at,
            last_pc: robot.robot().cpu.pc,
            stopped: None,
            skip_idle: self.skip_idle,
        };
        if !WATCH {
            robot.run_until_with(self.until, |robot, to| {
                robot.cpu.run(&mut robot.bus, to, &mut lean)
            })?;
            return Ok(lean.stopped);
        }
        let (read_blocks, write_blocks) = self.watched.blocks();
        robot.run_until_with(self.until, |robot, to| {
            let mut bus = WatchBus {
                board: &mut robot.bus,
                watches: self.points.watches,
                watched: self.watched,
                hit: &hit,
                read_blocks,
                write_blocks,
            };
            let stop = robot.cpu.run(&mut bus, to, &mut lean);
            // The hit's stop is this run's: the next one goes on.
            robot.bus.clear_stop_request();
            stop
        })?;
        // The run ended just after the instruction that made the access
        // (or at its limit, if that came first): it stops here.
        Ok(match (lean.stopped, hit.take()) {
            (None, Some(access)) => Some(LeanStop::Watch {
                access,
                pc: lean.last_pc,
            }),
            (stopped, _) => stopped,
        })
    }
}

fn signed(count: u64) -> i64 {
    i64::try_from(count).unwrap_or(i64::MAX)
}

/// What a run aims for besides breakpoints and watchpoints.
#[derive(Debug, Clone, Copy, Default)]
struct Goal {
    at_count: Option<u64>,
    returning_to: Option<(u16, u8)>,
    finish_at: Option<u8>,
}

/// Where a command arrives.
#[derive(Debug, Clone, Copy)]
struct Arrival {
    dispatch: Option<u16>,
    unknown: u16,
}

fn breakpoint_hits(
    point: &Breakpoint,
    pc: u16,
    arrival: &Arrival,
    peek: &dyn Fn(u16) -> u8,
) -> bool {
    match point {
        Breakpoint::At(address) => pc == *address,
        Breakpoint::UnknownHook => pc == arrival.unknown,
        Breakpoint::Command { count, letter } => {
            let at = arrival.dispatch.unwrap_or(arrival.unknown);
            pc == at
                && peek(romlib::symbols::CMDLEN) == *count
                && peek(romlib::symbols::CMDBUF) == *letter
        }
    }
}

fn apply(robot: &mut VirtualScorpion, event: &Event) {
    match event {
        Event::Send(bytes) => robot.send(bytes),
        Event::Bumpers(closed) => robot.set_bumpers(*closed),
        Event::Set(register, value) => register.write(&mut robot.robot_mut().cpu, *value),
        Event::Poke { address, bytes } => {
            // Checked when done: RAM all the way ([`Debugger::poke`]).
            let _ = robot.robot_mut().bus.load(*address, bytes);
        }
    }
}

fn numbered<T: Clone>(items: &[Option<T>]) -> Vec<(usize, T)> {
    items
        .iter()
        .enumerate()
        .filter_map(|(i, item)| Some((i + 1, item.clone()?)))
        .collect()
}
