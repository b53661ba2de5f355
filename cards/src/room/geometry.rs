//! Plane geometry of the room in centimetres: points, polygons, circles
//! and floor lines, and the sine and cosine the robot's heading needs.
//!
//! Only `+ - * /` and `sqrt` of `f64` are used, which IEEE 754 rounds the
//! same on every platform: the platform's `sin` and `cos` may differ in
//! the last bit between libraries, and a run must be the same everywhere,
//! instruction for instruction (the debugger's step back and snapshot
//! tests rest on it), so [`sin_cos`] is a series of our own.

/// A point on the floor, in centimetres: `x` east, `y` north.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// East, centimetres.
    pub x: f64,
    /// North, centimetres.
    pub y: f64,
}

impl Point {
    /// The point at `x`, `y`.
    #[must_use]
    pub fn new(x: f64, y: f64) -> Point {
        Point { x, y }
    }

    fn minus(self, other: Point) -> Point {
        Point::new(self.x - other.x, self.y - other.y)
    }

    fn dot(self, other: Point) -> f64 {
        self.x * other.x + self.y * other.y
    }

    /// The square of the distance to `other`.
    #[must_use]
    pub fn distance2(self, other: Point) -> f64 {
        let d = self.minus(other);
        d.dot(d)
    }
}

/// An outline that takes up floor: the robot cannot be inside it.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A closed polygon, its corners in order (either way round).
    Polygon(Vec<Point>),
    /// A circle.
    Circle {
        /// The centre.
        centre: Point,
        /// The radius, centimetres.
        radius: f64,
    },
}

impl Shape {
    /// Whether `point` lies inside the shape or on its edge.
    #[must_use]
    pub fn contains(&self, point: Point) -> bool {
        match self {
            Shape::Circle { centre, radius } => point.distance2(*centre) <= radius * radius,
            Shape::Polygon(corners) => inside_polygon(corners, point),
        }
    }
}

impl Shape {
    /// The box around the shape, a little wider than the arithmetic of
    /// [`Shape::contains`] can stray (a point it finds inside lies in
    /// it): its lowest and highest corners, or `None` for a shape with no
    /// finite bounds (no corners, or a coordinate that is not a number).
    #[must_use]
    pub fn bounds(&self) -> Option<(Point, Point)> {
        let (low, high) = match self {
            Shape::Circle { centre, radius } => {
                let r = radius.abs();
                (
                    Point::new(centre.x - r, centre.y - r),
                    Point::new(centre.x + r, centre.y + r),
                )
            }
            Shape::Polygon(corners) => {
                let first = corners.first()?;
                corners.iter().fold((*first, *first), |(low, high), p| {
                    (
                        Point::new(low.x.min(p.x), low.y.min(p.y)),
                        Point::new(high.x.max(p.x), high.y.max(p.y)),
                    )
                })
            }
        };
        let scale = 1.0
            + [low.x, low.y, high.x, high.y]
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()));
        // Rounding in `contains` is some 1e-16 of the coordinates: a
        // millionth of them is room to spare, and culls as well.
        let pad = scale * 1e-6;
        let (low, high) = (
            Point::new(low.x - pad, low.y - pad),
            Point::new(high.x + pad, high.y + pad),
        );
        [low.x, low.y, high.x, high.y]
            .iter()
            .all(|v| v.is_finite())
            .then_some((low, high))
    }
}

/// Shapes by where they lie: square cells of about a shape's size, each
/// listing the shapes whose box meets it (only the cells some shape
/// meets are kept), so that a point is tested against the shapes near it
/// only and the cost of a test does not grow with shapes far away. A
/// shape whose box spans many cells (a long wall among posts), or that
/// has none, is listed apart and tested for every point.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShapeGrid {
    /// A cell's side, centimetres.
    cell: f64,
    /// The cells some shape meets (column, row), in order.
    cells: Vec<(i64, i64)>,
    /// Where each cell's shapes begin in `members` (one more entry than
    /// cells: the last is the end).
    starts: Vec<u32>,
    /// Shape indices, cell after cell.
    members: Vec<u32>,
    /// Shapes tested for every point.
    everywhere: Vec<u32>,
}

/// The most cells one shape is listed in before it is listed apart.
const MAX_CELLS_A_SHAPE: i64 = 256;
/// The smallest cell, centimetres (a room of shapes with no size).
const MIN_CELL: f64 = 1.0;

