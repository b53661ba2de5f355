//! Robot time as a script sees it: the wake-up it asked for, which must
//! lie after the robot time of the call that asks (a script that asks for
//! `now` again would be woken for ever without robot time moving), and
//! the budget of operations a script earns per microsecond of robot time
//! (a script woken every microsecond must not hold the robot still).

use crate::sandbox::{HostError, OPERATION_BUDGET};

/// Operations a script earns per microsecond (cycle) of robot time, on
/// average: a call may take up to [`OPERATION_BUDGET`] at once, and what
/// it took is earned back at this rate. About what the host runs in real
/// time, so a script at its limit still keeps the virtual robot near the
/// real one's speed.
pub const OPERATIONS_PER_MICROSECOND: u64 = 100;

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

/// The operations a script may still take: [`OPERATION_BUDGET`] at most,
/// earned at [`OPERATIONS_PER_MICROSECOND`] of robot time.
#[derive(Debug, Clone)]
pub(crate) struct Budget {
    credit: u64,
    /// The robot time the credit was last earned up to.
    earned_to: u64,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            credit: OPERATION_BUDGET,
            earned_to: 0,
        }
    }
}

impl Budget {
    /// What a call at robot time `now` may take (`None`: before robot time
    /// starts, a full call's worth).
    pub(crate) fn allowance(&mut self, now: Option<u64>) -> u64 {
        let Some(now) = now else {
            return OPERATION_BUDGET;
        };
        if now > self.earned_to {
            let earned = (now - self.earned_to).saturating_mul(OPERATIONS_PER_MICROSECOND);
            self.credit = self.credit.saturating_add(earned).min(OPERATION_BUDGET);
            self.earned_to = now;
        }
        self.credit
    }

    /// Takes what a call at `now` spent.
    pub(crate) fn spend(&mut self, now: Option<u64>, operations: u64) {
        if now.is_some() {
            self.credit = self.credit.saturating_sub(operations);
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
        assert_eq!(budget.allowance(Some(0)), OPERATION_BUDGET);
        budget.spend(Some(0), OPERATION_BUDGET);
        assert_eq!(budget.allowance(Some(0)), 0);
        assert_eq!(budget.allowance(Some(3)), 3 * OPERATIONS_PER_MICROSECOND);
        assert_eq!(budget.allowance(Some(u64::MAX)), OPERATION_BUDGET, "capped");
    }
}
