//! The live view's messages (docs/WORLD.md, "The live view"): JSON text
//! over the WebSocket. The browser sends [`Incoming`] requests; the
//! server sends the room once (and again when an obstacle moves), a
//! state frame as the robot runs with what is new on the console and the
//! trail, and errors.

use std::sync::Arc;

use cards::room::drive::Pose;
use cards::room::file::Layout;
use cards::room::geometry::Shape;
use serde::{Deserialize, Serialize};

use super::Hub;

/// The longest console line a client may send, characters.
pub(crate) const MAX_COMMAND: usize = 256;

/// The most trail points one state frame carries: a long trail reaches a
/// new client over several frames.
pub(crate) const TRAIL_PER_FRAME: usize = 4000;

/// A request from the browser.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub(crate) enum Incoming {
    /// Type a line on the serial console (a carriage return follows).
    Send {
        /// The line, as typed.
        text: String,
    },
    /// Stop the robot's clock. (Braces: a unit variant would take
    /// unknown fields without a word.)
    Pause {},
    /// Start the robot's clock again.
    Run {},
    /// Pause, then run the robot `ms` milliseconds of robot time.
    Step {
        /// Robot time, milliseconds (1 to 10 000).
        ms: u64,
    },
    /// Robot time per wall-clock time (0.1 to 100).
    Speed {
        /// The factor.
        factor: f64,
    },
    /// Pick the robot up and put it down.
    MoveRobot {
        /// East, centimetres.
        x: f64,
        /// North, centimetres.
        y: f64,
        /// Degrees counter-clockwise from east.
        heading: f64,
    },
    /// Move an obstacle's middle to (x, y).
    MoveObstacle {
        /// The obstacle, in the world file's order from 0.
        index: usize,
        /// East, centimetres.
        x: f64,
        /// North, centimetres.
        y: f64,
    },
}

impl Incoming {
    /// Parses a client's message; in words what is wrong if it is not one.
    pub(crate) fn parse(text: &str) -> Result<Incoming, String> {
        let incoming: Incoming = serde_json::from_str(text).map_err(|error| {
            format!(
                "not a request of the view ({error}); send e.g. {{\"type\":\"send\",\"text\":\"/1B\"}}"
            )
        })?;
        match &incoming {
            Incoming::Send { text } if text.chars().count() > MAX_COMMAND => Err(format!(
                "a console line may be {MAX_COMMAND} characters; this one has {}",
                text.chars().count()
            )),
            // One send is one command line: a carriage return inside it
            // would type several commands (and other control characters
            // are not the robot's ASCII), so they are refused, not
            // stripped: what is typed is what the robot gets.
            Incoming::Send { text } if text.chars().any(|c| c.is_ascii_control()) => {
                let (at, control) = text
                    .chars()
                    .enumerate()
                    .find(|(_, c)| c.is_ascii_control())
                    .unwrap_or((0, '\0'));
                Err(format!(
                    "a console line is one command, without control characters: this one has {} at character {}; send each command on its own",
                    control.escape_default(),
                    at + 1
                ))
            }
            Incoming::Step { ms } if !(1..=10_000).contains(ms) => {
                Err(format!("a step is 1 to 10000 ms of robot time, not {ms}"))
            }
            Incoming::Speed { factor } if !(0.1..=100.0).contains(factor) => Err(format!(
                "the speed is 0.1 to 100 times the robot's, not {factor}"
            )),
            _ => Ok(incoming),
        }
    }
}

/// A line of the serial console.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ConsoleLine {
    /// Its number, counting from 1 over the session.
    pub(crate) seq: u64,
    /// `sent` (typed in a browser), `answer` (the robot's), `note` (what
    /// the line lost, a refused request).
    pub(crate) kind: &'static str,
    /// The text.
    pub(crate) text: String,
}

/// The robot as the room and the board show it, at a moment.
#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct State {
    /// Robot time, milliseconds since power-up.
    pub(crate) ms: f64,
    /// Whether the robot's clock is stopped.
    pub(crate) paused: bool,
    /// Robot time per wall-clock time.
    pub(crate) speed: f64,
    /// The middle of the axle and the heading (none without a room).
    pub(crate) pose: Option<PoseJson>,
    /// Closed bumper microswitches, a bit each.
    pub(crate) bumpers: u8,
    /// The lit phototransistors (`SENSE`: bit 0 right, bit 1 left).
    pub(crate) trackers: u8,
    /// Whether the ground-tracker lamps are on.
    pub(crate) lamps: bool,
    /// The eye lamps: left, right.
    pub(crate) eyes: [bool; 2],
    /// The drive motors' positions, steps: left, right.
    pub(crate) motors: [i64; 2],
    /// Clients connected.
    pub(crate) clients: usize,
}

