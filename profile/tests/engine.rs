//! The profiler's counts, exact: a routine counted by hand, idle loops the
//! emulator skips counted as if run, a command timed from its arrival to
//! `CMD_DONE` against breakpoints, interrupts as roots of their own.

mod common;

use emulator::{Breakpoints, Machine, StopAtTrap};
use romlib::VirtualScorpion;
use scorpion_profile::{Places, Profile, Profiler, Recorder};

/// A place the profiler watches nothing at (a plain RAM machine).
fn no_places() -> Places {
    Places {
        arrival: None,
        done: Vec::new(),
        main_loop: None,
        command_length: 0,
        command_buffer: 0,
    }
}

/// `routine` at $04F8: an indexed load that crosses a page and a taken
/// branch to the next page, counted by hand from the datasheet:
///
/// ```text
/// 04F8  BD F0 10  LDA $10F0,X   4 + 1 ($10F0 + $20 = $1110: page crossed)
/// 04FB  D0 03     BNE $0500     2 + 1 (taken) + 1 ($04FD -> $0500: page crossed)
/// 0500  CA        DEX           2
/// 0501  60        RTS           6
/// ```
///
/// 5 + 4 + 2 + 6 = 17 cycles from its first instruction to the end of
/// its RTS (the JSR is the caller's).
#[test]
fn a_routine_counted_by_hand_costs_what_the_profile_says() {
    let mut machine =
        Machine::with_image(0x0400, &[0xA2, 0x20, 0x20, 0xF8, 0x04, 0x4C, 0x05, 0x04])
            .expect("the caller fits");
    machine
        .bus
        .load(
            0x04F8,
            &[0xBD, 0xF0, 0x10, 0xD0, 0x03, 0xEA, 0xEA, 0xEA, 0xCA, 0x60],
        )
        .expect("the routine fits");
    machine.bus.bytes_mut()[0x1110] = 1;
    machine.cpu.pc = 0x0400;
    machine.cpu.s = 0xFF;
    let labels = [(0x0400, "start".to_owned()), (0x04F8, "routine".to_owned())];
    let mut profiler = Profiler::new(&labels, no_places());
    let stop = machine.run_with(10_000, &mut (&mut profiler, StopAtTrap));
    assert!(matches!(stop, emulator::Stop::Trap { .. }), "{stop:?}");
    profiler.end_run(&machine.cpu);
    let profile = profiler.finish(machine.cpu.cycles());

    let routine = &profile.routines["routine"];
    assert_eq!((routine.calls, routine.ended), (1, 1));
    assert_eq!(routine.inclusive, 17, "the hand count");
    assert_eq!((routine.min, routine.max), (17, 17));
    assert_eq!(routine.exclusive, 17, "it calls nothing");
    assert_eq!(profile.cycles[0x04F8], 5, "LDA abs,X across a page");
    assert_eq!(profile.cycles[0x04FB], 4, "BNE taken across a page");
    assert_eq!((profile.taken[0x04FB], profile.not_taken[0x04FB]), (1, 0));
    assert_eq!(profile.counts[0x04FD], 0, "the NOPs are jumped over");
    assert_eq!(routine.worst_path, "main;routine");
    // LDX 2 + JSR 6 + the routine + JMP 3 (the trap, counted once).
    assert_eq!(profile.total, 2 + 6 + 17 + 3);
    assert_eq!(
        profile.total,
        machine.cpu.cycles(),
        "every cycle of the run"
    );
}

/// `/1Q` answers `Q` and a byte from a table: a handler that loops, calls
/// ROM services, and is reached from the ROM's dispatch.
const SOURCE: &str = "
        .include \"scorpion.inc\"
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'Q'
        bne not_mine
        ldy #0
count:  iny
        cpy #20
        bne count
        lda #'Q'
        jsr PUTCH
        tya
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

fn image() -> linker::Image {
    common::extension(SOURCE)
}

fn robot() -> VirtualScorpion {
    let mut robot = VirtualScorpion::new();
    robot.load_image(&image()).expect("the image loads");
    robot
}

