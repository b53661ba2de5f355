//! The virtual Scorpion with a ROM in it, set up the way a robot is after
//! an upload, and a host that talks to it through the typed protocol.
//!
//! [`VirtualScorpion`] owns an [`emulator::board::Scorpion`] running the
//! reference ROM (or a ROM profile), powered up and past its reset code.
//! [`VirtualScorpion::load_image`] leaves an image as the uploader would:
//! every loaded area written into RAM, then each hook the image takes over
//! installed last, with the hook's previous target written into the image's
//! chain slot first, so images loaded one after the other chain.
//! [`VirtualScorpion::exchange`] sends a [`Command`] through the emulated
//! 6551 at the line's baud rate and parses the answer.

use emulator::board::{CPU_HZ, Scorpion};
use emulator::{Breakpoints, Stop};
use isa::objfmt::HookKind;
use linker::Image;
use platform::map::{self, KIM_BUS};

use crate::error::Error;
use std::ops::RangeInclusive;

use crate::installed;
use crate::protocol::{Answer, Command, EOL};
use crate::symbols;

/// Robot time the host waits for an answer by default: one second.
pub const ANSWER_TIMEOUT: u64 = CPU_HZ;

/// Robot time the ROM needs to act on an instruction once its last byte
/// arrived, with margin (the command loop, the dispatch, a handler).
pub const INSTRUCTION_TIME: u64 = 5_000;

/// Robot time [`VirtualScorpion::check_loop`] is given when the robot does
/// not answer: 100 ms, a hundred times the longest the reference ROM's loop
/// takes to come round.
pub const LOOP_WATCH: u64 = CPU_HZ / 10;

/// Robot time from power-up until the reference ROM waits for commands.
const BOOT_TIME: u64 = 20_000;

/// A hook [`VirtualScorpion::load_image`] installed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InstalledHook {
    /// Which hook.
    pub kind: HookKind,
    /// Where it jumps now.
    pub handler: u16,
    /// Where it jumped before (now in the chain slot, if the image has one).
    pub previous: u16,
    /// The image's chain slot.
    pub chain: Option<u16>,
}

/// The two RAM hooks of the ROM in use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Hooks {
    unknown: u16,
    main_loop: u16,
}

impl Hooks {
    fn address(self, kind: HookKind) -> u16 {
        match kind {
            HookKind::Unknown => self.unknown,
            HookKind::Loop => self.main_loop,
        }
    }
}

/// The virtual Scorpion and its host.
#[derive(Debug)]
pub struct VirtualScorpion {
    robot: Scorpion,
    hooks: Hooks,
    /// The ROM's table of installed extensions (`EXTTAB`) and its entries,
    /// if the ROM keeps one.
    table: Option<(u16, usize)>,
    /// The memory a loaded image may use: the user zero page and RAM the
    /// ROM exports, and the KIM bus (empty: the ROM does not say).
    user: Vec<RangeInclusive<u16>>,
    /// Labels of a ROM profile and of every image loaded, sorted, for
    /// naming the place a robot that stopped answering is stuck in.
    labels: Vec<(u16, String)>,
    /// The reference ROM's labels count too (read from its ELF only when a
    /// place is to be named: a robot that answers never needs them).
    reference_rom: bool,
    /// What changes the robot's inputs over time, if anything.
    world: Option<Box<dyn Surroundings>>,
    /// The host's own run of the CPU, if it set one (a profiler).
    runner: Option<Box<dyn Runner>>,
}

/// A run of the robot's CPU that every run of a [`VirtualScorpion`] goes
/// through once set ([`VirtualScorpion::set_runner`]): a profiler or a
/// coverage count watching every exchange of a test, with its own hooks.
pub trait Runner: std::fmt::Debug + Send {
    /// Runs `robot` to robot time `until` or an earlier stop, as
    /// [`emulator::Machine::run`] does (with hooks that never stop it, the
    /// same run).
    fn run(&mut self, robot: &mut Scorpion, until: u64) -> Stop;

    /// Runs `robot` to robot time `until` or to the first instruction at
    /// an address of `stops`, as [`emulator::Machine::run_with`] with
    /// `stops` does (a routine-level test's run to its return).
    fn run_to(&mut self, robot: &mut Scorpion, until: u64, stops: &mut Breakpoints) -> Stop {
        robot.run_with(until, stops)
    }

    /// The host entered the routine at `target` as a `JSR` does, without
    /// one (a routine-level test pushed a return address, S at
    /// `s_before` before the push, and set the PC): a profiler starts the
    /// routine's frame there. The default: nothing.
    fn entered(&mut self, robot: &Scorpion, target: u16, s_before: u8) {
        let _ = (robot, target, s_before);
    }
}

/// An image's labels: its symbols that lie in a section (not constants).
fn labels_of(image: &Image) -> impl Iterator<Item = (u16, String)> + '_ {
    image.symbols.iter().filter_map(|symbol| {
        symbol.section?;
        Some((u16::try_from(symbol.value).ok()?, symbol.name.clone()))
    })
}

