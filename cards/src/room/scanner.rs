//! What the infrared scanner sees in a room: a ray from the robot's axle
//! middle at each horizontal scanner step, against the walls and the
//! obstacles, its distance turned into a reading. Pure geometry, with the
//! same `+ - * /` and `sqrt` as [`geometry`](super::geometry), so the
//! readings are the same bits on every platform.

use super::drive::Pose;
use super::file::Layout;
use super::geometry::{PI, Point, Shape, inside_polygon, segment_distance2, sin_cos};

/// The scanner's turn per horizontal step, degrees: a 200-step-a-turn
/// stepper like the wheels', so the largest scan (`/3H99`) sweeps 178°
/// each side of straight ahead. A step `+` (the `SCAN_DIR` line high)
/// turns it right, clockwise seen from above.
pub const STEP_DEGREES: f64 = 1.8;

/// How far the scanner sees, centimetres from the robot's outline: past
/// it, a ray reads [`BACKGROUND`].
pub const RANGE: f64 = 200.0;

/// The reading of a ray that meets nothing within [`RANGE`]: the dark
/// floor and the open room reflect nothing back.
pub const BACKGROUND: u8 = 0;

/// The horizontal steps a row has, -128 to 127 (the scene's positions).
const STEPS: usize = 256;

/// How far past its ends (a fraction of its length) a ray may meet an
/// edge. Rounding puts a ray aimed exactly at a corner a little past the
/// end of each of the two edges that meet there: without the slack it
/// would slip between them through a closed room's corner (and read an
/// open floor). A billionth of an edge is far below a reading's worth.
const EDGE_SLACK: f64 = 1e-9;

/// How much farther than [`RANGE`] past the outline a row looks before
/// it leaves a wall or an obstacle out: enough that the rounding of the
/// gap cannot bring anything it leaves out into range.
const REACH_MARGIN: f64 = 1.0;

/// The cross product's z of `a` and `b`.
fn cross(a: Point, b: Point) -> f64 {
    a.x * b.y - a.y * b.x
}

/// How far along the ray from `origin` in the unit direction `direction`
/// it meets the circle at `centre` of `radius`; 0 from inside it, `None`
/// when it passes by or the circle is behind.
#[must_use]
pub fn ray_circle(origin: Point, direction: Point, centre: Point, radius: f64) -> Option<f64> {
    let from = Point::new(origin.x - centre.x, origin.y - centre.y);
    let inside = from.x * from.x + from.y * from.y - radius * radius;
    if inside <= 0.0 {
        return Some(0.0);
    }
    let half_b = from.x * direction.x + from.y * direction.y;
    let discriminant = half_b * half_b - inside;
    if discriminant < 0.0 {
        return None;
    }
    let near = -half_b - discriminant.sqrt();
    (near >= 0.0).then_some(near)
}

/// How far along the ray (as [`ray_circle`]) it meets the segment `a`-`b`;
/// `None` when it misses, or runs along it (a ray grazing an edge end on
/// meets the edges beside it).
#[must_use]
pub fn ray_segment(origin: Point, direction: Point, a: Point, b: Point) -> Option<f64> {
    let edge = Point::new(b.x - a.x, b.y - a.y);
    let denominator = cross(direction, edge);
    if denominator == 0.0 {
        return None;
    }
    let to_a = Point::new(a.x - origin.x, a.y - origin.y);
    let along_ray = cross(to_a, edge) / denominator;
    let along_edge = cross(to_a, direction) / denominator;
    (along_ray >= 0.0 && (-EDGE_SLACK..=1.0 + EDGE_SLACK).contains(&along_edge))
        .then_some(along_ray)
}

/// How far along the ray it first meets an edge of the closed polygon
/// `corners` (from outside or from inside: the walls are such a polygon).
#[must_use]
pub fn ray_polygon(origin: Point, direction: Point, corners: &[Point]) -> Option<f64> {
    let count = corners.len();
    (0..count)
        .filter_map(|k| ray_segment(origin, direction, corners[k], corners[(k + 1) % count]))
        .min_by(f64::total_cmp)
}

