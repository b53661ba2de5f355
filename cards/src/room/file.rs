//! The world file (`world.toml`): the room, its obstacles and floor lines,
//! the robot's start pose, outline, drive and sensors, read with every
//! default of docs/WORLD.md filled in; a mistake is an error at its
//! file:line:col.

use serde::Deserialize;
use toml::Spanned;

use super::drive::{Drive, Pose};
use super::geometry::{PI, Point, Shape};
use crate::error::{Located, ScriptError, offset_of};

/// A floor line the ground trackers see.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorLine {
    /// Its middle, a polyline.
    pub points: Vec<Point>,
    /// Its width, centimetres.
    pub width: f64,
}

/// The robot's body and sensors, in its own frame (`forward` from the
/// axle's middle, `left` of it), centimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The outline, a circle round the axle's middle.
    pub radius: f64,
    /// Each bumper microswitch (bit 0 first): the middle of the part of
    /// the outline it feels, radians counter-clockwise from straight
    /// ahead.
    pub bumpers: Vec<f64>,
    /// How much of the outline each bumper feels, radians.
    pub bumper_arc: f64,
    /// The left ground-tracker phototransistor: (forward, left).
    pub left_tracker: (f64, f64),
    /// The right one.
    pub right_tracker: (f64, f64),
}