/// The reference ROM's labels, read from its ELF once per process (every
/// virtual robot starts with them).
fn reference_labels() -> &'static [(u16, String)] {
    static LABELS: std::sync::OnceLock<Vec<(u16, String)>> = std::sync::OnceLock::new();
    LABELS.get_or_init(|| {
        let mut labels: Vec<(u16, String)> = Image::parse("scorpion-rom.elf", crate::ROM_ELF)
            .map(|rom| labels_of(&rom).collect())
            .unwrap_or_default();
        labels.sort();
        labels
    })
}

/// The robot's surroundings: what closes its bumpers, lights its
/// phototransistors, over robot time and in answer to its motion. The
/// session wakes them at the robot time they ask for.
pub trait Surroundings: std::fmt::Debug + Send {
    /// The robot time (cycles since power-up) to be woken at next, if any.
    fn next_wake(&self) -> Option<u64>;

    /// Woken at robot time `now`: change the robot's inputs, read its
    /// motors.
    ///
    /// # Errors
    /// The surroundings' own failure, located in their script.
    fn wake(
        &mut self,
        now: u64,
        robot: &mut Scorpion,
    ) -> Result<(), Box<dyn miette::Diagnostic + Send + Sync>>;

    /// A copy of the surroundings as they are now, which go on exactly as
    /// these would (for a debugger's checkpoints). `None`, the default,
    /// for surroundings that cannot be copied.
    fn snapshot(&self) -> Option<Box<dyn Surroundings>> {
        None
    }

    /// The surroundings as [`std::any::Any`], for a host that knows their
    /// type and asks what they hold now (a room's pose and trail, of the
    /// copy a debugger went back to rather than of the robot first built).
    /// `None`, the default, for surroundings that do not say.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}

impl Default for VirtualScorpion {
    fn default() -> VirtualScorpion {
        VirtualScorpion::new()
    }
}

impl VirtualScorpion {
    /// The reference ROM, powered up, waiting for commands at 9600 baud.
    #[must_use]
    pub fn new() -> VirtualScorpion {
        let robot = Scorpion::scorpion(crate::ROM)
            .unwrap_or_else(|_| unreachable!("the built ROM is 4 KiB, as build.rs checks"));
        let mut scorpion = VirtualScorpion {
            robot,
            hooks: Hooks {
                unknown: symbols::HOOK_UNKNOWN,
                main_loop: symbols::HOOK_LOOP,
            },
            table: Some((installed::TABLE, installed::ENTRIES)),
            user: vec![
                symbols::USER_ZP_START..=symbols::USER_ZP_END,
                symbols::USER_RAM_START..=symbols::USER_RAM_END,
                KIM_BUS,
            ],
            labels: Vec::new(),
            reference_rom: true,
            world: None,
            runner: None,
        };
        scorpion.boot();
        scorpion
    }

    /// A ROM profile: the linked ELF of a ROM for `$F000-$FFFF` that exports
    /// `HOOK_UNKNOWN` and `HOOK_LOOP`.
    ///
    /// # Errors
    /// [`Error::RomProfile`] if the image does not fill the ROM or lacks
    /// the hook symbols.
    pub fn with_rom(name: &str, rom: &Image) -> Result<VirtualScorpion, Error> {
        let bad = |reason: String| Error::RomProfile {
            name: name.to_owned(),
            reason,
        };
        let mut bytes = Vec::with_capacity(map::ROM_SIZE);
        for address in u32::from(map::ROM_START)..=0xFFFF_u32 {
            let byte = rom
                .byte_at(address)
                .ok_or_else(|| bad(format!("it has no byte for ${address:04X}")))?;
            bytes.push(byte);
        }
        let symbol = |name: &str| {
            rom.symbol(name)
                .and_then(|value| u16::try_from(value).ok())
                .ok_or_else(|| bad(format!("it does not export {name}")))
        };
        let hooks = Hooks {
            unknown: symbol("HOOK_UNKNOWN")?,
            main_loop: symbol("HOOK_LOOP")?,
        };
        // A table in the reference ROM's format, if this ROM keeps one.
        let table = rom
            .symbol("EXTTAB")
            .zip(rom.symbol("EXTTAB_ENTRIES"))
            .filter(|_| rom.symbol("EXTTAB_ENTRY_LEN") == Some(installed::ENTRY_LEN as u32))
            .and_then(|(at, entries)| Some((u16::try_from(at).ok()?, entries as usize)));
        let bounds = |first: &str, last: &str| {
            let first = u16::try_from(rom.symbol(first)?).ok()?;
            let last = u16::try_from(rom.symbol(last)?).ok()?;
            Some(first..=last)
        };
        let user = match (
            bounds("USER_ZP_START", "USER_ZP_END"),
            bounds("USER_RAM_START", "USER_RAM_END"),
        ) {
            (Some(zp), Some(ram)) => vec![zp, ram, KIM_BUS],
            _ => Vec::new(),
        };
        let mut scorpion = VirtualScorpion {
            robot: Scorpion::scorpion(&bytes)?,
            hooks,
            table,
            user,
            labels: Vec::new(),
            reference_rom: false,
            world: None,
            runner: None,
        };
        scorpion.add_labels(rom);
        scorpion.boot();
        Ok(scorpion)
    }

