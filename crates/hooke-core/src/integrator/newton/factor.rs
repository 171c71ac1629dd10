//! The springs' part of Newton's system, factored: each particle's diagonal block (inertia,
//! drag, attachments, its springs and contacts) and each spring's block between its ends,
//! as a sparse matrix whose pattern is the springs' (kept while the springs are), factored
//! by faer's sparse Cholesky on one thread (the same bits on any thread count). Its inverse
//! preconditions the conjugate gradients on the whole system, whose contact blocks between
//! particles it leaves out: without contact pairs it *is* the system, and the gradients
//! end in one iteration.

use crate::integrator::Sym3;
use crate::integrator::vbd::graph::Graph;
use crate::particles::Vec3;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// The lower triangle's slots of a 3×3 block's entries, `(row, column)` within the block,
/// in the order `Sym3` stores them: xx, yy, zz, xy, xz, yz.
const SYM: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 0), (2, 0), (2, 1)];

/// Adds `sign` times the symmetric `block` at `slots` (entry `(r, c)` at `slots[3r + c]`).
fn add(values: &mut [f64], slots: &[usize; 9], block: &Sym3, sign: f64) {
    let [xx, yy, zz, xy, xz, yz] = block.0;
    let m = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    for (k, &slot) in slots.iter().enumerate() {
        values[slot] += sign * m[k / 3][k % 3];
    }
}

/// A factorisation of the springs' part of Newton's system.
#[derive(Default)]
pub(super) struct Factor {
    /// The particle and spring counts the pattern was built for.
    built_for: (usize, usize),
    /// The lower triangle's pattern, column by column (3 columns a particle).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    /// Per particle: where its diagonal block's lower entries sit in `values`, as `SYM`.
    diagonal: Vec<[usize; 6]>,
    /// Per spring end, in the graph's order: where the block between its particle and the
    /// other end sits (rows of the later particle, columns of the earlier), when the other
    /// end is later.
    offdiagonal: Vec<Option<[usize; 9]>>,
    /// The same, by the two particles (earlier, later).
    blocks: std::collections::HashMap<(usize, usize), [usize; 9]>,
    symbolic: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    /// Whether the last factorisation succeeded (it may not where the system is not
    /// numerically positive definite: then the caller preconditions otherwise).
    pub(super) ready: bool,
    scratch: Option<MemBuffer>,
    rhs: Vec<f64>,
}

impl std::fmt::Debug for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Factor")
            .field("built_for", &self.built_for)
            .field("entries", &self.row_idx.len())
            .field("ready", &self.ready)
            .finish()
    }
}

