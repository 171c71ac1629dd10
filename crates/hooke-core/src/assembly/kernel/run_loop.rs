//! The force loop over runs: springs `(i + k, i + d + k)` for `k` in `0..len`, whose two
//! ends both advance one particle per spring.
//!
//! A run needs no end indices: its springs read two contiguous stretches of positions and
//! velocities and add their forces into two contiguous stretches of the window, so every
//! load and store moves whole vectors and the prefetcher sees plain streams. Meshes built
//! row by row (grids, extruded shapes, the jelly) are mostly runs; [`crate::assembly::Assembly`] finds
//! them and leaves the rest to [`super::force_loop`].
//!
//! Springs go in groups of four (eight with AVX-512): the vector kernels load the upper
//! ends' coordinates as consecutive values, transpose them in registers, compute the
//! group's forces in one instruction per operation and subtract them from the window,
//! which holds forces by component (`run_avx2.rs`, `run_avx512.rs`); the portable kernel
//! does the same lane by lane. The lower ends of a chunk of runs sit in component layout
//! throughout, and so do their forces until they are added to the window. Which width
//! is faster on a core with both depends on more than the instruction set: eight springs
//! per instruction halve the instructions waiting on each square root and division, but
//! a core may issue two 256-bit operations where it issues one 512-bit one, so the
//! AVX-512 kernel times both (`batch_choice.rs`).

use super::force_loop::RestLookup;
use crate::forces::spring::spring_formula;

/// Lower ends per chunk of runs: the layout cuts runs where their lower ends cross a
/// multiple of it, and the loop handles one chunk's pieces together. Longer pieces spread
/// each piece's set-up over more springs: 64 ran cloth-1024 about 4 % faster than 32 on two
/// threads (11.05–11.43 against 11.63–11.93 ms, interleaved), and a chunk's six rows of
/// forces (a cloth's offsets) still take 9 KiB of the L1 cache.
pub(crate) const RUN_CHUNK: usize = 64;

/// Lower ends whose pulls are summed together, in one register with AVX-512.
const PULL_LANES: usize = 8;

/// Springs computed together by the portable and AVX2 kernels.
pub(crate) const GROUP: usize = 4;

/// The most distinct offsets the pieces of one chunk may have (the layout keeps partitions
/// with more for the per-spring loop): a cloth has 6, a lattice with every neighbour to
/// distance two 13.
pub(crate) const MAX_OFFSETS: usize = 16;

/// A run of springs in the solver's layout: springs `first..first + len` of the assembly
/// join particle `lo + k` to `lo + offset + k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Run {
    /// The lower end of the run's first spring.
    pub lo: u32,
    /// How far above its lower end each spring's upper end is.
    pub offset: u32,
    /// Springs in the run.
    pub len: u32,
    /// The assembly index of the run's first spring (its rest length and parameters).
    pub first: u32,
    /// Whether every spring of the run has the first one's rest length (as on a grid), so
    /// that the loop reads it once instead of once per spring.
    pub same_rest: bool,
}

/// The arguments of [`scatter_runs`] for one partition.
pub(crate) type RunArgs<'a, R> = super::ScatterArgs<'a, R, &'a [Run], super::Window<'a>>;

/// A chunk's lower ends in component layout, read once per chunk, and the forces of its
/// pieces, one row per offset (pieces of one offset cover distinct lower ends), kept until
/// the chunk's lower ends take their sums.
struct Chunk {
    x: [[f64; RUN_CHUNK]; 3],
    v: [[f64; RUN_CHUNK]; 3],
    forces: [[[f64; RUN_CHUNK]; 3]; MAX_OFFSETS],
    lower: [bool; RUN_CHUNK],
}

