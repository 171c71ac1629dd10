//! The surfaces' primitives as block descent's detection sees them: the active surfaces'
//! triangles and edges, which surface each particle belongs to, the thickness each keeps,
//! and which triangle owns each shared edge and corner (so a pair is counted once).

use crate::collider::response::Response;
use crate::contact::exclusion::{Exclusion, Surfaces};
use crate::model::Model;
use crate::particles::Vec3;

/// The surfaces' primitives, fixed for a model.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Topology {
    pub(in crate::integrator) built_for: usize,
    /// Active surfaces' triangles and edges, with their surface's index.
    pub(in crate::integrator) triangles: Vec<([u32; 3], u16)>,
    pub(in crate::integrator) edges: Vec<([u32; 2], u16)>,
    /// Per particle: its active surface, or `u16::MAX`.
    pub(in crate::integrator) surface: Vec<u16>,
    /// Whether any surface pair (self or between bodies) can touch.
    pub(in crate::integrator) self_pairs: bool,
    /// Per surface of the model: whether it collides with itself.
    self_collision: Vec<bool>,
    /// The thickness particles outside every active surface keep from velocity-level
    /// colliders ([`Model::point_thickness`]).
    pub(in crate::integrator) point: f64,
    /// Per triangle: which of its edges (bits 0..3: ab, bc, ca) and corners (bits 3..6)
    /// it owns, being the first triangle of its surface to have them.
    pub(in crate::integrator) owns: Vec<u8>,
}

impl Topology {
    /// The thickness particle `i` keeps: its active surface's, zero outside every one.
    pub(in crate::integrator) fn margin(&self, model: &Model, i: usize) -> f64 {
        match self.surface[i] {
            u16::MAX => 0.0,
            s => model.surfaces[s as usize].thickness,
        }
    }

    /// The thickness particle `i` keeps from the colliders that bound it (velocity-level
    /// ones): its surface's, or the point thickness outside every active surface.
    pub(in crate::integrator) fn contact_margin(&self, model: &Model, i: usize) -> f64 {
        match self.surface[i] {
            u16::MAX => self.point,
            s => model.surfaces[s as usize].thickness,
        }
    }

    /// The thickness particle `i` keeps from a collider answering with `response`: its
    /// surface's from a penalty wall (the course's force field, which it may enter), and
    /// at least the point thickness from the others.
    pub(in crate::integrator) fn keeps(&self, model: &Model, i: usize, response: &Response) -> f64 {
        match response {
            Response::Penalty { .. } => self.margin(model, i),
            _ => self.contact_margin(model, i),
        }
    }

    pub(in crate::integrator) fn new(model: &Model, n: usize) -> Self {
        let mut t = Self {
            built_for: n,
            surface: vec![u16::MAX; n],
            point: model.point_thickness(),
            ..Self::default()
        };
        let active: Vec<_> = model.active_surfaces().collect();
        for &(k, s) in &active {
            for p in s.particles.clone() {
                t.surface[p] = k as u16;
            }
            t.triangles
                .extend(s.triangles.iter().map(|&tri| (tri, k as u16)));
            t.edges.extend(s.edges().into_iter().map(|e| (e, k as u16)));
        }
        t.self_pairs = model.surfaces_touch();
        t.self_collision = model.surfaces.iter().map(|s| s.self_collision).collect();
        let mut edges = std::collections::HashSet::new();
        let mut corners = vec![false; n];
        t.owns = t
            .triangles
            .iter()
            .map(|([a, b, c], _)| {
                let mut mask = 0u8;
                for (k, (u, v)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
                    if edges.insert((*u.min(v), *u.max(v))) {
                        mask |= 1 << k;
                    }
                }
                for (k, v) in [a, b, c].into_iter().enumerate() {
                    if !std::mem::replace(&mut corners[*v as usize], true) {
                        mask |= 1 << (3 + k);
                    }
                }
                mask
            })
            .collect();
        t
    }
}

impl Topology {
    /// The pairs of these surfaces that their own structure holds apart, from the rest
    /// positions `rest` with radius `radius` and, for pairs one edge apart, `near`
    /// (`crate::contact::exclusion`).
    pub(in crate::integrator) fn exclusion(
        &self,
        rest: &[Vec3],
        (radius, near): (f64, f64),
        pinned: &(dyn Fn(u32) -> bool + Sync),
    ) -> Exclusion {
        let triangles: Vec<[u32; 3]> = self.triangles.iter().map(|t| t.0).collect();
        let edges: Vec<[u32; 2]> = self.edges.iter().map(|e| e.0).collect();
        let surfaces = Surfaces {
            triangles: &triangles,
            edges: &edges,
            self_colliding: &|v| {
                let k = self.surface[v as usize];
                k != u16::MAX && self.self_collision[k as usize]
            },
            self_pairs: self.self_pairs,
        };
        Exclusion::new(&surfaces, rest, (radius, near), pinned)
    }
}