impl Clone for Factor {
    /// A clone starts without a pattern: it is built again on its first use.
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl Factor {
    /// The cost of a factorisation and of a solve with it, in multiply-adds, for `graph`'s
    /// springs on `n` particles (the pattern is built if it was not): with `c` the mean
    /// count of a column of the factor over `N` columns, `N c²` and `4 N c` (a triangular
    /// solve each way). A lattice's factor fills in where a cloth's hardly does.
    pub(super) fn costs(&mut self, graph: &Graph, n: usize, springs: usize) -> (f64, f64) {
        self.ensure(graph, n, springs);
        let columns = (3 * n).max(1) as f64;
        let entries = self.l_values.len() as f64;
        (entries * entries / columns, 4.0 * entries)
    }

    /// Whether its pattern was built for `n` particles and `springs` springs.
    pub(super) fn fits(&self, n: usize, springs: usize) -> bool {
        self.built_for == (n, springs) && self.symbolic.is_some()
    }

    /// Builds the pattern (and its symbolic analysis) for `graph`'s springs on `n`
    /// particles, unless it was built for them.
    fn ensure(&mut self, graph: &Graph, n: usize, springs: usize) {
        if self.fits(n, springs) {
            return;
        }
        self.built_for = (n, springs);
        // Per particle, the later particles it shares a spring with, in increasing order.
        let later: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                let mut js: Vec<usize> = graph
                    .of(i)
                    .iter()
                    .map(|s| s.other as usize)
                    .filter(|&j| j > i)
                    .collect();
                js.sort_unstable();
                js.dedup();
                js
            })
            .collect();
        self.col_ptr.clear();
        self.row_idx.clear();
        self.diagonal.clear();
        // Where block (j, i) starts, per column c of particle i: the index of row 3j.
        let mut at: Vec<std::collections::HashMap<usize, [usize; 3]>> = vec![Default::default(); n];
        self.col_ptr.push(0);
        for (i, js) in later.iter().enumerate() {
            let mut diag = [0; 6];
            let mut starts = std::collections::HashMap::new();
            for c in 0..3 {
                for r in c..3 {
                    let k = SYM.iter().position(|&rc| rc == (r, c)).unwrap_or(0);
                    diag[k] = self.row_idx.len();
                    self.row_idx.push(3 * i + r);
                }
                for &j in js {
                    starts.entry(j).or_insert([0; 3])[c] = self.row_idx.len();
                    self.row_idx.extend([3 * j, 3 * j + 1, 3 * j + 2]);
                }
                self.col_ptr.push(self.row_idx.len());
            }
            self.diagonal.push(diag);
            at[i] = starts;
        }
        self.offdiagonal.clear();
        self.blocks.clear();
        for (i, starts) in at.iter().enumerate() {
            for (&j, st) in starts {
                // Entry (r, c) of the block at rows 3j + r of column 3i + c.
                self.blocks
                    .insert((i, j), std::array::from_fn(|k| st[k / 3] + k % 3));
            }
            for s in graph.of(i) {
                self.offdiagonal
                    .push(self.blocks.get(&(i, s.other as usize)).copied());
            }
        }
        self.values = vec![0.0; self.row_idx.len()];
        let pattern =
            SymbolicSparseColMatRef::new_checked(3 * n, 3 * n, &self.col_ptr, None, &self.row_idx);
        self.symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .ok();
        if let Some(symbolic) = &self.symbolic {
            self.l_values = vec![0.0; symbolic.len_val()];
            let req = symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            self.scratch = Some(MemBuffer::new(req));
        }
        self.rhs = vec![0.0; 3 * n];
        self.ready = false;
    }

    /// Fills the matrix with the diagonal blocks `diagonal`, less each spring's block
    /// `springs` (in the graph's order), plus each contact's block `couplings` between two
    /// particles that share a spring (others are not in the pattern), none between pinned
    /// particles; and factors it.
    pub(super) fn factor(
        &mut self,
        graph: &Graph,
        (diagonal, springs): (&[Sym3], &[Sym3]),
        (pinned, couplings): (&[bool], &[(usize, usize, Sym3)]),
        count: usize,
    ) {
        let n = diagonal.len();
        self.ensure(graph, n, count);
        self.ready = false;
        let Some(symbolic) = &self.symbolic else {
            return;
        };
        self.values.fill(0.0);
        for (i, block) in diagonal.iter().enumerate() {
            for (k, &slot) in self.diagonal[i].iter().enumerate() {
                self.values[slot] += block.0[k];
            }
        }
        let mut e = 0;
        for i in 0..n {
            for s in graph.of(i) {
                let j = s.other as usize;
                if let Some(slots) = self.offdiagonal[e]
                    && !pinned[i]
                    && !pinned[j]
                {
                    add(&mut self.values, &slots, &springs[e], -1.0);
                }
                e += 1;
            }
        }
        for &(i, j, block) in couplings {
            if let Some(slots) = self.blocks.get(&(i, j))
                && !pinned[i]
                && !pinned[j]
            {
                add(&mut self.values, slots, &block, 1.0);
            }
        }
        let Some(scratch) = self.scratch.as_mut() else {
            return;
        };
        let pattern =
            SymbolicSparseColMatRef::new_checked(3 * n, 3 * n, &self.col_ptr, None, &self.row_idx);
        let a = SparseColMatRef::new(pattern, &self.values);
        self.ready = symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(scratch),
                Default::default(),
            )
            .is_ok();
    }

    /// `z = P⁻¹ r`, with the last factorisation.
    pub(super) fn solve(&mut self, r: &[Vec3], z: &mut [Vec3]) {
        let (Some(symbolic), Some(scratch)) = (&self.symbolic, self.scratch.as_mut()) else {
            return;
        };
        for (k, v) in r.iter().enumerate() {
            self.rhs[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
        }
        let n = self.rhs.len();
        let rhs = MatMut::from_column_major_slice_mut(&mut self.rhs, n, 1);
        LltRef::new(symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(scratch),
        );
        for (k, v) in z.iter_mut().enumerate() {
            *v = Vec3::new(self.rhs[3 * k], self.rhs[3 * k + 1], self.rhs[3 * k + 2]);
        }
    }
}