    fn boot(&mut self) {
        let until = self.robot.now() + BOOT_TIME;
        self.robot.run(until);
    }

    /// Runs the robot to robot time `until` (or, while the host watches its
    /// line, until a byte reaches it): the surroundings woken when they
    /// asked to be, then a jammed CPU or a failed card reported.
    fn advance(&mut self, until: u64) -> Result<(), Error> {
        let mut runner = self.runner.take();
        let result = self.advance_with(until, |robot, to| match runner.as_mut() {
            Some(runner) => runner.run(robot, to),
            None => robot.run(to),
        });
        self.runner = runner;
        result.map(|_| ())
    }

    /// Tells the runner, if one is set, that the host entered the
    /// routine at `target` as a `JSR` does ([`Runner::entered`]).
    pub fn entered(&mut self, target: u16, s_before: u8) {
        if let Some(runner) = self.runner.as_mut() {
            runner.entered(&self.robot, target, s_before);
        }
    }

    /// Runs the CPU alone (no surroundings woken, no host) to robot time
    /// `until` or to the first instruction at an address of `stops`,
    /// through the runner if one is set: a routine called directly, run
    /// to its return.
    pub fn run_to(&mut self, until: u64, stops: &mut Breakpoints) -> Stop {
        match self.runner.as_mut() {
            Some(runner) => runner.run_to(&mut self.robot, until, stops),
            None => self.robot.run_with(until, stops),
        }
    }

    /// Every run from now on (the host's exchanges, settling, waiting for
    /// answers) goes through `runner` instead of the plain run; `None`
    /// goes back to the plain run. Returns the runner there was.
    pub fn set_runner(&mut self, runner: Option<Box<dyn Runner>>) -> Option<Box<dyn Runner>> {
        std::mem::replace(&mut self.runner, runner)
    }

    /// [`VirtualScorpion::advance`] with the caller's own run of the CPU
    /// (`run(robot, to)` runs to `to` or stops earlier, as
    /// [`emulator::Cpu::run`] does): the surroundings are woken between
    /// runs, and a stop before `to` (a hook's, a watching host's) ends it.
    fn advance_with(
        &mut self,
        until: u64,
        mut run: impl FnMut(&mut Scorpion, u64) -> Stop,
    ) -> Result<Stop, Error> {
        loop {
            let wake = self
                .world
                .as_ref()
                .and_then(|world| world.next_wake())
                .filter(|&at| at <= until);
            let to = wake.unwrap_or(until);
            if to > self.robot.now() {
                let stop = run(&mut self.robot, to);
                self.after_run(stop)?;
                if self.robot.now() < to || matches!(stop, Stop::Bus | Stop::Hook { .. }) {
                    return Ok(stop);
                }
            }
            let (Some(_), Some(world)) = (wake, self.world.as_mut()) else {
                return Ok(Stop::Limit);
            };
            let now = self.robot.now();
            world
                .wake(now, &mut self.robot)
                .map_err(|fault| Error::Surroundings {
                    message: fault.to_string(),
                    fault: [crate::error::ScriptFault(fault)],
                })?;
        }
    }

    /// Runs the robot to robot time `until` with the caller's own run of
    /// the CPU (hooks, a bus that watches memory: a debugger's), the
    /// surroundings woken as in [`VirtualScorpion::run_until`]. Returns
    /// the stop that ended it: [`Stop::Limit`] at `until`, or the caller's
    /// run's earlier stop.
    ///
    /// # Errors
    /// [`Error::Jam`], a card's or the surroundings' failure.
    pub fn run_until_with(
        &mut self,
        until: u64,
        run: impl FnMut(&mut Scorpion, u64) -> Stop,
    ) -> Result<Stop, Error> {
        self.advance_with(until, run)
    }

    /// A copy of the robot as it is now: the board and its CPU, the
    /// cards, the surroundings and what the host knows of the ROM
    /// ([`emulator::board::Scorpion::snapshot`], [`Surroundings::snapshot`]).
    /// The copy runs on exactly as this one would. `None` if a card or the
    /// surroundings cannot be copied.
    #[must_use]
    pub fn snapshot(&self) -> Option<VirtualScorpion> {
        let world = match &self.world {
            Some(world) => Some(world.snapshot()?),
            None => None,
        };
        Some(VirtualScorpion {
            robot: self.robot.snapshot()?,
            hooks: self.hooks,
            table: self.table,
            user: self.user.clone(),
            labels: self.labels.clone(),
            reference_rom: self.reference_rom,
            world,
            // The copy runs plainly: the host watches the robot it set
            // its run on.
            runner: None,
        })
    }

