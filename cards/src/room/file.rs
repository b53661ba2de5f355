//! The world file (`world.toml`): the room, its obstacles and floor lines,
//! the robot's start pose, outline, drive and sensors, read with every
//! default of docs/WORLD.md filled in; a mistake is an error at its
//! file:line:col.

use serde::Deserialize;
use toml::Spanned;

use super::drive::{Drive, Pose};
use super::geometry::{PI, Point, Shape, inside_polygon, segment_distance2};
use super::live;
use crate::error::{Located, ScriptError, WorldMistake, offset_of};

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
    /// Where in the file `script`'s value is (bytes), for an error about
    /// the script it names ([`script_error`]).
    pub script_span: Option<std::ops::Range<usize>>,
}

/// A point as written: `[x, y]` (more or fewer numbers are refused at
/// the point).
type PointFile = Spanned<Vec<f64>>;

/// A list of points as written.
type PointsFile = Spanned<Vec<PointFile>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    walls: Option<PointsFile>,
    #[serde(default, rename = "obstacle")]
    obstacles: Vec<Spanned<ObstacleFile>>,
    #[serde(default, rename = "line")]
    lines: Vec<Spanned<LineFile>>,
    #[serde(default)]
    robot: RobotFile,
    script: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObstacleFile {
    polygon: Option<PointsFile>,
    circle: Option<Spanned<CircleFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleFile {
    x: f64,
    y: f64,
    radius: f64,
}

/// The ranges a world file's numbers must lie in (docs/WORLD.md): wide
/// enough for any room a robot drives in, narrow enough that the room's
/// arithmetic stays exact to well under a step.
pub mod limits {
    /// The largest coordinate, either way from 0, centimetres (1 km).
    pub const COORDINATE: f64 = 100_000.0;
    /// The largest outline radius, centimetres.
    pub const RADIUS: f64 = 100.0;
    /// The largest step, centimetres.
    pub const STEP: f64 = 10.0;
    /// The largest wheel base, centimetres.
    pub const WHEEL_BASE: f64 = 200.0;
    /// The smallest wheel base, centimetres: a step's turn is the step
    /// over the wheel base, and below this the heading grows past what
    /// the room's sines keep exact.
    pub const WHEEL_BASE_MIN: f64 = 1.0;
    /// The widest floor line, centimetres.
    pub const LINE_WIDTH: f64 = 100.0;
    /// The largest angle either way (a heading, a bumper's place), degrees.
    pub const ANGLE: f64 = 360.0;
    /// The largest bumper arc, degrees: the whole outline.
    pub const BUMPER_ARC: f64 = 360.0;
    /// The farthest a tracker sits from the axle's middle, either way,
    /// centimetres.
    pub const TRACKER: f64 = 100.0;
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LineFile {
    points: PointsFile,
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
    left_tracker: Option<PointFile>,
    right_tracker: Option<PointFile>,
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
        let span = error.span().unwrap_or(0..0);
        // An integer past i64 reaches serde as an i128 no f64 field
        // takes: the parser's words name types the user never wrote.
        if error.message().contains("as i128") {
            let written = text.get(span.clone()).unwrap_or("").trim();
            return at(
                span,
                format!("{written} is out of range: no setting of a world file is that large"),
                "coordinates are centimetres, at most 100000 (1 km) either way; docs/WORLD.md gives every setting's range",
            );
        }
        at(
            span,
            error.message().trim().to_owned(),
            "docs/WORLD.md lists the keys of a world file",
        )
    })?;
    let pair = |point: &PointFile, what: &str| -> Result<Point, ScriptError> {
        let numbers = point.get_ref();
        if numbers.len() != 2 {
            return Err(at(
                point.span(),
                format!(
                    "{what}: a point of {} numbers; a point is [x, y]",
                    numbers.len()
                ),
                "points are [x, y] pairs in centimetres",
            ));
        }
        if numbers.iter().any(|v| !v.is_finite()) {
            return Err(at(
                point.span(),
                format!("{what}: a point that is not a number"),
                "points are [x, y] pairs in centimetres",
            ));
        }
        if numbers.iter().any(|v| v.abs() > limits::COORDINATE) {
            return Err(at(
                point.span(),
                format!(
                    "{what}: a point at [{}, {}] is farther than {} cm from 0",
                    number(numbers[0]),
                    number(numbers[1]),
                    limits::COORDINATE
                ),
                "coordinates are centimetres, at most 100000 (1 km) either way (docs/WORLD.md)",
            ));
        }
        Ok(Point::new(numbers[0], numbers[1]))
    };
    let points = |spanned: &PointsFile, least: usize, what: &str| {
        let list = spanned.get_ref();
        if list.len() < least {
            return Err(at(
                spanned.span(),
                format!("{what}: {} points, at least {least} needed", list.len()),
                "points are [x, y] pairs in centimetres",
            ));
        }
        list.iter()
            .map(|point| pair(point, what))
            .collect::<Result<Vec<_>, _>>()
    };
    let polygon = |spanned: &PointsFile, what: &str| {
        let corners = points(spanned, 3, what)?;
        // Two corners at one place make an edge of no length, which every
        // other edge would be said to cross.
        let all_at_one = corners.iter().all(|corner| *corner == corners[0]);
        let list = spanned.get_ref();
        if let Some(i) = (0..corners.len())
            .find(|&i| !all_at_one && corners[i] == corners[(i + 1) % corners.len()])
        {
            let next = (i + 1) % corners.len();
            return Err(at(
                list[i.max(next)].span(),
                format!(
                    "{what}: edge {} has no length: corners {} and {} are both at [{}, {}]",
                    i + 1,
                    i + 1,
                    next + 1,
                    corners[i].x,
                    corners[i].y
                ),
                "give each corner once (the last corner joins the first by itself)",
            ));
        }
        // Two corners apart at one place: the outline touches itself
        // there, which the crossing check would name as two edges.
        let repeated = (0..corners.len()).find_map(|j| {
            (0..j)
                .find(|&i| !all_at_one && corners[i] == corners[j])
                .map(|i| (i, j))
        });
        if let Some((i, j)) = repeated {
            return Err(at(
                list[j].span(),
                format!(
                    "{what}: corners {} and {} are both at [{}, {}] (the outline touches itself there)",
                    i + 1,
                    j + 1,
                    corners[i].x,
                    corners[i].y
                ),
                "an outline goes round once: give each corner once, in order round the polygon",
            ));
        }
        if let Some((first, second)) = crossing_edges(&corners) {
            let edge = |i: usize| {
                let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
                format!("{} ([{}, {}]-[{}, {}])", i + 1, a.x, a.y, b.x, b.y)
            };
            return Err(at(
                spanned.span(),
                format!(
                    "{what}: edges {} and {} cross (the outline crosses itself)",
                    edge(first),
                    edge(second)
                ),
                "give the corners in order round the polygon (edge 1 runs from the first corner to the second, the last from the last corner back to the first)",
            ));
        }
        // Twice the area (the shoelace sum): none when every corner is on
        // one line, a polygon neither the bumpers nor the scanner can meet
        // the way they meet a circle of any size.
        let area2: f64 = (0..corners.len())
            .map(|i| {
                let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
                a.x * b.y - b.x * a.y
            })
            .sum();
        if area2 == 0.0 {
            return Err(at(
                spanned.span(),
                format!("{what}: no area: the corners are all on one line"),
                "give at least three corners that are not on one line (a post is a circle)",
            ));
        }
        Ok(corners)
    };
    // A number in (0, max] (a length), or the default.
    let length = |value: &Option<Spanned<f64>>, default: f64, max: f64, what: &str| match value {
        None => Ok(default),
        Some(spanned) => {
            let v = *spanned.get_ref();
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(v)
            } else {
                Err(at(
                    spanned.span(),
                    format!(
                        "{what} is {}; it must be more than 0 and at most {max}",
                        number(v)
                    ),
                    "lengths are in centimetres; docs/WORLD.md gives each one's range",
                ))
            }
        }
    };
    // A number in [-max, max], or 0.
    let within = |value: &Option<Spanned<f64>>, max: f64, what: &str| match value {
        None => Ok(0.0),
        Some(spanned) if !spanned.get_ref().is_finite() => Err(at(
            spanned.span(),
            format!("{what} is not a number"),
            "give a number",
        )),
        Some(spanned) if spanned.get_ref().abs() <= max => Ok(*spanned.get_ref()),
        Some(spanned) => Err(at(
            spanned.span(),
            format!(
                "{what} is {}; it must be from -{max} to {max}",
                number(*spanned.get_ref())
            ),
            "docs/WORLD.md gives each number's range",
        )),
    };

    let walls = file
        .walls
        .as_ref()
        .map(|walls| polygon(walls, "the walls"))
        .transpose()?;
    let mut obstacles = Vec::new();
    for obstacle in &file.obstacles {
        let shape = match (&obstacle.get_ref().polygon, &obstacle.get_ref().circle) {
            (Some(corners), None) => Shape::Polygon(polygon(corners, "a polygon")?),
            (None, Some(circle)) => {
                let CircleFile { x, y, radius } = *circle.get_ref();
                let finite = x.is_finite() && y.is_finite() && radius.is_finite() && radius > 0.0;
                if !finite
                    || x.abs() > limits::COORDINATE
                    || y.abs() > limits::COORDINATE
                    || radius > limits::COORDINATE
                {
                    return Err(at(
                        circle.span(),
                        format!(
                            "a circle at ({}, {}) of radius {}",
                            number(x),
                            number(y),
                            number(radius)
                        ),
                        "a circle is { x = .., y = .., radius = .. } in centimetres, the radius more than 0, each at most 100000 (1 km) either way",
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
        // One rule with the view's drags (`live::obstacle_out_of_walls`):
        // an obstacle beyond the walls is one the robot can never meet,
        // a mistake, and one across them a wall the file does not draw.
        if let Some(walls) = &walls
            && let Some(out) = live::obstacle_out_of_walls(walls, &shape)
        {
            let file = obstacle.get_ref();
            let span = file
                .polygon
                .as_ref()
                .map(Spanned::span)
                .or_else(|| file.circle.as_ref().map(Spanned::span))
                .unwrap_or_else(|| obstacle.span());
            return Err(at(
                span,
                format!(
                    "an obstacle outside the walls or across them: it reaches {} cm out of them",
                    live::centimetres(out)
                ),
                "give the obstacle inside the walls (it may press a wall 2 cm at most, as a drag in the live view may put it)",
            ));
        }
        obstacles.push((shape, obstacle.span()));
    }
    let mut lines = Vec::new();
    for line in &file.lines {
        let line = line.get_ref();
        lines.push(FloorLine {
            points: points(&line.points, 2, "a line")?,
            width: length(
                &line.width,
                defaults::LINE_WIDTH,
                limits::LINE_WIDTH,
                "the line's width",
            )?,
        });
    }
    let robot = &file.robot;
    let degrees = |d: f64| d * PI / 180.0;
    let bumpers = match &robot.bumpers {
        None => defaults::BUMPERS.to_vec(),
        Some(list) if list.get_ref().len() > 8 => {
            return Err(at(
                list.span(),
                format!(
                    "{} bumpers; the robot has eight microswitches at most, each an angle",
                    list.get_ref().len()
                ),
                "give each bumper's angle in degrees counter-clockwise from straight ahead, bit 0 first",
            ));
        }
        Some(list) if list.get_ref().iter().all(|a| a.abs() <= limits::ANGLE) => {
            list.get_ref().clone()
        }
        Some(list) => {
            return Err(at(
                list.span(),
                "a bumper's angle is not a number from -360 to 360".into(),
                "give each bumper's angle in degrees counter-clockwise from straight ahead, bit 0 first",
            ));
        }
    };
    let tracker = |value: &Option<PointFile>, default: [f64; 2], what: &str| match value {
        None => Ok((default[0], default[1])),
        Some(spanned) => {
            let numbers = spanned.get_ref();
            if numbers.len() != 2 {
                return Err(at(
                    spanned.span(),
                    format!(
                        "{what} has {} numbers; a tracker is at [forward, left]",
                        numbers.len()
                    ),
                    "a tracker is at [forward, left] centimetres from the axle's middle",
                ));
            }
            if numbers.iter().all(|v| v.abs() <= limits::TRACKER) {
                Ok((numbers[0], numbers[1]))
            } else {
                Err(at(
                    spanned.span(),
                    format!("{what} is not at numbers from -100 to 100"),
                    "a tracker is at [forward, left] centimetres from the axle's middle",
                ))
            }
        }
    };
    let start = Point::new(
        within(&robot.x, limits::COORDINATE, "x")?,
        within(&robot.y, limits::COORDINATE, "y")?,
    );
    // The start pose: inside the walls and in no obstacle, else the room
    // would see the robot through a wall from its first step. The error
    // points at `x` (or the `[robot]` table's keys, when `x` is left out).
    let start_span = robot
        .x
        .as_ref()
        .or(robot.y.as_ref())
        .map_or(0..0, Spanned::span);
    if let Some(walls) = &walls
        && !inside_polygon(walls, start)
    {
        return Err(at(
            start_span,
            format!(
                "the robot starts at ({}, {}), outside the walls",
                start.x, start.y
            ),
            "give the robot's `x` and `y` inside the walls (the middle of its axle)",
        ));
    }
    if let Some((_, span)) = obstacles.iter().find(|(shape, _)| shape.contains(start)) {
        let obstacle = located_line(text, span.start);
        return Err(at(
            start_span,
            format!(
                "the robot starts at ({}, {}), inside the obstacle at line {obstacle}",
                start.x, start.y
            ),
            "give the robot's `x` and `y` clear of the obstacles (the middle of its axle)",
        ));
    }
    // The outline clear of everything too: touching a wall or an
    // obstacle, the robot would start with a bumper closed, and the room
    // would see its first step as a bump it never made.
    let radius = length(
        &robot.radius,
        defaults::RADIUS,
        limits::RADIUS,
        "the radius",
    )?;
    if let Some(walls) = &walls
        && let Some(edge) = touched_edge(walls, start, radius)
    {
        return Err(at(
            start_span,
            format!(
                "the robot starts at ({}, {}) with its outline ({radius} cm round) touching the walls, at edge {}",
                start.x,
                start.y,
                edge + 1
            ),
            "give the robot's `x` and `y` more than its `radius` from the walls and the obstacles (edge 1 runs from the first corner to the second)",
        ));
    }
    if let Some((_, span)) = obstacles
        .iter()
        .find(|(shape, _)| outline_touches(shape, start, radius))
    {
        let obstacle = located_line(text, span.start);
        return Err(at(
            start_span,
            format!(
                "the robot starts at ({}, {}) with its outline ({radius} cm round) touching the obstacle at line {obstacle}",
                start.x, start.y
            ),
            "give the robot's `x` and `y` more than its `radius` from the walls and the obstacles",
        ));
    }
    let script_span = file.script.as_ref().map(Spanned::span);
    if let Some(script) = &file.script
        && script.get_ref().trim().is_empty()
    {
        return Err(at(
            script.span(),
            "`script` names no file".into(),
            "give the world script's path, relative to this file, or leave `script` out",
        ));
    }
    Ok(Layout {
        walls,
        obstacles: obstacles.into_iter().map(|(shape, _)| shape).collect(),
        lines,
        start: Pose {
            at: start,
            heading: degrees(within(&robot.heading, limits::ANGLE, "the heading")?),
        },
        drive: Drive {
            step: length(&robot.step, defaults::STEP, limits::STEP, "the step")?,
            wheel_base: match length(
                &robot.wheel_base,
                defaults::WHEEL_BASE,
                limits::WHEEL_BASE,
                "the wheel base",
            )? {
                base if base < limits::WHEEL_BASE_MIN => {
                    let span = robot.wheel_base.as_ref().map_or(0..0, Spanned::span);
                    return Err(at(
                        span,
                        format!(
                            "the wheel base is {}; it must be at least {} and at most {}",
                            number(base),
                            limits::WHEEL_BASE_MIN,
                            limits::WHEEL_BASE
                        ),
                        "lengths are in centimetres; docs/WORLD.md gives each one's range",
                    ));
                }
                base => base,
            },
        },
        body: Body {
            radius,
            bumpers: bumpers.into_iter().map(degrees).collect(),
            bumper_arc: degrees(length(
                &robot.bumper_arc,
                defaults::BUMPER_ARC,
                limits::BUMPER_ARC,
                "the bumper arc",
            )?),
            left_tracker: tracker(
                &robot.left_tracker,
                defaults::LEFT_TRACKER,
                "the left tracker",
            )?,
            right_tracker: tracker(
                &robot.right_tracker,
                defaults::RIGHT_TRACKER,
                "the right tracker",
            )?,
        },
        script: file.script.map(Spanned::into_inner),
        script_span,
    })
}

/// The first edge (from 0) of the closed polygon `corners` that the
/// outline of `radius` round `centre` touches (within it, or on it).
fn touched_edge(corners: &[Point], centre: Point, radius: f64) -> Option<usize> {
    let count = corners.len();
    (0..count).find(|&k| {
        segment_distance2(centre, corners[k], corners[(k + 1) % count]) <= radius * radius
    })
}

/// Whether the outline of `radius` round `centre` touches `shape` (an
/// edge within it or on it; the centre inside it is refused before).
fn outline_touches(shape: &Shape, centre: Point, radius: f64) -> bool {
    match shape {
        Shape::Circle {
            centre: middle,
            radius: round,
        } => centre.distance2(*middle) <= (radius + round) * (radius + round),
        Shape::Polygon(corners) => touched_edge(corners, centre, radius).is_some(),
    }
}

/// `v` for a message: `1e300` rather than its 301 digits.
fn number(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e9 {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The line number of byte `offset` of `text`.
fn located_line(text: &str, offset: usize) -> usize {
    text.get(..offset).unwrap_or_default().matches('\n').count() + 1
}

/// The first two edges of the closed polygon `corners` that cross (edge
/// `i` runs from corner `i` to the next), if any: neighbours share a
/// corner and are not counted, unless one folds back along the other.
#[must_use]
pub fn crossing_edges(corners: &[Point]) -> Option<(usize, usize)> {
    let n = corners.len();
    let edge = |i: usize| (corners[i], corners[(i + 1) % n]);
    for i in 0..n {
        for j in i + 1..n {
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            let (a, b) = edge(i);
            let (c, d) = edge(j);
            if neighbours {
                // Neighbours meet at their shared corner; they cross only
                // where one runs back along the other.
                if folds_back(a, b, c, d) {
                    return Some((i, j));
                }
            } else if segments_meet(a, b, c, d) {
                return Some((i, j));
            }
        }
    }
    None
}

/// The sign of the turn a-b-c: positive counter-clockwise, 0 in line.
fn turn(a: Point, b: Point, c: Point) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// Whether `p`, in line with a-b, lies within the box of a-b.
fn on_segment(a: Point, b: Point, p: Point) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Whether segments a-b and c-d have a point in common.
fn segments_meet(a: Point, b: Point, c: Point, d: Point) -> bool {
    let (d1, d2) = (turn(c, d, a), turn(c, d, b));
    let (d3, d4) = (turn(a, b, c), turn(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on_segment(c, d, a))
        || (d2 == 0.0 && on_segment(c, d, b))
        || (d3 == 0.0 && on_segment(a, b, c))
        || (d4 == 0.0 && on_segment(a, b, d))
}

/// Whether neighbouring edges a-b and c-d (sharing one corner) overlap
/// along more than that corner: in line, and pointing back over each
/// other.
fn folds_back(a: Point, b: Point, c: Point, d: Point) -> bool {
    let shared_is_b = b == c;
    let (corner, p, q) = if shared_is_b { (b, a, d) } else { (a, b, c) };
    if turn(corner, p, q) != 0.0 {
        return false;
    }
    // In line: back over each other when both run the same way from the
    // shared corner.
    (p.x - corner.x) * (q.x - corner.x) + (p.y - corner.y) * (q.y - corner.y) > 0.0
}

/// An error at `script`'s value in the world file (`name`, `text`): the
/// script it names cannot be read (`why`).
#[must_use]
pub fn script_error(name: &str, text: &str, layout: &Layout, why: String) -> ScriptError {
    located(
        name,
        text,
        layout.script_span.clone().unwrap_or(0..0),
        why,
        "`script` names a world script relative to the world file's folder",
    )
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
    ScriptError::World(Box::new(WorldMistake(Located {
        file: name.to_owned(),
        line,
        column,
        message,
        source_code: miette::NamedSource::new(name, text.to_owned()),
        at: miette::SourceSpan::from((start, len.min(text.len() - start))),
        help: Some(help.to_owned()),
    })))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A world file's mistake is no script's: its own code, its place.
    #[test]
    fn a_world_files_mistake_has_its_own_code() {
        use miette::Diagnostic;
        let error = parse("world.toml", "walls = [[0, 0], [1, 1]]\n").expect_err("refused");
        let code = error.code().map(|code| code.to_string());
        assert_eq!(code.as_deref(), Some("cards::world"), "{error}");
        assert!(
            error.help().is_some() && error.labels().is_some(),
            "{error:?}"
        );
        assert!(error.to_string().starts_with("world.toml:1:9: "), "{error}");
    }

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
                "world.toml:2:8: the step is -1; it must be more than 0 and at most 10",
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
