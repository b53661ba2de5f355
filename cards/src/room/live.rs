//! The room changed by the host while the robot runs (`scorpion sim
//! --view`: the robot or an obstacle dragged in the browser): edits wait
//! in a mailbox the host fills through [`RoomView::edit`], and the room
//! takes them at its next wake-up, then looks again, so the bumpers and
//! trackers follow the new geometry at once. Also the trail read a piece
//! at a time, for a view that draws it as it grows.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use super::drive::Pose;
use super::file::Layout;
use super::geometry::{Point, Shape};
use super::{Room, RoomView};

/// The most edits waiting: a host that sends more before the robot runs
/// again is told so ([`RoomView::edit`] returns `false`).
pub const MAX_EDITS: usize = 64;

/// The farthest from the origin anything may be put, centimetres (a
/// kilometre): past it a number is a mistake, not a room.
pub const MAX_COORDINATE: f64 = 100_000.0;

/// A change of the room asked by the host.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edit {
    /// The robot picked up and put down at `pose`.
    MoveRobot(Pose),
    /// Obstacle `index` (in the file's order) moved so that its middle
    /// (a circle's centre, the mean of a polygon's corners) is at `to`.
    MoveObstacle {
        /// Which obstacle, counting from 0.
        index: usize,
        /// Where its middle goes.
        to: Point,
    },
}

impl Edit {
    /// Whether the edit can be made to `layout`: finite numbers within
    /// [`MAX_COORDINATE`], an obstacle that exists. The reason if not.
    ///
    /// # Errors
    /// What is wrong with the edit, in words for the host to show.
    pub fn check(&self, layout: &Layout) -> Result<(), String> {
        let near = |p: Point| {
            p.x.is_finite()
                && p.y.is_finite()
                && p.x.abs() <= MAX_COORDINATE
                && p.y.abs() <= MAX_COORDINATE
        };
        match *self {
            Edit::MoveRobot(pose) => {
                if !near(pose.at) || !pose.heading.is_finite() || pose.heading.abs() > 1000.0 {
                    return Err(format!(
                        "the robot cannot go to x={} y={} heading={} (within {MAX_COORDINATE} cm of the origin)",
                        pose.at.x, pose.at.y, pose.heading
                    ));
                }
            }
            Edit::MoveObstacle { index, to } => {
                if index >= layout.obstacles.len() {
                    return Err(format!(
                        "the room has {} obstacle(s); there is no obstacle {index}",
                        layout.obstacles.len()
                    ));
                }
                if !near(to) {
                    return Err(format!(
                        "obstacle {index} cannot go to x={} y={} (within {MAX_COORDINATE} cm of the origin)",
                        to.x, to.y
                    ));
                }
            }
        }
        Ok(())
    }

    /// Makes the edit to `layout` and `pose` (a checked edit; an
    /// unchecked one that does not fit is ignored).
    pub fn apply(&self, layout: &mut Layout, pose: &mut Pose) {
        match *self {
            Edit::MoveRobot(to) => *pose = to,
            Edit::MoveObstacle { index, to } => {
                if let Some(shape) = layout.obstacles.get_mut(index) {
                    let middle = middle(shape);
                    let (dx, dy) = (to.x - middle.x, to.y - middle.y);
                    match shape {
                        Shape::Circle { centre, .. } => *centre = to,
                        Shape::Polygon(corners) => {
                            for corner in corners {
                                *corner = Point::new(corner.x + dx, corner.y + dy);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A shape's middle: a circle's centre, the mean of a polygon's corners.
#[must_use]
pub fn middle(shape: &Shape) -> Point {
    match shape {
        Shape::Circle { centre, .. } => *centre,
        Shape::Polygon(corners) => {
            #[allow(clippy::cast_precision_loss, reason = "a few corners")]
            let count = corners.len().max(1) as f64;
            Point::new(
                corners.iter().map(|c| c.x).sum::<f64>() / count,
                corners.iter().map(|c| c.y).sum::<f64>() / count,
            )
        }
    }
}

/// The host's edits waiting for the room.
#[derive(Debug, Default)]
pub struct Mailbox {
    /// Whether `edits` has any: read at every wake-up without a lock.
    pending: AtomicBool,
    edits: Mutex<Vec<Edit>>,
}

impl Mailbox {
    /// Whether edits wait.
    pub(super) fn pending(&self) -> bool {
        self.pending.load(Ordering::Acquire)
    }

    fn post(&self, edit: Edit) -> bool {
        let Ok(mut edits) = self.edits.lock() else {
            return false;
        };
        if edits.len() >= MAX_EDITS {
            return false;
        }
        edits.push(edit);
        self.pending.store(true, Ordering::Release);
        true
    }

    fn take(&self) -> Vec<Edit> {
        let Ok(mut edits) = self.edits.lock() else {
            return Vec::new();
        };
        self.pending.store(false, Ordering::Release);
        std::mem::take(&mut *edits)
    }
}

impl RoomView {
    /// Asks the room to make `edit` at its next wake-up (a run of the
    /// robot, even of no time: `run_for(0)`). `false` if
    /// [`MAX_EDITS`] already wait.
    pub fn edit(&self, edit: Edit) -> bool {
        self.edits.post(edit)
    }

    /// The room as the file gives it (the host follows its own edits).
    #[must_use]
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The trail's poses from the `from`th on, at most `most` of them,
    /// and how many poses the trail has: a view draws the trail as it
    /// grows without copying all of it each time.
    #[must_use]
    pub fn trail_since(&self, from: usize, most: usize) -> (Vec<(u64, Pose)>, usize) {
        self.trail.lock().map_or((Vec::new(), from), |trail| {
            let total = trail.poses.len();
            let start = from.min(total);
            let end = total.min(start.saturating_add(most));
            (trail.poses[start..end].to_vec(), total)
        })
    }
}

impl Room {
    /// Makes the host's waiting edits; whether there were any. A moved
    /// robot's new pose joins the trail.
    pub(super) fn take_edits(&mut self, now: u64) -> bool {
        let edits = self.view.edits.take();
        if edits.is_empty() {
            return false;
        }
        for edit in &edits {
            if edit.check(&self.layout).is_ok() {
                edit.apply(&mut self.layout, &mut self.pose);
            }
        }
        // A moved obstacle is in other cells of the grid, and what the
        // bumpers and trackers last felt is stale even where the pose is not.
        self.grid = super::geometry::ShapeGrid::new(&self.layout.obstacles);
        self.felt = None;
        self.seen = None;
        if let Ok(mut trail) = self.view.trail.lock()
            && trail.poses.len() < super::MAX_TRAIL
        {
            trail.poses.push((now, self.pose));
        }
        true
    }
}
