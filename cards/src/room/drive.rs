//! The robot's pose on the floor, following its drive motors' steps: a
//! differential drive (two wheels on one axle, each turned by its
//! stepper), the pose being the middle of the axle and the heading.

use super::geometry::{PI, Point, sin_cos};

/// Where the robot is and which way it faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The middle of the axle, centimetres.
    pub at: Point,
    /// Radians counter-clockwise from east (+x).
    pub heading: f64,
}

impl Pose {
    /// The heading in degrees, in [0, 360).
    #[must_use]
    pub fn heading_degrees(&self) -> f64 {
        (self.heading * 180.0 / PI).rem_euclid(360.0)
    }

    /// The floor point `forward` centimetres ahead of the axle's middle
    /// and `left` to its left, in the robot's own frame.
    #[must_use]
    pub fn place(&self, forward: f64, left: f64) -> Point {
        let (sin, cos) = sin_cos(self.heading);
        Point::new(
            self.at.x + forward * cos - left * sin,
            self.at.y + forward * sin + left * cos,
        )
    }
}

/// How the motors' steps move the robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// How far a wheel's rim moves in one step, centimetres.
    pub step: f64,
    /// The distance between the wheels, centimetres.
    pub wheel_base: f64,
}

impl Drive {
    /// `pose` after the left wheel moved `left` steps and the right
    /// `right` (forward positive), the two together: the arc they make,
    /// taken at its middle heading.
    #[must_use]
    pub fn moved(&self, pose: Pose, left: i64, right: i64) -> Pose {
        if left == 0 && right == 0 {
            return pose;
        }
        let left = left as f64 * self.step;
        let right = right as f64 * self.step;
        let distance = (left + right) / 2.0;
        let turn = (right - left) / self.wheel_base;
        let (sin, cos) = sin_cos(pose.heading + turn / 2.0);
        Pose {
            at: Point::new(pose.at.x + distance * cos, pose.at.y + distance * sin),
            heading: pose.heading + turn,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DRIVE: Drive = Drive {
        step: 0.5,
        wheel_base: 20.0,
    };

    #[test]
    fn both_wheels_forward_go_straight() {
        let start = Pose {
            at: Point::new(0.0, 0.0),
            heading: PI / 2.0,
        };
        let pose = DRIVE.moved(start, 10, 10);
        assert!((pose.at.x).abs() < 1e-12);
        assert!((pose.at.y - 5.0).abs() < 1e-12);
        assert_eq!(pose.heading, start.heading);
    }

    #[test]
    fn wheels_opposite_turn_on_the_spot() {
        let start = Pose {
            at: Point::new(3.0, 4.0),
            heading: 0.0,
        };
        // Each wheel on a circle of wheel_base / 2: a step of each turns
        // the robot by step / (wheel_base / 2) radians, left.
        let mut pose = start;
        for _ in 0..30 {
            pose = DRIVE.moved(pose, -1, 1);
        }
        assert_eq!(pose.at, start.at);
        let expected = 30.0 * 0.5 / 10.0 * 180.0 / PI;
        assert!(
            (pose.heading_degrees() - expected).abs() < 1e-9,
            "{} against {expected}",
            pose.heading_degrees()
        );
    }
}