/// A pose in the view's units: centimetres, degrees.
#[derive(Debug, Clone, Copy, Serialize)]
pub(crate) struct PoseJson {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) heading: f64,
}

impl From<Pose> for PoseJson {
    fn from(pose: Pose) -> PoseJson {
        PoseJson {
            x: tenth(pose.at.x),
            y: tenth(pose.at.y),
            heading: tenth(pose.heading_degrees()),
        }
    }
}

/// Radians to degrees, to a hundredth.
fn degrees(radians: f64) -> f64 {
    tenth(radians * 180.0 / cards::room::geometry::PI)
}

/// To a hundredth: the view draws at a fraction of a centimetre.
fn tenth(value: f64) -> f64 {
    (value * 100.0).round() / 100.0
}

/// What the robot's loop publishes for the clients ([`Hub::publish`]).
#[derive(Debug, Default)]
pub(crate) struct Frame {
    /// Bumped when the room changes (an obstacle moved).
    pub(crate) room_version: u64,
    /// The room message, as sent.
    pub(crate) room: Arc<String>,
    /// The robot now.
    pub(crate) state: State,
    /// The console's last lines ([`super::CONSOLE_KEPT`]).
    pub(crate) console: Arc<Vec<ConsoleLine>>,
}

/// A message to a client.
#[derive(Debug, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub(crate) enum Outgoing<'a> {
    /// The robot now, what is new on the console and the trail.
    State {
        #[serde(flatten)]
        state: &'a State,
        /// The index of the first trail point here, in the whole trail.
        trail_from: usize,
        /// New trail points: [x, y, ms].
        trail: Vec<[f64; 3]>,
        /// The points of `trail` (indices into it) the robot was put at by
        /// a drag rather than driven to: the stretch into each is a jump.
        jumps: Vec<usize>,
        /// New console lines.
        console: Vec<&'a ConsoleLine>,
    },
    /// A request refused, or a connection about to be closed.
    Error {
        /// Why.
        message: String,
    },
    /// A text already serialized (the room).
    #[serde(skip)]
    Raw(Arc<String>),
}

impl Outgoing<'_> {
    pub(crate) fn error(message: &str) -> Outgoing<'static> {
        Outgoing::Error {
            message: message.to_owned(),
        }
    }

    pub(crate) fn to_json(&self) -> String {
        match self {
            Outgoing::Raw(text) => text.as_str().to_owned(),
            other => serde_json::to_string(other).unwrap_or_else(|_| "{}".to_owned()),
        }
    }
}

/// The room message: walls, obstacles, floor lines, the robot's body.
pub(crate) fn room_message(layout: Option<&Layout>) -> String {
    let Some(layout) = layout else {
        return r#"{"type":"room","room":null}"#.to_owned();
    };
    let point = |p: &cards::room::geometry::Point| [p.x, p.y];
    let obstacles: Vec<serde_json::Value> = layout
        .obstacles
        .iter()
        .map(|shape| match shape {
            Shape::Circle { centre, radius } => serde_json::json!({
                "circle": {"x": centre.x, "y": centre.y, "radius": radius}
            }),
            Shape::Polygon(corners) => serde_json::json!({
                "polygon": corners.iter().map(point).collect::<Vec<_>>()
            }),
        })
        .collect();
    let body = &layout.body;
    serde_json::json!({
        "type": "room",
        "room": {
            "walls": layout.walls.as_ref().map(|w| w.iter().map(point).collect::<Vec<_>>()),
            "obstacles": obstacles,
            "lines": layout.lines.iter().map(|line| serde_json::json!({
                "points": line.points.iter().map(point).collect::<Vec<_>>(),
                "width": line.width,
            })).collect::<Vec<_>>(),
            "start": PoseJson::from(layout.start),
            "body": {
                "radius": body.radius,
                // Degrees, as the file writes them (the room keeps radians).
                "bumpers": body.bumpers.iter().map(|&b| degrees(b)).collect::<Vec<_>>(),
                "bumper_arc": degrees(body.bumper_arc),
                "left_tracker": [body.left_tracker.0, body.left_tracker.1],
                "right_tracker": [body.right_tracker.0, body.right_tracker.1],
            },
        }
    })
    .to_string()
}

/// What a connection has sent its client, to send only what is new.
#[derive(Debug, Default)]
pub(crate) struct Client {
    room_version: Option<u64>,
    generation: u64,
    trail: usize,
    /// The last trail point sent.
    drawn: Option<(f64, f64)>,
    console: u64,
}

