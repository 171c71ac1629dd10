//! A force field sampled on a regular grid over `[-2, 2]^3` (docs/physics.md §1, the jello course).

use crate::particles::Vec3;

/// Half the side of the cube the field covers, in metres.
pub(crate) const FIELD_HALF_EXTENT: f64 = 2.0;

/// `r × r × r` force vectors (newtons, not accelerations) on the nodes of a grid over
/// `[-2, 2]^3`, interpolated trilinearly; points outside are clamped to the box first.
///
/// Node `(a, b, c)` sits at `-2 + 4 (a, b, c) / (r - 1)` and is stored at `a r² + b r + c`.
///
/// ```
/// use hooke_core::{ForceField, Vec3};
/// let field = ForceField::new(1, vec![Vec3::new(0.0, -1.0, 0.0)]).unwrap();
/// assert_eq!(field.sample(&Vec3::new(5.0, 0.0, 0.0)), Vec3::new(0.0, -1.0, 0.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ForceField {
    resolution: usize,
    values: Vec<Vec3>,
    /// Node spacing and its inverse, computed once: [`ForceField::sample`] runs per particle
    /// per force evaluation, and two divisions there cost as much as the interpolation.
    h: f64,
    inv_h: f64,
}

impl ForceField {
    /// A field of resolution `r` with `r³` values in file order; `None` if the count is wrong
    /// or `r` is zero (a zero-resolution world simply has no field).
    pub fn new(resolution: usize, values: Vec<Vec3>) -> Option<Self> {
        let expected = resolution
            .checked_mul(resolution)?
            .checked_mul(resolution)?;
        let cells = resolution.saturating_sub(1).max(1) as f64;
        (resolution > 0 && values.len() == expected).then_some(Self {
            resolution,
            values,
            h: 2.0 * FIELD_HALF_EXTENT / cells,
            inv_h: cells / (2.0 * FIELD_HALF_EXTENT),
        })
    }

    /// Grid resolution `r`.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// Whether every node value is zero: such a field exerts no force anywhere.
    pub fn is_zero(&self) -> bool {
        self.values.iter().all(|v| *v == Vec3::zeros())
    }

    /// The node values in file order.
    pub fn values(&self) -> &[Vec3] {
        &self.values
    }

    /// The interpolated force at `p`.
    pub fn sample(&self, p: &Vec3) -> Vec3 {
        let r = self.resolution;
        if r == 1 {
            return self.values[0];
        }
        let (h, inv_h) = (self.h, self.inv_h);
        // Cell index and fraction along one axis, with the point clamped to the box and the
        // last node folded into the last cell so that `index + 1` stays on the grid.
        let axis = |x: f64| -> (usize, f64) {
            let x = x.clamp(-FIELD_HALF_EXTENT, FIELD_HALF_EXTENT);
            let cell = (((x + FIELD_HALF_EXTENT) * inv_h) as usize).min(r - 2);
            let t = (x - (-FIELD_HALF_EXTENT + cell as f64 * h)) * inv_h;
            (cell, t)
        };
        let (a, tx) = axis(p.x);
        let (b, ty) = axis(p.y);
        let (c, tz) = axis(p.z);
        let at = |da: usize, db: usize, dc: usize| {
            self.values[(a + da) * r * r + (b + db) * r + (c + dc)]
        };
        let lerp = |u: Vec3, w: Vec3, t: f64| u * (1.0 - t) + w * t;
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), tx);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), tx);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), tx);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), tx);
        let y0 = lerp(x00, x10, ty);
        let y1 = lerp(x01, x11, ty);
        lerp(y0, y1, tz)
    }
}