/// A world file, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The room's walls, a closed polygon the robot is inside (`None`: an
    /// open floor).
    pub walls: Option<Vec<Point>>,
    /// Obstacles on the floor.
    pub obstacles: Vec<Shape>,
    /// Lines on the floor.
    pub lines: Vec<FloorLine>,
    /// Where the robot starts.
    pub start: Pose,
    /// How its steps move it.
    pub drive: Drive,
    /// Its outline and sensors.
    pub body: Body,
    /// A world script that adds to the file, as written (relative to the
    /// file's folder).
    pub script: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    walls: Option<Spanned<Vec<[f64; 2]>>>,
    #[serde(default, rename = "obstacle")]
    obstacles: Vec<Spanned<ObstacleFile>>,
    #[serde(default, rename = "line")]
    lines: Vec<Spanned<LineFile>>,
    #[serde(default)]
    robot: RobotFile,
    script: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObstacleFile {
    polygon: Option<Spanned<Vec<[f64; 2]>>>,
    circle: Option<Spanned<CircleFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleFile {
    x: f64,
    y: f64,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LineFile {
    points: Spanned<Vec<[f64; 2]>>,
    width: Option<Spanned<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    x: Option<Spanned<f64>>,
    y: Option<Spanned<f64>>,
    heading: Option<Spanned<f64>>,
    radius: Option<Spanned<f64>>,
    step: Option<Spanned<f64>>,
    wheel_base: Option<Spanned<f64>>,
    bumpers: Option<Spanned<Vec<f64>>>,
    bumper_arc: Option<Spanned<f64>>,
    left_tracker: Option<Spanned<[f64; 2]>>,
    right_tracker: Option<Spanned<[f64; 2]>>,
}

/// The defaults (docs/WORLD.md lists them).
pub mod defaults {
    /// Width of a floor line, centimetres (electrical tape).
    pub const LINE_WIDTH: f64 = 2.0;
    /// The outline's radius, centimetres.
    pub const RADIUS: f64 = 15.0;
    /// A wheel's travel per step, centimetres: a 7 cm wheel on a
    /// 200-step motor.
    pub const STEP: f64 = 0.11;
    /// Distance between the wheels, centimetres.
    pub const WHEEL_BASE: f64 = 22.0;
    /// Bumper microswitches, bit 0 first, degrees counter-clockwise from
    /// straight ahead: bit 4 at the front, then round to the left.
    pub const BUMPERS: [f64; 8] = [180.0, 225.0, 270.0, 315.0, 0.0, 45.0, 90.0, 135.0];
    /// How much of the outline each bumper feels, degrees.
    pub const BUMPER_ARC: f64 = 45.0;
    /// The left phototransistor: forward, left, centimetres.
    pub const LEFT_TRACKER: [f64; 2] = [10.0, 1.5];
    /// The right phototransistor.
    pub const RIGHT_TRACKER: [f64; 2] = [10.0, -1.5];
}

/// Reads the world file `text`, named `name` in errors.
///
/// # Errors
/// [`ScriptError::Script`] at the place of a TOML mistake, an unknown
/// key, or a value out of range.
pub fn parse(name: &str, text: &str) -> Result<Layout, ScriptError> {
    let at = |span: std::ops::Range<usize>, message: String, help: &str| {
        located(name, text, span, message, help)
    };
    let file: WorldFile = toml::from_str(text).map_err(|error| {
        at(
            error.span().unwrap_or(0..0),
            error.message().trim().to_owned(),
            "docs/WORLD.md lists the keys of a world file",
        )
    })?;
    let points = |spanned: &Spanned<Vec<[f64; 2]>>, least: usize, what: &str| {
        let list = spanned.get_ref();
        if list.len() < least {
            return Err(at(
                spanned.span(),
                format!("{what}: {} points, at least {least} needed", list.len()),
                "points are [x, y] pairs in centimetres",
            ));
        }
        if list.iter().flatten().any(|v| !v.is_finite()) {
            return Err(at(
                spanned.span(),
                format!("{what} has a point that is not a number"),
                "points are [x, y] pairs in centimetres",
            ));
        }
        Ok(list
            .iter()
            .map(|&[x, y]| Point::new(x, y))
            .collect::<Vec<_>>())
    };
    let positive = |value: &Option<Spanned<f64>>, default: f64, what: &str| match value {
        None => Ok(default),
        Some(spanned) if spanned.get_ref().is_finite() && *spanned.get_ref() > 0.0 => {
            Ok(*spanned.get_ref())
        }
        Some(spanned) => Err(at(
            spanned.span(),
            format!("{what} is {}; it must be more than 0", spanned.get_ref()),
            "lengths are in centimetres",
        )),
    };
    let finite = |value: &Option<Spanned<f64>>, what: &str| match value {
        None => Ok(0.0),
        Some(spanned) if spanned.get_ref().is_finite() => Ok(*spanned.get_ref()),
        Some(spanned) => Err(at(
            spanned.span(),
            format!("{what} is not a number"),
            "give a number",
        )),
    };

    let walls = file
        .walls
        .as_ref()
        .map(|walls| points(walls, 3, "the walls"))
        .transpose()?;
    let mut obstacles = Vec::new();
    for obstacle in &file.obstacles {
        let shape = match (&obstacle.get_ref().polygon, &obstacle.get_ref().circle) {
            (Some(polygon), None) => Shape::Polygon(points(polygon, 3, "a polygon")?),
            (None, Some(circle)) => {
                let CircleFile { x, y, radius } = *circle.get_ref();
                if !(x.is_finite() && y.is_finite() && radius.is_finite() && radius > 0.0) {
                    return Err(at(
                        circle.span(),
                        format!("a circle at ({x}, {y}) of radius {radius}"),
                        "a circle is { x = .., y = .., radius = .. } in centimetres, the radius more than 0",
                    ));
                }
                Shape::Circle {
                    centre: Point::new(x, y),
                    radius,
                }
            }
            _ => {
                return Err(at(
                    obstacle.span(),
                    "an obstacle is either a `polygon` or a `circle`".into(),
                    "write `polygon = [[0, 0], [10, 0], [10, 10]]` or `circle = { x = 50, y = 50, radius = 10 }`",
                ));
            }
        };
        obstacles.push(shape);
    }
    let mut lines = Vec::new();
    for line in &file.lines {
        let line = line.get_ref();
        lines.push(FloorLine {
            points: points(&line.points, 2, "a line")?,
            width: positive(&line.width, defaults::LINE_WIDTH, "the line's width")?,
        });
    }
    let robot = &file.robot;
    let degrees = |d: f64| d * PI / 180.0;
    let bumpers = match &robot.bumpers {
        None => defaults::BUMPERS.to_vec(),
        Some(list) if list.get_ref().len() <= 8 && list.get_ref().iter().all(|a| a.is_finite()) => {
            list.get_ref().clone()
        }
        Some(list) => {
            return Err(at(
                list.span(),
                format!(
                    "{} bumpers; the robot has eight microswitches at most, each an angle",
                    list.get_ref().len()
                ),
                "give each bumper's angle in degrees counter-clockwise from straight ahead, bit 0 first",
            ));
        }
    };
    let tracker = |value: &Option<Spanned<[f64; 2]>>, default: [f64; 2]| match value {
        None => Ok((default[0], default[1])),
        Some(spanned) if spanned.get_ref().iter().all(|v| v.is_finite()) => {
            Ok((spanned.get_ref()[0], spanned.get_ref()[1]))
        }
        Some(spanned) => Err(at(
            spanned.span(),
            "a tracker's place is not a number".into(),
            "a tracker is at [forward, left] centimetres from the axle's middle",
        )),
    };
    Ok(Layout {
        walls,
        obstacles,
        lines,
        start: Pose {
            at: Point::new(finite(&robot.x, "x")?, finite(&robot.y, "y")?),
            heading: degrees(finite(&robot.heading, "the heading")?),
        },
        drive: Drive {
            step: positive(&robot.step, defaults::STEP, "the step")?,
            wheel_base: positive(&robot.wheel_base, defaults::WHEEL_BASE, "the wheel base")?,
        },
        body: Body {
            radius: positive(&robot.radius, defaults::RADIUS, "the radius")?,
            bumpers: bumpers.into_iter().map(degrees).collect(),
            bumper_arc: degrees(positive(
                &robot.bumper_arc,
                defaults::BUMPER_ARC,
                "the bumper arc",
            )?),
            left_tracker: tracker(&robot.left_tracker, defaults::LEFT_TRACKER)?,
            right_tracker: tracker(&robot.right_tracker, defaults::RIGHT_TRACKER)?,
        },
        script: file.script,
    })
}

/// An error at the byte range `span` of the file.
fn located(
    name: &str,
    text: &str,
    span: std::ops::Range<usize>,
    message: String,
    help: &str,
) -> ScriptError {
    let start = span.start.min(text.len());
    let before = text.get(..start).unwrap_or_default();
    let line = before.matches('\n').count() + 1;
    let column = before[before.rfind('\n').map_or(0, |n| n + 1)..]
        .chars()
        .count()
        + 1;
    debug_assert_eq!(offset_of(text, line, column), start);
    let len = span
        .end
        .saturating_sub(span.start)
        .max(usize::from(start < text.len()));
    ScriptError::Script(Box::new(Located {
        file: name.to_owned(),
        line,
        column,
        message,
        source_code: miette::NamedSource::new(name, text.to_owned()),
        at: miette::SourceSpan::from((start, len.min(text.len() - start))),
        help: Some(help.to_owned()),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A world file's mistakes, each with the error it must give.
    #[test]
    fn mistakes_are_located() {
        for (text, expected) in [
            (
                "wals = []\n",
                "world.toml:1:1: unknown field `wals`, expected one of `walls`, `obstacle`, `line`, `robot`, `script`",
            ),
            (
                "[[obstacle]]\ncircle = { x = 1, y = 2, radius = 0 }\n",
                "world.toml:2:10: a circle at (1, 2) of radius 0",
            ),
            (
                "[[obstacle]]\ncircle = { x = 1, y = 2, radius = 3 }\npolygon = [[0, 0], [1, 0], [1, 1]]\n",
                "world.toml:1:1: an obstacle is either a `polygon` or a `circle`",
            ),
            (
                "[[line]]\npoints = [[0, 0]]\n",
                "world.toml:2:10: a line: 1 points, at least 2 needed",
            ),
            (
                "[robot]\nstep = -1\n",
                "world.toml:2:8: the step is -1; it must be more than 0",
            ),
            (
                "[robot]\nbumpers = [0, 45, 90, 135, 180, 225, 270, 315, 360]\n",
                "world.toml:2:11: 9 bumpers; the robot has eight microswitches at most, each an angle",
            ),
            ("[robot]\nx = nan\n", "world.toml:2:5: x is not a number"),
            (
                "walls = [[0, 0]",
                "world.toml:1:16: unclosed array, expected `]`",
            ),
        ] {
            let error = parse("world.toml", text).expect_err(text);
            assert_eq!(error.to_string(), expected, "{text}");
        }
    }

    #[test]
    fn an_empty_file_is_an_open_floor_with_the_defaults() {
        let layout = parse("world.toml", "").expect("empty is fine");
        assert_eq!(layout.walls, None);
        assert_eq!(layout.body.radius, defaults::RADIUS);
        assert_eq!(layout.drive.step, defaults::STEP);
        assert_eq!(layout.body.bumpers.len(), 8);
        assert_eq!(layout.start.heading, 0.0);
    }
}
