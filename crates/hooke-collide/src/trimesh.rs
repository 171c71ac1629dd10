//! Triangle-mesh colliders on parry3d-f64: closed parts answer inside tests, every part
//! answers the crossing test so that a thin tabletop cannot be tunnelled through.

use crate::bounds::{boxes_meet, touch_reach};
use crate::convert::{from_parry, to_parry};
use crate::obj::{MeshError, MeshPart};
use crate::sharp::SharpEdges;
use crate::shells::{closedness_defect, outward};
use hooke_core::{Collider, Contact, Feature, Vec3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags};
use std::path::Path;

/// Crossings closer than this to the start of a step are the particle leaving a surface it
/// rests on, not a new crossing.
const CROSSING_EPSILON: f64 = 1e-9;
/// A particle stopped at a crossing is left this far on the side it came from, so the next
/// step's ray starts clear of the surface.
const CROSSING_STANDOFF: f64 = 1e-7;

#[derive(Clone, Debug)]
struct Part {
    mesh: ParryMesh,
    /// Whether the part is closed and consistently oriented (a solid).
    closed: bool,
    /// Bounds of the part, for a cheap rejection before parry's BVH query.
    aabb: Aabb,
    /// The edges a cloth can catch on, searched by their own boxes.
    sharp: SharpEdges,
}

/// A collider made of the objects of one OBJ file.
///
/// Closed parts are solids: a point inside gets the nearest surface point and the outward
/// normal there (from parry's pseudo-normals). A closed part that is inside out (its faces
/// wound clockwise seen from outside) is turned outward, shell by shell. Open parts are
/// thin sheets and only catch crossings. Every part catches crossings, so a fast particle
/// cannot tunnel through a thin closed part either.
#[derive(Clone, Debug)]
pub struct TriMeshCollider {
    label: String,
    parts: Vec<Part>,
}

impl TriMeshCollider {
    /// Builds a collider from mesh parts. With `require_closed`, an open part is an error.
    pub fn new(
        label: impl Into<String>,
        parts: Vec<MeshPart>,
        path: &Path,
        require_closed: bool,
    ) -> Result<Self, MeshError> {
        let flags =
            TriMeshFlags::MERGE_DUPLICATE_VERTICES | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES;
        Self::built(label.into(), parts, path, require_closed, flags)
    }

    /// A collider whose parts keep their vertices and triangles as given (no corner is
    /// merged, no triangle dropped; a closed shell's triangles may be turned outward), so
    /// that [`TriMeshCollider::locate`] names a part's own vertices: a mesh whose vertices
    /// move, built anew for each pose. The parts' corners must already be welded.
    pub(crate) fn exact(
        label: String,
        parts: Vec<MeshPart>,
        path: &Path,
    ) -> Result<Self, MeshError> {
        Self::built(label, parts, path, false, TriMeshFlags::empty())
    }

    fn built(
        label: String,
        parts: Vec<MeshPart>,
        path: &Path,
        require_closed: bool,
        base: TriMeshFlags,
    ) -> Result<Self, MeshError> {
        let mut built = Vec::with_capacity(parts.len());
        for part in parts {
            let defect = closedness_defect(&part.vertices, &part.triangles);
            if let (true, Some(detail)) = (require_closed, &defect) {
                return Err(MeshError::NotClosed {
                    path: path.to_path_buf(),
                    part: part.name,
                    detail: detail.clone(),
                });
            }
            let closed = defect.is_none();
            let count = part.vertices.len() as u32;
            if let Some(t) = part
                .triangles
                .iter()
                .find(|t| t.iter().any(|&i| i >= count))
            {
                return Err(MeshError::Build {
                    path: path.to_path_buf(),
                    part: part.name,
                    reason: format!("triangle {t:?} names a vertex beyond the {count} it has"),
                });
            }
            if !has_area(&part.vertices, &part.triangles) {
                return Err(MeshError::Build {
                    path: path.to_path_buf(),
                    part: part.name,
                    reason: format!(
                        "none of its {} triangle{} has an area (the vertices of each lie on a \
                         line or coincide): a collider needs a surface",
                        part.triangles.len(),
                        if part.triangles.len() == 1 { "" } else { "s" }
                    ),
                });
            }
            let mut flags = base;
            if closed {
                flags |= TriMeshFlags::ORIENTED;
            }
            let triangles = if closed {
                outward(&part.vertices, part.triangles)
            } else {
                part.triangles
            };
            let vertices = part.vertices.iter().map(to_parry).collect();
            let mesh = ParryMesh::with_flags(vertices, triangles, flags).map_err(|e| {
                MeshError::Build {
                    path: path.to_path_buf(),
                    part: part.name.clone(),
                    reason: e.to_string(),
                }
            })?;
            let aabb = mesh.local_aabb();
            let sharp = SharpEdges::of(&mesh, closed);
            built.push(Part {
                mesh,
                closed,
                aabb,
                sharp,
            });
        }
        Ok(Self {
            label,
            parts: built,
        })
    }

