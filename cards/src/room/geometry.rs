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
