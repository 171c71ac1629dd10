//! The springs in the solver's layout: ends, rest lengths and stiffness as separate arrays,
//! with tables where few values repeat, so that the force loop streams as few bytes per
//! spring as it can.

use std::collections::HashMap;

/// The springs of a model in the solver's layout: end pairs, rest lengths (see
/// [`RestLengths`]) and an index into a table of distinct `(ks, kd)` pairs, one array each,
/// so the hot loop streams 10 to 20 bytes per spring instead of the 40 of [`Spring`]
/// (`param` is left empty when all springs share one `(ks, kd)`).
#[derive(Clone, Debug, Default)]
pub(super) struct SpringTable {
    pub(super) ends: Vec<[u32; 2]>,
    pub(super) rest: RestLengths,
    pub(super) param: Vec<u32>,
    pub(super) params: Vec<[f64; 2]>,
}

/// The springs' rest lengths: grid meshes have a handful of distinct ones (13 on the
/// cloth-512 workload), kept in a table read through a 2-byte index, which takes 6 bytes per
/// spring off the stream the force loop reads; other meshes keep one per spring, and so do
/// systems of at most [`INDEX_REST_ABOVE`] springs.
#[derive(Clone, Debug)]
pub(super) enum RestLengths {
    Indexed(Vec<u16>, Vec<f64>),
    Each(Vec<f64>),
}

impl Default for RestLengths {
    fn default() -> Self {
        Self::Each(Vec::new())
    }
}

/// The index of `value` in `table`, which holds distinct values (told apart by `key`),
/// appending it when new.
pub(super) fn intern<K: std::hash::Hash + Eq, V>(
    seen: &mut HashMap<K, usize>,
    table: &mut Vec<V>,
    key: K,
    value: V,
) -> usize {
    *seen.entry(key).or_insert_with(|| {
        table.push(value);
        table.len() - 1
    })
}

/// The fewest springs whose rest lengths are indexed. Below it they fit in a core's L2
/// cache whole, where the index saves no memory traffic and costs a dependent load per
/// spring (on `jello.w`, 6,220 springs in the per-spring loop, one RK4 step on one
/// thread took 201 µs indexed and 188 µs without).
const INDEX_REST_ABOVE: usize = 1 << 15;

impl RestLengths {
    /// Indexes `rest` when it has more than [`INDEX_REST_ABOVE`] values and at most 2¹⁶
    /// distinct ones (by bits).
    pub(super) fn new(rest: Vec<f64>) -> Self {
        if rest.len() <= INDEX_REST_ABOVE {
            return Self::Each(rest);
        }
        let (mut seen, mut table) = (HashMap::new(), Vec::new());
        let mut index = Vec::with_capacity(rest.len());
        for &r in &rest {
            let Ok(k) = u16::try_from(intern(&mut seen, &mut table, r.to_bits(), r)) else {
                return Self::Each(rest);
            };
            index.push(k);
        }
        Self::Indexed(index, table)
    }

    pub(super) fn get(&self, k: usize) -> f64 {
        match self {
            Self::Indexed(index, table) => table[index[k] as usize],
            Self::Each(rest) => rest[k],
        }
    }
}

impl SpringTable {
    #[inline]
    pub(super) fn params(&self, k: usize) -> [f64; 2] {
        if self.param.is_empty() {
            self.params[0]
        } else {
            self.params[self.param[k] as usize]
        }
    }
}