    /// The surface point nearest `p`: its part, the corners (the part's vertex indices)
    /// of the triangle it lies on and its barycentric weights there. `None` for a point
    /// that is not finite.
    pub(crate) fn locate(&self, p: &Vec3) -> Option<(usize, [u32; 3], [f64; 3])> {
        let q = to_parry(p);
        let mut best: Option<(f64, usize, [u32; 3], [f64; 3])> = None;
        for (k, part) in self.parts.iter().enumerate() {
            // A part's box farther than the best so far holds no nearer point.
            if best.is_some_and(|(d, ..)| part.aabb.distance_to_local_point(q, true) > d) {
                continue;
            }
            let (proj, (t, location)) = part.mesh.project_local_point_and_get_location(q, false);
            let d = (from_parry(proj.point) - p).norm();
            if !d.is_finite() || best.is_some_and(|(b, ..)| d >= b) {
                continue;
            }
            let corners = part.mesh.indices()[t as usize];
            let weights = location.barycentric_coordinates().unwrap_or([1.0 / 3.0; 3]);
            best = Some((d, k, corners, weights));
        }
        best.map(|(_, k, corners, weights)| (k, corners, weights))
    }

    /// Number of parts (objects).
    pub fn part_count(&self) -> usize {
        self.parts.len()
    }

    /// Whether every part is closed (a solid).
    pub fn is_closed(&self) -> bool {
        self.parts.iter().all(|p| p.closed)
    }

    /// All triangles of all parts in world coordinates, for drawing.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.parts
            .iter()
            .flat_map(|p| {
                let v = p.mesh.vertices();
                p.mesh
                    .indices()
                    .iter()
                    .map(move |t| t.map(|i| from_parry(v[i as usize])))
            })
            .collect()
    }
}

impl Part {
    /// Whether the box `lo..hi`, grown by `grow`, meets the part's bounds.
    fn meets(&self, lo: &Vec3, hi: &Vec3, grow: f64) -> bool {
        let (a, b) = (from_parry(self.aabb.mins), from_parry(self.aabb.maxs));
        boxes_meet(lo, hi, &a, &b, grow)
    }
}

fn in_aabb(aabb: &Aabb, p: &Vec3) -> bool {
    in_aabb_within(aabb, p, 0.0)
}

/// Whether `p` is within `margin` of the box.
fn in_aabb_within(aabb: &Aabb, p: &Vec3, margin: f64) -> bool {
    let (lo, hi) = (aabb.mins, aabb.maxs);
    lo.x - margin <= p.x
        && p.x <= hi.x + margin
        && lo.y - margin <= p.y
        && p.y <= hi.y + margin
        && lo.z - margin <= p.z
        && p.z <= hi.z + margin
}

impl Collider for TriMeshCollider {
    fn name(&self) -> String {
        self.label.clone()
    }

    /// The smallest side of the closed parts' bounding boxes: the table top's 4 cm for the
    /// shipped tables.
    fn thickness(&self) -> Option<f64> {
        self.parts
            .iter()
            .filter(|p| p.closed)
            .map(|p| {
                let e = p.aabb.maxs - p.aabb.mins;
                e.x.min(e.y).min(e.z)
            })
            .reduce(f64::min)
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        for part in self
            .parts
            .iter()
            .filter(|part| part.closed && in_aabb(&part.aabb, p))
        {
            let proj = part.mesh.project_local_point(to_parry(p), false);
            if !proj.is_inside {
                continue;
            }
            let point = from_parry(proj.point);
            let offset = point - p;
            let depth = offset.norm();
            if depth > 0.0 {
                sink(Contact {
                    depth,
                    normal: offset / depth,
                    point,
                });
            }
        }
    }

