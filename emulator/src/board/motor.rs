//! Stepper motors behind their driver chips (the Scorpion's 4202 stepper
//! translators): one step per rising edge of the step input, in the
//! direction the direction input gives, only while the driver is enabled.

/// One stepper motor and its driver.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Stepper {
    position: i64,
    steps: u64,
    step_input: bool,
    enabled: bool,
    last_step_at: Option<u64>,
}

impl Stepper {
    /// A motor at position 0, driver disabled.
    #[must_use]
    pub fn new() -> Stepper {
        Stepper::default()
    }

    /// Applies the driver's inputs at `cycle`: a rising edge of `step`
    /// while `enabled` moves one step, forward when `forward`.
    pub fn drive(&mut self, step: bool, forward: bool, enabled: bool, cycle: u64) {
        if step && !self.step_input && enabled {
            self.position += if forward { 1 } else { -1 };
            self.steps += 1;
            self.last_step_at = Some(cycle);
        }
        self.step_input = step;
        self.enabled = enabled;
    }

    /// Steps from the starting point, forward positive.
    #[must_use]
    pub fn position(&self) -> i64 {
        self.position
    }

    /// Steps taken in either direction.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Whether the driver powers the motor.
    #[must_use]
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// The cycle of the last step.
    #[must_use]
    pub fn last_step_at(&self) -> Option<u64> {
        self.last_step_at
    }

    /// Puts the motor back at position 0 (a scanner's home switch, a test
    /// that re-centres the robot).
    pub fn set_position(&mut self, position: i64) {
        self.position = position;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_on_rising_edges_while_enabled() {
        let mut motor = Stepper::new();
        motor.drive(true, true, true, 1);
        motor.drive(true, true, true, 2); // no edge
        motor.drive(false, true, true, 3);
        motor.drive(true, false, true, 4);
        assert_eq!((motor.position(), motor.steps()), (0, 2));
        motor.drive(false, true, false, 5);
        motor.drive(true, true, false, 6); // disabled: no step
        assert_eq!(motor.steps(), 2);
        assert_eq!(motor.last_step_at(), Some(4));
        motor.drive(false, true, true, 7);
        motor.drive(true, true, true, 8);
        assert_eq!(motor.position(), 1);
    }
}
