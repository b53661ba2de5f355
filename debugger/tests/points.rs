//! Breakpoints and watchpoints that never hit cost no more than a bit
//! test where they could: the robot's idle loop is still skipped as in
//! the plain run (what makes the plain run fast), and the run ends in
//! exactly the state the plain run does. (The speed itself is the bench's:
//! `cargo bench -p debugger`.)

mod common;

use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

use debugger::{Breakpoint, Debugger, Watch, WatchKind, Why};

const CRUISE: u64 = 2_000_000;

/// Patrol cruising for `CRUISE` cycles with `setup`'s points set: the
/// cycles skipped and the state at the end.
fn cruise(setup: impl Fn(&mut Debugger)) -> (u64, (emulator::Cpu, Vec<u8>, String)) {
    let image = common::patrol();
    let mut d = common::debugger(&image, &Arc::new(AtomicUsize::new(0)));
    setup(&mut d);
    d.send(b"/2A1");
    let stop = d.run(CRUISE).expect("runs");
    assert_eq!(stop.why, Why::Budget, "nothing stops: {stop:?}");
    (d.cpu().skipped_cycles(), common::state(&d))
}

#[test]
fn breakpoints_that_never_hit_leave_the_idle_loop_skipped() {
    let (plain_skipped, plain) = cruise(|_| {});
    assert!(plain_skipped > 0, "the plain run skips");
    let (skipped, state) = cruise(|d| {
        for address in [0x0300, 0x0301, 0x0302] {
            d.add_breakpoint(Breakpoint::At(address));
        }
        d.add_breakpoint(Breakpoint::command("/9Z").expect("a command"));
    });
    assert!(
        skipped * 10 >= plain_skipped * 9,
        "with breakpoints {skipped} skipped, plain {plain_skipped}"
    );
    assert_eq!(state, plain);
}

#[test]
fn watchpoints_that_never_hit_leave_the_idle_loop_skipped() {
    let (plain_skipped, plain) = cruise(|_| {});
    let (skipped, state) = cruise(|d| {
        d.add_watch(Watch {
            start: 0x8000,
            end: 0x8003,
            kind: WatchKind::Access,
        });
        d.add_watch(Watch {
            start: 0x0380,
            end: 0x03FF,
            kind: WatchKind::Write,
        });
    });
    assert!(
        skipped * 10 >= plain_skipped * 9,
        "with watchpoints {skipped} skipped, plain {plain_skipped}"
    );
    assert_eq!(state, plain);
}

/// A point in the idle loop itself still stops there, where running
/// every instruction would: at the loop's first instruction after the
/// session's own first one.
#[test]
fn a_breakpoint_in_the_idle_loop_stops_in_it() {
    let image = common::patrol();
    let built = Arc::new(AtomicUsize::new(0));
    // Where the robot idles: the PC after a plain cruise, mostly in the
    // skipped loop.
    let mut d = common::debugger(&image, &built);
    d.send(b"/2A1");
    d.run(CRUISE).expect("runs");
    let idle = d.cpu().pc;
    let mut with = common::debugger(&image, &built);
    with.send(b"/2A1");
    with.add_breakpoint(Breakpoint::At(idle));
    let stop = with.run(CRUISE).expect("runs");
    assert!(matches!(stop.why, Why::Breakpoint { .. }), "{stop:?}");
    assert_eq!(stop.pc, idle);
    // Stepping instruction by instruction finds the same first arrival.
    let mut stepped = common::debugger(&image, &built);
    stepped.send(b"/2A1");
    stepped.step(1).expect("steps");
    while stepped.cpu().pc != idle {
        stepped.step(1).expect("steps");
    }
    assert_eq!(common::state(&stepped), common::state(&with));
}