impl ShapeGrid {
    /// The grid of `shapes` (indices into it are what [`ShapeGrid::near`]
    /// yields), its cells twice the median shape's box.
    #[must_use]
    pub fn new(shapes: &[Shape]) -> ShapeGrid {
        let bounds: Vec<Option<(Point, Point)>> = shapes.iter().map(Shape::bounds).collect();
        let mut sides: Vec<f64> = bounds
            .iter()
            .flatten()
            .map(|(low, high)| (high.x - low.x).max(high.y - low.y))
            .collect();
        sides.sort_by(f64::total_cmp);
        let median = sides.get(sides.len() / 2).copied().unwrap_or(MIN_CELL);
        let mut grid = ShapeGrid {
            cell: (2.0 * median).max(MIN_CELL),
            ..ShapeGrid::default()
        };
        let mut listed: Vec<((i64, i64), u32)> = Vec::new();
        for (shape, bounds) in bounds.iter().enumerate() {
            let Some((low, high)) = bounds else {
                grid.everywhere.push(index(shape));
                continue;
            };
            let (c0, r0) = grid.cell_of(*low);
            let (c1, r1) = grid.cell_of(*high);
            let across = |from: i64, to: i64| to.saturating_sub(from).saturating_add(1);
            let span = across(c0, c1).saturating_mul(across(r0, r1));
            if !(1..=MAX_CELLS_A_SHAPE).contains(&span) {
                grid.everywhere.push(index(shape));
                continue;
            }
            for row in r0..=r1 {
                for column in c0..=c1 {
                    listed.push(((column, row), index(shape)));
                }
            }
        }
        listed.sort_unstable();
        for (cell, shape) in listed {
            if grid.cells.last() != Some(&cell) {
                grid.cells.push(cell);
                grid.starts.push(index(grid.members.len()));
            }
            grid.members.push(shape);
        }
        grid.starts.push(index(grid.members.len()));
        grid
    }

    /// The cell `point` falls in. Rounding is monotonic, so a point in a
    /// box falls in a cell between those of the box's corners.
    fn cell_of(&self, point: Point) -> (i64, i64) {
        // `as` saturates, and makes NaN 0.
        (
            (point.x / self.cell).floor() as i64,
            (point.y / self.cell).floor() as i64,
        )
    }

    /// The shapes that may contain `point` (the others cannot): those
    /// listed in its cell, then those listed apart.
    pub fn near(&self, point: Point) -> impl Iterator<Item = usize> + '_ {
        let listed: &[u32] = match self.cells.binary_search(&self.cell_of(point)) {
            Ok(at) => self
                .members
                .get(self.starts[at] as usize..self.starts[at + 1] as usize)
                .unwrap_or(&[]),
            Err(_) => &[],
        };
        listed
            .iter()
            .chain(&self.everywhere)
            .map(|&shape| shape as usize)
    }
}

fn index(value: usize) -> u32 {
    u32::try_from(value).unwrap_or(u32::MAX)
}

