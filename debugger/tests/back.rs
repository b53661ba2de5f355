//! Stepping back restores the newest checkpoint before the target and runs
//! on from it: the robot is built again from power-up only when no
//! checkpoint lies before the target, and the state is exactly the one a
//! fresh run reaches (checked at random points against a fresh run).

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use debugger::{CHECKPOINT_EVERY, Debugger, Why};
use proptest::prelude::*;

#[test]
fn a_step_back_late_in_a_session_runs_from_a_checkpoint() {
    let image = common::patrol();
    let built = Arc::new(AtomicUsize::new(0));
    let mut d = common::debugger(&image, &built);
    d.send(b"/2A1");
    d.run(20 * CHECKPOINT_EVERY).expect("runs");
    assert!(d.checkpoints() > 10, "{} checkpoints", d.checkpoints());
    let now = d.cpu().instructions();
    let back = d.back(10).expect("goes back");
    assert_eq!(back.why, Why::Back);
    assert_eq!(d.cpu().instructions(), now - 10);
    assert_eq!(
        built.load(Ordering::Relaxed),
        1,
        "no robot built again from power-up"
    );
    // Forward again to where it was, the same way.
    let before = common::state(&d);
    d.step(10).expect("steps");
    assert_eq!(d.cpu().instructions(), now);
    d.back(10).expect("goes back");
    assert_eq!(common::state(&d), before);
}

#[test]
fn something_new_forgets_the_checkpoints_after_it() {
    let image = common::patrol();
    let built = Arc::new(AtomicUsize::new(0));
    let mut d = common::debugger(&image, &built);
    d.send(b"/2A1");
    d.run(10 * CHECKPOINT_EVERY).expect("runs");
    let kept = d.checkpoints();
    // Back about half way, then the host does something else there.
    let half = d.cpu().instructions() / 2;
    d.back(half).expect("goes back");
    d.send(b"/2A0");
    assert!(d.checkpoints() < kept, "the future's checkpoints are gone");
    d.run(3 * CHECKPOINT_EVERY).expect("runs");
    let now = d.cpu().instructions();
    let ahead = common::state(&d);
    d.back(1000).expect("goes back");
    d.step(1000).expect("steps");
    assert_eq!(d.cpu().instructions(), now);
    assert_eq!(common::state(&d), ahead);
}

/// What the host does in a session.
#[derive(Debug, Clone)]
enum Op {
    /// Run for this many cycles.
    Run(u64),
    /// Send a command.
    Send(&'static [u8]),
    /// Close bumpers.
    Bumpers(u8),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => (1..3 * CHECKPOINT_EVERY).prop_map(Op::Run),
        1 => prop::sample::select(vec![&b"/2A1"[..], b"/2A0", b"/1X", b"/1P"]).prop_map(Op::Send),
        1 => (0u8..4).prop_map(Op::Bumpers),
    ]
}

fn apply(d: &mut Debugger, op: &Op) {
    match op {
        Op::Run(cycles) => {
            d.run(*cycles).expect("runs");
        }
        Op::Send(bytes) => d.send(bytes),
        Op::Bumpers(closed) => d.set_bumpers(*closed),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// A session of runs, commands and bumpers, then a step back to a
    /// random instruction: the state is the one a fresh session reaches
    /// doing the same up to that instruction.
    #[test]
    fn a_step_back_gives_the_state_of_a_fresh_run(
        ops in prop::collection::vec(op(), 1..8),
        at in 0.0f64..1.0,
    ) {
        let image = common::patrol();
        let built = Arc::new(AtomicUsize::new(0));
        let mut d = common::debugger(&image, &built);
        let start = d.cpu().instructions();
        // The instruction count before each of the host's acts.
        let mut before = Vec::new();
        for op in &ops {
            before.push(d.cpu().instructions());
            apply(&mut d, op);
        }
        let end = d.cpu().instructions();
        prop_assume!(end > start);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
        let target = start + ((end - start) as f64 * at) as u64;
        d.back(end - target).expect("goes back");
        prop_assert_eq!(d.cpu().instructions(), target);

        // The fresh session: the acts begun at or before the target, the
        // run that crosses it stepped to it instead.
        let after: Vec<u64> = before[1..].iter().copied().chain([end]).collect();
        let mut fresh = common::debugger(&image, &built);
        for ((op, &from), &to) in ops.iter().zip(&before).zip(&after) {
            if from > target {
                break;
            }
            match op {
                Op::Run(_) if to > target => {
                    let left = target - fresh.cpu().instructions();
                    if left > 0 {
                        fresh.step(left).expect("steps");
                    }
                    break;
                }
                _ => apply(&mut fresh, op),
            }
        }
        prop_assert_eq!(fresh.cpu().instructions(), target);
        prop_assert_eq!(common::state(&d), common::state(&fresh));
    }
}
