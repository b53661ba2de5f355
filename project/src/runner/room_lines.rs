//! A transcript's lines about the robot in its room (a world file,
//! docs/WORLD.md), which only the virtual Scorpion can check: `wait` lets
//! robot time pass, `pose =>` asserts where the robot is, `bumped =>`
//! what its bumpers met. Read here, beside the command lines the uploader
//! reads; checked against the room's [`RoomView`] as the transcript runs.
//!
//! ```text
//! /2A1                                         the OS starts cruising
//! wait 1500ms                                  robot time passes
//! pose => x=125cm y=100cm heading=0° within 1cm 2°
//! bumped => $10                                the front bumper closed
//! bumped => nothing                            no bumper since that line
//! ```
//!
//! docs/WORLD.md ("In a transcript") is their reference.

use std::time::Duration;

use cards::RoomView;

/// One room line of a transcript.
#[derive(Debug, Clone, PartialEq)]
pub enum RoomLine {
    /// `wait 500ms`: robot time passes, whatever the robot says is
    /// dropped.
    Wait(Duration),
    /// `pose => x=..cm y=..cm [heading=..°] within ..cm [..°]`.
    Pose(PoseCheck),
    /// `bumped => $MASK | * | nothing`: since the previous `bumped` line
    /// (or the transcript's start).
    Bumped(BumpCheck),
}

/// Where the robot must be.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseCheck {
    /// The middle of the axle, centimetres east.
    pub x: f64,
    /// Centimetres north.
    pub y: f64,
    /// Degrees counter-clockwise from east, with its tolerance in
    /// degrees.
    pub heading: Option<(f64, f64)>,
    /// The farthest the axle's middle may be from (x, y), centimetres.
    pub within: f64,
}

/// What the bumpers must have done.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BumpCheck {
    /// These bumpers (Master I/O bits) closed together at some moment.
    Closed(u8),
    /// Some bumper closed.
    Any,
    /// None closed.
    Nothing,
}

/// A line that begins like a room line: the text after its keyword.
fn keyword(content: &str) -> Option<(&'static str, &str)> {
    ["wait", "pose", "bumped"].into_iter().find_map(|word| {
        content
            .strip_prefix(word)
            .filter(|rest| rest.is_empty() || rest.starts_with([' ', '=', '\t']))
            .map(|rest| (word, rest.trim()))
    })
}

/// The room line in `content` (a line without its comment, trimmed):
/// `None` if it is not one, the reason if it is and is wrong.
pub fn parse(content: &str) -> Option<Result<RoomLine, String>> {
    let (word, rest) = keyword(content)?;
    Some(match word {
        "wait" => time(rest)
            .ok_or_else(|| format!("`wait {rest}` is not a time: write `wait 500ms` or `wait 2s`"))
            .and_then(|wait| {
                // A transcript runs in robot time, about a thousand times
                // faster than the robot: an hour is seconds; a typo of a
                // few more digits would run for days.
                if wait > MAX_WAIT {
                    Err(format!(
                        "`wait {rest}` is longer than a transcript may wait ({} s of robot time)",
                        MAX_WAIT.as_secs()
                    ))
                } else {
                    Ok(RoomLine::Wait(wait))
                }
            }),
        "pose" => after_arrow(word, rest).and_then(pose).map(RoomLine::Pose),
        _ => after_arrow(word, rest).and_then(bump).map(RoomLine::Bumped),
    })
}

fn after_arrow<'a>(word: &str, rest: &'a str) -> Result<&'a str, String> {
    rest.strip_prefix("=>").map(str::trim).ok_or_else(|| {
        format!(
            "`{word}` is followed by `=>` and what it must be (docs/WORLD.md, \"In a transcript\")"
        )
    })
}

/// The longest `wait` a transcript may give: an hour of robot time.
pub const MAX_WAIT: Duration = Duration::from_secs(3600);

/// `500ms`, `2s`, `300us`.
fn time(text: &str) -> Option<Duration> {
    let (number, unit) = split_number(text)?;
    let n: u64 = number.parse().ok()?;
    match unit {
        "us" => Some(Duration::from_micros(n)),
        "ms" => Some(Duration::from_millis(n)),
        "s" => Some(Duration::from_secs(n)),
        _ => None,
    }
}

/// A number and the unit after it, spaces between allowed.
fn split_number(text: &str) -> Option<(&str, &str)> {
    let text = text.trim();
    let end = text
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .unwrap_or(text.len());
    (end > 0).then(|| (&text[..end], text[end..].trim()))
}

/// A number with the unit `unit` (`12.5cm`, `90°`).
fn measure(text: &str, unit: &[&str]) -> Option<f64> {
    let (number, found) = split_number(text)?;
    if !unit.contains(&found) {
        return None;
    }
    number.parse::<f64>().ok().filter(|n| n.is_finite())
}

