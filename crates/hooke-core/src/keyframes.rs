//! Keyframes (docs/physics.md §1.2): poses given at times, interpolated between them. What
//! moves by keys (pinned particles, colliders) reads them from here.

use crate::particles::Vec3;
use nalgebra::Rotation3;

/// One key: at time `t` (seconds), a translation (metres) and a rotation (degrees about x,
/// then y, then z), both relative to where the motion started.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Seconds.
    pub t: f64,
    /// Metres.
    pub translate: Vec3,
    /// Degrees about x, then y, then z.
    pub rotate: Vec3,
}

/// Keys in increasing time, at least one.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    keys: Vec<Key>,
}

/// Why keys were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KeyError {
    /// No key at all.
    #[error("expected at least one key")]
    Empty,
    /// A key's time is not after the one before it.
    #[error(
        "key {index} at t = {t} s is not after the key before it (t = {before} s): times must increase"
    )]
    Order {
        /// The key's index.
        index: usize,
        /// Its time.
        t: f64,
        /// The time of the key before it.
        before: f64,
    },
    /// A value is not finite.
    #[error("key {index} has a value that is not a finite number")]
    NotFinite {
        /// The key's index.
        index: usize,
    },
}

impl Keyframes {
    /// The keys, checked: at least one, finite, times strictly increasing.
    pub fn new(keys: Vec<Key>) -> Result<Self, KeyError> {
        if keys.is_empty() {
            return Err(KeyError::Empty);
        }
        for (index, k) in keys.iter().enumerate() {
            let finite = k.t.is_finite()
                && k.translate.iter().all(|c| c.is_finite())
                && k.rotate.iter().all(|c| c.is_finite());
            if !finite {
                return Err(KeyError::NotFinite { index });
            }
            if index > 0 && k.t <= keys[index - 1].t {
                return Err(KeyError::Order {
                    index,
                    t: k.t,
                    before: keys[index - 1].t,
                });
            }
        }
        Ok(Self { keys })
    }

    /// The keys.
    pub fn keys(&self) -> &[Key] {
        &self.keys
    }

    /// The translation and the rotation (degrees about x, then y, then z) at time `t`:
    /// each interpolated linearly between the keys around `t`, component by component;
    /// the first key's before it and the last key's after it.
    pub fn at(&self, t: f64) -> (Vec3, Vec3) {
        let keys = &self.keys;
        let first = &keys[0];
        if t <= first.t {
            return (first.translate, first.rotate);
        }
        let last = &keys[keys.len() - 1];
        if t >= last.t {
            return (last.translate, last.rotate);
        }
        // The segment holding t: the last key at or before it.
        let j = keys.partition_point(|k| k.t <= t) - 1;
        let (a, b) = (&keys[j], &keys[j + 1]);
        let s = (t - a.t) / (b.t - a.t);
        (
            a.translate + (b.translate - a.translate) * s,
            a.rotate + (b.rotate - a.rotate) * s,
        )
    }

    /// The pose at time `t` as a rotation and a translation.
    pub fn pose(&self, t: f64) -> (Rotation3<f64>, Vec3) {
        let (translate, rotate) = self.at(t);
        let r = rotate.map(f64::to_radians);
        (Rotation3::from_euler_angles(r.x, r.y, r.z), translate)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A key moving `x` along x and turning `rz` degrees about z at time `t`.
    pub(crate) fn key(t: f64, x: f64, rz: f64) -> Key {
        Key {
            t,
            translate: Vec3::new(x, 0.0, 0.0),
            rotate: Vec3::new(0.0, 0.0, rz),
        }
    }

    /// Keys out of order, none, or not finite are refused.
    #[test]
    fn bad_keys_are_refused() {
        assert_eq!(Keyframes::new(vec![]), Err(KeyError::Empty));
        let e = Keyframes::new(vec![key(1.0, 0.0, 0.0), key(1.0, 1.0, 0.0)]).unwrap_err();
        assert!(matches!(e, KeyError::Order { index: 1, .. }), "{e}");
        let e = Keyframes::new(vec![key(f64::NAN, 0.0, 0.0)]).unwrap_err();
        assert_eq!(e, KeyError::NotFinite { index: 0 });
    }
}
