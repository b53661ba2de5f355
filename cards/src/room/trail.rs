//! Where the robot went: its poses and bumps in robot time, the poses it
//! was put at by the host (a drag in the live view) told apart from those
//! it drove to, and the whole run of a session that steps back in time
//! (`scorpion debug`), gathered as robot time goes forward.

use super::drive::Pose;

/// Where the robot went, kept for the picture and the transcripts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trail {
    /// The pose after each look at which the robot had moved, with the
    /// robot time (cycles); the start pose at 0 first.
    pub poses: Vec<(u64, Pose)>,
    /// Each change of the bumpers the room closed, with the robot time.
    pub bumps: Vec<(u64, u8)>,
    /// The poses (indices into `poses`, rising) the robot was put at
    /// rather than driven to: a drag in the live view, or a session that
    /// went back in time and drove elsewhere. The stretch from the pose
    /// before is a jump, not a drive: drawn apart, never as driven trail.
    pub jumps: Vec<usize>,
}

/// The most poses a trail keeps: past that, the robot's later moves are
/// not drawn (a run of hours), and the pose is still followed.
pub const MAX_TRAIL: usize = 200_000;

impl Trail {
    /// Whether the pose at `index` was a jump (see [`Trail::jumps`]).
    #[must_use]
    pub fn is_jump(&self, index: usize) -> bool {
        self.jumps.binary_search(&index).is_ok()
    }

    /// Adds the pose the robot was put at, at `now`: a jump.
    pub(super) fn jump(&mut self, now: u64, pose: Pose) {
        if self.poses.len() < MAX_TRAIL {
            self.jumps.push(self.poses.len());
            self.poses.push((now, pose));
        }
    }

    /// What this trail holds after robot time `after`, and the pose the
    /// robot had then (the last at or before it), for
    /// [`Trail::follow`].
    #[must_use]
    pub fn after(&self, after: u64) -> (Option<Pose>, Trail) {
        let first = self.poses.partition_point(|&(at, _)| at <= after);
        let bumps = self.bumps.partition_point(|&(at, _)| at <= after);
        let jumps = self.jumps.partition_point(|&index| index < first);
        let then = first
            .checked_sub(1)
            .and_then(|index| self.poses.get(index))
            .map(|&(_, pose)| pose);
        let tail = Trail {
            poses: self.poses[first..].to_vec(),
            bumps: self.bumps[bumps..].to_vec(),
            jumps: self.jumps[jumps..]
                .iter()
                .map(|index| index - first)
                .collect(),
        };
        (then, tail)
    }

    /// Adds what a run holds past robot time `reached` (`then`, `tail`
    /// from [`Trail::after`]): the trail of a session that goes back in
    /// time grows as its robot time does, each stretch of robot time
    /// drawn once, as first run. A run that went back and left the way it
    /// first took (other commands sent) joins with a jump.
    pub fn follow(&mut self, then: Option<Pose>, tail: Trail) {
        if tail.poses.is_empty() && tail.bumps.is_empty() {
            return;
        }
        if let (Some(then), Some(&(first, _))) = (then, tail.poses.first())
            && self.poses.last().is_some_and(|&(_, last)| last != then)
            && !tail.jumps.contains(&0)
        {
            self.jump(first, then);
        }
        let offset = self.poses.len();
        for (index, entry) in tail.poses.into_iter().enumerate() {
            if self.poses.len() >= MAX_TRAIL {
                break;
            }
            if tail.jumps.binary_search(&index).is_ok() {
                self.jumps.push(offset + index);
            }
            self.poses.push(entry);
        }
        let room = MAX_TRAIL.saturating_sub(self.bumps.len());
        self.bumps.extend(tail.bumps.into_iter().take(room));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::room::geometry::Point;

    fn at(x: f64) -> Pose {
        Pose {
            at: Point::new(x, 0.0),
            heading: 0.0,
        }
    }

    fn trail(xs: &[(u64, f64)]) -> Trail {
        Trail {
            poses: xs.iter().map(|&(t, x)| (t, at(x))).collect(),
            ..Trail::default()
        }
    }

    /// A session runs to 5, steps back to 2 and runs on to 4 (the same
    /// way), then to 7: each stretch of robot time drawn once.
    #[test]
    fn a_run_again_over_the_same_time_is_drawn_once() {
        let first = trail(&[(0, 0.0), (1, 1.0), (2, 2.0), (3, 3.0), (4, 4.0), (5, 5.0)]);
        let mut run = Trail::default();
        let (then, tail) = first.after(0);
        run.poses.push((0, at(0.0)));
        run.follow(then, tail);
        assert_eq!(run, first);
        // Back to 2, on to 4: nothing past 5.
        let again = trail(&[(0, 0.0), (1, 1.0), (2, 2.0), (3, 3.0), (4, 4.0)]);
        let (then, tail) = again.after(5);
        run.follow(then, tail);
        assert_eq!(run, first);
        let on = trail(&[(0, 0.0), (1, 1.0), (2, 2.0), (5, 5.0), (6, 6.0), (7, 7.0)]);
        let (then, tail) = on.after(5);
        run.follow(then, tail);
        assert_eq!(run.poses.len(), 8);
        assert!(run.jumps.is_empty(), "the same way: no jump");
    }

    /// Back in time, then elsewhere: the new way joins with a jump.
    #[test]
    fn a_run_that_left_its_way_joins_with_a_jump() {
        let mut run = trail(&[(0, 0.0), (5, 5.0)]);
        let other = trail(&[(0, 0.0), (3, -3.0), (6, -6.0)]);
        let (then, tail) = other.after(5);
        run.follow(then, tail);
        assert_eq!(run.jumps, vec![2]);
        assert_eq!(run.poses[2].1, at(-3.0));
        assert_eq!(run.poses[3].1, at(-6.0));
    }
}
