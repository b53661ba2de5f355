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
    trail_lines(&mut out, trail, &at);
    let pose_at = |cycle: u64| {
        let index = trail.poses.partition_point(|&(at, _)| at <= cycle);
        index
            .checked_sub(1)
            .and_then(|index| trail.poses.get(index))
            .map_or(layout.start, |&(_, pose)| pose)
    };
    // Marks and their labels, laid out so that no label covers another:
    // the marks of one drawn point share one label (a robot standing
    // still through several seconds, commands sent together), and a
    // label that would cover one laid before goes below it.
    let mut labels = Labels::default();
    // Nor does a label cover an obstacle: each is taken before any label
    // is laid (a circle as itself, a polygon by its box). The walls and the
    // trail run through everything, and the robot's outline, drawn last
    // where the trail ends, would push every label near there away.
    let flip = |y: f64| max_y + min_y - y;
    for shape in &layout.obstacles {
        match shape {
            Shape::Circle { centre, radius } => {
                labels.discs.push((centre.x, flip(centre.y), *radius));
            }
            Shape::Polygon(corners) => labels.blocked.push(corners.iter().fold(
                [
                    f64::INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::NEG_INFINITY,
                ],
                |b, p| {
                    [
                        b[0].min(p.x),
                        b[1].min(flip(p.y)),
                        b[2].max(p.x),
                        b[3].max(flip(p.y)),
                    ]
                },
            )),
        }
    }
    let end = trail.poses.last().map_or(0, |&(at, _)| at);
    let mut times: Vec<(String, Vec<u64>)> = Vec::new();
    let mut mark = MARK_EVERY;
    while mark <= end {
        let point = at(pose_at(mark).at);
        match times.last_mut() {
            Some((last, marks)) if *last == point => marks.push(mark / MARK_EVERY),
            _ => times.push((point, vec![mark / MARK_EVERY])),
        }
        mark += MARK_EVERY;
    }
    for (point, marks) in &times {
        let text = format!("{} s", runs(marks));
        labels.mark(
            &mut out,
            "time",
            "#06c",
            1.0,
            point,
            &[text],
            LabelSide::Right,
        );
    }
    let mut bumps: Vec<(String, Vec<String>)> = Vec::new();
    for &(cycle, mask) in &trail.bumps {
        if mask == 0 {
            continue;
        }
        let point = at(pose_at(cycle).at);
        let text = format!("bump {mask:02X} at {}", seconds(cycle));
        match bumps.last_mut() {
            Some((last, texts)) if *last == point => texts.push(text),
            _ => bumps.push((point, vec![text])),
        }
    }
    for (point, texts) in &bumps {
        labels.mark(
            &mut out,
            "bump",
            "#c00",
            2.0,
            point,
            texts,
            LabelSide::Above,
        );
    }
    let mut sent: Vec<(String, Vec<String>)> = Vec::new();
    for (cycle, command) in commands {
        let point = at(pose_at(*cycle).at);
        let text = format!("{} at {}", escape(command), seconds(*cycle));
        match sent.iter_mut().find(|(p, _)| *p == point) {
            Some((_, texts)) => texts.push(text),
            None => sent.push((point, vec![text])),
        }
    }
    for (point, texts) in &sent {
        labels.mark(
            &mut out,
            "command",
            "#080",
            1.0,
            point,
            texts,
            LabelSide::Below,
        );
    }
    let last = trail.poses.last().map_or(layout.start, |&(_, pose)| pose);
    robot(&mut out, layout, last, &at);
    out.push_str("</svg>\n");
    // The view box holds the room and every label (a label laid below
    // others may reach past the room's edge).
    let (min_x, min_y, max_x, max_y) =
        labels
            .boxes
            .iter()
            .fold((min_x, min_y, max_x, max_y), |(x0, y0, x1, y1), b| {
                (
                    x0.min(b[0] - 1.0),
                    y0.min(b[1] - 1.0),
                    x1.max(b[2] + 1.0),
                    y1.max(b[3] + 1.0),
                )
            });
    let body = out;
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
    out.push_str(&body);
    out
}