const DEGREES: &[&str] = &["°", "deg"];
const POSE_FORM: &str = "write `pose => x=125cm y=100cm heading=90° within 1cm 2°` (heading and its tolerance may be left out)";

fn pose(text: &str) -> Result<PoseCheck, String> {
    let (place, within) = text
        .split_once(" within ")
        .ok_or_else(|| format!("a pose needs its tolerance, `within 1cm`: {POSE_FORM}"))?;
    let (mut x, mut y, mut heading) = (None, None, None);
    for word in place.split_whitespace() {
        let (name, value) = word
            .split_once('=')
            .ok_or_else(|| format!("`{word}` is not `NAME=VALUE`: {POSE_FORM}"))?;
        let (slot, units): (&mut Option<f64>, &[&str]) = match name {
            "x" => (&mut x, &["cm"]),
            "y" => (&mut y, &["cm"]),
            "heading" => (&mut heading, DEGREES),
            _ => {
                return Err(format!(
                    "a pose has `x`, `y` and `heading`, not `{name}`: {POSE_FORM}"
                ));
            }
        };
        if slot.is_some() {
            return Err(format!("`{name}` is given twice"));
        }
        *slot =
            Some(measure(value, units).ok_or_else(|| {
                format!("`{word}`: {name} is a number in {}: {POSE_FORM}", units[0])
            })?);
    }
    let (Some(x), Some(y)) = (x, y) else {
        return Err(format!("a pose needs both `x` and `y`: {POSE_FORM}"));
    };
    let mut parts = within.split_whitespace();
    let distance = parts
        .next()
        .and_then(|d| measure(d, &["cm"]))
        .filter(|d| *d >= 0.0)
        .ok_or_else(|| {
            format!("`within {within}`: the first tolerance is a distance in cm: {POSE_FORM}")
        })?;
    let angle =
        match parts.next() {
            Some(a) => Some(measure(a, DEGREES).filter(|a| *a >= 0.0).ok_or_else(|| {
                format!("`{a}`: the second tolerance is an angle in °: {POSE_FORM}")
            })?),
            None => None,
        };
    if let Some(extra) = parts.next() {
        return Err(format!("`{extra}` after the tolerances: {POSE_FORM}"));
    }
    let heading = match (heading, angle) {
        (Some(h), Some(a)) => Some((h, a)),
        (None, None) => None,
        (Some(_), None) => {
            return Err(format!(
                "the heading needs its tolerance in degrees, `within 1cm 2°`: {POSE_FORM}"
            ));
        }
        (None, Some(_)) => {
            return Err(format!(
                "an angle's tolerance with no heading to apply it to: {POSE_FORM}"
            ));
        }
    };
    Ok(PoseCheck {
        x,
        y,
        heading,
        within: distance,
    })
}

fn bump(text: &str) -> Result<BumpCheck, String> {
    let form = "write `bumped => $10` (these bumpers closed together), `bumped => *` (some bumper) or `bumped => nothing`";
    match text {
        "*" => Ok(BumpCheck::Any),
        uploader::NOTHING => Ok(BumpCheck::Nothing),
        _ => text
            .strip_prefix('$')
            .and_then(|hex| u8::from_str_radix(hex, 16).ok())
            .filter(|mask| *mask != 0)
            .map(BumpCheck::Closed)
            .ok_or_else(|| format!("`{text}` is not a bumper mask: {form}")),
    }
}

/// Centimetres and degrees for people: to the tenth.
fn said(x: f64, y: f64, heading: f64) -> String {
    format!("x={x:.1}cm y={y:.1}cm heading={heading:.1}°")
}

impl PoseCheck {
    /// What the line requires, as it would write it.
    #[must_use]
    pub fn expected(&self) -> String {
        match self.heading {
            Some((h, a)) => format!(
                "x={}cm y={}cm heading={h}° within {}cm {a}°",
                self.x, self.y, self.within
            ),
            None => format!("x={}cm y={}cm within {}cm", self.x, self.y, self.within),
        }
    }

    /// `None` if the robot in `room` is where the line says; what was
    /// found if not.
    #[must_use]
    pub fn check(&self, room: &RoomView) -> Option<String> {
        let pose = room.pose()?;
        let heading = pose.heading_degrees();
        self.misses(pose.at.x, pose.at.y, heading)
            .then(|| said(pose.at.x, pose.at.y, heading))
    }

    /// Whether a robot at `x`, `y` facing `heading` degrees is not where
    /// the line says; a pose gone to NaN misses (a NaN compares false).
    fn misses(&self, x: f64, y: f64, heading: f64) -> bool {
        let (dx, dy) = (x - self.x, y - self.y);
        let distance = (dx * dx + dy * dy).sqrt();
        let far = distance.is_nan() || distance > self.within;
        let turned = self.heading.is_some_and(|(h, a)| {
            // The difference either way round the circle.
            let d = (heading - h).rem_euclid(360.0);
            let off = d.min(360.0 - d);
            off.is_nan() || off > a
        });
        far || turned
    }
}