/// How far along the ray it first meets a wall or an obstacle of
/// `layout`; `None` when nothing is in its way (an open floor). From
/// inside an obstacle, 0: the robot is in contact with it whichever way
/// it looks.
#[must_use]
pub fn distance(layout: &Layout, origin: Point, direction: Point) -> Option<f64> {
    Near::of(layout, origin, f64::INFINITY).distance(origin, direction)
}

/// What a ray from one place can meet within a reach: the edges (of the
/// walls and the polygons) and the circles near enough, so that a row's
/// 256 rays are not each tested against a room's far obstacles.
#[derive(Debug, Default)]
struct Near {
    edges: Vec<(Point, Point)>,
    circles: Vec<(Point, f64)>,
    /// The place is inside a polygon obstacle: every ray meets it at 0.
    inside: bool,
}

impl Near {
    /// What lies within `reach` of `origin` in `layout`.
    fn of(layout: &Layout, origin: Point, reach: f64) -> Near {
        let reach2 = reach * reach;
        let mut near = Near::default();
        let add_edges = |near: &mut Near, corners: &[Point]| {
            let count = corners.len();
            for k in 0..count {
                let (a, b) = (corners[k], corners[(k + 1) % count]);
                if segment_distance2(origin, a, b) <= reach2 {
                    near.edges.push((a, b));
                }
            }
        };
        if let Some(walls) = &layout.walls {
            add_edges(&mut near, walls);
        }
        for obstacle in &layout.obstacles {
            // A box out of reach holds nothing within it.
            if let Some((low, high)) = obstacle.bounds() {
                let dx = (low.x - origin.x).max(origin.x - high.x).max(0.0);
                let dy = (low.y - origin.y).max(origin.y - high.y).max(0.0);
                if dx * dx + dy * dy > reach2 {
                    continue;
                }
            }
            match obstacle {
                Shape::Circle { centre, radius } => near.circles.push((*centre, *radius)),
                Shape::Polygon(corners) => {
                    near.inside |= inside_polygon(corners, origin);
                    add_edges(&mut near, corners);
                }
            }
        }
        near
    }

    /// How far along the ray from `origin` in `direction` it first meets
    /// something near.
    fn distance(&self, origin: Point, direction: Point) -> Option<f64> {
        if self.inside {
            return Some(0.0);
        }
        self.circles
            .iter()
            .filter_map(|&(centre, radius)| ray_circle(origin, direction, centre, radius))
            .chain(
                self.edges
                    .iter()
                    .filter_map(|&(a, b)| ray_segment(origin, direction, a, b)),
            )
            .min_by(f64::total_cmp)
    }

    /// [`Near::distance`] tested against `items` only (circles first,
    /// then edges, by index: [`Near::rays`]).
    fn distance_among(&self, origin: Point, direction: Point, items: &[u32]) -> Option<f64> {
        if self.inside {
            return Some(0.0);
        }
        let circles = self.circles.len();
        items
            .iter()
            .filter_map(|&item| {
                let item = item as usize;
                match self.circles.get(item) {
                    Some(&(centre, radius)) => ray_circle(origin, direction, centre, radius),
                    None => {
                        let &(a, b) = self.edges.get(item - circles)?;
                        ray_segment(origin, direction, a, b)
                    }
                }
            })
            .min_by(f64::total_cmp)
    }