    /// Every label the robot knows (the ROM's, a ROM profile's, every
    /// loaded image's), in address order.
    #[must_use]
    pub fn labels(&self) -> Vec<(u16, String)> {
        self.all_labels().into_iter().cloned().collect()
    }

    /// The address of `kind`'s hook (the `JMP` in RAM the ROM goes through).
    #[must_use]
    pub fn hook_address(&self, kind: HookKind) -> u16 {
        self.hooks.address(kind)
    }

    fn after_run(&mut self, stop: Stop) -> Result<(), Error> {
        if let Some((base, fault)) = self.robot.board_mut().take_device_fault() {
            return Err(Error::Card {
                base,
                message: fault.to_string(),
                fault: [crate::error::ScriptFault(fault)],
            });
        }
        check(stop)
    }

    /// Gives the robot surroundings that change its inputs over robot
    /// time (bumpers, phototransistors), replacing any it had.
    pub fn set_surroundings(&mut self, world: Box<dyn Surroundings>) {
        self.world = Some(world);
    }

    /// The surroundings the robot has now, if any.
    #[must_use]
    pub fn surroundings(&self) -> Option<&dyn Surroundings> {
        self.world.as_deref()
    }

    /// Maps a card into the KIM-bus space at `start..=end`.
    ///
    /// # Errors
    /// [`Error::Emulator`] if the window leaves the KIM bus or overlaps
    /// another card.
    pub fn map_card(
        &mut self,
        start: u16,
        end: u16,
        card: Box<dyn emulator::board::Device>,
    ) -> Result<emulator::board::KimSlotId, Error> {
        Ok(self.robot.map_kim(start, end, card)?)
    }

    /// Keeps `image`'s labels (symbols in its sections) for
    /// [`Error::Stuck`] reports (loading an image keeps its own).
    pub fn add_labels(&mut self, image: &Image) {
        self.labels.extend(labels_of(image));
    }

    /// Every label, the reference ROM's (if it runs) and the others', in
    /// address order.
    fn all_labels(&self) -> Vec<&(u16, String)> {
        let rom = if self.reference_rom {
            reference_labels()
        } else {
            &[]
        };
        let mut labels: Vec<_> = rom.iter().chain(&self.labels).collect();
        labels.sort();
        labels
    }

    /// The label at or below `pc` (within a page), as `name+$offset`.
    #[must_use]
    pub fn place_of(&self, pc: u16) -> Option<String> {
        let labels = self.all_labels();
        let index = labels.partition_point(|(at, _)| *at <= pc);
        let (at, name) = labels.get(index.checked_sub(1)?)?;
        let offset = pc - at;
        (offset < 0x100).then(|| match offset {
            0 => name.clone(),
            _ => format!("{name}+${offset:X}"),
        })
    }

    /// Whether `pc` is in the ROM's `GETCH`/`CHKCH` (from `getch` up to the
    /// label after `chkch`): a handler waiting there for the host's next
    /// byte is waiting, not stuck.
    fn waiting_for_input(&self, pc: u16) -> bool {
        let labels = self.all_labels();
        let find = |name: &str| labels.iter().find(|(_, n)| n == name).map(|(at, _)| *at);
        let (Some(getch), Some(chkch)) = (find("getch"), find("chkch")) else {
            return false;
        };
        let end = labels
            .iter()
            .map(|(at, _)| *at)
            .find(|&at| at > chkch)
            .unwrap_or(chkch);
        (getch.min(chkch)..end).contains(&pc)
    }

    /// Watches the control loop for up to `within` cycles: `Ok(())` as soon
    /// as it passes `HOOK_LOOP` (the ROM's loop, or an operating system's,
    /// jumps through it every pass) or when a handler waits in `GETCH` for
    /// the host's next byte, else [`Error::Stuck`] saying where the CPU is. A handler that never
    /// returns, a JAM or a BRK into nowhere all end here.
    ///
    /// # Errors
    /// [`Error::Stuck`], [`Error::Jam`].
    pub fn check_loop(&mut self, within: u64) -> Result<(), Error> {
        let mut watch = emulator::Breakpoints::new();
        watch.insert(self.hooks.main_loop);
        let until = self.robot.now().saturating_add(within);
        match self.robot.run_with(until, &mut watch) {
            Stop::Hook { .. } => Ok(()),
            Stop::Jam { pc, opcode } => Err(Error::Jam { pc, opcode }),
            _ if self.waiting_for_input(self.robot.cpu.pc) => Ok(()),
            _ => {
                let pc = self.robot.cpu.pc;
                Err(Error::Stuck {
                    pc,
                    place: self
                        .place_of(pc)
                        .map_or_else(String::new, |p| format!(" ({p})")),
                    for_ms: within * 1000 / CPU_HZ,
                })
            }
        }
    }

    /// The emulated robot: the CPU, the board and the host's end of the
    /// line.
    #[must_use]
    pub fn robot(&self) -> &Scorpion {
        &self.robot
    }

