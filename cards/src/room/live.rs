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
use super::geometry::{Point, Shape, inside_polygon, segment_distance2};
use super::{Room, RoomView};

/// The most edits waiting: a host that sends more before the robot runs
/// again is told so ([`RoomView::edit`] returns `false`).
pub const MAX_EDITS: usize = 64;

/// The farthest from the origin anything may be put, centimetres (a
/// kilometre): past it a number is a mistake, not a room.
pub const MAX_COORDINATE: f64 = 100_000.0;

/// How far a drag may press the robot's outline into a wall or an
/// obstacle, centimetres: a bumper pressed against something (which
/// closes it, the point of such a drag), not a robot inside it. The world
/// file's start pose is refused inside an obstacle or outside the walls;
/// a drag is held to the outline, as the robot is a body, not a point.
pub const CONTACT: f64 = 2.0;

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
    /// Whether the edit can be made to `layout` with the robot at
    /// `pose`: finite numbers within [`MAX_COORDINATE`], an obstacle that
    /// exists, and a room that still makes sense after it: the robot's
    /// outline inside the walls and out of every obstacle (pressed into
    /// one [`CONTACT`] at most), an obstacle not across a wall nor onto
    /// the robot. The reason if not.
    ///
    /// # Errors
    /// What is wrong with the edit, in words for the host to show.
    pub fn check(&self, layout: &Layout, pose: Pose) -> Result<(), String> {
        let near = |p: Point| {
            p.x.is_finite()
                && p.y.is_finite()
                && p.x.abs() <= MAX_COORDINATE
                && p.y.abs() <= MAX_COORDINATE
        };
        let radius = layout.body.radius;
        match *self {
            Edit::MoveRobot(to) => {
                if !near(to.at) || !to.heading.is_finite() || to.heading.abs() > 1000.0 {
                    return Err(format!(
                        "the robot cannot go to x={} y={} heading={} (within {MAX_COORDINATE} cm of the origin)",
                        to.at.x, to.at.y, to.heading
                    ));
                }
                let here = format!("the robot cannot go to x={} y={}", to.at.x, to.at.y);
                if let Some(walls) = &layout.walls {
                    let depth = circle_out_of(walls, to.at, radius);
                    if !inside_polygon(walls, to.at) {
                        return Err(format!("{here}: its middle would be outside the walls"));
                    }
                    if depth > CONTACT {
                        return Err(format!(
                            "{here}: its outline would be {} cm across the walls (it may press a wall {CONTACT} cm at most)",
                            centimetres(depth)
                        ));
                    }
                }
                for (index, shape) in layout.obstacles.iter().enumerate() {
                    let depth = circle_into(shape, to.at, radius);
                    if shape.contains(to.at) {
                        return Err(format!("{here}: its middle would be in obstacle {index}"));
                    }
                    if depth > CONTACT {
                        return Err(format!(
                            "{here}: its outline would be {} cm into obstacle {index} (it may press an obstacle {CONTACT} cm at most)",
                            centimetres(depth)
                        ));
                    }
                }
            }
            Edit::MoveObstacle { index, to } => {
                let Some(shape) = layout.obstacles.get(index) else {
                    return Err(format!(
                        "the room has {} obstacle(s); there is no obstacle {index}",
                        layout.obstacles.len()
                    ));
                };
                if !near(to) {
                    return Err(format!(
                        "obstacle {index} cannot go to x={} y={} (within {MAX_COORDINATE} cm of the origin)",
                        to.x, to.y
                    ));
                }
                let moved = moved_to(shape, to);
                let here = format!("obstacle {index} cannot go to x={} y={}", to.x, to.y);
                let depth = circle_into(&moved, pose.at, radius);
                if depth > CONTACT {
                    return Err(format!(
                        "{here}: it would be {} cm into the robot (it may press the robot {CONTACT} cm at most)",
                        centimetres(depth)
                    ));
                }
                if let Some(walls) = &layout.walls
                    && let Some(out) = obstacle_out_of_walls(walls, &moved)
                {
                    return Err(format!(
                        "{here}: it would be across or outside the walls ({} cm out of them; it may press a wall {CONTACT} cm at most)",
                        centimetres(out)
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
                    *shape = moved_to(shape, to);
                }
            }
        }
    }
}

/// `shape` moved so that its middle is at `to`.
fn moved_to(shape: &Shape, to: Point) -> Shape {
    let middle = middle(shape);
    let (dx, dy) = (to.x - middle.x, to.y - middle.y);
    match shape {
        Shape::Circle { radius, .. } => Shape::Circle {
            centre: to,
            radius: *radius,
        },
        Shape::Polygon(corners) => Shape::Polygon(
            corners
                .iter()
                .map(|c| Point::new(c.x + dx, c.y + dy))
                .collect(),
        ),
    }
}

/// The distance from `point` to the nearest edge of the closed polygon
/// `corners`.
fn edge_distance(corners: &[Point], point: Point) -> f64 {
    let count = corners.len();
    (0..count)
        .map(|i| segment_distance2(point, corners[i], corners[(i + 1) % count]))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// How far a circle (the robot's outline) at `centre` reaches into
/// `shape`, centimetres (0 or less: clear of it). A centre inside the
/// shape is the radius and more.
fn circle_into(shape: &Shape, centre: Point, radius: f64) -> f64 {
    match shape {
        Shape::Circle {
            centre: middle,
            radius: size,
        } => radius + size - centre.distance2(*middle).sqrt(),
        Shape::Polygon(corners) => {
            let edge = edge_distance(corners, centre);
            if inside_polygon(corners, centre) {
                radius + edge
            } else {
                radius - edge
            }
        }
    }
}

/// How far a circle at `centre` reaches out of the walls `walls`
/// (0 or less: inside them). A centre outside them is the radius and
/// more.
fn circle_out_of(walls: &[Point], centre: Point, radius: f64) -> f64 {
    let edge = edge_distance(walls, centre);
    if inside_polygon(walls, centre) {
        radius - edge
    } else {
        radius + edge
    }
}

/// How far `shape` reaches out of (or across) the walls: a circle as
/// [`circle_out_of`]; a polygon by its farthest corner outside, or the
/// walls' deepest corner inside it (a wall's corner poking through).
fn shape_out_of(walls: &[Point], shape: &Shape) -> f64 {
    match shape {
        Shape::Circle { centre, radius } => circle_out_of(walls, *centre, *radius),
        Shape::Polygon(corners) => {
            let out = corners
                .iter()
                .filter(|c| !inside_polygon(walls, **c))
                .map(|c| edge_distance(walls, *c))
                .fold(0.0, f64::max);
            let through = walls
                .iter()
                .filter(|w| inside_polygon(corners, **w))
                .map(|w| edge_distance(corners, *w))
                .fold(0.0, f64::max);
            // A number that is not one (a corner at NaN) is never clear.
            if out.is_nan() || through.is_nan() {
                f64::INFINITY
            } else {
                out.max(through)
            }
        }
    }
}

/// How far `shape` reaches across or out of the walls, if more than
/// [`CONTACT`]: the one rule of where an obstacle may be, for the world
/// file's obstacles and the view's drags alike (a drag keeps the room one
/// the file could give). `None`: it is inside them (pressing a wall
/// `CONTACT` at most).
#[must_use]
pub fn obstacle_out_of_walls(walls: &[Point], shape: &Shape) -> Option<f64> {
    let out = shape_out_of(walls, shape);
    (out > CONTACT || out.is_nan()).then_some(out)
}

/// A length to a tenth of a centimetre, for a message.
pub(super) fn centimetres(length: f64) -> String {
    format!("{:.1}", (length * 10.0).round() / 10.0)
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
    /// each with whether the robot was put there (a jump: a drag, not a
    /// drive), and how many poses the trail has: a view draws the trail
    /// as it grows without copying all of it each time.
    #[must_use]
    pub fn trail_since(&self, from: usize, most: usize) -> (Vec<(u64, Pose, bool)>, usize) {
        self.trail.lock().map_or((Vec::new(), from), |trail| {
            let total = trail.poses.len();
            let start = from.min(total);
            let end = total.min(start.saturating_add(most));
            let poses = (start..end)
                .zip(&trail.poses[start..end])
                .map(|(index, &(at, pose))| (at, pose, trail.is_jump(index)))
                .collect();
            (poses, total)
        })
    }
}

impl Room {
    /// Makes the host's waiting edits; whether there were any. A moved
    /// robot's new pose joins the trail as a jump: it was put there, it
    /// did not drive.
    pub(super) fn take_edits(&mut self, now: u64) -> bool {
        let edits = self.view.edits.take();
        if edits.is_empty() {
            return false;
        }
        let before = self.pose;
        for edit in &edits {
            if edit.check(&self.layout, self.pose).is_ok() {
                edit.apply(&mut self.layout, &mut self.pose);
            }
        }
        // A moved obstacle is in other cells of the grid, and what the
        // bumpers and trackers last felt is stale even where the pose is not.
        self.grid = super::geometry::ShapeGrid::new(&self.layout.obstacles);
        self.felt = None;
        self.seen = None;
        if self.pose != before
            && let Ok(mut trail) = self.view.trail.lock()
        {
            trail.jump(now, self.pose);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::room::file::parse;

    /// The example room: walls 300 by 200, a post 20 cm round at (160,
    /// 100), a box from (240, 20) to (280, 60); the robot 15 cm round.
    const ROOM: &str = "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]
[[obstacle]]
circle = { x = 160, y = 100, radius = 20 }
[[obstacle]]
polygon = [[240, 20], [280, 20], [280, 60], [240, 60]]
[robot]
x = 100
y = 100
radius = 15
";

    fn robot_to(x: f64, y: f64) -> Edit {
        Edit::MoveRobot(Pose {
            at: Point::new(x, y),
            heading: 0.0,
        })
    }

    /// The hostile tester's finding: a drag put the robot through a wall
    /// or inside the post, which the world file refuses for its start.
    /// The outline decides: pressed against something (a bumper closed)
    /// is a drag's point; farther in is refused.
    #[test]
    fn drags_keep_the_robot_in_the_room_and_out_of_the_obstacles() {
        let layout = parse("room.toml", ROOM).expect("the room");
        let pose = layout.start;
        for (edit, refused) in [
            // Pressed 1 cm against the post: its front bumper closes.
            (robot_to(126.0, 100.0), None),
            // 2 cm against the west wall, 1 cm against the box.
            (robot_to(13.0, 100.0), None),
            (robot_to(226.0, 40.0), None),
            (
                robot_to(160.0, 100.0),
                Some("its middle would be in obstacle 0"),
            ),
            (
                robot_to(130.0, 100.0),
                Some("its outline would be 5.0 cm into obstacle 0"),
            ),
            (
                robot_to(250.0, 30.0),
                Some("its middle would be in obstacle 1"),
            ),
            (
                robot_to(228.0, 40.0),
                Some("its outline would be 3.0 cm into obstacle 1"),
            ),
            (
                robot_to(-5.0, 100.0),
                Some("its middle would be outside the walls"),
            ),
            (
                robot_to(10.0, 100.0),
                Some("its outline would be 5.0 cm across the walls"),
            ),
            (
                robot_to(f64::NAN, 100.0),
                Some("within 100000 cm of the origin"),
            ),
            // The post onto the robot at (100, 100), and pressed against it.
            (
                Edit::MoveObstacle {
                    index: 0,
                    to: Point::new(120.0, 100.0),
                },
                Some("it would be 15.0 cm into the robot"),
            ),
            (
                Edit::MoveObstacle {
                    index: 0,
                    to: Point::new(134.0, 100.0),
                },
                None,
            ),
            // Through a wall, flush with it, and outside the room.
            (
                Edit::MoveObstacle {
                    index: 0,
                    to: Point::new(160.0, 190.0),
                },
                Some("across or outside the walls"),
            ),
            (
                Edit::MoveObstacle {
                    index: 1,
                    to: Point::new(280.0, 180.0),
                },
                None,
            ),
            (
                Edit::MoveObstacle {
                    index: 1,
                    to: Point::new(290.0, 100.0),
                },
                Some("across or outside the walls"),
            ),
            (
                Edit::MoveObstacle {
                    index: 1,
                    to: Point::new(500.0, 100.0),
                },
                Some("across or outside the walls"),
            ),
        ] {
            match (edit.check(&layout, pose), refused) {
                (Ok(()), None) => {}
                (Err(why), Some(said)) => assert!(why.contains(said), "{edit:?}: {why}"),
                (outcome, _) => panic!("{edit:?}: {outcome:?}, expected {refused:?}"),
            }
        }
    }

    /// The room checks again what it is given: a refused edit sent past
    /// the host's check leaves the robot and the room as they were.
    #[test]
    fn the_room_ignores_an_edit_that_does_not_fit() {
        let layout = parse("room.toml", ROOM).expect("the room");
        let mut room = crate::room::Room::load("room.toml", ROOM).expect("the room");
        let view = room.view();
        assert!(view.edit(robot_to(160.0, 100.0)));
        assert!(view.edit(Edit::MoveObstacle {
            index: 0,
            to: Point::new(100.0, 100.0),
        }));
        assert!(room.take_edits(0));
        assert_eq!(room.pose(), layout.start);
        assert_eq!(room.layout().obstacles, layout.obstacles);
    }

    /// A drag puts the robot somewhere: a jump in the trail, not a
    /// stretch driven; an obstacle moved is no pose at all.
    #[test]
    fn a_dragged_robot_jumps_in_the_trail() {
        let mut room = crate::room::Room::load("room.toml", ROOM).expect("the room");
        let view = room.view();
        assert!(view.edit(robot_to(60.0, 60.0)));
        assert!(room.take_edits(5000));
        assert!(view.edit(Edit::MoveObstacle {
            index: 0,
            to: Point::new(170.0, 100.0),
        }));
        assert!(room.take_edits(6000));
        let trail = view.trail();
        assert_eq!(trail.poses.len(), 2, "{trail:?}");
        assert_eq!(trail.poses[1], (5000, room.pose()));
        assert_eq!(trail.jumps, vec![1]);
        let (poses, _) = view.trail_since(0, 10);
        assert_eq!(poses.iter().map(|p| p.2).collect::<Vec<_>>(), [false, true]);
    }

    /// One rule for where an obstacle may be: the world file refuses what
    /// a drag refuses (an obstacle outside the walls could not be dragged,
    /// even to where it was), and takes what a drag may do.
    #[test]
    fn the_file_and_a_drag_agree_on_where_an_obstacle_may_be() {
        for (obstacle, fits) in [
            ("circle = { x = 1000, y = 100, radius = 5 }", false),
            ("circle = { x = 160, y = 195, radius = 10 }", false),
            ("circle = { x = 292, y = 150, radius = 10 }", true),
            ("polygon = [[200, 180], [240, 180], [240, 210]]", false),
            ("polygon = [[200, 150], [240, 150], [240, 190]]", true),
        ] {
            let text = format!(
                "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n[[obstacle]]\n{obstacle}\n[robot]\nx = 100\ny = 100\n"
            );
            let file = parse("room.toml", &text);
            assert_eq!(file.is_ok(), fits, "{obstacle}: {file:?}");
            // The same obstacle in the same room, dragged to where it is.
            let mut layout = parse(
                "room.toml",
                "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n[robot]\nx = 100\ny = 100\n",
            )
            .expect("the room");
            let alone = format!("[[obstacle]]\n{obstacle}\n[robot]\nx = -500\ny = -500\n");
            let shape = parse("room.toml", &alone)
                .expect("the obstacle alone")
                .obstacles[0]
                .clone();
            let drag = Edit::MoveObstacle {
                index: 0,
                to: middle(&shape),
            };
            layout.obstacles.push(shape);
            assert_eq!(
                drag.check(&layout, layout.start).is_ok(),
                fits,
                "{obstacle}"
            );
        }
    }
}