/// A session with the host: questions, the extension, waits between.
fn session(robot: &mut VirtualScorpion) {
    for command in [&b"/1Q"[..], b"/1X", b"/1Q", b"/1P"] {
        robot.transact(command, 1_000_000).expect("answered");
        robot.run_for(50_000).expect("runs");
    }
}

fn profiled(idle_skip: bool) -> Profile {
    let mut robot = robot();
    robot.robot_mut().cpu.set_idle_skip(idle_skip);
    let recorder = Recorder::attach(&mut robot);
    session(&mut robot);
    recorder.finish(&mut robot)
}

#[test]
fn idle_laps_the_emulator_skips_count_as_if_run() {
    let skipped = profiled(true);
    let run = profiled(false);
    assert!(
        skipped.skipped_laps > 1000,
        "the idle loop was skipped: {}",
        skipped.skipped_laps
    );
    assert_eq!(run.skipped_laps, 0);
    assert_eq!(skipped.total, run.total);
    assert!(skipped.counts == run.counts, "executions by address differ");
    assert!(skipped.cycles == run.cycles, "cycles by address differ");
    assert!(skipped.taken == run.taken && skipped.not_taken == run.not_taken);
    assert_eq!(skipped.routines, run.routines);
    assert_eq!(skipped.stacks, run.stacks);
    assert_eq!(skipped.commands, run.commands);
}

#[test]
fn a_command_costs_what_breakpoints_at_dispatch_and_cmd_done_measure() {
    let profile = profiled(true);
    let q: Vec<_> = profile
        .commands
        .iter()
        .filter(|run| run.text == "/1Q")
        .collect();
    assert_eq!(q.len(), 2);
    let cycles = q[0].cycles.expect("/1Q reaches CMD_DONE");

    // The same command, timed by stopping at the ROM's dispatch and at
    // CMD_DONE.
    let mut robot = robot();
    let places = Places::of(&robot);
    let dispatch = places.arrival.expect("the reference ROM's dispatch");
    let mut at_dispatch = Breakpoints::new();
    at_dispatch.insert(dispatch);
    robot.send(b"/1Q");
    let until = robot.cycles() + 1_000_000;
    robot
        .run_until_with(until, |r, to| r.run_with(to, &mut at_dispatch))
        .expect("runs");
    assert_eq!(robot.robot().cpu.pc, dispatch);
    let arrived = robot.cycles();
    let mut at_done = Breakpoints::new();
    for &done in &places.done {
        at_done.insert(done);
    }
    // Off the dispatch first, then to the first of CMD_DONE / cmd_done.
    robot.robot_mut().step();
    let until = robot.cycles() + 1_000_000;
    robot
        .run_until_with(until, |r, to| r.run_with(to, &mut at_done))
        .expect("runs");
    assert!(places.done.contains(&robot.robot().cpu.pc));
    assert_eq!(cycles, robot.cycles() - arrived);

    let cost = &profile.routines["/1Q"];
    assert_eq!(cost.calls, 2);
    assert!(cost.max >= cycles);
}

#[test]
fn interrupts_are_roots_of_their_own() {
    let profile = profiled(true);
    let irq = &profile.routines["IRQ"];
    // Every byte the host sends interrupts (the 6551's receive IRQ).
    assert!(irq.calls >= 4 * 3, "{irq:?}");
    assert_eq!(irq.calls, irq.ended);
    assert!(profile.stacks.keys().any(|stack| stack.starts_with("IRQ")));
    assert!(
        !profile.stacks.keys().any(|stack| stack.contains(";IRQ")),
        "an interrupt is nobody's callee"
    );
    // The handler's calls into the ROM hang under the command.
    assert!(
        profile
            .stacks
            .keys()
            .any(|stack| stack.starts_with("main;/1Q;")),
        "{:?}",
        profile.stacks.keys().collect::<Vec<_>>()
    );
    // Everything counted once: the stacks add up to the total.
    assert_eq!(profile.stacks.values().sum::<u64>(), profile.total);
}