impl BumpCheck {
    /// What the line requires, for a failure.
    #[must_use]
    pub fn expected(self) -> String {
        match self {
            BumpCheck::Closed(mask) => format!("bumpers ${mask:02X} closed"),
            BumpCheck::Any => "a bumper closed".into(),
            BumpCheck::Nothing => "no bumper closed".into(),
        }
    }

    /// `None` if the bumper changes `bumps` (robot time, mask) satisfy
    /// the line; what they were if not.
    #[must_use]
    pub fn check(self, bumps: &[(u64, u8)]) -> Option<String> {
        let closed = |mask: u8| bumps.iter().any(|&(_, m)| m & mask == mask && m != 0);
        let ok = match self {
            BumpCheck::Closed(mask) => closed(mask),
            BumpCheck::Any => closed(0),
            BumpCheck::Nothing => !closed(0),
        };
        (!ok).then(|| {
            if bumps.is_empty() {
                "no change of the bumpers".into()
            } else {
                bumps
                    .iter()
                    .map(|&(at, m)| {
                        format!(
                            "${m:02X} at {:.3} ms",
                            Duration::from_micros(at).as_secs_f64() * 1000.0
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_with_its_heading_and_tolerances() {
        assert_eq!(
            parse("pose => x=125cm y=100.5cm heading=90° within 1cm 2°"),
            Some(Ok(RoomLine::Pose(PoseCheck {
                x: 125.0,
                y: 100.5,
                heading: Some((90.0, 2.0)),
                within: 1.0,
            })))
        );
    }

    #[test]
    fn commands_are_not_room_lines() {
        assert_eq!(parse("/1P => *"), None);
        assert_eq!(parse("poser"), None);
    }

    #[test]
    fn wait_and_bumped() {
        assert_eq!(
            parse("wait 1500ms"),
            Some(Ok(RoomLine::Wait(Duration::from_millis(1500))))
        );
        assert_eq!(
            parse("bumped => $10"),
            Some(Ok(RoomLine::Bumped(BumpCheck::Closed(0x10))))
        );
        assert_eq!(
            parse("bumped => nothing"),
            Some(Ok(RoomLine::Bumped(BumpCheck::Nothing)))
        );
    }

    #[test]
    fn mistakes_say_how_to_write_it() {
        let reason = |line: &str| match parse(line) {
            Some(Err(reason)) => reason,
            other => panic!("{line}: {other:?}"),
        };
        assert!(reason("pose => x=1cm y=2cm").contains("needs its tolerance"));
        assert!(reason("pose => x=1m y=2cm within 1cm").contains("`x=1m`: x is a number in cm"));
        assert!(
            reason("pose => x=1cm y=2cm heading=3° within 1cm")
                .contains("heading needs its tolerance")
        );
        assert!(reason("pose x=1cm").contains("followed by `=>`"));
        assert!(reason("bumped => 10").contains("not a bumper mask"));
        assert!(reason("wait 3 parsecs").contains("not a time"));
        // The hostile tester's hang: a wait of years.
        assert!(reason("wait 99999999999s").contains("longer than a transcript may wait"));
        assert!(reason("wait 18446744073709551615ms").contains("longer than"));
        assert!(reason("wait 3601s").contains("longer than"));
        assert!(matches!(parse("wait 3600s"), Some(Ok(RoomLine::Wait(_)))));
    }

    #[test]
    fn bumps_since_the_last_line() {
        let bumps = [(1000, 0x10), (5000, 0x00)];
        assert_eq!(BumpCheck::Closed(0x10).check(&bumps), None);
        assert_eq!(BumpCheck::Any.check(&bumps), None);
        assert_eq!(
            BumpCheck::Nothing.check(&bumps).as_deref(),
            Some("$10 at 1.000 ms, $00 at 5.000 ms")
        );
        assert_eq!(
            BumpCheck::Closed(0x01).check(&[]).as_deref(),
            Some("no change of the bumpers")
        );
    }

    #[test]
    fn a_pose_gone_to_nan_is_never_where_a_line_says() {
        let Some(Ok(RoomLine::Pose(line))) = parse("pose => x=125cm y=100cm within 99999cm") else {
            panic!("not a pose line");
        };
        assert!(!line.misses(125.0, 100.0, 0.0));
        assert!(line.misses(f64::NAN, f64::NAN, 0.0), "a NaN position");
        let Some(Ok(RoomLine::Pose(turned))) =
            parse("pose => x=125cm y=100cm heading=90° within 1cm 2°")
        else {
            panic!("not a pose line");
        };
        assert!(!turned.misses(125.0, 100.0, 91.0));
        assert!(turned.misses(125.0, 100.0, f64::NAN), "a NaN heading");
    }
}
