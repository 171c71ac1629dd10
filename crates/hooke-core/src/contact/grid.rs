//! The broad phase: boxes binned into a uniform grid whose cells are hashed into buckets.
//!
//! Every box goes into the one cell that holds its low corner, and cells are at least as
//! large as any box, so a box reaches at most one cell further per axis. The bins are made
//! by a counting sort that keeps item order, and lookups check the exact cell, so what a
//! query visits and in which order depends on the boxes alone: never on threads or hash
//! collisions.

use crate::particles::Vec3;

/// A cell's integer coordinates.
pub(crate) type Cell = [i64; 3];

/// Boxes binned by the cell of their low corner.
#[derive(Clone, Debug, Default)]
pub(crate) struct Grid {
    /// Cell side, metres.
    cell: f64,
    /// Buckets − 1 (a power of two less one).
    mask: usize,
    /// Where each bucket's items start in `items`; one more entry than buckets.
    start: Vec<u32>,
    /// Item ids, by bucket, in increasing id within a bucket.
    items: Vec<u32>,
    /// Each item's cell.
    cells: Vec<Cell>,
}

impl Grid {
    /// Bins `lows.len()` boxes by their low corners. `cell` must be at least the largest
    /// extent of any box on any axis.
    pub(crate) fn build(&mut self, cell: f64, lows: impl ExactSizeIterator<Item = Vec3>) {
        self.cell = cell;
        let n = lows.len();
        let buckets = (2 * n).next_power_of_two().max(16);
        self.mask = buckets - 1;
        self.cells.clear();
        self.cells.extend(lows.map(|lo| cell_of(cell, &lo)));
        self.start.clear();
        self.start.resize(buckets + 1, 0);
        for c in &self.cells {
            self.start[hash(c) as usize & self.mask] += 1;
        }
        let mut sum = 0;
        for s in &mut self.start {
            let count = *s;
            *s = sum;
            sum += count;
        }
        self.items.clear();
        self.items.resize(n, 0);
        // `start[b]` is used as bucket b's write cursor, then restored by the shift below.
        for (id, c) in self.cells.iter().enumerate() {
            let b = hash(c) as usize & self.mask;
            self.items[self.start[b] as usize] = id as u32;
            self.start[b] += 1;
        }
        for b in (1..=buckets).rev() {
            self.start[b] = self.start[b - 1];
        }
        self.start[0] = 0;
    }

    /// The cell holding point `p`.
    pub(crate) fn cell_of(&self, p: &Vec3) -> Cell {
        cell_of(self.cell, p)
    }

    /// Calls `f` with every item whose low corner lies in `cell`, in increasing id.
    pub(crate) fn visit(&self, cell: Cell, mut f: impl FnMut(u32)) {
        let b = hash(&cell) as usize & self.mask;
        let (s, e) = (self.start[b] as usize, self.start[b + 1] as usize);
        for &id in &self.items[s..e] {
            if self.cells[id as usize] == cell {
                f(id);
            }
        }
    }

    /// The cell of item `id`.
    pub(crate) fn item_cell(&self, id: u32) -> Cell {
        self.cells[id as usize]
    }
}

/// The cell of side `cell` holding `p`.
fn cell_of(cell: f64, p: &Vec3) -> Cell {
    [0, 1, 2].map(|k| (p[k] / cell).floor() as i64)
}

/// The usual spatial hash (Teschner et al. 2003): three large primes mixed by xor.
fn hash(c: &Cell) -> u64 {
    (c[0].wrapping_mul(73_856_093) ^ c[1].wrapping_mul(19_349_663) ^ c[2].wrapping_mul(83_492_791))
        as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_is_found_in_its_own_cell_once() {
        let lows: Vec<Vec3> = (0..500)
            .map(|i| {
                let f = i as f64;
                Vec3::new(
                    (f * 0.37).sin() * 3.0,
                    (f * 0.11).cos(),
                    (f * 0.73).sin() - 2.0,
                )
            })
            .collect();
        let mut grid = Grid::default();
        grid.build(0.25, lows.iter().copied());
        for (id, lo) in lows.iter().enumerate() {
            let mut found = Vec::new();
            grid.visit(grid.cell_of(lo), |i| found.push(i));
            assert_eq!(found.iter().filter(|&&i| i == id as u32).count(), 1);
            assert!(found.windows(2).all(|w| w[0] < w[1]), "ids in order");
            assert!(found.iter().all(|&i| grid.item_cell(i) == grid.cell_of(lo)));
        }
    }
}