/// `rec: JSR rec` never returns: the 6502 stack wraps every 128 calls and
/// overwrites the oldest return addresses, so the shadow stack (and every
/// folded path) stays as deep as the real stack can hold, not as deep as
/// the number of calls.
#[test]
fn a_call_that_never_returns_keeps_the_stack_as_deep_as_the_6502s() {
    let mut machine = Machine::with_image(0x0400, &[0x20, 0x00, 0x04]).expect("the loop fits");
    machine.cpu.pc = 0x0400;
    machine.cpu.s = 0xFF;
    let labels = [(0x0400, "rec".to_owned())];
    let mut profiler = Profiler::new(&labels, no_places());
    // 1000 calls: almost eight times round the stack.
    let _ = machine.run_with(6_000, &mut (&mut profiler, StopAtTrap));
    profiler.end_run(&machine.cpu);
    let profile = profiler.finish(machine.cpu.cycles());

    let deepest = profile
        .stacks
        .keys()
        .map(|path| path.split(';').count())
        .max()
        .expect("some stack");
    assert!(
        (100..=130).contains(&deepest),
        "deepest path {deepest} frames"
    );
    assert_eq!(profile.routines["rec"].calls, 1000);
    assert_eq!(profile.total, machine.cpu.cycles(), "every cycle counted");
}

/// A run that ends stuck (`JSR sp` / `sp: JMP sp`) and whose clock moved on
/// past the last instruction counted (the robot's stuck window): a frame
/// still open is closed at the last instruction counted, so its inclusive
/// cycles are no more than the run's.
#[test]
fn a_frame_open_at_the_end_closes_at_the_last_instruction_counted() {
    let mut machine =
        Machine::with_image(0x0400, &[0x20, 0x03, 0x04, 0x4C, 0x03, 0x04]).expect("it fits");
    machine.cpu.pc = 0x0400;
    machine.cpu.s = 0xFF;
    let labels = [(0x0400, "start".to_owned()), (0x0403, "sp".to_owned())];
    let mut profiler = Profiler::new(&labels, no_places());
    let _ = machine.run_with(3_000, &mut (&mut profiler, StopAtTrap));
    profiler.end_run(&machine.cpu);
    let stuck_window = 100_000;
    let profile = profiler.finish(machine.cpu.cycles() + stuck_window);

    let sp = &profile.routines["sp"];
    assert_eq!(sp.inclusive, profile.total - 6, "all but the JSR");
    assert_eq!(sp.inclusive, sp.exclusive);
}

/// `down` calls itself ten deep: its inclusive cycles are those of its
/// outermost call (every cycle but the caller's), not the sum over the
/// ten nested calls, each of which holds the ones inside it.
///
/// ```text
/// 0400  A2 0A     LDX #10
/// 0402  20 08 04  JSR down
/// 0405  4C 05 04  JMP *        (the trap)
/// 0408  CA        down: DEX
/// 0409  F0 03     BEQ out
/// 040B  20 08 04  JSR down
/// 040E  60        out: RTS
/// ```
#[test]
fn a_recursive_routine_counts_its_outermost_call_only() {
    let mut machine = Machine::with_image(
        0x0400,
        &[
            0xA2, 0x0A, 0x20, 0x08, 0x04, 0x4C, 0x05, 0x04, 0xCA, 0xF0, 0x03, 0x20, 0x08, 0x04,
            0x60,
        ],
    )
    .expect("it fits");
    machine.cpu.pc = 0x0400;
    machine.cpu.s = 0xFF;
    let labels = [(0x0400, "start".to_owned()), (0x0408, "down".to_owned())];
    let mut profiler = Profiler::new(&labels, no_places());
    let stop = machine.run_with(10_000, &mut (&mut profiler, StopAtTrap));
    assert!(matches!(stop, emulator::Stop::Trap { .. }), "{stop:?}");
    profiler.end_run(&machine.cpu);
    let profile = profiler.finish(machine.cpu.cycles());

    let down = &profile.routines["down"];
    assert_eq!((down.calls, down.ended), (10, 10));
    // LDX 2 + JSR 6 + JMP 3 are the caller's.
    assert_eq!(down.inclusive, profile.total - 11);
    assert_eq!(down.inclusive, down.exclusive, "it calls only itself");
}

