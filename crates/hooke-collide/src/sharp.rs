//! A mesh's sharp edges, the features a cloth can catch on (docs/physics.md §2): found
//! once when the mesh is built, kept as segments in the order of the triangles that own
//! them, and searched by the segments' own boxes. A triangle's box is what parry's mesh
//! BVH holds, and a fan of long triangles (a round tabletop) puts dozens of boxes over any
//! point of the top: a cloth triangle asking for the rim's edges near it would visit them
//! all and be handed edges a metre away.

use crate::convert::{from_parry, to_parry};
use hooke_core::{Feature, Vec3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::shape::TriMesh as ParryMesh;
use std::cell::RefCell;
use std::collections::HashMap;

/// Two faces meeting at an edge count as one flat surface when the far corner of one lies
/// within this fraction of the edge's length of the other's plane (an angle under about
/// 0.06°): the diagonals of a flat top are no edges a cloth can catch on.
const FLAT_TOLERANCE: f64 = 1e-3;

/// Which edges of a mesh a cloth can catch on, as a bit mask per triangle: boundary edges,
/// edges of three or more faces, and edges between two faces at an angle, where for a solid
/// only convex edges count (a concave valley cannot poke through a sheet whose corners are
/// outside). Each edge is owned by the lowest triangle that has it, so it is reported once.
fn feature_edges(mesh: &ParryMesh, closed: bool) -> Vec<u8> {
    let v = mesh.vertices();
    let idx = mesh.indices();
    let mut by_edge: HashMap<(u32, u32), Vec<(u32, u8)>> = HashMap::new();
    for (t, tri) in idx.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push((t as u32, k as u8));
        }
    }
    let mut mask = vec![0u8; idx.len()];
    for (&(a, b), faces) in &by_edge {
        let sharp = match faces.as_slice() {
            [(t1, _), (t2, _)] => {
                let corner = |t: u32, skip: [u32; 2]| {
                    idx[t as usize]
                        .into_iter()
                        .find(|i| !skip.contains(i))
                        .map(|i| from_parry(v[i as usize]))
                };
                let tri = idx[*t1 as usize].map(|i| from_parry(v[i as usize]));
                let normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
                let (pa, pb) = (from_parry(v[a as usize]), from_parry(v[b as usize]));
                let length = (pb - pa).norm();
                match (normal.try_normalize(0.0), corner(*t2, [a, b])) {
                    (Some(n), Some(far)) => {
                        let height = (far - pa).dot(&n);
                        // For a solid with outward normals, the far corner below the first
                        // face's plane makes the edge convex.
                        height.abs() > FLAT_TOLERANCE * length && (!closed || height < 0.0)
                    }
                    _ => true,
                }
            }
            _ => true,
        };
        if sharp {
            let &(t, k) = faces.iter().min().expect("an edge has a face");
            mask[t as usize] |= 1 << k;
        }
    }
    mask
}

/// A mesh part's sharp edges and their search.
#[derive(Clone, Debug)]
pub(crate) struct SharpEdges {
    /// The edges' ends, by the triangle that owns each, then its edge `k → k+1`: the order
    /// the features go out in, fixed by the mesh alone.
    segments: Vec<[Vec3; 2]>,
    /// Over the segments' boxes (leaf `s` is `segments[s]`).
    bvh: Bvh,
}

thread_local! {
    /// The segments a query found, kept per thread so that a query allocates nothing once
    /// it has grown (block descent asks once per cloth triangle per detection).
    static FOUND: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

impl SharpEdges {
    /// The sharp edges of `mesh` (see [`feature_edges`]).
    pub(crate) fn of(mesh: &ParryMesh, closed: bool) -> Self {
        let v = mesh.vertices();
        let mut segments = Vec::new();
        for (mask, tri) in feature_edges(mesh, closed).into_iter().zip(mesh.indices()) {
            for k in 0..3 {
                if mask & (1 << k) != 0 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    segments.push([from_parry(v[a as usize]), from_parry(v[b as usize])]);
                }
            }
        }
        let boxes: Vec<Aabb> = segments
            .iter()
            .map(|[a, b]| Aabb::new(to_parry(&a.inf(b)), to_parry(&a.sup(b))))
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
        Self { segments, bvh }
    }

    /// Whether the mesh has no sharp edge.
    pub(crate) fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// Calls `sink` with every sharp edge whose box meets `lo..hi` (boundaries included),
    /// in the edges' order.
    pub(crate) fn within(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        if self.is_empty() {
            return;
        }
        let query = Aabb::new(to_parry(lo), to_parry(hi));
        // Taken out of the thread's slot, not borrowed, so that a sink that asks again
        // (none does) finds an empty buffer instead of a borrow error.
        let mut found = FOUND.take();
        found.clear();
        found.extend(self.bvh.intersect_aabb(&query));
        // The BVH's order is its own; the edges go out in theirs.
        found.sort_unstable();
        for &s in &found {
            sink(Feature::Segment(self.segments[s as usize]));
        }
        FOUND.set(found);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::obj::{Placement, parse_obj};
    use parry3d_f64::shape::TriMeshFlags;

    /// The round table's top and pedestal as parry holds them.
    fn table() -> ParryMesh {
        let obj = crate::table::round_table_obj();
        let parts = parse_obj(
            &obj,
            std::path::Path::new("table.obj"),
            &Placement::default(),
        )
        .expect("the shipped table reads");
        let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
        for part in parts {
            let base = vertices.len() as u32;
            vertices.extend(part.vertices.iter().map(to_parry));
            triangles.extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        ParryMesh::with_flags(vertices, triangles, TriMeshFlags::MERGE_DUPLICATE_VERTICES)
            .expect("the shipped table builds")
    }

    /// Boxes of every size over the table hand out exactly the sharp edges that meet them,
    /// in the edges' own order (their owning triangles'): what testing every edge gives.
    #[test]
    fn a_query_finds_exactly_the_edges_that_meet_its_box_in_triangle_order() {
        let mesh = table();
        let sharp = SharpEdges::of(&mesh, false);
        let all = &sharp.segments;
        // The rim's circle and the pedestal: edges to find, and far more of them than any
        // small box meets.
        assert!(all.len() > 100, "{} sharp edges", all.len());
        let mut state = 7u64;
        let mut unit = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut met, mut queries) = (0usize, 0usize);
        for _ in 0..2000 {
            let centre = Vec3::new(1.6 * unit() - 0.8, 1.2 * unit(), 1.6 * unit() - 0.8);
            let half = Vec3::repeat(0.002 + 0.2 * unit().powi(3));
            let (lo, hi) = (centre - half, centre + half);
            let want: Vec<[Vec3; 2]> = all
                .iter()
                .filter(|[a, b]| {
                    let (slo, shi) = (a.inf(b), a.sup(b));
                    (0..3).all(|k| slo[k] <= hi[k] && lo[k] <= shi[k])
                })
                .copied()
                .collect();
            let mut got = Vec::new();
            sharp.within(&lo, &hi, &mut |f| match f {
                Feature::Segment(s) => got.push(s),
                other => panic!("a mesh's feature is a segment, not {other:?}"),
            });
            assert_eq!(got, want, "box {lo:?}..{hi:?}");
            met += usize::from(!want.is_empty());
            queries += 1;
        }
        // The boxes sample both the rim and the open top.
        assert!(
            met > 50 && met < queries - 50,
            "{met} of {queries} boxes met an edge"
        );
    }
}
