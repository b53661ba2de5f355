//! What the infrared scanner sees: a reading for every position the
//! horizontal and vertical scanners can point at.

use std::collections::BTreeMap;

/// Readings by scanner position. Positions are steps from the centre,
/// clamped to -128..=127 on each axis.
///
/// A scene keeps a table of its 65,536 readings only once a single
/// position is set: every virtual robot starts with the default wall, and
/// filling a table for it cost more than booting the robot. A room sets
/// a row ([`Scene::set_row`]): a reading per horizontal step, the same at
/// every vertical one, 256 bytes to refill when the robot moves.
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
    /// A reading per horizontal step (at `h + 128`), the same for every
    /// vertical one, under the positions set one by one since, which win.
    Row {
        row: Box<[u8]>,
        set: BTreeMap<(i64, i64), u8>,
    },
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

/// The place of the horizontal step `h` in a row.
fn column(h: i64) -> usize {
    usize::try_from(clamp(h) + SIDE / 2).unwrap_or(0)
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
            Readings::Row { row, set } => set
                .get(&(clamp(h), clamp(v)))
                .copied()
                .unwrap_or_else(|| row[column(h)]),
        }
    }

    /// Sets the readings from one per horizontal step, `row[h + 128]`
    /// for h from -128 to 127, the same at every vertical step (what a
    /// room sees round the robot), when the scene is the default wall or
    /// such a row already. What was set whole ([`Scene::uniform`],
    /// [`Scene::from_fn`]) or position by position ([`Scene::set`]) since
    /// stays: the one who set it wins where it did. Returns whether the
    /// row was taken.
    pub fn set_row(&mut self, new: &[u8; 256]) -> bool {
        match &mut self.readings {
            Readings::Wall => {
                self.readings = Readings::Row {
                    row: Box::new(*new),
                    set: BTreeMap::new(),
                };
                true
            }
            Readings::Row { row, .. } => {
                row.copy_from_slice(new);
                true
            }
            Readings::Uniform(_) | Readings::Table(_) => false,
        }
    }

    /// Sets the reading at (h, v).
    pub fn set(&mut self, h: i64, v: i64, value: u8) {
        if let Readings::Row { set, .. } = &mut self.readings {
            set.insert((clamp(h), clamp(v)), value);
            return;
        }
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

    #[test]
    fn a_row_reads_by_horizontal_step_under_positions_set_since() {
        let mut row = [0u8; 256];
        for (k, reading) in row.iter_mut().enumerate() {
            *reading = u8::try_from(k).unwrap_or(0);
        }
        let mut scene = Scene::default();
        assert!(scene.set_row(&row), "the default wall takes a row");
        assert_eq!(scene.reading(-128, 0), 0);
        assert_eq!(scene.reading(5, 0), 133);
        assert_eq!(scene.reading(5, -40), 133, "the same at every v");
        assert_eq!(scene.reading(500, 9), 255, "clamped");
        scene.set(5, 1, 7);
        assert_eq!(scene.reading(5, 1), 7);
        assert_eq!(scene.reading(5, 0), 133);
        row[133] = 1;
        assert!(scene.set_row(&row));
        assert_eq!(scene.reading(5, 0), 1, "the new row");
        assert_eq!(scene.reading(5, 1), 7, "the position set still wins");
        let mut whole = Scene::uniform(9);
        assert!(!whole.set_row(&row), "a scene set whole stays");
        assert_eq!(whole, Scene::uniform(9));
        let mut table = Scene::default();
        table.set(0, 0, 3);
        assert!(!table.set_row(&row), "a scene set by position stays");
        assert_eq!(table.reading(0, 0), 3);
    }
}
