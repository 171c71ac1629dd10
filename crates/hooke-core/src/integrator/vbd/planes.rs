//! Colliders as a particle sees them between detections: tangent planes.

use crate::particles::Vec3;

/// A collider's surface near a particle, as its tangent plane at the last detection: the
/// iterations measure the particle's gap to it as `normal · (x - point)`, exact for flat
/// faces and within the bound's reach of exact for curved ones, at the cost of a dot
/// product instead of a collider query.
#[derive(Clone, Copy, Debug)]
pub(super) struct Plane {
    pub(super) collider: u16,
    pub(super) point: Vec3,
    pub(super) normal: Vec3,
}

/// Planes a particle keeps at most (a box's corner and a table's edge need three).
const TOUCHES: usize = 4;

/// The collider planes one particle may touch, nearest kept when there are more.
#[derive(Clone, Copy, Debug)]
pub(super) struct Touches {
    pub(super) count: u8,
    planes: [Plane; TOUCHES],
    gaps: [f64; TOUCHES],
}

impl Default for Touches {
    fn default() -> Self {
        let none = Plane {
            collider: 0,
            point: Vec3::zeros(),
            normal: Vec3::zeros(),
        };
        Self {
            count: 0,
            planes: [none; TOUCHES],
            gaps: [f64::INFINITY; TOUCHES],
        }
    }
}

impl Touches {
    /// The planes.
    pub(super) fn planes(&self) -> &[Plane] {
        &self.planes[..self.count as usize]
    }

    /// Keeps `plane` at gap `d` if there is room or it is nearer than the farthest kept.
    pub(super) fn keep(&mut self, plane: Plane, d: f64) {
        let k = if (self.count as usize) < TOUCHES {
            self.count += 1;
            self.count as usize - 1
        } else {
            let (far, gap) =
                self.gaps
                    .iter()
                    .enumerate()
                    .fold(
                        (0, f64::NEG_INFINITY),
                        |a, (k, &g)| if g > a.1 { (k, g) } else { a },
                    );
            if d >= gap {
                return;
            }
            far
        };
        self.planes[k] = plane;
        self.gaps[k] = d;
    }
}