impl Client {
    /// The next message for this client, if anything is new.
    pub(crate) fn next(&mut self, hub: &Hub) -> Option<Outgoing<'static>> {
        let (generation, frame) = hub.frame();
        if frame.room.is_empty() {
            // The robot's loop has not published its first frame yet.
            return None;
        }
        if self.room_version != Some(frame.room_version) {
            self.room_version = Some(frame.room_version);
            return Some(Outgoing::Raw(Arc::clone(&frame.room)));
        }
        let (trail, total) = hub.room.as_ref().map_or((Vec::new(), 0), |room| {
            room.trail_since(self.trail, TRAIL_PER_FRAME)
        });
        if generation == self.generation && trail.is_empty() {
            return None;
        }
        self.generation = generation;
        let trail_from = self.trail;
        self.trail = (self.trail + trail.len()).min(total);
        let console: Vec<&ConsoleLine> = frame
            .console
            .iter()
            .filter(|line| line.seq > self.console)
            .collect();
        if let Some(last) = console.last() {
            self.console = last.seq;
        }
        let (trail, jumps) = self.thin(&trail);
        let message = Outgoing::State {
            state: &frame.state,
            trail_from,
            trail,
            jumps,
            console,
        };
        // Serialized here: the frame's borrow ends with this call.
        Some(Outgoing::Raw(Arc::new(message.to_json())))
    }

    /// The poses as points half a centimetre apart at least (the room
    /// looks every millisecond: the picture needs far fewer), the last
    /// one always, and each jump with the point before it: [x, y, ms];
    /// and which of them are jumps.
    fn thin(&mut self, poses: &[(u64, Pose, bool)]) -> (Vec<[f64; 3]>, Vec<usize>) {
        let mut points = Vec::new();
        let mut jumps = Vec::new();
        for (index, &(cycle, pose, jump)) in poses.iter().enumerate() {
            let (x, y) = (pose.at.x, pose.at.y);
            let far = self
                .drawn
                .is_none_or(|(px, py)| (x - px) * (x - px) + (y - py) * (y - py) >= 0.25);
            let before_jump = poses.get(index + 1).is_some_and(|next| next.2);
            if far || jump || before_jump || index + 1 == poses.len() {
                self.drawn = Some((x, y));
                if jump {
                    jumps.push(points.len());
                }
                #[allow(clippy::cast_precision_loss, reason = "robot time in ms")]
                points.push([tenth(x), tenth(y), cycle as f64 / 1000.0]);
            }
        }
        (points, jumps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_parse_and_bad_ones_say_why() {
        assert_eq!(
            Incoming::parse(r#"{"type":"send","text":"/2A1"}"#),
            Ok(Incoming::Send {
                text: "/2A1".into()
            })
        );
        assert_eq!(
            Incoming::parse(r#"{"type":"step","ms":100}"#),
            Ok(Incoming::Step { ms: 100 })
        );
        for (text, said) in [
            ("not json", "not a request of the view"),
            (r#"{"type":"launch"}"#, "unknown variant `launch`"),
            (r#"{"type":"pause","extra":1}"#, "unknown field"),
            (r#"{"type":"step","ms":0}"#, "1 to 10000 ms"),
            (r#"{"type":"speed","factor":1000}"#, "0.1 to 100"),
            (
                r#"{"type":"move_robot","x":1,"y":2}"#,
                "missing field `heading`",
            ),
        ] {
            let error = Incoming::parse(text).expect_err(text);
            assert!(error.contains(said), "{text}: {error}");
        }
        let long = format!(
            r#"{{"type":"send","text":"{}"}}"#,
            "/".repeat(MAX_COMMAND + 1)
        );
        assert!(
            Incoming::parse(&long)
                .expect_err("too long")
                .contains("256 characters")
        );
    }

    /// The hostile tester's finding: `/1B` CR `/4C+40` in one send typed
    /// two commands. One send is one line; control characters are
    /// refused, named with their place.
    #[test]
    fn a_console_line_is_one_command() {
        for (text, said) in [
            (
                r#"{"type":"send","text":"/1B\r/4C+40"}"#,
                "\\r at character 4",
            ),
            (r#"{"type":"send","text":"/1B\n"}"#, "\\n at character 4"),
            (
                r#"{"type":"send","text":"\u001b/1B"}"#,
                "\\u{1b} at character 1",
            ),
            (
                r#"{"type":"send","text":"/1B\u007f"}"#,
                "\\u{7f} at character 4",
            ),
        ] {
            let error = Incoming::parse(text).expect_err(text);
            assert!(error.contains(said), "{text}: {error}");
            assert!(error.contains("one command"), "{text}: {error}");
        }
        assert_eq!(
            Incoming::parse(r#"{"type":"send","text":"/2A1 é"}"#),
            Ok(Incoming::Send {
                text: "/2A1 é".into()
            })
        );
    }
}
