//! The robot's path as a picture: an SVG of the room (walls, obstacles,
//! floor lines), the trail with a mark every second of robot time, where
//! the bumpers closed, the commands received along the way and the robot
//! where it ended. The text depends on nothing but its inputs (numbers
//! written to a tenth of a centimetre, elements in a fixed order), so a
//! project can snapshot its robot's path like its bytes.

use std::fmt::Write as _;

use super::Trail;
use super::drive::Pose;
use super::file::Layout;
use super::geometry::{Point, Shape};

/// Robot time between two time marks on the trail, cycles (1 s).
const MARK_EVERY: u64 = 1_000_000;

/// The picture of `layout` with `trail`, and `commands` (robot time,
/// text) placed where the robot was when each arrived.
#[must_use]
pub fn svg(layout: &Layout, trail: &Trail, commands: &[(u64, String)]) -> String {
    let mut points: Vec<Point> = Vec::new();
    match &layout.walls {
        Some(walls) => points.extend(walls),
        None => {
            points.extend(trail.poses.iter().map(|(_, pose)| pose.at));
            for shape in &layout.obstacles {
                match shape {
                    Shape::Polygon(corners) => points.extend(corners),
                    Shape::Circle { centre, radius } => {
                        points.push(Point::new(centre.x - radius, centre.y - radius));
                        points.push(Point::new(centre.x + radius, centre.y + radius));
                    }
                }
            }
            for line in &layout.lines {
                points.extend(&line.points);
            }
        }
    }
    points.push(layout.start.at);
    let margin = layout.body.radius + 5.0;
    let min_x = points.iter().map(|p| p.x).fold(f64::INFINITY, f64::min) - margin;
    let max_x = points.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max) + margin;
    let min_y = points.iter().map(|p| p.y).fold(f64::INFINITY, f64::min) - margin;
    let max_y = points.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max) + margin;
    // North up: the picture's y runs down.
    let at = |p: Point| format!("{},{}", tenth(p.x), tenth(max_y + min_y - p.y));
    let list = |ps: &[Point]| ps.iter().map(|&p| at(p)).collect::<Vec<_>>().join(" ");
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="{} {} {} {}" width="{}" height="{}">"#,
        tenth(min_x),
        tenth(min_y),
        tenth(max_x - min_x),
        tenth(max_y - min_y),
        tenth((max_x - min_x) * 3.0),
        tenth((max_y - min_y) * 3.0),
    );
    let _ = writeln!(
        out,
        "<title>the robot's path (centimetres, north up)</title>"
    );
    let _ = writeln!(
        out,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#fafafa"/>"##,
        tenth(min_x),
        tenth(min_y),
        tenth(max_x - min_x),
        tenth(max_y - min_y)
    );
    if let Some(walls) = &layout.walls {
        let _ = writeln!(
            out,
            r#"<polygon class="walls" points="{}" fill="none" stroke="black" stroke-width="2"/>"#,
            list(walls)
        );
    }
    for line in &layout.lines {
        let _ = writeln!(
            out,
            r##"<polyline class="line" points="{}" fill="none" stroke="#333" stroke-width="{}"/>"##,
            list(&line.points),
            tenth(line.width)
        );
    }
    for shape in &layout.obstacles {
        match shape {
            Shape::Polygon(corners) => {
                let _ = writeln!(
                    out,
                    r##"<polygon class="obstacle" points="{}" fill="#999"/>"##,
                    list(corners)
                );
            }
            Shape::Circle { centre, radius } => {
                let (x, y) = split(&at(*centre));
                let _ = writeln!(
                    out,
                    r##"<circle class="obstacle" cx="{x}" cy="{y}" r="{}" fill="#999"/>"##,
                    tenth(*radius)
                );
            }
        }
    }
    // A point every half centimetre at most (the robot is looked at
    // every millisecond): the picture stays small.
    let mut trail_points: Vec<Point> = Vec::new();
    for (index, (_, pose)) in trail.poses.iter().enumerate() {
        let far = trail_points
            .last()
            .is_none_or(|last| last.distance2(pose.at) >= 0.25);
        if far || index + 1 == trail.poses.len() {
            trail_points.push(pose.at);
        }
    }
    let _ = writeln!(
        out,
        r##"<polyline class="trail" points="{}" fill="none" stroke="#06c" stroke-width="0.5"/>"##,
        list(&trail_points)
    );
    let pose_at = |cycle: u64| {
        trail
            .poses
            .iter()
            .take_while(|(at, _)| *at <= cycle)
            .last()
            .map_or(layout.start, |&(_, pose)| pose)
    };
    let end = trail.poses.last().map_or(0, |&(at, _)| at);
    let mut mark = MARK_EVERY;
    while mark <= end {
        let (x, y) = split(&at(pose_at(mark).at));
        let _ = writeln!(
            out,
            r##"<g class="time"><circle cx="{x}" cy="{y}" r="1" fill="#06c"/><text x="{x}" y="{y}" dx="2" font-size="4">{} s</text></g>"##,
            mark / MARK_EVERY
        );
        mark += MARK_EVERY;
    }
    for &(cycle, mask) in &trail.bumps {
        if mask == 0 {
            continue;
        }
        let (x, y) = split(&at(pose_at(cycle).at));
        let _ = writeln!(
            out,
            r##"<g class="bump"><circle cx="{x}" cy="{y}" r="2" fill="#c00"/><text x="{x}" y="{y}" dy="-3" font-size="4" fill="#c00">bump {mask:02X} at {}</text></g>"##,
            seconds(cycle)
        );
    }
    for (cycle, command) in commands {
        let (x, y) = split(&at(pose_at(*cycle).at));
        let _ = writeln!(
            out,
            r##"<g class="command"><circle cx="{x}" cy="{y}" r="1" fill="#080"/><text x="{x}" y="{y}" dy="5" font-size="4" fill="#080">{} at {}</text></g>"##,
            escape(command),
            seconds(*cycle)
        );
    }
    let last = trail.poses.last().map_or(layout.start, |&(_, pose)| pose);
    robot(&mut out, layout, last, &at);
    out.push_str("</svg>\n");
    out
}

/// The robot at `pose`: its outline and a stroke the way it faces.
fn robot(out: &mut String, layout: &Layout, pose: Pose, at: &dyn Fn(Point) -> String) {
    let (x, y) = split(&at(pose.at));
    let radius = layout.body.radius;
    let (nose_x, nose_y) = split(&at(pose.place(radius, 0.0)));
    let _ = writeln!(
        out,
        r##"<g class="robot"><circle cx="{x}" cy="{y}" r="{}" fill="none" stroke="#06c"/><line x1="{x}" y1="{y}" x2="{nose_x}" y2="{nose_y}" stroke="#06c"/></g>"##,
        tenth(radius)
    );
}

/// A length to a tenth, without `-0.0`.
fn tenth(value: f64) -> String {
    let text = format!("{value:.1}");
    if text == "-0.0" { "0.0".into() } else { text }
}

fn split(pair: &str) -> (String, String) {
    let (x, y) = pair.split_once(',').unwrap_or((pair, "0"));
    (x.to_owned(), y.to_owned())
}

/// Robot time in seconds, to the millisecond.
fn seconds(cycle: u64) -> String {
    format!("{}.{:03} s", cycle / 1_000_000, cycle % 1_000_000 / 1000)
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
