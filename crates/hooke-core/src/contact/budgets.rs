//! The travel budgets of the contact phase's candidate lists: how far a pair's particles
//! may travel before it can come within its thickness, per pair and per block of pairs, so
//! that a resting cloth skips its narrow phase (docs/physics.md §3.3).

use super::gather::{CHUNKS, PARALLEL_MIN};
use super::stencil::Stencil;
use crate::particles::Vec3;
use rayon::prelude::*;

/// The travel sum up to which a pair tested at `x`, with its particles' travel summing to
/// `moved`, cannot come within its thickness: `moved + d - h` less a margin for rounding
/// (relative to the distances and travel involved), or `-inf` when it is within it now.
pub(super) fn next_budget(s: &Stencil, x: &[Vec3], moved: f64) -> f64 {
    let d = s.gap(x).norm();
    let slack = d - s.h - 1e-6 * (d + moved) - 1e-9;
    if slack > 0.0 {
        moved + slack
    } else {
        f64::NEG_INFINITY
    }
}

/// Candidates tested together: a block is skipped whole while no candidate in it can have
/// used up its budget.
pub(super) const BLOCK: usize = 64;

/// A block of candidates: the climb when it was last tested, and the smallest budget left
/// (budget less the travel sum) among its candidates then.
#[derive(Clone, Copy, Debug)]
pub(super) struct Block {
    pub(super) climb: f64,
    pub(super) left: f64,
}

impl Block {
    pub(super) const UNTESTED: Self = Self {
        climb: 0.0,
        left: f64::NEG_INFINITY,
    };
}

/// A candidate list's budgets: one per candidate (see [`ContactState::detect`]), and per
/// block of [`BLOCK`] candidates when it was last tested and its least budget left.
#[derive(Clone, Debug, Default)]
pub(super) struct Budgets {
    pub(super) per_pair: Vec<f64>,
    pub(super) blocks: Vec<Block>,
}

impl Budgets {
    /// Budgets for a new list of `n` candidates: every one untested.
    pub(super) fn reset(&mut self, n: usize) {
        self.per_pair.clear();
        self.per_pair.resize(n, f64::NEG_INFINITY);
        self.blocks.clear();
        self.blocks.resize(n.div_ceil(BLOCK), Block::UNTESTED);
    }

    /// [`par_blocks`] over these budgets.
    pub(super) fn run<U: Send>(
        &mut self,
        bufs: &mut Vec<Vec<U>>,
        climb: Option<f64>,
        f: impl Fn(usize, &mut f64, &mut Vec<U>) -> f64 + Sync + Send,
    ) {
        par_blocks(bufs, &mut self.per_pair, &mut self.blocks, climb, f);
    }
}

/// Calls `f(i, &mut budget[i], out)` for every candidate of a block that may have used up
/// its budget, in [`CHUNKS`] parallel chunks of whole blocks whose outputs read in order give
/// what a sequential pass pushes; `f` returns the candidate's budget left. A block is
/// skipped while four times the climb since its test (a bound on any candidate's travel
/// sum's growth: four particles, none of whose travel grew by more than the climb) is below
/// the least budget left in it; with `climb` `None` no block is skipped.
pub(super) fn par_blocks<U: Send>(
    bufs: &mut Vec<Vec<U>>,
    budgets: &mut [f64],
    blocks: &mut [Block],
    climb: Option<f64>,
    f: impl Fn(usize, &mut f64, &mut Vec<U>) -> f64 + Sync + Send,
) {
    // `None`: test every block.
    let (climb, skip) = (climb.unwrap_or(0.0), climb.is_some());
    bufs.resize_with(CHUNKS, Vec::new);
    for b in bufs.iter_mut() {
        b.clear();
    }
    let run = |first: usize, budgets: &mut [f64], blocks: &mut [Block], out: &mut Vec<U>| {
        for (k, (chunk, block)) in budgets.chunks_mut(BLOCK).zip(blocks).enumerate() {
            if skip && 4.0 * (climb - block.climb) < block.left {
                continue;
            }
            let start = first + k * BLOCK;
            let mut left = f64::INFINITY;
            for (j, budget) in chunk.iter_mut().enumerate() {
                left = left.min(f(start + j, budget, out));
            }
            *block = Block { climb, left };
        }
    };
    let n = budgets.len();
    if n < PARALLEL_MIN {
        run(0, budgets, blocks, &mut bufs[0]);
        return;
    }
    let per = blocks.len().div_ceil(CHUNKS);
    bufs.par_iter_mut()
        .zip(
            budgets
                .par_chunks_mut(per * BLOCK)
                .zip(blocks.par_chunks_mut(per)),
        )
        .enumerate()
        .for_each(|(k, (out, (budgets, blocks)))| run(k * per * BLOCK, budgets, blocks, out));
}
