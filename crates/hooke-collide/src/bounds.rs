//! Box tests the shapes share for their cheap rejections.

use hooke_core::Vec3;

/// Whether the box `lo..hi`, grown by `grow` on every side, meets the box `a..b`. NaN
/// bounds answer `true`.
pub(crate) fn boxes_meet(lo: &Vec3, hi: &Vec3, a: &Vec3, b: &Vec3, grow: f64) -> bool {
    !(0..3).any(|k| hi[k] + grow < a[k] || lo[k] - grow > b[k])
}

/// How far `Collider::may_touch` grows the box `lo..hi` for `margin`: the margin and a
/// little for the rounding of coordinates as large as the box's, so that its promise holds
/// against the contact tests' own arithmetic.
pub(crate) fn touch_reach(lo: &Vec3, hi: &Vec3, margin: f64) -> f64 {
    margin + 1e-9 + 1e-9 * lo.amax().max(hi.amax())
}