    /// The emulated robot, mutable (press bumpers, set sensors, map KIM-bus
    /// devices).
    pub fn robot_mut(&mut self) -> &mut Scorpion {
        &mut self.robot
    }

    /// Robot time since power-up, in cycles of the 1 MHz CPU.
    #[must_use]
    pub fn cycles(&self) -> u64 {
        self.robot.now()
    }

    /// Sets the line to `bits_per_second` on both ends: the host's UART and
    /// the robot's DIP switches, then presses reset so the ROM programs the
    /// new rate. Returns `false` (and changes nothing) if the 6551 has no
    /// such rate.
    pub fn set_baud(&mut self, bits_per_second: u32) -> bool {
        if self.robot.set_switch_baud(bits_per_second).is_none() {
            return false;
        }
        self.robot.set_baud(bits_per_second);
        self.robot.power_on();
        self.boot();
        true
    }

    /// Loads `image` as an upload leaves it: the table of installed
    /// extensions read first (an image that overlaps one is refused), every
    /// loaded area written into RAM, the image's table entries, then each
    /// hook it takes over installed (chain slot first, then the hook's
    /// operand). Returns the hooks installed.
    ///
    /// # Errors
    /// [`Error::Emulator`] if an area does not fit in RAM,
    /// [`Error::Overlap`] if it overlaps an installed extension,
    /// [`Error::TableFull`], [`Error::DamagedTable`], [`Error::HookNotJmp`]
    /// if a hook does not hold a `JMP`. Nothing is written when any of
    /// these is found before the first write.
    pub fn load_image(&mut self, image: &Image) -> Result<Vec<InstalledHook>, Error> {
        for area in &image.areas {
            self.check_ram(area.load, area.bytes.len())?;
        }
        let extents = installed::image_extents(image);
        if !self.user.is_empty()
            && let Some(outside) = extents.iter().find(|extent| {
                !self
                    .user
                    .iter()
                    .any(|user| user.start() <= extent.start() && extent.end() <= user.end())
            })
        {
            let allowed: Vec<String> = self.user.iter().map(installed::extent_text).collect();
            return Err(Error::NotUserMemory {
                extent: installed::extent_text(outside),
                allowed: allowed.join(", "),
            });
        }
        let mut entry = None;
        if let Some((table, capacity)) = self.table {
            let present = self.installed()?;
            if let Some(refusal) = present.iter().find_map(|old| old.overlap(&extents)) {
                return Err(refusal);
            }
            let id = installed::image_id(image.areas.iter().flat_map(|a| a.bytes.iter().copied()));
            let new = installed::Installed::new(id, extents, &image.hooks.records);
            let slot =
                installed::free_slot(&present, new.entries(), capacity).ok_or_else(|| {
                    Error::TableFull {
                        capacity,
                        reason: format!(
                            "the image needs {}",
                            installed::entries_text(new.entries())
                        ),
                    }
                })?;
            entry = Some((
                installed::entry_address(table, capacity, slot),
                new.encode(),
                installed::flags_address(table, slot),
                new.flags(),
            ));
        }
        for area in &image.areas {
            let start = u16::try_from(area.load).unwrap_or_else(|_| unreachable!("checked"));
            self.robot.board_mut().load(start, &area.bytes)?;
        }
        // The entries, then their flags, which make them count.
        if let Some((at, bytes, flags_at, flags)) = entry {
            self.robot.board_mut().load(at, &bytes)?;
            self.robot.board_mut().load(flags_at, &flags)?;
        }
        self.add_labels(image);
        let mut installed = Vec::new();
        for record in &image.hooks.records {
            installed.push(self.install_hook(record.kind, record.handler, record.chain)?);
        }
        Ok(installed)
    }

    /// What the robot's table of installed extensions holds (empty if the
    /// ROM keeps no table).
    ///
    /// # Errors
    /// [`Error::DamagedTable`] if it holds what no loader wrote.
    pub fn installed(&self) -> Result<Vec<installed::Installed>, Error> {
        let Some((table, capacity)) = self.table else {
            return Ok(Vec::new());
        };
        let memory = self.robot.board().memory();
        let start = usize::from(table);
        let bytes = memory
            .get(start..start + capacity * (1 + installed::ENTRY_LEN))
            .unwrap_or_default();
        Ok(installed::decode_table(table, capacity, bytes)?)
    }

    /// Whether `len` bytes from `load` are all RAM the board lets a loader
    /// write (no ROM, I/O page or mapped KIM-bus device, nothing past `$FFFF`).
    fn check_ram(&self, load: u32, len: usize) -> Result<(), Error> {
        let board = self.robot.board();
        for offset in 0..len {
            let at = u64::from(load) + offset as u64;
            let address = u16::try_from(at).ok().filter(|&a| board.is_ram(a));
            if address.is_none() {
                return Err(emulator::Error::NotRam {
                    address: u16::try_from(at).unwrap_or(0xFFFF),
                    len,
                }
                .into());
            }
        }
        Ok(())
    }

