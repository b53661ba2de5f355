//! Checkpoints: copies of the whole robot (CPU, RAM, board devices, cards'
//! and surroundings' script state) taken as it runs, so that going back
//! re-runs from the nearest copy before the target instead of from
//! power-up.
//!
//! One is taken every [`CHECKPOINT_EVERY`] cycles of robot time the
//! session runs forward; at most [`MAX_CHECKPOINTS`] are kept. Past that,
//! the one whose removal leaves the smallest gap for its age goes, so the
//! kept ones are dense near now and log-spaced into the past: going back a
//! little re-runs at most about two intervals, going back far re-runs a
//! stretch proportional to how far. The memory bound is
//! [`MAX_CHECKPOINTS`] copies of the robot (each its 64 KiB of memory, the
//! scanner's scene table if a script filled one, and the cards' state).
//!
//! A robot with a card or surroundings that cannot be copied
//! ([`emulator::board::Device::snapshot`], [`romlib::Surroundings::snapshot`])
//! gets no checkpoints: going back re-runs from power-up, as before.

use romlib::VirtualScorpion;

/// Robot cycles between checkpoints: half a second of robot time, a re-run
/// of a few milliseconds.
pub const CHECKPOINT_EVERY: u64 = 500_000;

/// The most checkpoints kept (the power-up one among them).
pub const MAX_CHECKPOINTS: usize = 48;

/// The robot as it was at one moment.
pub(crate) struct Checkpoint {
    /// The copy (copied again to run from it: the checkpoint stays),
    /// boxed: thinning moves checkpoints, not their 64 KiB.
    pub(crate) robot: Box<VirtualScorpion>,
    /// Its cycle.
    pub(crate) cycle: u64,
    /// Its instruction count.
    pub(crate) instructions: u64,
    /// How many of the host's actions had been done on it.
    pub(crate) events: usize,
}

/// The checkpoints of a session, oldest first.
pub(crate) struct Checkpoints {
    kept: Vec<Checkpoint>,
    /// The robot could not be copied: none is taken any more.
    off: bool,
}

impl Checkpoints {
    /// None yet.
    pub(crate) fn new() -> Checkpoints {
        Checkpoints {
            kept: Vec::new(),
            off: false,
        }
    }

    /// The cycle at which the next one is due (`u64::MAX`: never). After a
    /// step back the newest lies ahead: none is taken until the run passes
    /// it.
    pub(crate) fn next_due(&self) -> u64 {
        if self.off {
            return u64::MAX;
        }
        self.kept
            .last()
            .map_or(0, |newest| newest.cycle.saturating_add(CHECKPOINT_EVERY))
    }

    /// Takes a copy of `robot`, on which the host's first `events` actions
    /// were done, and thins the older ones out.
    pub(crate) fn take(&mut self, robot: &VirtualScorpion, events: usize) {
        let Some(copy) = robot.snapshot() else {
            // A card or the surroundings cannot be copied: re-runs start
            // from power-up.
            self.off = true;
            self.kept.clear();
            return;
        };
        self.kept.push(Checkpoint {
            cycle: copy.cycles(),
            instructions: copy.robot().cpu.instructions(),
            robot: Box::new(copy),
            events,
        });
        while self.kept.len() > MAX_CHECKPOINTS {
            self.thin();
        }
    }

    /// Removes the checkpoint whose removal leaves the smallest gap for
    /// its age (the gap over the time from it to the newest): the first
    /// and the newest always stay.
    fn thin(&mut self) {
        let Some(newest) = self.kept.last().map(|c| c.cycle) else {
            return;
        };
        let cost = |i: usize| {
            let gap = self.kept[i + 1].cycle - self.kept[i - 1].cycle;
            let age = (newest - self.kept[i].cycle).max(1);
            (gap, age)
        };
        let mut best = 1;
        for i in 2..self.kept.len() - 1 {
            let ((gap, age), (best_gap, best_age)) = (cost(i), cost(best));
            // gap / age < best_gap / best_age, without division.
            if u128::from(gap) * u128::from(best_age) < u128::from(best_gap) * u128::from(age) {
                best = i;
            }
        }
        self.kept.remove(best);
    }

    /// The newest checkpoint strictly before instruction `target` (a re-run
    /// from it runs at least one instruction, so it stops where a re-run
    /// from power-up stops, interrupt sequences included).
    pub(crate) fn before(&self, target: u64) -> Option<&Checkpoint> {
        self.kept.iter().rev().find(|c| c.instructions < target)
    }

    /// Every checkpoint, oldest first.
    pub(crate) fn all(&self) -> &[Checkpoint] {
        &self.kept
    }

    /// Forgets the checkpoints after `cycle` and `instructions`: the host
    /// did something new there, so what followed will not happen again.
    pub(crate) fn forget_after(&mut self, cycle: u64, instructions: u64) {
        self.kept
            .retain(|c| c.cycle <= cycle && c.instructions <= instructions);
    }

    /// How many are kept.
    pub(crate) fn len(&self) -> usize {
        self.kept.len()
    }
}
