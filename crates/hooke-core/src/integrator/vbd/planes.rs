//! Colliders as a particle sees them between detections: tangent planes, gathered per
//! particle at a detection and kept in [`Lists`].

use crate::particles::Vec3;

/// A collider's surface near a particle, as its tangent plane at the last detection: the
/// iterations measure the particle's gap to it as `normal · (x - point)`, exact for flat
/// faces and within the bound's reach of exact for curved ones, at the cost of a dot
/// product instead of a collider query.
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) struct Plane {
    pub(in crate::integrator) collider: u16,
    pub(in crate::integrator) point: Vec3,
    pub(in crate::integrator) normal: Vec3,
}

/// Planes a particle keeps at most (a box's corner and a table's edge need three).
const TOUCHES: usize = 4;

/// The collider planes one particle may touch, nearest kept when there are more.
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) struct Touches {
    count: u8,
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
    pub(in crate::integrator) fn planes(&self) -> &[Plane] {
        &self.planes[..self.count as usize]
    }

    /// Keeps `plane` at gap `d` if there is room or it is nearer than the farthest kept.
    pub(in crate::integrator) fn keep(&mut self, plane: Plane, d: f64) {
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

/// Half-space colliders a particle keeps at most (ground and an inclined plane); further
/// ones bound it with its ball, as any collider does.
const HALF_SPACES: usize = 2;

/// The half-space colliders (infinite planes) near one particle at the last detection, with
/// its gap to each. Between detections the particle may move anywhere that keeps
/// `normal · (x - point)` above `(1 - γ)` of that gap: sliding along a plane closes no gap,
/// so only the motion along its normal is bounded (docs/physics.md §4.1).
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::integrator) struct HalfSpaces {
    count: u8,
    planes: [(Vec3, Vec3, f64); HALF_SPACES],
}

impl HalfSpaces {
    /// Keeps the plane through `point` with unit `normal` at gap `d`; `false` when full.
    pub(in crate::integrator) fn keep(&mut self, point: Vec3, normal: Vec3, d: f64) -> bool {
        if self.count as usize == HALF_SPACES {
            return false;
        }
        self.planes[self.count as usize] = (point, normal, d);
        self.count += 1;
        true
    }

    /// `(point, normal, gap)` of each plane kept.
    pub(in crate::integrator) fn planes(&self) -> &[(Vec3, Vec3, f64)] {
        &self.planes[..self.count as usize]
    }
}

/// A list per particle, end to end in one array: most particles touch no collider, and a
/// fixed room for the most any may keep took 380 bytes a particle (6 MB on the 128² cloth).
#[derive(Clone, Debug)]
pub(in crate::integrator) struct Lists<T> {
    /// List `i` is `items[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T> Default for Lists<T> {
    fn default() -> Self {
        Self {
            start: vec![0],
            items: Vec::new(),
        }
    }
}

impl<T: Copy> Lists<T> {
    /// List `i`.
    #[inline]
    pub(in crate::integrator) fn of(&self, i: usize) -> &[T] {
        &self.items[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Whether list `i` is empty.
    #[inline]
    pub(in crate::integrator) fn is_empty_at(&self, i: usize) -> bool {
        self.start[i] == self.start[i + 1]
    }

    /// No lists.
    pub(in crate::integrator) fn clear(&mut self) {
        self.start.clear();
        self.start.push(0);
        self.items.clear();
    }

    /// Appends `list` as the next one.
    pub(in crate::integrator) fn push(&mut self, list: &[T]) {
        self.items.extend_from_slice(list);
        self.start.push(self.items.len() as u32);
    }

    /// Appends `other`'s lists after these, in their order.
    pub(in crate::integrator) fn append(&mut self, other: &Self) {
        let base = self.items.len() as u32;
        self.items.extend_from_slice(&other.items);
        self.start.extend(other.start[1..].iter().map(|s| base + s));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lists pushed one by one, or in two runs appended, read back as they were given,
    /// empty ones included: what the detection's chunks rely on.
    #[test]
    fn lists_appended_in_parts_read_as_pushed() {
        let given: [&[u32]; 5] = [&[], &[7, 8], &[], &[1], &[4, 5, 6]];
        let mut whole = Lists::default();
        for list in given {
            whole.push(list);
        }
        let (mut first, mut second) = (Lists::default(), Lists::default());
        for list in &given[..2] {
            first.push(list);
        }
        for list in &given[2..] {
            second.push(list);
        }
        let mut joined = Lists::default();
        joined.append(&first);
        joined.append(&second);
        for (i, list) in given.iter().enumerate() {
            assert_eq!(whole.of(i), *list);
            assert_eq!(joined.of(i), *list);
            assert_eq!(joined.is_empty_at(i), list.is_empty());
        }
        joined.clear();
        joined.push(&[3]);
        assert_eq!(joined.of(0), &[3]);
    }
}