    /// Points a hook at `handler`, first writing its previous target into
    /// `chain` (two bytes, little-endian) when given.
    ///
    /// # Errors
    /// [`Error::HookNotJmp`] if the hook does not hold a `JMP`.
    pub fn install_hook(
        &mut self,
        kind: HookKind,
        handler: u16,
        chain: Option<u16>,
    ) -> Result<InstalledHook, Error> {
        let hook = self.hooks.address(kind);
        let memory = self.robot.board().memory();
        let opcode = memory[usize::from(hook)];
        if opcode != 0x4C {
            return Err(Error::HookNotJmp {
                hook: kind.rom_symbol(),
                address: hook,
                found: opcode,
            });
        }
        let previous = u16::from_le_bytes([
            memory[usize::from(hook.wrapping_add(1))],
            memory[usize::from(hook.wrapping_add(2))],
        ]);
        if previous == handler {
            return Err(Error::HookedTwice {
                hook: kind.rom_symbol(),
                handler,
            });
        }
        if let Some(slot) = chain {
            self.robot.board_mut().load(slot, &previous.to_le_bytes())?;
        }
        self.robot
            .board_mut()
            .load(hook.wrapping_add(1), &handler.to_le_bytes())?;
        Ok(InstalledHook {
            kind,
            handler,
            previous,
            chain,
        })
    }

    /// Sends raw bytes, back to back from now, without running the robot.
    pub fn send(&mut self, bytes: &[u8]) {
        self.robot.send(bytes);
    }

    /// What the robot sent that the host has not read yet.
    pub fn receive(&mut self) -> Vec<u8> {
        self.robot.receive()
    }

    /// Runs the robot for `cycles`.
    ///
    /// # Errors
    /// [`Error::Jam`] if the CPU jams.
    pub fn run_for(&mut self, cycles: u64) -> Result<(), Error> {
        let until = self.robot.now().saturating_add(cycles);
        self.run_until(until)
    }

    /// Runs the robot until robot time `cycle` (since power-up).
    ///
    /// # Errors
    /// [`Error::Jam`] if the CPU jams.
    pub fn run_until(&mut self, cycle: u64) -> Result<(), Error> {
        self.advance(cycle)
    }

    /// Runs the robot until robot time `cycle`, or until a byte reaches
    /// the host if one does before: the end of the instruction during
    /// which it arrived, as a host that waits for an answer sees it. What
    /// the robot does is the same either way; only the host looks sooner.
    ///
    /// # Errors
    /// [`Error::Jam`] if the CPU jams.
    pub fn run_until_received(&mut self, cycle: u64) -> Result<(), Error> {
        self.robot.board_mut().watch_host(true);
        let result = self.advance(cycle);
        self.robot.board_mut().watch_host(false);
        result
    }

    /// Whether everything the host sent has gone down the wire.
    #[must_use]
    pub fn line_idle(&self) -> bool {
        self.robot.host_line_free_at() <= self.robot.now()
    }

    /// Sets the host's end of the line only (the robot keeps the rate its
    /// switches gave the ROM): what a host does when the robot was told to
    /// change its rate. See [`VirtualScorpion::set_baud`] for both ends.
    pub fn set_host_baud(&mut self, bits_per_second: u32) {
        self.robot.set_baud(bits_per_second);
    }