/// `W` consecutive springs of a piece, as [`scatter_runs`] hands them to a group step.
pub(crate) struct Group<'a, const W: usize> {
    /// The lower ends' positions and velocities, by component.
    pub x: [&'a [f64; W]; 3],
    pub v: [&'a [f64; W]; 3],
    /// Where the step writes the group's forces, by component.
    pub keep: [&'a mut [f64; W]; 3],
    /// The upper ends' positions and velocities.
    pub xb: &'a [[f64; 3]; W],
    pub vb: &'a [[f64; 3]; W],
    /// The upper ends' forces, by component: the step subtracts each spring's force.
    pub out: [&'a mut [f64; W]; 3],
    /// Rest lengths, stiffnesses and dampings.
    pub rest: [f64; W],
    pub ks: [f64; W],
    pub kd: [f64; W],
}

/// Lanes `a..a + W` of a chunk's row.
#[inline(always)]
fn lanes<const W: usize>(row: &[f64; RUN_CHUNK], a: usize) -> &[f64; W] {
    row[a..a + W].try_into().expect("a group's lanes")
}

/// Lanes `a..a + W` of a chunk's row, to write.
#[inline(always)]
fn lanes_mut<const W: usize>(row: &mut [f64; RUN_CHUNK], a: usize) -> &mut [f64; W] {
    (&mut row[a..a + W]).try_into().expect("a group's lanes")
}

/// The group step of the portable kernel: lane by lane with [`spring_formula`], the same
/// operations in the same order as every other kernel's.
#[inline(always)]
pub(crate) fn group_by_lane<const W: usize>(g: Group<W>) {
    for l in 0..W {
        let d = [0, 1, 2].map(|c| g.x[c][l] - g.xb[l][c]);
        let dv = [0, 1, 2].map(|c| g.v[c][l] - g.vb[l][c]);
        let f = spring_formula(d, dv, g.rest[l], g.ks[l], g.kd[l]);
        for (c, f) in f.into_iter().enumerate() {
            g.keep[c][l] = f;
            g.out[c][l] -= f;
        }
    }
}

/// Adds the forces of every spring of `runs` into the window, `W` springs at a time
/// through `group` (which must compute [`group_by_lane`]'s bits), in exactly the sequence of
/// the per-spring loop over the same springs in sorted order (`super::force_loop`): each
/// particle first loses the forces of the springs it is the upper end of, by ascending
/// lower end, then gains once the sum of those it is the lower end of, taken by ascending
/// upper end.
///
/// Runs come cut into pieces within one chunk of [`RUN_CHUNK`] lower ends each, sorted by
/// chunk and then by offset from the largest. A chunk's lower ends are loaded into
/// component layout once; each piece then loads only its upper ends, computes its forces
/// and subtracts them from its upper ends: by descending offset, which is ascending lower
/// end for any one upper end. The pieces' forces are kept, and once the chunk is done each
/// lower end sums its pieces' by ascending offset and adds the sum to the window.
#[inline(always)]
pub(crate) fn scatter_runs<const UNIFORM: bool, R: RestLookup, const W: usize>(
    RunArgs {
        springs: runs,
        rest,
        param,
        params,
        lo,
        mut force,
        x,
        v,
    }: RunArgs<R>,
    mut group: impl FnMut(Group<W>),
) {
    let (x, v): (&[[f64; 3]], &[[f64; 3]]) = (bytemuck::cast_slice(x), bytemuck::cast_slice(v));
    // On the stack (28 KiB): stepping allocates nothing.
    let mut chunk = Chunk {
        x: [[0.0; RUN_CHUNK]; 3],
        v: [[0.0; RUN_CHUNK]; 3],
        forces: [[[0.0; RUN_CHUNK]; 3]; MAX_OFFSETS],
        lower: [false; RUN_CHUNK],
    };
    let mut start = 0;
    while start < runs.len() {
        let at = runs[start].lo as usize / RUN_CHUNK;
        let end = start
            + runs[start..]
                .iter()
                .take_while(|r| r.lo as usize / RUN_CHUNK == at)
                .count();
        let pieces = &runs[start..end];
        // Each piece's row: pieces come by descending offset, and the layout keeps at most
        // `MAX_OFFSETS` offsets per chunk (`chunk.forces` has that many rows).
        let rows = 1 + pieces
            .windows(2)
            .filter(|w| w[0].offset != w[1].offset)
            .count();
        let first = pieces.iter().map(|r| r.lo).min().unwrap_or(0) as usize;
        let last = pieces.iter().map(|r| r.lo + r.len).max().unwrap_or(0) as usize;
        let span = (last - first).min(RUN_CHUNK);
        let chunk = &mut chunk;
        let (xs, vs) = (
            &x[first - lo..first - lo + span],
            &v[first - lo..first - lo + span],
        );
        for c in 0..3 {
            for l in 0..span {
                chunk.x[c][l] = xs[l][c];
                chunk.v[c][l] = vs[l][c];
            }
        }
        // Zero where no piece of a row writes, so that every row adds in whole; a row's
        // zeros add nothing to a pull, which starts at +0 and so is never -0. Pieces of one
        // row cover distinct lower ends, so a row whose pieces hold `span` springs in all is
        // written whole and needs none (most rows of a mesh built row by row).
        let mut covered = [0usize; MAX_OFFSETS];
        let mut q = 0;
        for (p, piece) in pieces.iter().enumerate() {
            if p > 0 && piece.offset != pieces[p - 1].offset {
                q += 1;
            }
            let i = piece.lo as usize - first;
            covered[q] += (piece.len as usize).min(span - i);
        }
        for (row, &covered) in chunk.forces[..rows].iter_mut().zip(&covered) {
            if covered < span {
                for c in row.iter_mut() {
                    c[..span].fill(0.0);
                }
            }
        }
        let mut q = 0;
        for (p, piece) in pieces.iter().enumerate() {
            if p > 0 && piece.offset != pieces[p - 1].offset {
                q += 1;
            }
            let i = piece.lo as usize - first;
            let n = (piece.len as usize).min(span - i);
            let j = piece.lo as usize + piece.offset as usize;
            let k = piece.first as usize;
            let (xb, vb) = (&x[j - lo..j - lo + n], &v[j - lo..j - lo + n]);
            let [o0, o1, o2] = &mut force;
            let mut out = [o0, o1, o2].map(|o| &mut o[j - lo..j - lo + n]);
            let rest = rest.slice(k..k + n);
            let same_rest = piece.same_rest.then(|| rest.rest(0));
            let param = if UNIFORM { &[][..] } else { &param[k..k + n] };
            let ks_kd = |l: usize| {
                if UNIFORM {
                    params[0]
                } else {
                    params[param[l] as usize]
                }
            };
            let kept = &mut chunk.forces[q];
            let mut g = 0;
            while g + W <= n {
                let a = i + g;
                let [f0, f1, f2] = &mut *kept;
                let pairs: [[f64; 2]; W] = std::array::from_fn(|l| ks_kd(g + l));
                group(Group {
                    x: [0, 1, 2].map(|c| lanes(&chunk.x[c], a)),
                    v: [0, 1, 2].map(|c| lanes(&chunk.v[c], a)),
                    keep: [lanes_mut(f0, a), lanes_mut(f1, a), lanes_mut(f2, a)],
                    xb: xb[g..g + W].try_into().expect("a group's ends"),
                    vb: vb[g..g + W].try_into().expect("a group's ends"),
                    out: out
                        .each_mut()
                        .map(|o| (&mut o[g..g + W]).try_into().expect("a group's ends")),
                    rest: match same_rest {
                        Some(r) => [r; W],
                        None => std::array::from_fn(|l| rest.rest(g + l)),
                    },
                    ks: pairs.map(|p| p[0]),
                    kd: pairs.map(|p| p[1]),
                });
                g += W;
            }
            for l in g..n {
                let a = i + l;
                let dx = [0, 1, 2].map(|c| chunk.x[c][a] - xb[l][c]);
                let dv = [0, 1, 2].map(|c| chunk.v[c][a] - vb[l][c]);
                let [ks, kd] = ks_kd(l);
                let f = spring_formula(dx, dv, rest.rest(l), ks, kd);
                for c in 0..3 {
                    kept[c][a] = f[c];
                    out[c][l] -= f[c];
                }
            }
        }
        chunk.lower[..span].fill(false);
        for piece in pieces {
            let i = piece.lo as usize - first;
            let n = (piece.len as usize).min(span - i);
            chunk.lower[i..i + n].fill(true);
        }
        // Each lower end's pull: its pieces' forces by ascending offset, from zero, added to
        // the window. Eight lanes at a time the sum stays in one register across the rows.
        let rows = &chunk.forces[..rows];
        let whole = span / PULL_LANES * PULL_LANES;
        for (c, out) in force.iter_mut().enumerate() {
            let out = &mut out[first - lo..first - lo + span];
            for a in (0..whole).step_by(PULL_LANES) {
                let mut pull = [0.0; PULL_LANES];
                for row in rows.iter().rev() {
                    for (p, f) in pull.iter_mut().zip(&row[c][a..a + PULL_LANES]) {
                        *p += f;
                    }
                }
                let (out, lower) = (&mut out[a..a + PULL_LANES], &chunk.lower[a..a + PULL_LANES]);
                for ((o, p), &lower) in out.iter_mut().zip(pull).zip(lower) {
                    *o = if lower { *o + p } else { *o };
                }
            }
            for l in whole..span {
                if chunk.lower[l] {
                    let mut pull = 0.0;
                    for row in rows.iter().rev() {
                        pull += row[c][l];
                    }
                    out[l] += pull;
                }
            }
        }
        start = end;
    }
}
