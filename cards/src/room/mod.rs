//! The robot in a room: a world file ([`file`]) gives the walls,
//! obstacles and floor lines, the robot's start pose, drive and sensors;
//! [`Room`] follows the drive motors' steps to the robot's pose
//! ([`drive`]) and closes a bumper while its part of the outline touches
//! something, lights a ground-tracker phototransistor over a floor line
//! while the lamps are on, and fills the infrared scanner's readings
//! from what is round the robot ([`scanner`]). A world script named by the file adds what
//! the file cannot say. See docs/WORLD.md.

pub mod drive;
pub mod file;
pub mod geometry;
pub mod live;
pub mod picture;
pub mod raster;
pub mod scanner;
pub mod trail;

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use emulator::board::{Motor, Scorpion};
use romlib::Surroundings;

use crate::error::ScriptError;
use drive::Pose;
use file::Layout;
use geometry::{Point, ShapeGrid, near_polyline, sin_cos};
pub use trail::{MAX_TRAIL, Trail};

/// Robot time between two looks at the motors, cycles (1 ms): a drive
/// steps at most 495 times a second (speed 99), so each look sees one
/// step a wheel at most, and a bumper closes within a millisecond of the
/// step that made the contact.
pub const TICK: u64 = 1000;

/// The `DRIVE` latch's scanner driver enables.
const SCANNERS: u8 = platform::map::drive::H_SCANNER | platform::map::drive::V_SCANNER;

/// Points each bumper's part of the outline is felt at.
const FEELERS: u32 = 9;

/// A handle on the room as the robot runs: its pose and trail, read by
/// the host while the room itself belongs to the virtual robot.
#[derive(Debug, Clone)]
pub struct RoomView {
    trail: Arc<Mutex<Trail>>,
    layout: Arc<Layout>,
    /// The host's changes of the room ([`live`]).
    edits: Arc<live::Mailbox>,
    /// The room's [`Room::obstacle_tests`], as of its last look.
    obstacle_tests: Arc<AtomicU64>,
}

impl RoomView {
    /// The robot's pose now.
    #[must_use]
    pub fn pose(&self) -> Option<Pose> {
        self.trail
            .lock()
            .ok()
            .and_then(|trail| trail.poses.last().map(|&(_, pose)| pose))
    }

    /// The trail so far.
    #[must_use]
    pub fn trail(&self) -> Trail {
        self.trail.lock().map(|t| t.clone()).unwrap_or_default()
    }

    /// What the trail holds after robot time `after`, and the pose then
    /// ([`Trail::after`]): a session that goes back in time gathers its
    /// whole run with [`Trail::follow`], without copying all of it each
    /// time.
    #[must_use]
    pub fn trail_after(&self, after: u64) -> (Option<Pose>, Trail) {
        self.trail
            .lock()
            .map(|trail| trail.after(after))
            .unwrap_or_default()
    }

    /// How many times the room has tested a point against an obstacle,
    /// as of its last look at the motors ([`Room::obstacle_tests`]).
    #[must_use]
    pub fn obstacle_tests(&self) -> u64 {
        self.obstacle_tests.load(Ordering::Relaxed)
    }

    /// The path as a picture (SVG text, [`picture::svg`]), with
    /// `commands` (robot time, text) placed along it.
    #[must_use]
    pub fn svg(&self, commands: &[(u64, String)]) -> String {
        picture::svg(&self.layout, &self.trail(), commands)
    }
}

/// The robot's surroundings from a world file.
#[derive(Debug)]
pub struct Room {
    layout: Layout,
    /// The obstacles by where they lie.
    grid: ShapeGrid,
    pose: Pose,
    /// The drive motors' positions at the last look (`None`: no look
    /// yet; the robot stands at its start pose whatever they read).
    motors: Option<(i64, i64)>,
    /// What the room last set: bumpers, phototransistors.
    bumpers: u8,
    sense: u8,
    /// The pose the bumpers were last felt at, and what they felt: a
    /// robot standing still touches what it touched.
    felt: Option<(Pose, u8)>,
    /// The pose and lamps the trackers last looked with, and what they
    /// saw.
    seen: Option<(Pose, bool, u8)>,
    /// Points tested against obstacles ([`Room::obstacle_tests`]).
    obstacle_tests: std::cell::Cell<u64>,
    next_look: u64,
    /// The scanner's rays, and whether the pose (or the room) changed
    /// since its readings were last set.
    scanner: scanner::Scanner,
    scan_due: bool,
    script: Option<Box<dyn Surroundings>>,
    view: RoomView,
}