    /// Which items each of a row's rays can meet, the ray of column `k`
    /// looking at `heading − (k − 128) × STEP_DEGREES` from `origin`:
    /// each item (a circle, an edge inside a circle round its middle) is
    /// listed for the rays within the angle it fills as seen from
    /// `origin`, and a ray tests those only, not every item near: among a
    /// thousand close obstacles a row would be 256 times a thousand tests.
    ///
    /// The angles come from the platform's `atan2` and `asin`, which may
    /// differ in the last bit between platforms: each item is listed for
    /// [`PAD_STEPS`] more steps either way than it fills, far more than
    /// such a difference, so the lists hold every item a ray meets and the
    /// readings (computed as before, from `+ - * /` and `sqrt`) are the
    /// same bits everywhere.
    fn rays(&self, origin: Point, heading: f64) -> Rays {
        let circles = self
            .circles
            .iter()
            .map(|&(centre, radius)| (centre, radius));
        let edges = self.edges.iter().map(|&(a, b)| {
            let middle = Point::new((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
            // The ray may meet an edge EDGE_SLACK past its ends.
            let half = a.distance2(b).sqrt() / 2.0 * (1.0 + 4.0 * EDGE_SLACK);
            (middle, half)
        });
        let step = STEP_DEGREES * PI / 180.0;
        let mut spans: Vec<(u32, usize, usize)> = Vec::new();
        for (item, (centre, radius)) in circles.chain(edges).enumerate() {
            let item = u32::try_from(item).unwrap_or(u32::MAX);
            let (dx, dy) = (centre.x - origin.x, centre.y - origin.y);
            let far = (dx * dx + dy * dy).sqrt();
            // Round it, or nearly: any ray may meet it.
            let half_width = if far <= radius * (1.0 + 1e-6) + 1e-9 {
                f64::INFINITY
            } else {
                (radius / far).asin() / step + PAD_STEPS
            };
            if !half_width.is_finite() || half_width >= (STEPS_A_TURN / 2) as f64 {
                spans.push((item, 0, STEPS));
                continue;
            }
            // The column (less 128) looking straight at it, within a turn.
            let straight = ((heading - dy.atan2(dx)) / step).rem_euclid(STEPS_A_TURN as f64);
            if !straight.is_finite() {
                spans.push((item, 0, STEPS));
                continue;
            }
            for turns in -2i32..=2 {
                let middle = (STEPS / 2) as f64 + straight + f64::from(turns) * STEPS_A_TURN as f64;
                let low = (middle - half_width).ceil().max(0.0);
                let high = (middle + half_width).floor().min((STEPS - 1) as f64);
                if low <= high {
                    // Whole numbers within 0..STEPS.
                    spans.push((item, low as usize, high as usize + 1));
                }
            }
        }
        let mut counts = [0u32; STEPS + 1];
        for &(_, low, high) in &spans {
            for count in &mut counts[low..high] {
                *count += 1;
            }
        }
        let mut starts = [0u32; STEPS + 1];
        let mut total = 0;
        for (start, count) in starts.iter_mut().zip(counts) {
            *start = total;
            total += count;
        }
        let mut fill = starts;
        let mut items = vec![0u32; total as usize];
        for &(item, low, high) in &spans {
            for column in low..high {
                items[fill[column] as usize] = item;
                fill[column] += 1;
            }
        }
        Rays { starts, items }
    }
}

/// The steps of a whole turn of the scanner: 360° / [`STEP_DEGREES`].
const STEPS_A_TURN: usize = 200;

/// How many steps either way past the angle an item fills it is listed
/// for ([`Near::rays`]).
const PAD_STEPS: f64 = 1.5;

/// What each ray of a row can meet ([`Near::rays`]).
#[derive(Debug)]
struct Rays {
    /// Where column `k`'s items begin in `items` (the last: the end).
    starts: [u32; STEPS + 1],
    items: Vec<u32>,
}

impl Rays {
    fn of(&self, column: usize) -> &[u32] {
        let (start, end) = (self.starts[column], self.starts[column + 1]);
        self.items.get(start as usize..end as usize).unwrap_or(&[])
    }
}

/// The reading for something `gap` centimetres beyond the robot's outline
/// (`None`: nothing): `round(255 × (RANGE − gap) / RANGE)`, 0xFF at
/// contact falling in a straight line to 0 at [`RANGE`], then
/// [`BACKGROUND`].
#[must_use]
pub fn reading(gap: Option<f64>) -> u8 {
    match gap {
        Some(gap) if gap < RANGE => {
            let gap = gap.max(0.0);
            // In 0..=255 by the guard above: the cast cannot truncate.
            (255.0 * (RANGE - gap) / RANGE).round() as u8
        }
        _ => BACKGROUND,
    }
}

/// The scanner's directions, kept from one pose to the next: the sine
/// and cosine of each step's turn from straight ahead.
#[derive(Debug, Clone)]
pub struct Scanner {
    turns: Vec<(f64, f64)>,
}

impl Default for Scanner {
    fn default() -> Scanner {
        let turns = (0..STEPS)
            .map(|column| {
                let h = column as f64 - (STEPS / 2) as f64;
                sin_cos(h * STEP_DEGREES * PI / 180.0)
            })
            .collect();
        Scanner { turns }
    }
}

impl Scanner {
    /// The readings at `pose` in `layout`, one per horizontal step h
    /// from -128 to 127 (at `h + 128`): the ray at `heading − h ×
    /// STEP_DEGREES` from the axle's middle, its distance less the
    /// outline's radius through [`reading`].
    #[must_use]
    pub fn row(&self, layout: &Layout, pose: Pose) -> [u8; STEPS] {
        let (sin, cos) = sin_cos(pose.heading);
        let mut row = [BACKGROUND; STEPS];
        // Anything farther reads BACKGROUND: left out, the row is the
        // same and costs what the room near the robot costs.
        let near = Near::of(layout, pose.at, RANGE + layout.body.radius + REACH_MARGIN);
        let rays = near.rays(pose.at, pose.heading);
        for (column, (reading_at, &(turn_sin, turn_cos))) in
            row.iter_mut().zip(&self.turns).enumerate()
        {
            // heading − turn: a `+` step turns right (clockwise).
            let direction = Point::new(
                cos * turn_cos + sin * turn_sin,
                sin * turn_cos - cos * turn_sin,
            );
            let gap = near
                .distance_among(pose.at, direction, rays.of(column))
                .map(|d| d - layout.body.radius);
            *reading_at = reading(gap);
        }
        row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EAST: Point = Point { x: 1.0, y: 0.0 };
    const ORIGIN: Point = Point { x: 0.0, y: 0.0 };

    fn layout(text: &str) -> Layout {
        super::super::file::parse("room.toml", text).expect("the world file loads")
    }

    fn close(found: Option<f64>, expected: f64) -> bool {
        found.is_some_and(|d| (d - expected).abs() < 1e-9)
    }

    #[test]
    fn distance_to_a_circle() {
        let centre = Point::new(50.0, 0.0);
        assert!(close(ray_circle(ORIGIN, EAST, centre, 10.0), 40.0));
        // Off the axis by 6: the chord's near end at 50 − 8.
        let off = Point::new(50.0, 6.0);
        assert!(close(ray_circle(ORIGIN, EAST, off, 10.0), 42.0));
        assert_eq!(ray_circle(ORIGIN, EAST, Point::new(50.0, 11.0), 10.0), None);
        assert_eq!(ray_circle(ORIGIN, EAST, Point::new(-50.0, 0.0), 10.0), None);
        assert!(close(
            ray_circle(ORIGIN, EAST, Point::new(5.0, 0.0), 10.0),
            0.0
        ));
    }

    #[test]
    fn distance_to_a_polygon_edge() {
        let a = Point::new(30.0, -5.0);
        let b = Point::new(30.0, 5.0);
        assert!(close(ray_segment(ORIGIN, EAST, a, b), 30.0));
        assert_eq!(ray_segment(ORIGIN, EAST, a, Point::new(30.0, -1.0)), None);
        assert_eq!(ray_segment(ORIGIN, Point::new(-1.0, 0.0), a, b), None);
        let north_east = Point::new(0.6, 0.8);
        // It meets x = 30 at y = 40: past this edge, on a longer one.
        assert_eq!(ray_segment(ORIGIN, north_east, a, b), None);
        let long = Point::new(30.0, 45.0);
        assert!(close(ray_segment(ORIGIN, north_east, a, long), 50.0));
        // A square ahead: its near side first.
        let square = [
            Point::new(20.0, -10.0),
            Point::new(40.0, -10.0),
            Point::new(40.0, 10.0),
            Point::new(20.0, 10.0),
        ];
        assert!(close(ray_polygon(ORIGIN, EAST, &square), 20.0));
    }

    #[test]
    fn distance_to_the_walls_from_inside() {
        let layout = layout("walls = [[-100, -50], [100, -50], [100, 50], [-100, 50]]");
        assert!(close(distance(&layout, ORIGIN, EAST), 100.0));
        assert!(close(
            distance(&layout, ORIGIN, Point::new(0.0, -1.0)),
            50.0
        ));
    }

    #[test]
    fn nothing_hit_on_an_open_floor() {
        let layout = layout("");
        assert_eq!(distance(&layout, ORIGIN, EAST), None);
        let row = Scanner::default().row(&layout, layout.start);
        assert!(row.iter().all(|&r| r == BACKGROUND));
    }

    #[test]
    fn nearer_reads_stronger() {
        assert_eq!(reading(Some(0.0)), 0xFF);
        assert_eq!(reading(Some(-3.0)), 0xFF, "inside the outline: contact");
        assert_eq!(reading(Some(RANGE / 2.0)), 128);
        assert_eq!(reading(Some(RANGE)), BACKGROUND);
        assert_eq!(reading(None), BACKGROUND);
        assert!(reading(Some(10.0)) > reading(Some(20.0)));
    }

    #[test]
    fn a_row_sees_a_post_ahead_and_to_the_right() {
        // A post 60 cm east of the robot (radius 15), 20 cm round.
        let layout =
            layout("[[obstacle]]\ncircle = { x = 60, y = 0, radius = 20 }\n[robot]\nradius = 15\n");
        let scanner = Scanner::default();
        let pose = Pose {
            at: ORIGIN,
            heading: 0.0,
        };
        let row = scanner.row(&layout, pose);
        assert_eq!(
            row[128],
            reading(Some(60.0 - 20.0 - 15.0)),
            "straight ahead"
        );
        // The post spans asin(20/60) = 19.5°: steps up to 10 either way.
        assert!(row[128 + 10] > BACKGROUND && row[128 - 10] > BACKGROUND);
        assert_eq!(row[128 + 11], BACKGROUND);
        assert_eq!(row[128 - 11], BACKGROUND);
        // Facing north, the post is 50 steps (90°) to the right.
        let north = Pose {
            at: ORIGIN,
            heading: PI / 2.0,
        };
        let turned = scanner.row(&layout, north);
        assert_eq!(turned[128 + 50], row[128]);
        assert_eq!(turned[128 - 50], BACKGROUND);
    }
    /// A square room of 300 by 200 cm.
    const ROOM: &str =
        "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n[robot]\nx = 100\ny = 100\n";

    /// A ray aimed exactly at a corner of a closed room meets the walls:
    /// rounding put it a little past the end of both edges there, and it
    /// slipped through to an open floor (the hostile pass's finding). The
    /// robot is placed back along each ray from each corner.
    #[test]
    fn a_ray_at_a_corner_of_the_room_meets_it() {
        let layout = layout(ROOM);
        let walls = layout.walls.clone().expect("walls");
        let scanner = Scanner::default();
        let mut slipped = Vec::new();
        for corner in &walls {
            for heading_step in [0.0, 25.0, 50.0, 137.0] {
                let heading = heading_step * STEP_DEGREES * PI / 180.0;
                let (sin, cos) = sin_cos(heading);
                for (column, &(turn_sin, turn_cos)) in scanner.turns.iter().enumerate() {
                    let direction = Point::new(
                        cos * turn_cos + sin * turn_sin,
                        sin * turn_cos - cos * turn_sin,
                    );
                    for back in [7.3, 58.0, 91.7, 123.4, 170.9] {
                        let at = Point::new(
                            corner.x - direction.x * back,
                            corner.y - direction.y * back,
                        );
                        if !super::super::geometry::inside_polygon(&walls, at) {
                            continue;
                        }
                        if distance(&layout, at, direction).is_none() {
                            slipped.push((at, column));
                        }
                    }
                }
            }
        }
        assert!(
            slipped.is_empty(),
            "rays through a corner met nothing: {slipped:?}"
        );
        // One the pass found, the whole row's way (heading east, step 47
        // right): the corner at (300, 0), read as its distance.
        let at = Point::new(294.437_167_709_281_94, 58.848_618_669_432_47);
        let row = scanner.row(&layout, Pose { at, heading: 0.0 });
        let corner = Point::new(300.0, 0.0).distance2(at).sqrt();
        assert_eq!(row[128 + 47], reading(Some(corner - layout.body.radius)));
    }

    /// Readings worked by hand in the room of 300 by 200 cm from (100,
    /// 100) facing east, the outline 15 cm round: `round(255 × (200 −
    /// gap) / 200)` with the gap to the wall the ray meets.
    #[test]
    fn readings_agree_with_a_hand_computation() {
        let layout = layout(ROOM);
        let row = Scanner::default().row(&layout, layout.start);
        // Straight ahead: the east wall 200 cm off, a gap of 185:
        // 255 × 15 / 200 = 19.125.
        assert_eq!(row[128], 19);
        // Step 25 left, 45° north of east: the north wall at 100 / sin
        // 45° = 141.42, a gap of 126.42: 255 × 73.58 / 200 = 93.81.
        assert_eq!(row[128 - 25], 94);
        // Step 25 right, 45° south: the south wall as far.
        assert_eq!(row[128 + 25], 94);
        // Step 50 right, due south: 100 cm, a gap of 85: 146.625.
        assert_eq!(row[128 + 50], 147);
        // Step 30 right, 54° south of east: 100 / sin 54° = 123.61, a gap
        // of 108.61: 255 × 91.39 / 200 = 116.53.
        assert_eq!(row[128 + 30], 117);
        // Step 100 right, 180°: the west wall 100 cm behind: 147 too.
        assert_eq!(row[128 + 100], 147);
    }

    /// A robot dragged into a polygon obstacle is in contact with it
    /// whichever way it looks, as inside a circle: not the distance to
    /// the far side of the polygon.
    #[test]
    fn inside_a_polygon_every_ray_reads_contact() {
        let layout = layout(
            "[[obstacle]]\npolygon = [[40, 40], [160, 40], [160, 160], [40, 160]]\n[[obstacle]]\ncircle = { x = 400, y = 100, radius = 60 }\n",
        );
        let scanner = Scanner::default();
        for at in [Point::new(100.0, 100.0), Point::new(400.0, 100.0)] {
            let row = scanner.row(&layout, Pose { at, heading: 0.0 });
            assert!(row.iter().all(|&r| r == 0xFF), "at {at:?}: {row:02X?}");
        }
    }

    /// Obstacles beyond the scanner's range (10,000 of them) change no
    /// reading: the row leaves them out, and is the one every ray
    /// tested against everything gives.
    #[test]
    fn far_obstacles_change_nothing() {
        let mut text = String::from(ROOM);
        text.push_str("[[obstacle]]\ncircle = { x = 200, y = 150, radius = 10 }\n");
        for k in 0..10_000 {
            let (x, y) = (600 + (k % 100) * 30, (k / 100) * 30 - 1500);
            text.push_str(&format!(
                "[[obstacle]]\ncircle = {{ x = {x}, y = {y}, radius = 5 }}\n"
            ));
            if k % 3 == 0 {
                text.push_str(&format!(
                    "[[obstacle]]\npolygon = [[{x}, {y}], [{}, {y}], [{x}, {}]]\n",
                    x + 4,
                    y + 4
                ));
            }
        }
        // And some in range, just past the walls (the walls hide them).
        text.push_str("[[obstacle]]\ncircle = { x = 320, y = 100, radius = 5 }\n");
        // The world file refuses obstacles beyond the walls (one rule
        // with the view's drags): the walls are put round them after.
        let walls = layout(ROOM).walls;
        let mut crowded = layout(&text.replacen(ROOM.lines().next().unwrap_or_default(), "", 1));
        crowded.walls = walls;
        let scanner = Scanner::default();
        for (x, y, heading) in [(100.0, 100.0, 0.0), (250.0, 60.0, 1.0), (40.0, 170.0, 4.0)] {
            let pose = Pose {
                at: Point::new(x, y),
                heading,
            };
            let row = scanner.row(&crowded, pose);
            let (sin, cos) = sin_cos(heading);
            for (column, &(turn_sin, turn_cos)) in scanner.turns.iter().enumerate() {
                let direction = Point::new(
                    cos * turn_cos + sin * turn_sin,
                    sin * turn_cos - cos * turn_sin,
                );
                let every = distance(&crowded, pose.at, direction).map(|d| d - crowded.body.radius);
                assert_eq!(row[column], reading(every), "at {pose:?}, column {column}");
            }
        }
    }

    /// Among a thousand obstacles close round the robot (circles,
    /// triangles, some touching the rays' origin), each ray of a row
    /// tested against the items listed for it reads what it reads tested
    /// against everything, at any heading (many turns round included).
    #[test]
    fn a_crowd_close_by_reads_as_every_ray_tested_against_everything() {
        let mut text = String::from("walls = [[0, 0], [3000, 0], [3000, 3000], [0, 3000]]\n");
        let mut seed: u64 = 1;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..1000 {
            let (angle, far) = (next() * 2.0 * PI, 20.0 + next() * 230.0);
            let (sin, cos) = sin_cos(angle);
            let (x, y) = (1500.0 + far * cos, 1500.0 + far * sin);
            let size = 0.3 + next() * 3.0;
            if k % 2 == 0 {
                text.push_str(&format!(
                    "[[obstacle]]\ncircle = {{ x = {x}, y = {y}, radius = {size} }}\n"
                ));
            } else {
                text.push_str(&format!(
                    "[[obstacle]]\npolygon = [[{x}, {y}], [{}, {y}], [{x}, {}]]\n",
                    x + size,
                    y + size
                ));
            }
        }
        text.push_str("[robot]\nx = 1500\ny = 1500\nradius = 10\n");
        let crowded = layout(&text);
        let scanner = Scanner::default();
        let mut met = 0;
        for (dx, dy, heading) in [
            (0.0, 0.0, 0.0),
            (3.5, -7.25, 1.0),
            (-12.0, 4.0, -2.5),
            (40.0, 41.0, 100.0),
            (-90.0, 10.0, -777.7),
        ] {
            let pose = Pose {
                at: Point::new(1500.0 + dx, 1500.0 + dy),
                heading,
            };
            let row = scanner.row(&crowded, pose);
            let (sin, cos) = sin_cos(heading);
            for (column, &(turn_sin, turn_cos)) in scanner.turns.iter().enumerate() {
                let direction = Point::new(
                    cos * turn_cos + sin * turn_sin,
                    sin * turn_cos - cos * turn_sin,
                );
                let every = distance(&crowded, pose.at, direction).map(|d| d - crowded.body.radius);
                assert_eq!(row[column], reading(every), "at {pose:?}, column {column}");
                met += usize::from(row[column] != BACKGROUND);
            }
        }
        assert!(met > 1000, "the rays met the crowd: {met}");
    }
}