    /// The host's end of the line's rate, in whole bits per second.
    #[must_use]
    pub fn host_baud(&self) -> u32 {
        let rate = self.robot.board().acia().host_baud().bits_per_second();
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "a 6551 rate, 50 to 19200"
        )]
        let whole = rate.round() as u32;
        whole
    }

    /// Closes the bumpers whose bits are set in `closed` (bit 0 the first
    /// switch), opening the others, now.
    pub fn set_bumpers(&mut self, closed: u8) {
        self.robot.set_bumpers(closed);
    }

    /// Runs the robot until everything sent has arrived and the ROM had
    /// [`INSTRUCTION_TIME`] to act on it.
    ///
    /// # Errors
    /// [`Error::Jam`] if the CPU jams.
    pub fn settle(&mut self) -> Result<(), Error> {
        let until = self
            .robot
            .host_line_free_at()
            .saturating_add(INSTRUCTION_TIME);
        self.advance(until)
    }

    /// Runs the robot until the host has received an answer's carriage
    /// return or `timeout` cycles passed, and returns what the host received
    /// up to and including it; bytes after it stay for the next call.
    ///
    /// # Errors
    /// [`Error::Jam`] if the CPU jams; [`Error::NoAnswer`] on timeout (or
    /// [`Error::Stuck`] if the ROM's loop stopped coming round), with what
    /// did arrive.
    pub fn read_answer(&mut self, timeout: u64) -> Result<Vec<u8>, Error> {
        self.read_answer_to(b"", timeout)
    }

    /// [`VirtualScorpion::read_answer`], naming `command` in the error.
    fn read_answer_to(&mut self, command: &[u8], timeout: u64) -> Result<Vec<u8>, Error> {
        let deadline = self.robot.now().saturating_add(timeout);
        loop {
            let now = self.robot.now();
            if let Some(answer) = self.robot.receive_until(EOL) {
                return Ok(answer);
            }
            if now >= deadline {
                // No answer: a robot whose loop stopped says where.
                let received = self.robot.receive();
                self.check_loop(LOOP_WATCH)?;
                return Err(Error::NoAnswer {
                    command: escape(command),
                    received: escape(&received),
                    timeout_ms: timeout * 1000 / CPU_HZ,
                });
            }
            self.run_until_received(deadline)?;
        }
    }

    /// Sends `bytes` and waits up to `timeout` cycles for an answer (up to
    /// and including its carriage return). Bytes received before the
    /// command are discarded first.
    ///
    /// # Errors
    /// As [`VirtualScorpion::read_answer`].
    pub fn transact(&mut self, bytes: &[u8], timeout: u64) -> Result<Vec<u8>, Error> {
        self.robot.receive();
        self.robot.send(bytes);
        self.read_answer_to(bytes, timeout)
    }

    /// Sends a command; for a question, waits for its answer and parses
    /// it, for an instruction lets the robot act on it. Extension commands
    /// are treated as instructions: use [`VirtualScorpion::ask_extension`]
    /// for one that answers.
    ///
    /// # Errors
    /// [`Error::NoAnswer`], a [`Error::Protocol`] error for an answer that
    /// is malformed or not the one asked for, [`Error::Jam`].
    pub fn exchange(&mut self, command: &Command) -> Result<Option<Answer>, Error> {
        if command.is_question() {
            let raw = self.transact(&command.encode(), ANSWER_TIMEOUT)?;
            Ok(Some(command.parse_answer(&raw)?))
        } else {
            self.robot.receive();
            self.robot.send(&command.encode());
            self.settle()?;
            Ok(None)
        }
    }

    /// Sends an extension command that answers, and returns its answer.
    ///
    /// # Errors
    /// As [`VirtualScorpion::exchange`].
    pub fn ask_extension(&mut self, command: &Command) -> Result<Answer, Error> {
        let raw = self.transact(&command.encode(), ANSWER_TIMEOUT)?;
        Ok(command.parse_answer(&raw)?)
    }
}

fn check(stop: Stop) -> Result<(), Error> {
    match stop {
        Stop::Jam { pc, opcode } => Err(Error::Jam { pc, opcode }),
        _ => Ok(()),
    }
}

/// Bytes as text with control characters escaped (`\r`).
#[must_use]
pub fn escape(bytes: &[u8]) -> String {
    bytes
        .iter()
        .flat_map(|&byte| std::ascii::escape_default(byte))
        .map(char::from)
        .collect()
}

#[cfg(test)]
mod tests {
    use isa::objfmt::{HookRecord, Hooks};
    use linker::LoadArea;

    use super::*;
    use crate::protocol::{Answer, BusyByte};

    /// An image of `bytes` at `load` taking `hooks`.
    fn image(load: u32, bytes: &[u8], hooks: Vec<HookRecord>) -> Image {
        Image {
            entry: load,
            areas: vec![LoadArea {
                load,
                run: load,
                bytes: bytes.to_vec(),
            }],
            hooks: Hooks { records: hooks },
            ..Image::default()
        }
    }

    /// A handler: if the letter is `letter`, answer `letter` and end the
    /// command; else `JMP` through its chain slot (the handler's byte 14).
    fn handler(letter: u8) -> Vec<u8> {
        let [pl, ph] = symbols::PUTCH.to_le_bytes();
        let [el, eh] = symbols::PUTEOL.to_le_bytes();
        let [dl, dh] = symbols::CMD_DONE.to_le_bytes();
        vec![
            0xC9, letter, // CMP #letter
            0xD0, 0x09, // BNE chain (skip 9 bytes)
            0x20, pl, ph, // JSR PUTCH
            0x20, el, eh, // JSR PUTEOL
            0x4C, dl, dh, // JMP CMD_DONE
            0x4C, 0x00, 0x00, // chain: JMP (filled in by the loader)
        ]
    }

    #[test]
    fn boots_and_answers() {
        let mut robot = VirtualScorpion::new();
        let answer = robot.exchange(&Command::Busy).expect("an answer");
        assert_eq!(answer, Some(Answer::Busy(BusyByte(0))));
        assert!(robot.cycles() > BOOT_TIME);
    }