/// The trail: the driven stretches as polylines, a point every half
/// centimetre at most (the robot is looked at every millisecond: the
/// picture stays small), and each jump (the robot put somewhere by a drag
/// in the live view, not driven there) a dashed line of its own.
fn trail_lines(out: &mut String, trail: &Trail, at: &dyn Fn(Point) -> String) {
    let mut stretch: Vec<Point> = Vec::new();
    let flush = |out: &mut String, stretch: &mut Vec<Point>| {
        let list = stretch.iter().map(|&p| at(p)).collect::<Vec<_>>().join(" ");
        let _ = writeln!(
            out,
            r##"<polyline class="trail" points="{list}" fill="none" stroke="#06c" stroke-width="0.5"/>"##
        );
        stretch.clear();
    };
    for (index, (_, pose)) in trail.poses.iter().enumerate() {
        if trail.is_jump(index)
            && let Some(&from) = stretch.last()
        {
            flush(out, &mut stretch);
            let ((x1, y1), (x2, y2)) = (split(&at(from)), split(&at(pose.at)));
            let _ = writeln!(
                out,
                r##"<line class="jump" x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke="#06c" stroke-width="0.5" stroke-dasharray="1.5 1.5"/>"##
            );
        }
        let far = stretch
            .last()
            .is_none_or(|last| last.distance2(pose.at) >= 0.25);
        let last_of_stretch = index + 1 == trail.poses.len() || trail.is_jump(index + 1);
        if far || last_of_stretch {
            stretch.push(pose.at);
        }
    }
    flush(out, &mut stretch);
}

/// Whole seconds as runs: `1-3, 5`.
fn runs(marks: &[u64]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut index = 0;
    while index < marks.len() {
        let first = marks[index];
        let mut last = first;
        while index + 1 < marks.len() && marks[index + 1] == last + 1 {
            index += 1;
            last = marks[index];
        }
        parts.push(if last == first {
            first.to_string()
        } else {
            format!("{first}-{last}")
        });
        index += 1;
    }
    parts.join(", ")
}

/// The most lines one mark's label has: past them, the rest are counted
/// in its last line (a thousand commands sent where the robot stands
/// would otherwise stack a thousand lines down the picture).
const MAX_LINES: usize = 6;
/// A label's font size, in the picture's units (centimetres).
const FONT: f64 = 4.0;
/// The height of a line of labels: the font and a little space.
const LINE: f64 = 5.0;
/// The widest a character of a label is taken to be, a share of the font
/// size: more than the average of any common font, so that a box laid
/// clear of another is clear of it once drawn.
const CHAR_WIDTH: f64 = 0.62;

/// Where a mark's label goes first, before it is moved clear of others.
#[derive(Debug, Clone, Copy)]
enum LabelSide {
    /// Right of the mark (time marks).
    Right,
    /// Above it (bumps).
    Above,
    /// Below it (commands).
    Below,
}

/// The labels laid so far (their boxes: left, top, right, bottom in the
/// picture's units), so that each new one is laid clear of them and of
/// what else it must not cover.
#[derive(Debug, Default)]
struct Labels {
    boxes: Vec<[f64; 4]>,
    /// Boxes of what is drawn besides labels and must stay readable
    /// (polygon obstacles).
    blocked: Vec<[f64; 4]>,
    /// Circles likewise (circle obstacles): centre x, y and radius.
    discs: Vec<(f64, f64, f64)>,
}

