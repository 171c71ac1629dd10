//! The force loop: every spring's force in batches, added into a partition's window.
//!
//! This is the code [`super::Kernel`] compiles once per instruction set; the layout it reads
//! (sorted end pairs, indexed rest lengths, a `(ks, kd)` table) is built by
//! [`crate::assembly::Assembly`].

use crate::forces::spring::SpringBatch;
use crate::particles::Vec3;
use std::ops::Range;

/// Where the force loop reads a batch's rest lengths.
pub(crate) trait RestLookup: Copy + Send + Sync {
    /// The rest length of the `l`-th spring of the slice.
    fn rest(self, l: usize) -> f64;
    /// Springs `range` of the slice.
    fn slice(self, range: Range<usize>) -> Self;
}

impl RestLookup for &[f64] {
    #[inline(always)]
    fn rest(self, l: usize) -> f64 {
        self[l]
    }
    #[inline(always)]
    fn slice(self, range: Range<usize>) -> Self {
        &self[range]
    }
}

impl RestLookup for (&[u16], &[f64]) {
    #[inline(always)]
    fn rest(self, l: usize) -> f64 {
        self.1[self.0[l] as usize]
    }
    #[inline(always)]
    fn slice(self, range: Range<usize>) -> Self {
        (&self.0[range], self.1)
    }
}

/// Springs per batch of the force loop.
pub(crate) const LANES: usize = 64;

/// Adds the forces of the springs `ends`/`rest` into `force`, the window of particles from
/// `lo`. With `UNIFORM`, every spring has stiffness and damping `params[0]`; otherwise
/// spring `k` has `params[param[k]]`.
///
/// Springs go in batches of [`LANES`], in three passes: load each spring's end
/// differences into the batch, compute the batch's forces in one vectorised loop
/// ([`SpringBatch::run`]), then add them to the ends. The middle pass is where the
/// arithmetic is, and only there can the compiler run several springs per instruction; the
/// outer passes move data between the particles' layout and the batch's.
#[inline(always)]
pub(crate) fn scatter_springs<const UNIFORM: bool, R: RestLookup, B: SpringBatch<LANES>>(
    ScatterArgs {
        springs: ends,
        rest,
        param,
        params,
        lo,
        force,
        x,
        v,
    }: ScatterArgs<R>,
) {
    // Equal lengths let one bounds check on `x` cover `v` too.
    let v = &v[..x.len()];
    let mut batch = B::default();
    if UNIFORM {
        let [ks, kd] = params[0];
        batch.set_all_params(ks, kd);
    }
    // Springs sharing a lower end are consecutive: sum their pull on it in a register and
    // store once, instead of a store-to-load chain through memory per spring.
    let mut current = lo;
    let mut pull = Vec3::zeros();
    let (mut lower, mut xi, mut vi) = (usize::MAX, Vec3::zeros(), Vec3::zeros());
    for (b, ends) in ends.chunks(LANES).enumerate() {
        // `n <= LANES` is what lets the compiler drop the batch's bounds checks.
        let n = ends.len().min(LANES);
        let rest = rest.slice(b * LANES..b * LANES + n);
        for (l, &[i, j]) in ends[..n].iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            // Consecutive springs mostly share their lower end: load it once per run.
            if i != lower {
                lower = i;
                (xi, vi) = (x[i - lo], v[i - lo]);
            }
            batch.set(l, &(xi - x[j - lo]), &(vi - v[j - lo]), rest.rest(l));
            if !UNIFORM {
                let [ks, kd] = params[param[b * LANES + l] as usize];
                batch.set_params(l, ks, kd);
            }
        }
        batch.run(n);
        for (l, &[i, j]) in ends[..n].iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let f = batch.force(l);
            if i != current {
                force[current - lo] += pull;
                pull = Vec3::zeros();
                current = i;
            }
            pull += f;
            force[j - lo] -= f;
        }
    }
    force[current - lo] += pull;
}

/// A partition's window of forces by component: `force[c][k]` is component `c` of the
/// force on particle `lo + k`.
pub(crate) type Window<'a> = [&'a mut [f64]; 3];

/// The arguments of a force loop for one partition: [`scatter_springs`]'s, whose springs
/// are end pairs and whose window holds each force whole, or
/// `super::run_loop::scatter_runs`'s, whose springs come in runs and whose window holds
/// forces by component ([`Window`]).
pub(crate) struct ScatterArgs<'a, R, S = &'a [[u32; 2]], F = &'a mut [Vec3]> {
    /// The springs: their ends, lower end first, or runs of them.
    pub springs: S,
    /// Their rest lengths: from the first of `springs` for end pairs, by assembly index
    /// for runs (whose `first` indexes them).
    pub rest: R,
    /// Each spring's index into `params`, indexed as `rest` (empty when every spring has
    /// `params[0]`).
    pub param: &'a [u32],
    /// The distinct `(ks, kd)` pairs.
    pub params: &'a [[f64; 2]],
    /// The window's first particle.
    pub lo: usize,
    /// The window's forces, particle `lo + k` at `k`.
    pub force: F,
    /// The window's positions, particle `lo + k` at `k`.
    pub x: &'a [Vec3],
    /// The window's velocities, as `x`.
    pub v: &'a [Vec3],
}
