//! Triangle-mesh colliders on parry3d-f64: closed parts answer inside tests, every part
//! answers the crossing test so that a thin tabletop cannot be tunnelled through.

use crate::obj::{MeshError, MeshPart};
use hooke_core::{Collider, Contact, Vec3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags};
use std::collections::HashMap;
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
}

/// A collider made of the objects of one OBJ file.
///
/// Closed parts are solids: a point inside gets the nearest surface point and the outward
/// normal there (from parry's pseudo-normals). Open parts are thin sheets and only catch
/// crossings. Every part catches crossings, so a fast particle cannot tunnel through a thin
/// closed part either.
#[derive(Clone, Debug)]
pub struct TriMeshCollider {
    label: String,
    parts: Vec<Part>,
}

fn to_parry(v: &Vec3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

fn from_parry(v: PVec) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// Why a part is not a closed, consistently oriented surface, if it is not: every directed
/// edge must appear once and its reverse once.
pub fn closedness_defect(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Option<String> {
    // Weld exactly equal positions: OBJ files repeat vertices per face group.
    let mut weld: HashMap<[u64; 3], u32> = HashMap::new();
    let ids: Vec<u32> = vertices
        .iter()
        .map(|v| {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            let next = weld.len() as u32;
            *weld.entry(key).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (ids[t[k] as usize], ids[t[(k + 1) % 3] as usize]);
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    let mut sorted: Vec<_> = edges.iter().collect();
    sorted.sort();
    for (&(a, b), &count) in sorted {
        if count > 1 {
            return Some(format!(
                "edge {a}-{b} is used {count} times in the same direction"
            ));
        }
        if !edges.contains_key(&(b, a)) {
            return Some(format!(
                "edge {a}-{b} has no opposite: the surface has a hole"
            ));
        }
    }
    None
}

impl TriMeshCollider {
    /// Builds a collider from mesh parts. With `require_closed`, an open part is an error.
    pub fn new(
        label: impl Into<String>,
        parts: Vec<MeshPart>,
        path: &Path,
        require_closed: bool,
    ) -> Result<Self, MeshError> {
        let label = label.into();
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
            let mut flags =
                TriMeshFlags::MERGE_DUPLICATE_VERTICES | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES;
            if closed {
                flags |= TriMeshFlags::ORIENTED;
            }
            let vertices = part.vertices.iter().map(to_parry).collect();
            let mesh = ParryMesh::with_flags(vertices, part.triangles, flags).map_err(|e| {
                MeshError::Build {
                    path: path.to_path_buf(),
                    part: part.name.clone(),
                    reason: e.to_string(),
                }
            })?;
            let aabb = mesh.local_aabb();
            built.push(Part { mesh, closed, aabb });
        }
        Ok(Self {
            label,
            parts: built,
        })
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

fn in_aabb(aabb: &Aabb, p: &Vec3) -> bool {
    let (lo, hi) = (aabb.mins, aabb.maxs);
    lo.x <= p.x && p.x <= hi.x && lo.y <= p.y && p.y <= hi.y && lo.z <= p.z && p.z <= hi.z
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
            let (a, b) = (part.aabb.mins, part.aabb.maxs);
            if hi.x < a.x || lo.x > b.x || hi.y < a.y || lo.y > b.y || hi.z < a.z || lo.z > b.z {
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
