//! Robot time as a script sees it: the wake-up it asked for, which must
//! lie after the robot time of the call that asks (a script that asks for
//! `now` again would be woken for ever without robot time moving), and
//! the budget of operations a script earns per microsecond of robot time
//! (a script woken every microsecond must not hold the robot still). A
//! call is charged [`CALL_COST`] besides the operations it runs: entering
//! a script costs the host far more than one operation, and a script that
//! runs almost nothing per call but is called every microsecond would
//! otherwise stay inside the budget while the robot crawls.

use crate::sandbox::{HostError, OPERATION_BUDGET};

/// Operations a script earns per microsecond (cycle) of robot time, on
/// average: a call may take up to [`OPERATION_BUDGET`] at once, and what
/// it took is earned back at this rate. Set so that a script spending all
/// of it keeps the virtual robot near the real one's speed: an operation
/// costs the host about 0.1 to 0.2 µs in an optimised build
/// (`cargo bench -p cards` measures it), so ten a microsecond is about
/// real time. (It was 100, which let a script hold the robot at 16 times
/// real time.)
pub const OPERATIONS_PER_MICROSECOND: u64 = 10;

/// Operations a call into a script is charged for itself, on top of the
/// operations it runs: what the host spends to enter the script, look up
/// the function, bind `this`, come back, and stop the emulator there.
/// `cargo bench -p cards` measures a call at about 27 operations' worth;
/// this keeps a margin. So a script is called at most once every
/// `CALL_COST / OPERATIONS_PER_MICROSECOND` (5) microseconds on average,
/// and over any stretch of robot time `T` its calls and operations are
/// bounded: `calls * CALL_COST + operations <= OPERATION_BUDGET +
/// CALL_COST + OPERATIONS_PER_MICROSECOND * T`.
pub const CALL_COST: u64 = 50;

/// The wake-up a script asked for.
#[derive(Debug, Default, Clone)]
pub(crate) struct Alarm {
    /// The robot time of the running call; `None` in `init` and the top
    /// level, which run before robot time starts for the script.
    now: Option<u64>,
    /// The earliest wake-up asked for.
    at: Option<u64>,
}

impl Alarm {
    /// `wake_at(cycle)`: the earliest request counts; it must be after the
    /// running call's robot time.
    pub(crate) fn ask(&mut self, cycle: i64) -> Result<(), HostError> {
        let earliest = self.now.map_or(0, |now| now.saturating_add(1));
        match u64::try_from(cycle) {
            Ok(at) if at >= earliest => {
                self.at = Some(self.at.map_or(at, |old| old.min(at)));
                Ok(())
            }
            _ => Err(HostError {
                message: match self.now {
                    Some(now) => format!(
                        "`wake_at({cycle})` at robot time {now}: a wake-up must come after now"
                    ),
                    None => format!("`wake_at({cycle})`: robot time starts at 0"),
                },
                help: "robot time stands still while a script runs; ask for a later time, as in `wake_at(now + us(100))`".into(),
            }),
        }
    }

    /// Sets the robot time of the call about to run.
    pub(crate) fn set_now(&mut self, now: Option<u64>) {
        self.now = now;
    }

    /// The wake-up asked for.
    pub(crate) fn at(&self) -> Option<u64> {
        self.at
    }

    /// Forgets the wake-up (it is being served, or the script failed).
    pub(crate) fn clear(&mut self) {
        self.at = None;
    }
}

/// The operations a script may still take: [`OPERATION_BUDGET`] and a
/// call's [`CALL_COST`] at most, earned at [`OPERATIONS_PER_MICROSECOND`]
/// of robot time, each call paying [`CALL_COST`] of them besides what it
/// runs.
#[derive(Debug, Clone)]
pub(crate) struct Budget {
    credit: u64,
    /// The robot time the credit was last earned up to.
    earned_to: u64,
}

/// The most credit a script holds: a call's whole budget and the call
/// itself, so a call with full credit is stopped by the per-call budget
/// ("ran out of its operation budget", a loop without end), not by robot
/// time.
const MAX_CREDIT: u64 = OPERATION_BUDGET + CALL_COST;

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            credit: MAX_CREDIT,
            earned_to: 0,
        }
    }
}

impl Budget {
    /// What a call at robot time `now` may run once it has paid
    /// [`CALL_COST`] (`None`: the credit does not cover the call itself);
    /// before robot time starts (`now` is `None`), a full call's worth.
    pub(crate) fn allowance(&mut self, now: Option<u64>) -> Option<u64> {
        let Some(now) = now else {
            return Some(OPERATION_BUDGET);
        };
        if now > self.earned_to {
            let earned = (now - self.earned_to).saturating_mul(OPERATIONS_PER_MICROSECOND);
            self.credit = self.credit.saturating_add(earned).min(MAX_CREDIT);
            self.earned_to = now;
        }
        self.credit.checked_sub(CALL_COST)
    }

    /// Takes what a call at `now` spent: the call itself and the
    /// operations it ran.
    pub(crate) fn spend(&mut self, now: Option<u64>, operations: u64) {
        if now.is_some() {
            self.credit = self
                .credit
                .saturating_sub(operations.saturating_add(CALL_COST));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wake_ups_move_forward() {
        let mut alarm = Alarm::default();
        assert!(alarm.ask(0).is_ok(), "init may ask for power-up");
        assert!(alarm.ask(-5).is_err(), "before power-up");
        alarm.set_now(Some(10));
        assert!(alarm.ask(10).is_err(), "now again");
        assert!(alarm.ask(9).is_err(), "the past");
        assert!(alarm.ask(11).is_ok());
        assert_eq!(alarm.at(), Some(0), "the earliest counts");
    }

    #[test]
    fn credit_is_earned_with_robot_time() {
        let mut budget = Budget::default();
        assert_eq!(budget.allowance(Some(0)), Some(OPERATION_BUDGET));
        budget.spend(Some(0), OPERATION_BUDGET);
        assert_eq!(budget.allowance(Some(0)), None, "not even the call");
        let later = CALL_COST / OPERATIONS_PER_MICROSECOND + 3;
        assert_eq!(
            budget.allowance(Some(later)),
            Some(later * OPERATIONS_PER_MICROSECOND - CALL_COST)
        );
        assert_eq!(
            budget.allowance(Some(u64::MAX)),
            Some(OPERATION_BUDGET),
            "capped"
        );
        assert_eq!(budget.allowance(None), Some(OPERATION_BUDGET), "init");
    }

    #[test]
    fn each_call_pays_for_itself() {
        // Calls that run nothing, one every microsecond: at HEAD they
        // were free, and a script woken every microsecond ran for ever.
        let mut budget = Budget::default();
        let mut calls = 0u64;
        let mut now = 0;
        while budget.allowance(Some(now)).is_some() {
            budget.spend(Some(now), 0);
            calls += 1;
            now += 1;
        }
        assert!(
            calls * CALL_COST <= MAX_CREDIT + OPERATIONS_PER_MICROSECOND * now,
            "{calls} calls in {now} us"
        );
    }
}