impl Room {
    /// Reads the world file `text` (named `name` in errors).
    ///
    /// # Errors
    /// [`ScriptError::Script`] at the place of a mistake in the file.
    pub fn load(name: &str, text: &str) -> Result<Room, ScriptError> {
        let layout = file::parse(name, text)?;
        let pose = layout.start;
        let view = RoomView {
            trail: Arc::new(Mutex::new(Trail {
                poses: vec![(0, pose)],
                ..Trail::default()
            })),
            layout: Arc::new(layout.clone()),
            edits: Arc::default(),
            obstacle_tests: Arc::new(AtomicU64::new(0)),
        };
        Ok(Room {
            grid: ShapeGrid::new(&layout.obstacles),
            layout,
            pose,
            motors: None,
            bumpers: 0,
            sense: 0,
            felt: None,
            seen: None,
            obstacle_tests: std::cell::Cell::new(0),
            next_look: 0,
            scanner: scanner::Scanner::default(),
            scan_due: true,
            script: None,
            view,
        })
    }

    /// The world script the file names (`script = "..."`), as written:
    /// relative to the file's folder.
    #[must_use]
    pub fn script_path(&self) -> Option<&str> {
        self.layout.script.as_deref()
    }

    /// Adds surroundings (the world script) that run with the room.
    pub fn add(&mut self, script: Box<dyn Surroundings>) {
        self.script = Some(script);
    }

    /// The file as read, defaults filled in.
    #[must_use]
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// A handle on the robot's pose and trail.
    #[must_use]
    pub fn view(&self) -> RoomView {
        self.view.clone()
    }

    /// The robot's pose.
    #[must_use]
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// How many times the room has tested a point against an obstacle:
    /// its work, which grows with the obstacles near the robot, not with
    /// those far away, and stops while the robot stands still.
    #[must_use]
    pub fn obstacle_tests(&self) -> u64 {
        self.obstacle_tests.get()
    }

    /// Whether the floor point `point` is taken by a wall or an obstacle
    /// (only those whose box it is in can hold it).
    fn blocked(&self, point: Point) -> bool {
        self.layout
            .walls
            .as_ref()
            .is_some_and(|walls| !geometry::inside_polygon(walls, point))
            || self.grid.near(point).any(|shape| {
                self.obstacle_tests.set(self.obstacle_tests.get() + 1);
                self.layout
                    .obstacles
                    .get(shape)
                    .is_some_and(|o| o.contains(point))
            })
    }

    /// The bumpers closed at the robot's pose: a bit for each whose part
    /// of the outline touches a wall or an obstacle.
    #[must_use]
    pub fn contacts(&self) -> u8 {
        let body = &self.layout.body;
        let mut closed = 0;
        for (bit, &middle) in body.bumpers.iter().enumerate() {
            let touches = (0..FEELERS).any(|k| {
                let share = f64::from(k) / f64::from(FEELERS - 1) - 0.5;
                let (sin, cos) = sin_cos(middle + share * body.bumper_arc);
                self.blocked(self.pose.place(body.radius * cos, body.radius * sin))
            });
            if touches {
                closed |= 1 << bit;
            }
        }
        closed
    }

    /// The phototransistors (`SENSE` bits: 0 right, 1 left) at the
    /// robot's pose with the lamps as `lamps` says.
    #[must_use]
    pub fn sees(&self, lamps: bool) -> u8 {
        if !lamps {
            return 0;
        }
        let body = &self.layout.body;
        let over = |(forward, left): (f64, f64)| {
            let point = self.pose.place(forward, left);
            self.layout
                .lines
                .iter()
                .any(|line| near_polyline(&line.points, line.width / 2.0, point))
        };
        u8::from(over(body.right_tracker)) | (u8::from(over(body.left_tracker)) << 1)
    }

