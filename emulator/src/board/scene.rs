//! What the infrared scanner sees: a reading for every position the
//! horizontal and vertical scanners can point at.

/// Readings by scanner position. Positions are steps from the centre,
/// clamped to -128..=127 on each axis.
#[derive(Clone, PartialEq, Eq)]
pub struct Scene {
    readings: Box<[u8]>,
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("centre", &self.reading(0, 0))
            .finish_non_exhaustive()
    }
}

fn index(h: i64, v: i64) -> usize {
    let h = h.clamp(-128, 127) + 128;
    let v = v.clamp(-128, 127) + 128;
    usize::try_from(v * 256 + h).unwrap_or(0)
}

impl Default for Scene {
    /// A wall straight ahead: the reflection is strongest at the centre
    /// and falls off by two per step away from it on either axis.
    fn default() -> Scene {
        Scene::from_fn(|h, v| {
            let distance = h.unsigned_abs() + v.unsigned_abs();
            u8::try_from(0xC0_u64.saturating_sub(2 * distance)).unwrap_or(0)
        })
    }
}

impl Scene {
    /// The same reading everywhere.
    #[must_use]
    pub fn uniform(value: u8) -> Scene {
        Scene {
            readings: vec![value; 256 * 256].into_boxed_slice(),
        }
    }

    /// Readings from a function of (horizontal, vertical) position.
    #[must_use]
    pub fn from_fn(mut reading: impl FnMut(i64, i64) -> u8) -> Scene {
        let mut scene = Scene::uniform(0);
        for v in -128..=127 {
            for h in -128..=127 {
                scene.readings[index(h, v)] = reading(h, v);
            }
        }
        scene
    }

    /// The reading at (h, v).
    #[must_use]
    pub fn reading(&self, h: i64, v: i64) -> u8 {
        self.readings[index(h, v)]
    }

    /// Sets the reading at (h, v).
    pub fn set(&mut self, h: i64, v: i64, value: u8) {
        self.readings[index(h, v)] = value;
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
    }
}
