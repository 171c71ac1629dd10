//! The inside of an axis-aligned box as the free space: the jello course's bounding box.

use hooke_core::{Collider, Contact, Vec3};

/// The six faces of an axis-aligned box as quads of corner numbers, counter-clockwise seen
/// from outside. Corner `k` takes x from bit 2 of `k`, y from bit 1 and z from bit 0 (`0` is
/// the low corner, `7` the high one).
pub const BOX_FACES: [[usize; 4]; 6] = [
    [0, 1, 3, 2],
    [4, 6, 7, 5],
    [0, 4, 5, 1],
    [2, 3, 7, 6],
    [0, 2, 6, 4],
    [1, 5, 7, 3],
];

/// Particles must stay inside `[min, max]`; every coordinate strictly beyond a face is a
/// violation of that face, with the excess as depth and the normal pointing into the box.
/// A corner violates up to three faces at once and reports each (docs/physics.md §1: each violated face
/// adds its own penalty term).
///
/// ```
/// use hooke_collide::BoxInterior;
/// use hooke_core::{Collider, Vec3};
/// let room = BoxInterior::jello();
/// let mut faces = 0;
/// room.contacts(&Vec3::new(2.5, -2.25, 0.0), &mut |_| faces += 1);
/// assert_eq!(faces, 2);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxInterior {
    /// Lower corner, metres.
    pub min: Vec3,
    /// Upper corner, metres.
    pub max: Vec3,
}

impl BoxInterior {
    /// The jello course's box `[-2, 2]^3`.
    pub fn jello() -> Self {
        Self {
            min: Vec3::repeat(-2.0),
            max: Vec3::repeat(2.0),
        }
    }

    /// Whether `p` is at least `margin` inside every face, so that it has no contact: a
    /// branch-free test that spares the particles well inside (nearly all of them, every
    /// force evaluation of a jello world) the per-face loop. NaN fails it.
    #[inline]
    fn clear(&self, p: &Vec3, margin: f64) -> bool {
        // `max - p` is the exact negation of the face loop's `(p - max) * -1`.
        let mut clear = true;
        for axis in 0..3 {
            clear &= (p[axis] - self.min[axis] >= margin) & (self.max[axis] - p[axis] >= margin);
        }
        clear
    }
}

impl Collider for BoxInterior {
    fn name(&self) -> String {
        "box".to_string()
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        if self.clear(p, 0.0) {
            return;
        }
        for axis in 0..3 {
            let mut normal = Vec3::zeros();
            if p[axis] < self.min[axis] {
                normal[axis] = 1.0;
                let mut point = *p;
                point[axis] = self.min[axis];
                sink(Contact {
                    depth: self.min[axis] - p[axis],
                    normal,
                    point,
                });
            } else if p[axis] > self.max[axis] {
                normal[axis] = -1.0;
                let mut point = *p;
                point[axis] = self.max[axis];
                sink(Contact {
                    depth: p[axis] - self.max[axis],
                    normal,
                    point,
                });
            }
        }
    }

    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        // Every particle in the box is at least as far inside each face as its corner
        // nearest that face. NaN bounds fail `clear`.
        !(self.clear(lo, margin) && self.clear(hi, margin))
    }

    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        if margin == 0.0 {
            return self.contacts(p, sink);
        }
        if self.clear(p, margin) {
            return;
        }
        for axis in 0..3 {
            for (face, inward) in [(self.min[axis], 1.0), (self.max[axis], -1.0)] {
                let distance = (p[axis] - face) * inward;
                if distance < margin {
                    let mut normal = Vec3::zeros();
                    normal[axis] = inward;
                    let mut point = *p;
                    point[axis] = face;
                    sink(Contact {
                        depth: margin - distance,
                        normal,
                        point,
                    });
                }
            }
        }
    }
}
