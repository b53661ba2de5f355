//! What a breakpoint asks before it stops (issue 25): a condition over
//! registers, memory and symbols, a hit count, a log message instead of a
//! stop; and what the user changes: registers, flags and RAM, kept as host
//! actions so that a step back and forward again sees them. Also `until`
//! and a run paused by its interrupt flag (Ctrl-C in the monitor).

mod build;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use debugger::{Breakpoint, Debugger, Expr, HitCondition, PointOptions, Register, Template, Why};
use romlib::VirtualScorpion;

/// `/1Q` answers `Q` and its result byte (`result`, 0 at power-up), in
/// hex; `/1X` is the ROM's.
const SOURCE: &str = "
        .include \"scorpion.inc\"
        .bss
result: .res 1
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'Q'
        bne not_mine
        lda #'Q'
        jsr PUTCH
answer: lda result
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

fn debugger() -> Debugger {
    let image = build::extension("q.s", SOURCE);
    let loaded = image.clone();
    let make = Box::new(move || {
        let mut robot = VirtualScorpion::new();
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    Debugger::new(make, &[image]).expect("the robot builds")
}

fn at(d: &Debugger, name: &str) -> u16 {
    d.symbols().get(name).expect("a label")
}

fn when(d: &Debugger, condition: &str) -> PointOptions {
    PointOptions {
        condition: Some(Expr::parse(condition, d.symbols()).expect("the condition parses")),
        ..PointOptions::default()
    }
}

/// Sends `command` and runs a tenth of a second of robot time.
fn ask(d: &mut Debugger, command: &[u8]) -> debugger::Stopped {
    d.send(command);
    d.run(100_000).expect("runs")
}

#[test]
fn a_condition_over_registers_memory_and_symbols_stops_only_where_it_holds() {
    let mut d = debugger();
    let handler = at(&d, "handler");
    let options = when(&d, "A == 'Q' && [CMDBUF] == $51 && X == 1");
    let id = d.add_breakpoint_with(Breakpoint::At(handler), options);
    // The handler is reached for /2QZ too: A is 'Q' there, but X is 2.
    let other = ask(&mut d, b"/2QZ");
    assert_eq!(other.why, Why::Budget, "{other:?}");
    let stop = ask(&mut d, b"/1Q");
    assert_eq!(
        stop.why,
        Why::Breakpoint {
            id,
            point: Breakpoint::At(handler)
        }
    );
    assert_eq!((d.cpu().a, d.cpu().x), (b'Q', 1));
    // The same condition re-run backwards finds the same hit.
    let on = d.run(100_000).expect("runs");
    assert_eq!(on.received, b"Q00\r");
    let back = d.reverse_continue().expect("re-runs").expect("a hit");
    assert_eq!(back.pc, handler);
    assert_eq!(d.cpu().x, 1);
}

#[test]
fn a_hit_count_stops_at_the_nth_hit_and_after() {
    for (hits, stops_at) in [("3", vec![3, 4]), ("== 2", vec![2]), ("% 2", vec![2, 4])] {
        let mut d = debugger();
        let handler = at(&d, "handler");
        let options = PointOptions {
            hits: Some(HitCondition::parse(hits).expect("a hit count")),
            ..PointOptions::default()
        };
        let id = d.add_breakpoint_with(Breakpoint::At(handler), options);
        let mut stopped = Vec::new();
        for n in 1..=4 {
            let stop = ask(&mut d, b"/1Q");
            if matches!(stop.why, Why::Breakpoint { .. }) {
                stopped.push(n);
                // On to the answer.
                d.run(100_000).expect("runs");
            }
        }
        assert_eq!(stopped, stops_at, "hits {hits}");
        assert_eq!(d.breakpoint_options(id).map(|(_, n)| n), Some(4));
    }
}

/// A hit count on the ROM's idle loop counts every lap: the idle loop is
/// not skipped under it. Fifty laps by count stop where fifty stops of a
/// plain breakpoint do.
#[test]
fn a_hit_count_in_the_idle_loop_counts_every_lap() {
    let mut counted = debugger();
    let idle = at(&counted, "rom_loop");
    let options = PointOptions {
        hits: Some(HitCondition::Exactly(50)),
        ..PointOptions::default()
    };
    counted.add_breakpoint_with(Breakpoint::At(idle), options);
    let stop = counted.run(10_000_000).expect("runs");
    assert!(matches!(stop.why, Why::Breakpoint { .. }), "{stop:?}");
    let mut plain = debugger();
    plain.add_breakpoint(Breakpoint::At(idle));
    for _ in 0..50 {
        let stop = plain.run(10_000_000).expect("runs");
        assert!(matches!(stop.why, Why::Breakpoint { .. }), "{stop:?}");
    }
    assert_eq!(
        counted.cpu().instructions(),
        plain.cpu().instructions(),
        "the 50th lap"
    );
}

#[test]
fn a_log_point_logs_its_message_and_goes_on() {
    let mut d = debugger();
    let handler = at(&d, "handler");
    let message = Template::parse("got {A} count {X} at {PC}", d.symbols()).expect("parses");
    let options = PointOptions {
        log: Some(message),
        ..when(&d, "A == 'Q'")
    };
    d.add_breakpoint_with(Breakpoint::At(handler), options);
    let done = ask(&mut d, b"/1Q");
    assert_eq!(done.why, Why::Budget);
    assert_eq!(done.received, b"Q00\r");
    ask(&mut d, b"/2QZ");
    ask(&mut d, b"/1X");
    let (logs, dropped) = d.take_logs();
    let texts: Vec<&str> = logs.iter().map(|l| l.text.as_str()).collect();
    let expected = [1, 2].map(|x| format!("got $51 count $0{x} at ${handler:04X}"));
    assert_eq!(texts, expected, "one line for each hit where A is 'Q'");
    assert_eq!(dropped, 0);
    assert!(d.take_logs().0.is_empty(), "taken");
}

#[test]
fn a_register_set_changes_the_answer_and_is_replayed_after_a_step_back() {
    let mut d = debugger();
    let answer = at(&d, "answer");
    let id = d.add_breakpoint(Breakpoint::At(answer));
    let stop = ask(&mut d, b"/1Q");
    assert!(matches!(stop.why, Why::Breakpoint { .. }), "{stop:?}");
    d.delete_breakpoint(id);
    // After `lda result`: A is the byte answered.
    d.step(1).expect("steps");
    assert_eq!(d.cpu().a, 0);
    d.set_register(Register::A, 0x5A).expect("A holds a byte");
    d.set_register(Register::named("C").expect("a flag"), 1)
        .expect("a flag holds 1");
    assert!(d.set_register(Register::A, 0x100).is_err(), "A is a byte");
    assert!(
        d.set_register(Register::Flag(1), 2).is_err(),
        "a flag is 0 or 1"
    );
    d.step(3).expect("steps");
    let after: (u8, u64) = (d.cpu().a, d.cpu().instructions());
    // Back past the set and forward again: the set is done again.
    d.back(5).expect("goes back");
    d.step(5).expect("steps");
    assert_eq!((d.cpu().a, d.cpu().instructions()), after);
    let done = d.run(100_000).expect("runs");
    assert_eq!(done.received, b"Q5A\r");
}

#[test]
fn memory_is_written_in_ram_only() {
    let mut d = debugger();
    let result = at(&d, "result");
    d.poke(result, &[0x2F]).expect("RAM");
    assert_eq!(ask(&mut d, b"/1Q").received, b"Q2F\r");
    // The ROM, and a run past $FFFF, are refused whole.
    let rom = at(&d, "PUTCH");
    assert!(d.poke(rom, &[0xEA]).is_err());
    assert!(d.poke(0xFFFF, &[1, 2]).is_err());
}

#[test]
fn until_runs_to_an_address_and_leaves_no_breakpoint() {
    let mut d = debugger();
    let answer = at(&d, "answer");
    d.send(b"/1Q");
    let stop = d.until(answer, 1_000_000).expect("runs");
    assert_eq!(stop.why, Why::Stepped);
    assert_eq!(d.cpu().pc, answer);
    assert!(d.breakpoints().is_empty());
}

#[test]
fn a_set_interrupt_flag_pauses_a_run_within_a_slice() {
    let mut d = debugger();
    let flag = Arc::new(AtomicBool::new(true));
    d.set_interrupt(Arc::clone(&flag));
    let stop = d.run(60_000_000).expect("runs");
    assert_eq!(stop.why, Why::Paused);
    assert!(stop.cycles <= debugger::session::SLICE + 10, "{stop:?}");
    assert!(!flag.load(std::sync::atomic::Ordering::Relaxed), "cleared");
    // Not set: the run goes its whole length.
    assert_eq!(d.run(1_000_000).expect("runs").why, Why::Budget);
}

#[test]
fn a_condition_that_cannot_be_evaluated_stops_and_says_why() {
    let mut d = debugger();
    let handler = at(&d, "handler");
    let id = d.add_breakpoint_with(Breakpoint::At(handler), when(&d, "1/(A-A) == 1"));
    let stop = ask(&mut d, b"/1Q");
    assert_eq!(
        stop.why,
        Why::Breakpoint {
            id,
            point: Breakpoint::At(handler)
        }
    );
    let (logs, _) = d.take_logs();
    let said: Vec<&str> = logs.iter().map(|l| l.text.as_str()).collect();
    assert!(
        said.len() == 1 && said[0].contains("cannot be evaluated") && said[0].contains("zero"),
        "{said:?}"
    );
}

#[test]
fn a_megabyte_condition_is_not_echoed_whole() {
    let d = debugger();
    let long = "(".repeat(1_000_000);
    let error = Expr::parse(&long, d.symbols()).expect_err("does not parse");
    assert!(
        error.to_string().len() < 1000,
        "{} bytes",
        error.to_string().len()
    );
    assert!(error.pointed().len() < 1000);
}
