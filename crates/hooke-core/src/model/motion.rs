//! Keyframed motion (docs/physics.md §1.2): poses given at times, and pinned particles that
//! follow them.

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

/// Pinned particles moved rigidly by keys about their centroid at the start: particle `k`
/// is at `c + T(t) + R(t) (x_k - c)`, with `x_k` where it started and `c` their centroid.
#[derive(Clone, Debug, PartialEq)]
pub struct PinMotion {
    /// The particles moved (pinned ones), by index in the system.
    pub particles: Vec<u32>,
    /// Their centroid at the start.
    pub centre: Vec3,
    /// Each particle's start position less the centroid.
    pub offsets: Vec<Vec3>,
    /// The motion.
    pub keys: Keyframes,
}

impl PinMotion {
    /// The motion of `particles`, which start at `x[particles[k]]`.
    pub fn new(particles: Vec<u32>, x: &[Vec3], keys: Keyframes) -> Self {
        let n = particles.len().max(1) as f64;
        let centre = particles.iter().map(|&i| x[i as usize]).sum::<Vec3>() / n;
        let offsets = particles.iter().map(|&i| x[i as usize] - centre).collect();
        Self {
            particles,
            centre,
            offsets,
            keys,
        }
    }

    /// Where each particle is at time `t`, in the order of [`PinMotion::particles`].
    pub fn positions(&self, t: f64) -> impl Iterator<Item = (usize, Vec3)> + '_ {
        let (rotation, translate) = self.keys.pose(t);
        self.particles
            .iter()
            .zip(&self.offsets)
            .map(move |(&i, o)| (i as usize, self.centre + translate + rotation * o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(t: f64, x: f64, rz: f64) -> Key {
        Key {
            t,
            translate: Vec3::new(x, 0.0, 0.0),
            rotate: Vec3::new(0.0, 0.0, rz),
        }
    }

    /// Between keys the pose is linear; before the first and after the last it holds.
    #[test]
    fn poses_interpolate_linearly_and_hold_outside_the_keys() {
        let k = Keyframes::new(vec![key(1.0, 0.0, 0.0), key(3.0, 2.0, 90.0)]).unwrap();
        assert_eq!(k.at(0.0), (Vec3::zeros(), Vec3::zeros()));
        assert_eq!(
            k.at(2.0),
            (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 45.0))
        );
        assert_eq!(
            k.at(9.0),
            (Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 90.0))
        );
        let m = PinMotion::new(
            vec![0, 1],
            &[Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)],
            k,
        );
        let at: Vec<(usize, Vec3)> = m.positions(3.0).collect();
        // Turned 90° about z around their centroid, then moved 2 m along x.
        assert!(
            (at[0].1 - Vec3::new(2.0, -1.0, 0.0)).norm() < 1e-12,
            "{:?}",
            at[0]
        );
        assert!(
            (at[1].1 - Vec3::new(2.0, 1.0, 0.0)).norm() < 1e-12,
            "{:?}",
            at[1]
        );
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
