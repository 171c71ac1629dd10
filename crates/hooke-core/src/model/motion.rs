//! Pinned particles that follow keyframes or a vertex cache (docs/physics.md §1.2).

use crate::keyframes::Keyframes;
use crate::particles::Vec3;

/// How pinned particles move: rigidly by keys, or each along its own sampled path.
#[derive(Clone, Debug, PartialEq)]
pub enum PinPath {
    /// Moved rigidly by keys about their centroid at the start: particle `k` is at
    /// `c + T(t) + R(t) (x_k - c)`, with `x_k` where it started and `c` their centroid.
    Keys {
        /// Their centroid at the start.
        centre: Vec3,
        /// Each particle's start position less the centroid.
        offsets: Vec<Vec3>,
        /// The motion.
        keys: Keyframes,
    },
    /// Each particle at its own target, sampled at even times (a vertex cache): on the
    /// straight line between samples, held before the first and after the last.
    Track {
        /// Per sample, each particle's target, in the order of [`PinMotion::particles`].
        samples: Vec<Vec<Vec3>>,
        /// Seconds between samples.
        interval: f64,
    },
}

/// A motion's state at one time, found once for all its particles.
enum At<'a> {
    /// The keys' pose, and the particles' centre and offsets from it.
    Keys {
        rotation: nalgebra::Rotation3<f64>,
        translate: Vec3,
        centre: Vec3,
        offsets: &'a [Vec3],
    },
    /// The samples before and after, and the weight of the one after.
    Track(&'a [Vec3], &'a [Vec3], f64),
}

impl<'a> At<'a> {
    fn of(path: &'a PinPath, t: f64) -> Self {
        match path {
            PinPath::Keys {
                centre,
                offsets,
                keys,
            } => {
                let (rotation, translate) = keys.pose(t);
                At::Keys {
                    rotation,
                    translate,
                    centre: *centre,
                    offsets,
                }
            }
            PinPath::Track { samples, interval } => {
                let last = samples.len() - 1;
                let s = (t / interval).clamp(0.0, last as f64);
                let k = (s.floor() as usize).min(last);
                if k == last {
                    At::Track(&samples[k], &samples[k], 0.0)
                } else {
                    At::Track(&samples[k], &samples[k + 1], s - k as f64)
                }
            }
        }
    }

    /// Where particle `j` of the motion is.
    fn position(&self, j: usize) -> Vec3 {
        match self {
            At::Keys {
                rotation,
                translate,
                centre,
                offsets,
            } => centre + translate + rotation * offsets[j],
            At::Track(a, b, w) => {
                if *w == 0.0 {
                    a[j]
                } else {
                    a[j] + (b[j] - a[j]) * *w
                }
            }
        }
    }
}

/// Pinned particles that follow a motion (docs/physics.md §1.2).
#[derive(Clone, Debug, PartialEq)]
pub struct PinMotion {
    /// The particles moved (pinned ones), by index in the system.
    pub particles: Vec<u32>,
    /// How they move.
    pub path: PinPath,
}

impl PinMotion {
    /// The rigid motion by `keys` of `particles`, which start at `x[particles[k]]`.
    pub fn new(particles: Vec<u32>, x: &[Vec3], keys: Keyframes) -> Self {
        let n = particles.len().max(1) as f64;
        let centre = particles.iter().map(|&i| x[i as usize]).sum::<Vec3>() / n;
        let offsets = particles.iter().map(|&i| x[i as usize] - centre).collect();
        Self {
            particles,
            path: PinPath::Keys {
                centre,
                offsets,
                keys,
            },
        }
    }

    /// `particles` each following its own targets, `samples[k][j]` the target of
    /// `particles[j]` at `k · interval` seconds.
    pub fn track(particles: Vec<u32>, samples: Vec<Vec<Vec3>>, interval: f64) -> Self {
        Self {
            particles,
            path: PinPath::Track { samples, interval },
        }
    }

    /// Where each particle is at time `t`, in the order of [`PinMotion::particles`].
    pub fn positions(&self, t: f64) -> impl Iterator<Item = (usize, Vec3)> + '_ {
        let at = At::of(&self.path, t);
        self.particles
            .iter()
            .enumerate()
            .map(move |(j, &i)| (i as usize, at.position(j)))
    }

    /// The times at which the motion turns (its keys or samples), in order.
    pub fn times(&self) -> Vec<f64> {
        match &self.path {
            PinPath::Keys { keys, .. } => keys.keys().iter().map(|k| k.t).collect(),
            PinPath::Track { samples, interval } => {
                (0..samples.len()).map(|k| interval * k as f64).collect()
            }
        }
    }

    /// The fastest any of the particles moves, m/s (for keys a bound: the translation's
    /// speed plus the turn's rate, radians summed over the axes, times the farthest
    /// particle's distance from the centre).
    pub fn speed(&self) -> f64 {
        match &self.path {
            PinPath::Keys { offsets, keys, .. } => {
                let reach = offsets.iter().map(|o| o.norm()).fold(0.0, f64::max);
                keys.keys()
                    .windows(2)
                    .map(|w| {
                        let turn = (w[1].rotate - w[0].rotate).map(f64::to_radians).abs().sum();
                        ((w[1].translate - w[0].translate).norm() + turn * reach)
                            / (w[1].t - w[0].t)
                    })
                    .fold(0.0, f64::max)
            }
            PinPath::Track { samples, interval } => {
                samples
                    .windows(2)
                    .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| (b - a).norm()))
                    .fold(0.0, f64::max)
                    / interval
            }
        }
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

    #[test]
    fn a_track_moves_each_pin_on_its_own_line_and_holds_outside() {
        let samples = vec![
            vec![Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)],
            vec![Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 2.0)],
        ];
        let m = PinMotion::track(vec![4, 7], samples, 0.5);
        let at: Vec<(usize, Vec3)> = m.positions(0.25).collect();
        assert_eq!(
            at,
            vec![(4, Vec3::new(0.0, 0.5, 0.0)), (7, Vec3::new(1.0, 0.0, 1.0))]
        );
        assert_eq!(m.positions(9.0).nth(1), Some((7, Vec3::new(1.0, 0.0, 2.0))));
        assert_eq!(m.positions(-1.0).next(), Some((4, Vec3::zeros())));
        assert_eq!(m.speed(), 4.0);
        assert_eq!(m.times(), vec![0.0, 0.5]);
    }
}
