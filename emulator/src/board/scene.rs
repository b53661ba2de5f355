//! What the infrared scanner sees: a reading for every position the
//! horizontal and vertical scanners can point at.

/// Readings by scanner position. Positions are steps from the centre,
/// clamped to -128..=127 on each axis.
///
/// A scene keeps a table of its 65,536 readings only once a single
/// position is set: every virtual robot starts with the default wall, and
/// filling a table for it cost more than booting the robot.
#[derive(Clone)]
pub struct Scene {
    readings: Readings,
}

#[derive(Clone)]
enum Readings {
    /// [`Scene::default`]'s wall, by its formula.
    Wall,
    /// One reading everywhere.
    Uniform(u8),
    /// A reading per position, at [`index`].
    Table(Box<[u8]>),
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("centre", &self.reading(0, 0))
            .finish_non_exhaustive()
    }
}

/// Two scenes are equal when every position reads the same.
impl PartialEq for Scene {
    fn eq(&self, other: &Scene) -> bool {
        positions().all(|(h, v)| self.reading(h, v) == other.reading(h, v))
    }
}

impl Eq for Scene {}

const SIDE: i64 = 256;

fn clamp(step: i64) -> i64 {
    step.clamp(-SIDE / 2, SIDE / 2 - 1)
}

fn index(h: i64, v: i64) -> usize {
    usize::try_from((clamp(v) + SIDE / 2) * SIDE + clamp(h) + SIDE / 2).unwrap_or(0)
}

/// Every position, in [`index`] order.
fn positions() -> impl Iterator<Item = (i64, i64)> {
    (-SIDE / 2..SIDE / 2).flat_map(|v| (-SIDE / 2..SIDE / 2).map(move |h| (h, v)))
}

/// The default wall's reading at a clamped position.
fn wall(h: i64, v: i64) -> u8 {
    let distance = h.unsigned_abs() + v.unsigned_abs();
    u8::try_from(0xC0_u64.saturating_sub(2 * distance)).unwrap_or(0)
}

impl Default for Scene {
    /// A wall straight ahead: the reflection is strongest at the centre
    /// and falls off by two per step away from it on either axis.
    fn default() -> Scene {
        Scene {
            readings: Readings::Wall,
        }
    }
}

impl Scene {
    /// The same reading everywhere.
    #[must_use]
    pub fn uniform(value: u8) -> Scene {
        Scene {
            readings: Readings::Uniform(value),
        }
    }

    /// Readings from a function of (horizontal, vertical) position.
    #[must_use]
    pub fn from_fn(mut reading: impl FnMut(i64, i64) -> u8) -> Scene {
        Scene {
            readings: Readings::Table(positions().map(|(h, v)| reading(h, v)).collect()),
        }
    }

    /// The reading at (h, v).
    #[must_use]
    pub fn reading(&self, h: i64, v: i64) -> u8 {
        match &self.readings {
            Readings::Wall => wall(clamp(h), clamp(v)),
            Readings::Uniform(value) => *value,
            Readings::Table(table) => table[index(h, v)],
        }
    }

    /// Sets the reading at (h, v).
    pub fn set(&mut self, h: i64, v: i64, value: u8) {
        if !matches!(self.readings, Readings::Table(_)) {
            *self = Scene::from_fn(|h, v| self.reading(h, v));
        }
        if let Readings::Table(table) = &mut self.readings {
            table[index(h, v)] = value;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_by_position_with_clamping() {
        let mut scene = Scene::uniform(7);
        scene.set(-3, 2, 99);
        assert_eq!(scene.reading(-3, 2), 99);
        assert_eq!(scene.reading(3, 2), 7);
        scene.set(500, 0, 1);
        assert_eq!(scene.reading(127, 0), 1);
        let wall = Scene::default();
        assert_eq!(wall.reading(0, 0), 0xC0);
        assert_eq!(wall.reading(-10, 5), 0xC0 - 30);
        assert_eq!(wall.reading(127, 127), 0);
        assert_eq!(wall.reading(-500, 0), wall.reading(-128, 0));
    }

    #[test]
    fn a_set_position_keeps_the_rest_of_the_scene() {
        let mut wall = Scene::default();
        wall.set(4, -4, 1);
        assert_eq!(wall.reading(4, -4), 1);
        assert_eq!(wall.reading(0, 0), 0xC0);
        assert_eq!(wall.reading(-10, 5), 0xC0 - 30);
        assert_ne!(wall, Scene::default());
        wall.set(4, -4, 0xC0 - 16);
        assert_eq!(wall, Scene::default());
        assert_eq!(Scene::uniform(3), Scene::from_fn(|_, _| 3));
    }
}