/// Whether `point` is inside the closed polygon `corners` (even-odd rule).
#[must_use]
pub fn inside_polygon(corners: &[Point], point: Point) -> bool {
    let mut inside = false;
    let count = corners.len();
    for index in 0..count {
        let a = corners[index];
        let b = corners[(index + 1) % count];
        if (a.y > point.y) != (b.y > point.y) {
            let crossing = a.x + (point.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if point.x < crossing {
                inside = !inside;
            }
        }
    }
    inside
}

/// The square of the distance from `point` to the segment `a`-`b`.
#[must_use]
pub fn segment_distance2(point: Point, a: Point, b: Point) -> f64 {
    let along = b.minus(a);
    let length2 = along.dot(along);
    if length2 == 0.0 {
        return point.distance2(a);
    }
    let t = (point.minus(a).dot(along) / length2).clamp(0.0, 1.0);
    point.distance2(Point::new(a.x + t * along.x, a.y + t * along.y))
}

/// Whether `point` is within `half_width` of the polyline `points` (a
/// floor line of that half width).
#[must_use]
pub fn near_polyline(points: &[Point], half_width: f64, point: Point) -> bool {
    let limit = half_width * half_width;
    match points {
        [] => false,
        [only] => point.distance2(*only) <= limit,
        _ => points
            .windows(2)
            .any(|pair| segment_distance2(point, pair[0], pair[1]) <= limit),
    }
}

/// π, as the nearest `f64`.
pub const PI: f64 = std::f64::consts::PI;

/// The sine and cosine of `angle` radians, from `+ - * /` only (see the
/// module's comment): the angle is brought into [-π/4, π/4] by quarter
/// turns, where twelve terms of the Taylor series are exact to the last
/// bit or so, and the same bits on every platform.
#[must_use]
pub fn sin_cos(angle: f64) -> (f64, f64) {
    let quarter = PI / 2.0;
    let turns = (angle / quarter).round();
    let reduced = angle - turns * quarter;
    let square = reduced * reduced;
    // sin = x - x^3/3! + ..., cos = 1 - x^2/2! + ...
    let (mut sin, mut cos) = (0.0, 0.0);
    let (mut sin_term, mut cos_term) = (reduced, 1.0);
    for n in 0..12 {
        sin += sin_term;
        cos += cos_term;
        let k = f64::from(2 * n + 2);
        sin_term = -sin_term * square / (k * (k + 1.0));
        cos_term = -cos_term * square / ((k - 1.0) * k);
    }
    // A quarter turn: (sin, cos) -> (cos, -sin). `turns` is whole: the
    // remainder of a division by four picks the quadrant.
    match turns.rem_euclid(4.0) as u8 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_and_cosine_agree_with_the_library_closely() {
        for step in -720..=720 {
            let angle = f64::from(step) * PI / 180.0;
            let (sin, cos) = sin_cos(angle);
            assert!((sin - angle.sin()).abs() < 1e-12, "sin {step}°");
            assert!((cos - angle.cos()).abs() < 1e-12, "cos {step}°");
        }
    }

    #[test]
    fn points_inside_shapes() {
        let square = Shape::Polygon(vec![
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
            Point::new(0.0, 10.0),
        ]);
        assert!(square.contains(Point::new(5.0, 5.0)));
        assert!(!square.contains(Point::new(15.0, 5.0)));
        let circle = Shape::Circle {
            centre: Point::new(0.0, 0.0),
            radius: 2.0,
        };
        assert!(circle.contains(Point::new(1.0, 1.0)));
        assert!(!circle.contains(Point::new(2.0, 1.0)));
    }

    /// Whatever the shapes, big or small, the grid's candidates for a
    /// point include every shape that contains it, edges included, and
    /// leave out shapes far away.
    #[test]
    fn the_grid_finds_every_shape_a_point_is_in() {
        let mut shapes = vec![
            // Wider than the cells a shape may be listed in: tested for
            // every point.
            Shape::Polygon(vec![
                Point::new(-50.0, -50.0),
                Point::new(250.0, -40.0),
                Point::new(0.0, 240.0),
            ]),
            Shape::Polygon(Vec::new()),
            Shape::Circle {
                centre: Point::new(1e6, 1e6),
                radius: 0.5,
            },
        ];
        for index in 0..400 {
            let (x, y) = (f64::from(index % 20) * 10.0, f64::from(index / 20) * 10.0);
            shapes.push(if index % 3 == 0 {
                Shape::Polygon(vec![
                    Point::new(x, y),
                    Point::new(x + 4.0, y + 0.5),
                    Point::new(x + 1.0, y + 3.0),
                ])
            } else {
                Shape::Circle {
                    centre: Point::new(x, y),
                    radius: 0.25 + f64::from(index % 7),
                }
            });
        }
        let grid = ShapeGrid::new(&shapes);
        let mut candidates = 0;
        for step in -300..2300 {
            // A lattice that falls on corners and edges, and between.
            let point = Point::new(f64::from(step % 230) * 0.97 - 10.0, f64::from(step) * 0.09);
            let near: Vec<usize> = grid.near(point).collect();
            candidates += near.len();
            for (index, shape) in shapes.iter().enumerate() {
                if shape.contains(point) {
                    assert!(near.contains(&index), "shape {index} at {point:?}");
                }
            }
        }
        let points = 2600;
        assert!(
            candidates < points * 20,
            "a few candidates a point, not {}: {candidates}",
            shapes.len()
        );
    }

    #[test]
    fn a_point_near_a_line() {
        let line = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
        ];
        assert!(near_polyline(&line, 1.0, Point::new(5.0, 0.5)));
        assert!(near_polyline(&line, 1.0, Point::new(10.5, 5.0)));
        assert!(!near_polyline(&line, 1.0, Point::new(5.0, 2.0)));
    }
}
