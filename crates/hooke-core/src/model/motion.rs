//! Pinned particles that follow keyframes (docs/physics.md §1.2).

use crate::keyframes::Keyframes;
use crate::particles::Vec3;

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
    use crate::keyframes::tests::key;

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
}