impl Labels {
    /// Draws a mark of `class` at `point` (the picture's "x,y") and its
    /// label, a line per text, where it covers no label laid before: at
    /// its `side` of the mark if that is clear, else moved down past what
    /// it would cover, joined to its mark by a thin line.
    #[allow(clippy::too_many_arguments, reason = "one mark's look")]
    fn mark(
        &mut self,
        out: &mut String,
        class: &str,
        colour: &str,
        radius: f64,
        point: &str,
        texts: &[String],
        side: LabelSide,
    ) {
        let summary;
        let texts = if texts.len() > MAX_LINES {
            summary = texts[..MAX_LINES - 1]
                .iter()
                .cloned()
                .chain([format!(
                    "and {} more, the last {}",
                    texts.len() - (MAX_LINES - 1),
                    texts[texts.len() - 1]
                )])
                .collect::<Vec<_>>();
            &summary[..]
        } else {
            texts
        };
        let (x, y) = split(point);
        let (px, py) = (
            x.parse::<f64>().unwrap_or(0.0),
            y.parse::<f64>().unwrap_or(0.0),
        );
        #[allow(clippy::cast_precision_loss, reason = "a label's length")]
        let width = texts
            .iter()
            .map(|t| unescaped_len(t) as f64)
            .fold(0.0, f64::max)
            * FONT
            * CHAR_WIDTH;
        #[allow(clippy::cast_precision_loss, reason = "a few lines")]
        let height = texts.len() as f64 * LINE;
        let left = px + radius + 1.0;
        // The box's top: the first line's baseline is a font size below.
        let mut top = match side {
            LabelSide::Right => py - FONT / 2.0 - 0.5,
            LabelSide::Above => py - radius - 1.0 - height,
            LabelSide::Below => py + radius + 0.5,
        };
        let wanted = top;
        loop {
            let right = left + width;
            let bottom = top + height;
            let disc = self
                .discs
                .iter()
                .filter(|&&(cx, cy, r)| {
                    let dx = cx - cx.clamp(left, right);
                    let dy = cy - cy.clamp(top, bottom);
                    dx * dx + dy * dy < r * r
                })
                .map(|&(_, cy, r)| cy + r);
            let covered = self
                .boxes
                .iter()
                .chain(&self.blocked)
                .filter(|b| left < b[2] && b[0] < right && top < b[3] && b[1] < bottom)
                .map(|b| b[3])
                .chain(disc)
                .fold(f64::NEG_INFINITY, f64::max);
            if covered == f64::NEG_INFINITY {
                break;
            }
            top = covered + 0.5;
        }
        self.boxes.push([left, top, left + width, top + height]);
        let _ = write!(
            out,
            r#"<g class="{class}"><circle cx="{x}" cy="{y}" r="{}" fill="{colour}"/>"#,
            tenth(radius)
        );
        if top != wanted {
            let _ = write!(
                out,
                r#"<line x1="{x}" y1="{y}" x2="{}" y2="{}" stroke="{colour}" stroke-width="0.2"/>"#,
                tenth(left),
                tenth(top + 1.0)
            );
        }
        for (line, text) in texts.iter().enumerate() {
            #[allow(clippy::cast_precision_loss, reason = "a few lines")]
            let baseline = top + FONT + line as f64 * LINE;
            let _ = write!(
                out,
                r#"<text x="{}" y="{}" font-size="{}" fill="{colour}">{text}</text>"#,
                tenth(left),
                tenth(baseline),
                tenth(FONT)
            );
        }
        out.push_str("</g>\n");
    }
}