    /// Follows the motors to `now` and sets the robot's inputs.
    fn look(&mut self, now: u64, robot: &mut Scorpion) {
        let board = robot.board();
        let motors = (
            board.motor(Motor::Left).position(),
            board.motor(Motor::Right).position(),
        );
        let lamps = board.lamps();
        // The first look sets the scanner's readings whatever the
        // drivers: a world script's `scene_at` then lands on the room's
        // row and keeps the rest of it.
        let first = self.motors.is_none();
        let last = self.motors.unwrap_or(motors);
        let (left, right) = (motors.0 - last.0, motors.1 - last.1);
        self.motors = Some(motors);
        let moved = left != 0 || right != 0;
        if moved {
            self.pose = self.layout.drive.moved(self.pose, left, right);
        }
        let closed = match self.felt {
            Some((pose, closed)) if pose == self.pose => closed,
            _ => self.contacts(),
        };
        self.felt = Some((self.pose, closed));
        if closed != self.bumpers {
            self.bumpers = closed;
            robot.set_bumpers(closed);
        }
        let sense = match self.seen {
            Some((pose, on, sense)) if pose == self.pose && on == lamps => sense,
            _ => self.sees(lamps),
        };
        self.seen = Some((self.pose, lamps, sense));
        self.view
            .obstacle_tests
            .store(self.obstacle_tests.get(), Ordering::Relaxed);
        if sense != self.sense {
            self.sense = sense;
            robot.board_mut().set_phototransistors(sense);
        }
        self.scan_due |= moved;
        // The detector is read while a scan runs, which has a scanner's
        // driver enabled: 256 rays at every look of a drive would cost
        // as much as the robot's own program.
        if self.scan_due && (first || robot.board().drive_latch() & SCANNERS != 0) {
            self.scan_due = false;
            let row = self.scanner.row(&self.layout, self.pose);
            robot.board_mut().scene_mut().set_row(&row);
        }
        if let Ok(mut trail) = self.view.trail.lock() {
            if moved && trail.poses.len() < MAX_TRAIL {
                trail.poses.push((now, self.pose));
            }
            if trail
                .bumps
                .last()
                .map_or(closed != 0, |&(_, b)| b != closed)
                && trail.bumps.len() < MAX_TRAIL
            {
                trail.bumps.push((now, closed));
            }
        }
    }
}

impl Surroundings for Room {
    fn next_wake(&self) -> Option<u64> {
        if self.view.edits.pending() {
            // Now: the host's edit is made even while the robot stands.
            return Some(0);
        }
        let script = self.script.as_ref().and_then(|s| s.next_wake());
        Some(script.map_or(self.next_look, |s| s.min(self.next_look)))
    }

    fn wake(
        &mut self,
        now: u64,
        robot: &mut Scorpion,
    ) -> Result<(), Box<dyn miette::Diagnostic + Send + Sync>> {
        let edited = self.take_edits(now);
        self.scan_due |= edited;
        if now >= self.next_look {
            self.look(now, robot);
            self.next_look = now + TICK;
        } else if edited {
            self.look(now, robot);
        }
        if let Some(script) = &mut self.script
            && script.next_wake().is_some_and(|at| at <= now)
        {
            script.wake(now, robot)?;
        }
        Ok(())
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    /// The room with its pose and script copied; the copy's trail goes on
    /// from this one's in its own [`RoomView`].
    fn snapshot(&self) -> Option<Box<dyn Surroundings>> {
        let script = match &self.script {
            Some(script) => Some(script.snapshot()?),
            None => None,
        };
        Some(Box::new(Room {
            layout: self.layout.clone(),
            grid: self.grid.clone(),
            pose: self.pose,
            motors: self.motors,
            bumpers: self.bumpers,
            sense: self.sense,
            felt: self.felt,
            seen: self.seen,
            obstacle_tests: self.obstacle_tests.clone(),
            next_look: self.next_look,
            scanner: self.scanner.clone(),
            scan_due: self.scan_due,
            script,
            view: RoomView {
                trail: Arc::new(Mutex::new(self.view.trail())),
                layout: Arc::clone(&self.view.layout),
                edits: Arc::default(),
                obstacle_tests: Arc::new(AtomicU64::new(self.obstacle_tests.get())),
            },
        }))
    }
}
