//! The run loop's shortcuts change nothing but the host's time. The
//! reference ROM on the Scorpion board goes through a conformance-style
//! session three ways: with idle-loop skipping allowed; running every
//! cycle; and running every cycle on a bus that passes only `read`,
//! `write`, `peek` and `poll` to the board, so that no poll is skipped as
//! quiet, every dummy read is a read, and page zero and the stack are
//! decoded like any address. All three end in the same state (registers,
//! counters, memory, every chip, motor and latch, the KIM-bus card) having
//! sent the host the same bytes at the same cycles. Skipping must also
//! really happen, or the test proves nothing.

use std::any::Any;

use emulator::board::{Board, Device, HostByte, Scorpion};
use emulator::{Bus, Interrupts, Machine, NoHooks, Ram, Stop};

/// The board through the four required methods of [`Bus`] only: every
/// provided method keeps its default.
struct Generic<'a>(&'a mut Board);

impl Bus for Generic<'_> {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        self.0.read(address, cycle)
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.0.write(address, value, cycle);
    }

    fn peek(&self, address: u16) -> u8 {
        self.0.peek(address)
    }

    fn poll(&mut self, cycle: u64) -> Interrupts {
        self.0.poll(cycle)
    }
}

/// How the session runs the CPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Skipping,
    Running,
    GenericBus,
    /// Skipping, with the host watching its line: every byte that reaches
    /// it ends the run.
    Watching,
}

/// A KIM-bus card with a clock: it catches up every 10,000 cycles (device
/// events that raise no interrupt but bound every skip) and reads back how
/// many it has counted, with a read side effect (a read counter).
#[derive(Debug, Default)]
struct ClockCard {
    now: u64,
    ticks: u64,
    reads: u8,
}

const TICK: u64 = 10_000;