/// How many characters `text` shows, its entities (`&amp;`) one each.
fn unescaped_len(text: &str) -> usize {
    text.replace("&amp;", "&")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .chars()
        .count()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::room::file::parse;
    use crate::room::geometry::Point;

    const ROOM: &str =
        "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n[robot]\nx = 100\ny = 100\n";

    fn pose(x: f64) -> Pose {
        Pose {
            at: Point::new(x, 100.0),
            heading: 0.0,
        }
    }

    /// Each label's box (left, top, right, bottom) from the picture's
    /// text: a character as wide as the font at most, the line as tall.
    fn boxes(svg: &str) -> Vec<([f64; 4], String)> {
        let number = |text: &str, key: &str| -> f64 {
            let start = text.find(key).expect(key) + key.len();
            text[start..start + text[start..].find('"').expect("a quote")]
                .parse()
                .expect("a number")
        };
        svg.split("<text ")
            .skip(1)
            .map(|text| {
                let (x, y, size) = (
                    number(text, "x=\""),
                    number(text, "y=\""),
                    number(text, "font-size=\""),
                );
                let words =
                    &text[text.find('>').expect(">") + 1..text.find("</text>").expect("</text>")];
                let width = words.chars().count() as f64 * size * 0.5;
                (
                    [x, y - size * 0.8, x + width, y + size * 0.2],
                    words.to_owned(),
                )
            })
            .collect()
    }

    /// The hostile tester's finding: the labels of commands sent at one
    /// pose, and the time marks of a robot standing still, were drawn on
    /// one point, each over the other. The robot drives 10 cm in 1.5 s,
    /// then stands 4.5 s; four commands arrive while it stands, two
    /// at one moment, and a bump is felt there.
    #[test]
    fn no_label_covers_another() {
        let layout = parse("room.toml", ROOM).expect("the room");
        let mut trail = Trail::default();
        for ms in 0..=1500u64 {
            #[allow(clippy::cast_precision_loss, reason = "a test")]
            trail
                .poses
                .push((ms * 1000, pose(100.0 + ms as f64 / 150.0)));
        }
        trail.poses.push((6_000_000, pose(110.0)));
        trail.bumps.push((1_500_000, 0x10));
        let commands: Vec<(u64, String)> = [
            (1_200_000, "/1B"),
            (2_000_000, "/8C+500100"),
            (2_000_000, "/8D+500100"),
            (3_000_000, "/1P"),
        ]
        .iter()
        .map(|&(at, text)| (at, text.to_owned()))
        .collect();
        let svg = svg(&layout, &trail, &commands);
        let labels = boxes(&svg);
        assert_eq!(labels.len(), 1 + 1 + 1 + 4, "{svg}");
        for (index, (a, first)) in labels.iter().enumerate() {
            for (b, second) in &labels[index + 1..] {
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "`{first}` {a:?} covers `{second}` {b:?}:\n{svg}");
            }
        }
        // The marks of seconds 2 to 6, where the robot stood, are one.
        assert!(svg.contains(">1 s</text>"), "{svg}");
        assert!(svg.contains(">2-6 s</text>"), "{svg}");
        // Deterministic text: the same picture twice.
        assert_eq!(svg, super::svg(&layout, &trail, &commands));
    }

    /// The view box, from the picture's header: left, top, right, bottom.
    fn view_box(svg: &str) -> [f64; 4] {
        let start = svg.find("viewBox=\"").expect("a view box") + 9;
        let numbers: Vec<f64> = svg[start..start + svg[start..].find('"').expect("a quote")]
            .split(' ')
            .map(|n| n.parse().expect("a number"))
            .collect();
        [
            numbers[0],
            numbers[1],
            numbers[0] + numbers[2],
            numbers[1] + numbers[3],
        ]
    }

    /// The hostile tester's finding: a thousand commands sent where the
    /// robot stood stacked a thousand lines down to y = 5100, far outside
    /// the picture. One mark's label has a few lines and counts the rest;
    /// labels laid below others (a robot creeping, a command at each
    /// step) make the picture taller, never fall outside it.
    #[test]
    fn every_label_lies_inside_the_picture() {
        let layout = parse("room.toml", ROOM).expect("the room");
        let mut trail = Trail::default();
        trail.poses.push((0, pose(100.0)));
        let still: Vec<(u64, String)> = (0..1000u64)
            .map(|i| (i * 10_000, "/1B".to_owned()))
            .collect();
        let svg = svg(&layout, &trail, &still);
        let labels = boxes(&svg);
        assert_eq!(labels.len(), MAX_LINES, "{svg}");
        assert!(
            labels[MAX_LINES - 1]
                .1
                .starts_with("and 995 more, the last /1B at 9.990 s"),
            "{svg}"
        );
        let mut creeping = Trail::default();
        let mut sent = Vec::new();
        for step in 0..200u64 {
            #[allow(clippy::cast_precision_loss, reason = "a test")]
            creeping
                .poses
                .push((step * 100_000, pose(100.0 + step as f64 * 0.5)));
            sent.push((step * 100_000, format!("/1P {step}")));
        }
        for svg in [svg, super::svg(&layout, &creeping, &sent)] {
            let inside = view_box(&svg);
            for (b, text) in boxes(&svg) {
                assert!(
                    inside[0] <= b[0]
                        && inside[1] <= b[1]
                        && b[2] <= inside[2]
                        && b[3] <= inside[3],
                    "`{text}` {b:?} outside the view box {inside:?}"
                );
            }
        }
    }

    /// The new user's finding: labels were laid clear of each other only,
    /// and covered the obstacles. A robot that
    /// drives up to a post, is bumped and stands there, commands sent at
    /// every stage.
    #[test]
    fn no_label_covers_an_obstacle() {
        let room = "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n\
            [[obstacle]]\ncircle = { x = 148, y = 100, radius = 8 }\n\
            [[obstacle]]\npolygon = [[100, 120], [130, 120], [130, 140], [100, 140]]\n\
            [robot]\nx = 100\ny = 100\n";
        let layout = parse("room.toml", room).expect("the room");
        let mut trail = Trail::default();
        for ms in 0..=3000u64 {
            #[allow(clippy::cast_precision_loss, reason = "a test")]
            trail
                .poses
                .push((ms * 1000, pose(100.0 + (ms.min(1500) as f64) / 60.0)));
        }
        trail.bumps.push((1_500_000, 0x01));
        let commands: Vec<(u64, String)> = (0..12u64)
            .map(|i| (i * 250_000, format!("/1P {i}")))
            .collect();
        let svg = svg(&layout, &trail, &commands);
        let [_, y0, _, y1] = view_box(&svg);
        let flip = |y: f64| (y0 + y1) - y;
        // The post by its box: a label clear of the box is clear of it.
        let drawn: Vec<([f64; 4], &str)> = vec![
            (
                [140.0, flip(100.0) - 8.0, 156.0, flip(100.0) + 8.0],
                "the post",
            ),
            ([100.0, flip(140.0), 130.0, flip(120.0)], "the box"),
        ];
        let labels = boxes(&svg);
        assert!(labels.len() >= 8, "{svg}");
        for (a, text) in &labels {
            for (b, what) in &drawn {
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "`{text}` {a:?} covers {what} {b:?}:\n{svg}");
            }
        }
    }

    /// A drag (the robot put elsewhere) is a dashed jump between two
    /// stretches of trail, not a stretch driven.
    #[test]
    fn a_jump_is_drawn_apart_from_the_trail() {
        let layout = parse("room.toml", ROOM).expect("the room");
        let mut trail = Trail::default();
        trail.poses.push((0, pose(100.0)));
        trail.poses.push((1000, pose(101.0)));
        trail.jump(2000, pose(200.0));
        trail.poses.push((3000, pose(201.0)));
        let svg = svg(&layout, &trail, &[]);
        assert_eq!(
            svg.matches(r#"<polyline class="trail""#).count(),
            2,
            "{svg}"
        );
        assert!(
            svg.contains(r#"<polyline class="trail" points="100.0,100.0 101.0,100.0""#),
            "{svg}"
        );
        assert!(
            svg.contains(r#"<line class="jump" x1="101.0" y1="100.0" x2="200.0" y2="100.0""#),
            "{svg}"
        );
    }
}