    #[test]
    fn images_load_and_hooks_chain_in_order() {
        let mut robot = VirtualScorpion::new();
        let first = image(
            0x0400,
            &handler(b'Q'),
            vec![HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0400,
                chain: Some(0x0400 + 14),
            }],
        );
        let second = image(
            0x0500,
            &handler(b'J'),
            vec![HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0500,
                chain: Some(0x0500 + 14),
            }],
        );
        let hooks = robot.load_image(&first).expect("fits in RAM");
        assert_eq!(hooks[0].previous, symbols::BAD_COMMAND);
        let hooks = robot.load_image(&second).expect("fits in RAM");
        assert_eq!(hooks[0].previous, 0x0400, "the second chains to the first");
        assert_eq!(robot.transact(b"/1J", ANSWER_TIMEOUT).expect("J"), b"J\r");
        assert_eq!(robot.transact(b"/1Q", ANSWER_TIMEOUT).expect("Q"), b"Q\r");
        let error = robot
            .transact(b"/1Z", 50_000)
            .expect_err("nobody answers /1Z");
        assert!(matches!(error, Error::NoAnswer { .. }), "{error}");
        // The ROM's own commands still work.
        assert_eq!(robot.transact(b"/1E", ANSWER_TIMEOUT).expect("E"), b"E0\r");
    }

    #[test]
    fn an_image_outside_ram_is_refused_whole() {
        let mut robot = VirtualScorpion::new();
        let mut bad = image(0x0F3E, &[1, 2, 3, 4], Vec::new());
        // $0F3E-$0F41 runs from user RAM into INJECT's queue, the ROM's.
        let error = robot.load_image(&bad).expect_err("into the ROM's RAM");
        assert!(
            matches!(&error, Error::NotUserMemory { extent, .. } if extent == "$0F3E-$0F41"),
            "{error}"
        );
        assert_eq!(robot.robot().board().memory()[0x0F3E], 0, "nothing written");
        bad.areas[0].load = 0x0200;
        assert!(
            matches!(robot.load_image(&bad), Err(Error::NotUserMemory { .. })),
            "onto the hooks"
        );
        bad.areas[0].load = 0x1000;
        robot.load_image(&bad).expect("KIM-bus RAM");
        bad.areas[0].load = 0xBFFE;
        let error = robot.load_image(&bad).expect_err("runs into the I/O page");
        assert!(
            matches!(
                error,
                Error::Emulator(emulator::Error::NotRam {
                    address: 0xC000,
                    ..
                })
            ),
            "{error}"
        );
        assert_eq!(robot.robot().board().memory()[0xBFFE], 0, "nothing written");
        bad.areas[0].load = 0xFFFE;
        assert!(robot.load_image(&bad).is_err(), "past $FFFF");
    }

    #[test]
    fn a_hook_that_is_not_a_jmp_is_not_installed() {
        let mut robot = VirtualScorpion::new();
        robot
            .robot_mut()
            .board_mut()
            .load(symbols::HOOK_LOOP, &[0xEA])
            .expect("RAM");
        let error = robot
            .install_hook(HookKind::Loop, 0x0400, None)
            .expect_err("a NOP is not a JMP");
        assert!(
            matches!(error, Error::HookNotJmp { found: 0xEA, .. }),
            "{error}"
        );
    }

    #[test]
    fn a_jam_is_reported() {
        let mut robot = VirtualScorpion::new();
        // A handler that is a JAM opcode.
        robot
            .load_image(&image(0x0400, &[0x02], Vec::new()))
            .expect("RAM");
        robot
            .install_hook(HookKind::Unknown, 0x0400, None)
            .expect("a JMP");
        let error = robot
            .transact(b"/1Z", ANSWER_TIMEOUT)
            .expect_err("the CPU jams");
        assert!(
            matches!(
                error,
                Error::Jam {
                    pc: 0x0400,
                    opcode: 0x02
                }
            ),
            "{error}"
        );
    }

    #[test]
    fn the_baud_rate_is_set_on_both_ends() {
        let mut robot = VirtualScorpion::new();
        assert!(!robot.set_baud(1000), "the 6551 has no 1000 baud");
        assert!(robot.set_baud(19_200));
        assert_eq!(robot.transact(b"/1X", ANSWER_TIMEOUT).expect("X"), b"X00\r");
        // Host and robot at different rates: garbage, no answer.
        robot.robot_mut().set_baud(9600);
        assert!(robot.transact(b"/1X", 100_000).is_err());
    }

    #[test]
    fn a_rom_profile_needs_the_whole_rom_and_its_hooks() {
        let rom = Image::parse("rom", crate::ROM_ELF).expect("the reference ROM's ELF");
        let mut robot = VirtualScorpion::with_rom("reference", &rom).expect("a valid profile");
        assert_eq!(robot.transact(b"/1E", ANSWER_TIMEOUT).expect("E"), b"E0\r");
        let mut short = rom.clone();
        short.areas[0].bytes.truncate(100);
        let error = VirtualScorpion::with_rom("short", &short).expect_err("missing bytes");
        assert!(error.to_string().contains("no byte for"), "{error}");
        let mut nameless = rom;
        nameless.symbols.retain(|symbol| symbol.name != "HOOK_LOOP");
        let error = VirtualScorpion::with_rom("nameless", &nameless).expect_err("no HOOK_LOOP");
        assert!(error.to_string().contains("HOOK_LOOP"), "{error}");
    }
}