/// A `;` command letter (`/1;`) would split its frame in two in the folded
/// stacks (`main;/1;;dispatch`), where `;` parts frames: it is replaced.
#[test]
fn a_semicolon_in_a_command_does_not_split_its_frame() {
    let mut robot = robot();
    let recorder = Recorder::attach(&mut robot);
    // Nothing answers it; it runs all the same.
    let _ = robot.transact(b"/1;", 1_000_000);
    robot.run_for(50_000).expect("runs");
    let profile = recorder.finish(&mut robot);

    let command: Vec<_> = profile
        .stacks
        .keys()
        .filter(|path| path.contains("/1"))
        .collect();
    assert!(
        !command.is_empty(),
        "the command shows: {:?}",
        profile.stacks
    );
    for path in command {
        assert!(
            path.split(';').all(|frame| !frame.is_empty()),
            "an empty frame in {path}"
        );
    }
}

/// A command that never reaches `CMD_DONE` (`spin: jmp spin`) has no
/// finished run to hold against its budget: it is over it, not passed.
#[test]
fn a_command_that_never_finishes_is_over_its_budget() {
    let profile = Profile {
        commands: vec![scorpion_profile::CommandRun {
            text: "/1Q".to_owned(),
            arrival: 1000,
            cycles: None,
            origin: Some("t.expect:1".to_owned()),
        }],
        ..Profile::default()
    };
    let budgets = [scorpion_profile::budget::Budget::new("/1Q", 10)];
    let (overruns, unused) = scorpion_profile::budget::check(&profile, &budgets);
    assert!(unused.is_empty(), "{unused:?}");
    assert_eq!(overruns.len(), 1, "the budget fails");
    assert_eq!(overruns[0].unfinished, 1);
    let said = overruns[0].to_string();
    assert!(said.contains("never finished"), "{said}");
    assert!(said.contains("t.expect:1"), "{said}");
}

/// Each IRQ's seven-cycle entry sequence is counted at the handler's
/// first instruction: cycles by address (hence by line, in the hot lines
/// and the coverage report) add up to the profile's total, as the stacks
/// do.
#[test]
fn an_interrupt_entry_is_counted_at_its_handler() {
    let profile = profiled(true);
    assert!(profile.routines["IRQ"].calls > 0, "the session interrupts");
    assert_eq!(profile.cycles.iter().sum::<u64>(), profile.total);
    let table = scorpion_profile::lines::LineTable::default();
    let by_line: u64 = scorpion_profile::report::hot_lines(&profile, &table, &|_| true)
        .iter()
        .map(|line| line.cycles)
        .sum();
    assert_eq!(by_line, profile.total);
}

/// The speedscope file, read back as speedscope reads it (its "sampled"
/// schema): every stack a sample, weighted by its cycles, adding up to
/// the profile's total.
#[test]
fn the_speedscope_file_reads_back_to_the_profiles_totals() {
    use scorpion_profile::speedscope;
    let profile = profiled(true);
    let text = speedscope::json(&profile, "q").expect("written");
    let value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(value["$schema"], speedscope::SCHEMA);
    assert_eq!(value["profiles"][0]["type"], "sampled");
    let file: speedscope::File = serde_json::from_str(&text).expect("the schema's fields");
    let sampled = &file.profiles[0];
    assert_eq!(sampled.samples.len(), sampled.weights.len());
    assert_eq!(sampled.weights.iter().sum::<u64>(), profile.total);
    assert_eq!(sampled.end_value, profile.total);
    for (sample, weight) in sampled.samples.iter().zip(&sampled.weights) {
        let stack: Vec<&str> = sample
            .iter()
            .map(|&frame| file.shared.frames[frame].name.as_str())
            .collect();
        assert_eq!(profile.stacks.get(&stack.join(";")), Some(weight));
    }
}