    /// Inside a solid part: to its nearest surface point and `margin` beyond. Outside any
    /// part (solid or sheet) but nearer than `margin` to it: away from its nearest point.
    /// Whether the box, grown by `margin` (and a little for rounding), meets the bounds of
    /// some part: every contact and crossing lies within a part's bounds.
    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        let grow = touch_reach(lo, hi, margin);
        self.parts.iter().any(|part| part.meets(lo, hi, grow))
    }

    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        if margin == 0.0 {
            return self.contacts(p, sink);
        }
        for part in self
            .parts
            .iter()
            .filter(|part| in_aabb_within(&part.aabb, p, margin))
        {
            // Only a point in a solid's box can be inside it; elsewhere only the shell of
            // width `margin` matters, which parry's bounded query answers without a full
            // projection.
            let proj = if part.closed && in_aabb(&part.aabb, p) {
                part.mesh.project_local_point(to_parry(p), false)
            } else {
                match part
                    .mesh
                    .project_local_point_with_max_dist(to_parry(p), false, margin)
                {
                    Some(proj) => proj,
                    None => continue,
                }
            };
            let point = from_parry(proj.point);
            let offset = point - p;
            let distance = offset.norm();
            if part.closed && proj.is_inside {
                if distance > 0.0 {
                    sink(Contact {
                        depth: distance + margin,
                        normal: offset / distance,
                        point,
                    });
                }
            } else if distance < margin && distance > 0.0 {
                sink(Contact {
                    depth: margin - distance,
                    normal: -offset / distance,
                    point,
                });
            }
        }
    }

    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        for part in &self.parts {
            if part.meets(lo, hi, 0.0) {
                part.sharp.within(lo, hi, sink);
            }
        }
    }

    fn has_features(&self) -> bool {
        self.parts.iter().any(|p| !p.sharp.is_empty())
    }

    fn crossing(&self, from: &Vec3, to: &Vec3) -> Option<Contact> {
        let dir = to - from;
        let length = dir.norm();
        if length <= CROSSING_EPSILON {
            return None;
        }
        let lo = from.inf(to);
        let hi = from.sup(to);
        let ray = Ray::new(to_parry(from), to_parry(&dir));
        let mut best: Option<(f64, Vec3)> = None;
        for part in &self.parts {
            if !part.meets(&lo, &hi, 0.0) {
                continue;
            }
            let Some(hit) = part.mesh.cast_local_ray_and_get_normal(&ray, 1.0, false) else {
                continue;
            };
            let normal = from_parry(hit.normal);
            let entering = normal.dot(&dir) < 0.0;
            // A closed part's normals point out, so only entering counts; an open sheet is
            // two-sided.
            if hit.time_of_impact * length <= CROSSING_EPSILON || (part.closed && !entering) {
                continue;
            }
            if best.is_none_or(|(t, _)| hit.time_of_impact < t) {
                let facing = if entering { normal } else { -normal };
                best = Some((hit.time_of_impact, facing));
            }
        }
        best.map(|(t, normal)| {
            let point = from + dir * t + normal * CROSSING_STANDOFF;
            Contact {
                depth: (point - to).dot(&normal),
                normal,
                point,
            }
        })
    }
}

/// Whether some triangle has an area that is not lost in rounding at the mesh's size.
fn has_area(vertices: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    let (lo, hi) = vertices.iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.inf(v), hi.sup(v)),
    );
    let size = (hi - lo).norm();
    triangles.iter().any(|t| {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        (b - a).cross(&(c - a)).norm() > 1e-12 * size * size
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shells::signed_volume;

    /// A unit cube from the origin, its faces wound outward, as two shells when `two`
    /// (the second 2 m along x).
    fn cubes(two: bool) -> MeshPart {
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for shift in if two { &[0.0, 2.0][..] } else { &[0.0][..] } {
            let base = vertices.len() as u32;
            for k in 0..8 {
                let c = |bit: u32| f64::from((k >> bit) & 1);
                vertices.push(Vec3::new(c(2) + shift, c(1), c(0)));
            }
            for q in crate::BOX_FACES {
                let q = q.map(|i| base + i as u32);
                triangles.push([q[0], q[1], q[2]]);
                triangles.push([q[0], q[2], q[3]]);
            }
        }
        MeshPart {
            name: "cubes".into(),
            vertices,
            triangles,
        }
    }

    /// An inside-out solid (every shell, or one of two) answers as the outward one does: a
    /// point above it is clear of it, and a point just under its top is pushed up through
    /// the top.
    #[test]
    fn an_inside_out_solid_is_turned_outward() {
        for two in [false, true] {
            let outward = cubes(two);
            assert!(signed_volume(&outward.vertices, &outward.triangles) > 0.0);
            let mut inverted = outward.clone();
            for t in &mut inverted.triangles {
                t.swap(1, 2);
            }
            let mut one_inverted = outward.clone();
            for t in &mut one_inverted.triangles[12..] {
                t.swap(1, 2);
            }
            let mut cases = vec![("outward", outward), ("inside out", inverted)];
            if two {
                cases.push(("one shell inside out", one_inverted));
            }
            for (name, part) in cases {
                let path = Path::new("cubes.obj");
                let collider = TriMeshCollider::new("cubes", vec![part], path, true).unwrap();
                for x in if two { &[0.5, 2.5][..] } else { &[0.5][..] } {
                    let mut above = Vec::new();
                    collider.contacts(&Vec3::new(*x, 1.5, 0.5), &mut |c| above.push(c));
                    assert!(above.is_empty(), "{name}, two {two}: a point above touches");
                    let mut under = Vec::new();
                    collider.contacts(&Vec3::new(*x, 0.9, 0.5), &mut |c| under.push(c));
                    assert_eq!(under.len(), 1, "{name}, two {two}: under the top");
                    let c = under[0];
                    assert!(
                        (c.depth - 0.1).abs() < 1e-12 && (c.normal - Vec3::y()).norm() < 1e-12,
                        "{name}, two {two}: depth {} normal {:?}",
                        c.depth,
                        c.normal
                    );
                }
            }
        }
    }
}
