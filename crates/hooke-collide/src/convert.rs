//! Points between Hooke's vectors (nalgebra) and parry's (glam), for the meshes' queries.

use hooke_core::Vec3;
use parry3d_f64::math::Vector as PVec;

/// `v` as parry holds a point.
pub(crate) fn to_parry(v: &Vec3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

/// A point parry gave back, as Hooke's vector.
pub(crate) fn from_parry(v: PVec) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}