impl Device for ClockCard {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.sync(cycle);
        self.reads = self.reads.wrapping_add(1);
        match offset {
            0 => self.ticks.to_le_bytes()[0],
            _ => self.reads,
        }
    }

    fn write(&mut self, _offset: u16, _value: u8, cycle: u64) {
        self.sync(cycle);
    }

    fn peek(&self, offset: u16) -> u8 {
        match offset {
            0 => self.ticks.to_le_bytes()[0],
            _ => self.reads,
        }
    }

    fn sync(&mut self, cycle: u64) {
        if cycle > self.now {
            self.ticks = cycle / TICK;
            self.now = cycle;
        }
    }

    fn next_event(&self) -> Option<u64> {
        Some((self.now / TICK + 1) * TICK)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// What the host does, and when (in milliseconds of robot time).
enum Action {
    Send(&'static [u8]),
    Bumpers(u8),
}

/// A session touching every part of the board: questions, lamps, eyes, the
/// speaker (timer 1 running free), both drives in both modes, a scan, the
/// bumpers and the Master I/O byte, RAM writes and reads, the KIM-bus card,
/// a reset, a burst of back-to-back commands, and long idle stretches.
const SCRIPT: &[(u64, Action)] = &[
    (5, Action::Send(b"/1P")),
    (30, Action::Send(b"/2E3/2G1")),
    (60, Action::Send(b"/3K20")),
    (90, Action::Send(b"/1X/1E/1G")),
    (120, Action::Send(b"/3K00/4C+50")),
    (200, Action::Send(b"/8D-100500")),
    (400, Action::Send(b"/1C/1D/1M")),
    (450, Action::Send(b"/3H05")),
    (700, Action::Send(b"/1S")),
    (750, Action::Bumpers(0x04)),
    (800, Action::Send(b"/1B/1P")),
    (850, Action::Bumpers(0x00)),
    (900, Action::Send(b"/3Z7F/3Y00/3ZFF/1P")),
    (1000, Action::Send(b"/9W04031234/9W0405BEEF/7R040304")),
    (1100, Action::Send(b"/7R800002/7R800002")),
    (1200, Action::Send(b"/1R")),
    (1250, Action::Send(b"/1P")),
    (
        1300,
        Action::Send(b"/9W10001234/9W10021234/9W10041234/9W10061234/9W10081234/7R100010"),
    ),
    (4000, Action::Send(b"/1P/7R800002")),
];

const END_MS: u64 = 5_000;

/// Runs the session; returns the robot and everything the host received.
fn session(mode: Mode) -> (Scorpion, Vec<HostByte>) {
    let mut robot = Scorpion::scorpion(romlib::ROM).expect("the reference ROM is 4 KiB");
    robot
        .cpu
        .set_idle_skip(matches!(mode, Mode::Skipping | Mode::Watching));
    robot.board_mut().watch_host(mode == Mode::Watching);
    robot
        .map_kim(0x8000, 0x8001, Box::new(ClockCard::default()))
        .expect("free KIM-bus space");
    let mut received = Vec::new();
    let mut stops = 0;
    let mut script = SCRIPT.iter().peekable();
    // Slices of odd lengths, so that runs end in every phase of the loops.
    let mut slice = 0u64;
    while robot.now() < END_MS * 1000 {
        while let Some((_, action)) = script.next_if(|(at, _)| *at * 1000 <= robot.now()) {
            match action {
                Action::Send(bytes) => {
                    robot.send(bytes);
                }
                Action::Bumpers(closed) => robot.set_bumpers(*closed),
            }
        }
        slice = (slice * 7 + 613) % 5_000 + 1;
        let until = robot.now() + slice;
        // A watching host's runs also end at every byte that reaches it;
        // it takes the byte and runs on to the slice's end, so the host
        // acts at the same cycles in every mode.
        loop {
            let stop = if mode == Mode::GenericBus {
                robot
                    .cpu
                    .run(&mut Generic(&mut robot.bus), until, &mut NoHooks)
            } else {
                robot.run(until)
            };
            let arrived = robot.receive_detailed();
            let watched = stop == Stop::Bus;
            if watched {
                // Ended by a byte's arrival, at the end of the instruction
                // it arrived in: no later than the longest one after it.
                let last = arrived.last().expect("a byte ended the run");
                assert!(
                    last.at <= robot.now() && robot.now() - last.at <= 8,
                    "a byte at {} seen at {}",
                    last.at,
                    robot.now()
                );
                stops += 1;
            } else {
                assert_eq!(stop, Stop::Limit, "the ROM runs on");
            }
            received.extend(arrived);
            if !watched {
                break;
            }
        }
    }
    if mode == Mode::Watching {
        assert!(stops >= 100, "every byte ended a run: {stops} did");
    }
    // Every mode ends at the same cycle, whatever its last slices were.
    robot.board_mut().watch_host(false);
    assert_eq!(robot.run(END_MS * 1000 + 6_000), Stop::Limit);
    received.extend(robot.receive_detailed());
    (robot, received)
}

/// Asserts that two sessions ended alike.
fn assert_same(a: &(Scorpion, Vec<HostByte>), b: &(Scorpion, Vec<HostByte>), what: &str) {
    assert_eq!(a.0.cpu, b.0.cpu, "{what}: registers, flags and counters");
    assert_eq!(a.0.board().memory(), b.0.board().memory(), "{what}: memory");
    assert_eq!(
        format!("{:?}", a.0.board()),
        format!("{:?}", b.0.board()),
        "{what}: the chips, motors, latches, lines, device schedule and KIM-bus card"
    );
    assert_eq!(a.1, b.1, "{what}: what the host received, and when");
}

#[test]
fn skipping_idle_loops_and_the_board_shortcuts_leave_the_board_exactly_as_running_every_cycle() {
    let skipped = session(Mode::Skipping);
    let run = session(Mode::Running);
    let generic = session(Mode::GenericBus);
    let watched = session(Mode::Watching);
    assert_same(&skipped, &run, "skipping against running");
    assert_same(&watched, &run, "a watching host against running");
    assert_same(
        &run,
        &generic,
        "the board's shortcuts against the plain contract",
    );
    let text: Vec<u8> = run.1.iter().map(|b| b.byte).collect();
    let text = String::from_utf8_lossy(&text);
    assert!(
        text.contains("R1234BEEF"),
        "the session did its work: {text}"
    );
    assert!(
        text.matches("\r").count() >= 15,
        "every question answered: {text}"
    );
    // Skipping happened, and most of a mostly idle session was skipped.
    assert_eq!(run.0.cpu.skipped_cycles(), 0);
    assert_eq!(generic.0.cpu.skipped_cycles(), 0);
    let share = skipped.0.cpu.skipped_cycles() * 100 / skipped.0.cpu.cycles();
    assert!(share >= 50, "only {share}% of the cycles were skipped");
}

/// A KIM-bus card whose one register counts its ticks: it changes only at
/// the card's events and reading it has no side effect, so it is stable.
#[derive(Debug, Default)]
struct TickCard {
    now: u64,
}

impl Device for TickCard {
    fn read(&mut self, _offset: u16, cycle: u64) -> u8 {
        self.sync(cycle);
        self.peek(0)
    }

    fn write(&mut self, _offset: u16, _value: u8, cycle: u64) {
        self.sync(cycle);
    }

    fn peek(&self, _offset: u16) -> u8 {
        (self.now / TICK).to_le_bytes()[0]
    }

    fn is_stable(&self, _offset: u16) -> bool {
        true
    }

    fn sync(&mut self, cycle: u64) {
        self.now = self.now.max(cycle);
    }

    fn next_event(&self) -> Option<u64> {
        Some((self.now / TICK + 1) * TICK)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

#[test]
fn a_loop_polling_a_stable_card_register_is_skipped_to_the_cards_events() {
    // $F000: LDA $8000 / CMP #5 / BNE $F000 / STA $0300 / JMP $F00A - waits
    // for the card's fifth tick, then writes it down.
    let mut rom = vec![0xEA; 4096];
    rom[..13].copy_from_slice(&[
        0xAD, 0x00, 0x80, 0xC9, 0x05, 0xD0, 0xF9, 0x8D, 0x00, 0x03, 0x4C, 0x0A, 0xF0,
    ]);
    rom[0xFFC..].copy_from_slice(&0xF000u16.to_le_bytes().repeat(2));
    let robots = [true, false].map(|skip| {
        let mut robot = Scorpion::scorpion(&rom).expect("4 KiB");
        robot.cpu.set_idle_skip(skip);
        robot
            .map_kim(0x8000, 0x8000, Box::new(TickCard::default()))
            .expect("free KIM-bus space");
        assert_eq!(robot.run(80_000), Stop::Limit);
        robot
    });
    let [skipped, run] = robots;
    assert_eq!(skipped.cpu, run.cpu);
    assert_eq!(skipped.board().memory(), run.board().memory());
    assert_eq!(
        run.board().memory()[0x0300],
        5,
        "the loop saw the fifth tick"
    );
    assert!(skipped.cpu.skipped_cycles() > 40_000);
}

/// Breakpoints look at every instruction, yet a loop that passes none of
/// them is skipped as without them, and the run stops where running every
/// cycle stops: at the breakpoint after the loop, in the same state.
#[test]
fn breakpoints_elsewhere_let_the_loop_be_skipped_and_stop_where_running_stops() {
    // The loop of the test above; $F007 is its STA $0300, after the loop.
    let mut rom = vec![0xEA; 4096];
    rom[..13].copy_from_slice(&[
        0xAD, 0x00, 0x80, 0xC9, 0x05, 0xD0, 0xF9, 0x8D, 0x00, 0x03, 0x4C, 0x0A, 0xF0,
    ]);
    rom[0xFFC..].copy_from_slice(&0xF000u16.to_le_bytes().repeat(2));
    let robots = [true, false].map(|skip| {
        let mut robot = Scorpion::scorpion(&rom).expect("4 KiB");
        robot.cpu.set_idle_skip(skip);
        robot
            .map_kim(0x8000, 0x8000, Box::new(TickCard::default()))
            .expect("free KIM-bus space");
        let mut points = emulator::Breakpoints::new();
        points.insert(0xF007);
        points.insert(0x0300);
        let stop = robot.run_with(80_000, &mut points);
        assert_eq!(stop, Stop::Hook { pc: 0xF007 });
        robot
    });
    let [skipped, run] = robots;
    assert_eq!(skipped.cpu, run.cpu);
    assert_eq!(skipped.board().memory(), run.board().memory());
    assert!(skipped.cpu.cycles() >= 5 * TICK);
    assert!(
        skipped.cpu.skipped_cycles() > 40_000,
        "skipped {}",
        skipped.cpu.skipped_cycles()
    );
}

/// A count the hooks stop at bounds the skip: the run stops before the
/// instruction with that count, as running every cycle does.
#[test]
fn a_count_to_stop_at_bounds_the_skip() {
    /// Stops before the instruction with count `0`.
    struct AtCount(u64);
    impl emulator::Hooks for AtCount {
        fn may_skip_idle(&self) -> bool {
            true
        }
        fn instruction_bound(&self) -> u64 {
            self.0
        }
        fn before_instruction<B: Bus>(
            &mut self,
            cpu: &emulator::Cpu,
            _bus: &B,
        ) -> emulator::Control {
            if cpu.instructions() >= self.0 {
                emulator::Control::Stop
            } else {
                emulator::Control::Continue
            }
        }
    }
    let program = [
        0xA6, 0x10, 0xE8, 0xCA, 0xE4, 0x11, 0xD0, 0xF8, 0x4C, 0x00, 0x04,
    ];
    let machines = [true, false].map(|skip| {
        let mut ram = Ram::new();
        ram.load(0x0400, &program).expect("fits");
        let mut machine = Machine::new(ram);
        machine.cpu.pc = 0x0400;
        machine.cpu.set_idle_skip(skip);
        let stop = machine.run_with(u64::MAX, &mut AtCount(100_003));
        assert!(matches!(stop, Stop::Hook { .. }), "{stop:?}");
        machine
    });
    let [skipped, run] = machines;
    assert_eq!(skipped.cpu, run.cpu);
    assert_eq!(skipped.cpu.instructions(), 100_003);
    assert!(skipped.cpu.skipped_cycles() > 0);
}

/// `program` at $0400 on the plain RAM machine, run to `until` with idle
/// skipping and without: [skipped, run].
fn both_ways(program: &[u8], until: u64) -> [emulator::RamMachine; 2] {
    [true, false].map(|skip| {
        let mut ram = Ram::new();
        ram.load(0x0400, program).expect("fits");
        let mut machine = Machine::new(ram);
        machine.cpu.pc = 0x0400;
        machine.cpu.set_idle_skip(skip);
        let stop = machine.run_with(until, &mut NoHooks);
        assert_eq!(stop, Stop::Limit);
        machine
    })
}

#[test]
fn a_loop_on_plain_ram_is_skipped_to_the_limit_and_counted_exactly() {
    // $0400: LDX $10 / INX / DEX / CPX $11 / BNE $0400 / JMP $0400 - the
    // BNE falls through (X equals $11's zero), so the loop is LDX..JMP.
    let program = [
        0xA6, 0x10, 0xE8, 0xCA, 0xE4, 0x11, 0xD0, 0xF8, 0x4C, 0x00, 0x04,
    ];
    let [skipped, run] = both_ways(&program, 1_000_003);
    assert_eq!(skipped.cpu, run.cpu);
    assert!(skipped.cpu.cycles() >= 1_000_003 && skipped.cpu.cycles() < 1_000_003 + 4);
    assert!(skipped.cpu.skipped_cycles() > 990_000);
    assert_eq!(run.cpu.skipped_cycles(), 0);
}

#[test]
fn a_loop_that_stores_what_is_there_is_skipped_exactly() {
    // $0400: JSR $0410 / LDA $10 / STA $11 / JMP $0400, $0410: RTS - the
    // JSR pushes the same return address every lap and the STA stores the
    // zero already at $11: writes, but nothing changes.
    let mut program = vec![0x20, 0x10, 0x04, 0xA5, 0x10, 0x85, 0x11, 0x4C, 0x00, 0x04];
    program.resize(0x10, 0xEA);
    program.push(0x60);
    let [skipped, run] = both_ways(&program, 500_001);
    assert_eq!(skipped.cpu, run.cpu);
    assert_eq!(skipped.bus.bytes(), run.bus.bytes());
    assert!(skipped.cpu.skipped_cycles() > 490_000);
}

#[test]
fn loops_that_change_memory_or_write_the_rom_are_run() {
    // $0400: JSR $0410 / INC $11 / JMP $0400: the stores of the JSR change
    // nothing after the first lap, the INC changes $11 every lap.
    let mut program = vec![0x20, 0x10, 0x04, 0xE6, 0x11, 0x4C, 0x00, 0x04];
    program.resize(0x10, 0xEA);
    program.push(0x60);
    let mut ram = Ram::new();
    ram.load(0x0400, &program).expect("fits");
    let mut machine = Machine::new(ram);
    machine.cpu.pc = 0x0400;
    machine.run_with(200_000, &mut NoHooks);
    assert_eq!(machine.cpu.skipped_cycles(), 0, "a changing counter");
    // $F000: LDA $F000 / STA $F000 / JMP $F000 stores the ROM's own byte
    // back: the board counts every ROM write, so that is not nothing.
    let mut rom = vec![0xEA; 4096];
    rom[..9].copy_from_slice(&[0xAD, 0x00, 0xF0, 0x8D, 0x00, 0xF0, 0x4C, 0x00, 0xF0]);
    rom[0xFFC..].copy_from_slice(&0xF000u16.to_le_bytes().repeat(2));
    let mut robot = Scorpion::scorpion(&rom).expect("4 KiB");
    robot.run(200_000);
    assert_eq!(robot.cpu.skipped_cycles(), 0, "ROM writes");
    assert!(robot.board().rom_writes() > 10_000);
}

#[test]
fn loops_that_write_or_touch_io_are_run() {
    // $F000: INC $0300 / JMP $F000 writes every lap; $F006: LDA $C011 /
    // JMP $F006 reads the 6551's status (an I/O read) every lap.
    for (entry, what) in [(0xF000u16, "a write"), (0xF006, "an I/O read")] {
        let mut rom = vec![0xEA; 4096];
        rom[..9].copy_from_slice(&[0xEE, 0x00, 0x03, 0x4C, 0x00, 0xF0, 0xAD, 0x11, 0xC0]);
        rom[9..12].copy_from_slice(&[0x4C, 0x06, 0xF0]);
        rom[0xFFC..].copy_from_slice(&entry.to_le_bytes().repeat(2));
        let mut robot = Scorpion::scorpion(&rom).expect("4 KiB");
        robot.run(200_000);
        assert_eq!(robot.cpu.skipped_cycles(), 0, "{what}");
    }
}

/// Hooks that write down every instruction they are told of after it
/// ran, and replay the laps of a skipped idle loop from the instructions
/// the probe ran, as a profiler does.
#[derive(Default)]
struct Ledger {
    /// (address, opcode, cycles it took, where it went), in order.
    ran: Vec<(u16, u8, u64, u16)>,
    /// The instructions the probes ran, last ones last.
    probed: Vec<(u16, u8, u64, u16)>,
    start: u64,
}

impl Ledger {
    fn note(&mut self, cpu: &emulator::Cpu, pc: u16, opcode: u8) -> (u16, u8, u64, u16) {
        let entry = (pc, opcode, cpu.cycles() - self.start, cpu.pc);
        self.ran.push(entry);
        entry
    }
}

impl emulator::Hooks for Ledger {
    fn may_skip_idle(&self) -> bool {
        true
    }

    fn before_instruction<B: Bus>(&mut self, cpu: &emulator::Cpu, _bus: &B) -> emulator::Control {
        self.start = cpu.cycles();
        emulator::Control::Continue
    }

    fn after_instruction<B: Bus>(&mut self, cpu: &emulator::Cpu, _bus: &B, pc: u16, opcode: u8) {
        self.note(cpu, pc, opcode);
    }

    fn after_probed_instruction<B: Bus>(
        &mut self,
        cpu: &emulator::Cpu,
        _bus: &B,
        pc: u16,
        opcode: u8,
    ) {
        let entry = self.note(cpu, pc, opcode);
        self.probed.push(entry);
    }

    fn idle_skipped(&mut self, _cpu: &emulator::Cpu, laps: u64, instructions: u64, _cycles: u64) {
        let lap = self.probed[self.probed.len() - instructions as usize..].to_vec();
        for _ in 0..laps {
            self.ran.extend_from_slice(&lap);
        }
    }
}

/// Every instruction is told of after it ran, with the opcode the CPU
/// fetched, what it took and where it went, whether it ran in the run
/// loop or in the idle probe; and the probe's instructions, replayed for
/// the laps skipped, are exactly the ones running every lap shows.
#[test]
fn the_hooks_are_told_of_every_instruction_after_it_ran() {
    // $0400: JSR $0410 / LDA $10 / STA $11 / JMP $0400, $0410: RTS.
    let mut program = vec![0x20, 0x10, 0x04, 0xA5, 0x10, 0x85, 0x11, 0x4C, 0x00, 0x04];
    program.resize(0x10, 0xEA);
    program.push(0x60);
    let [skipped, run] = [true, false].map(|skip| {
        let mut ram = Ram::new();
        ram.load(0x0400, &program).expect("fits");
        let mut machine = Machine::new(ram);
        machine.cpu.pc = 0x0400;
        machine.cpu.set_idle_skip(skip);
        let mut ledger = Ledger::default();
        let stop = machine.run_with(100_000, &mut ledger);
        assert_eq!(stop, Stop::Limit);
        (machine, ledger)
    });
    assert!(
        skipped.0.cpu.skipped_cycles() > 90_000,
        "the loop was skipped"
    );
    assert!(run.1.probed.is_empty(), "no probe without skipping");
    assert_eq!(run.1.ran.len() as u64, run.0.cpu.instructions());
    assert_eq!(skipped.1.ran, run.1.ran);
    for &(pc, opcode, cycles, _) in &run.1.ran {
        assert_eq!(opcode, run.0.bus.bytes()[usize::from(pc)]);
        let expected = isa::opcode(opcode).cycles;
        assert_eq!(u64::from(expected), cycles, "${pc:04X}");
    }
    let total: u64 = run.1.ran.iter().map(|entry| entry.2).sum();
    assert_eq!(total, run.0.cpu.cycles());
}
