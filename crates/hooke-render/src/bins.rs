//! Binning primitives into screen tiles.
//!
//! Primitives are split into fixed chunks; each chunk sorts its primitives into tiles with a
//! counting sort (one pass to count, one to fill). A tile then reads every chunk's list in
//! chunk order, so it sees its primitives in draw-list order however the chunks were
//! scheduled: that order, not the thread count, decides ties in the depth test.

use crate::setup::Rect;
use rayon::prelude::*;

/// Primitives per binning chunk.
const CHUNK: usize = 1 << 14;

/// The tile grid over the sample buffer.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grid {
    /// Tile side in samples.
    pub side: u32,
    /// Tiles across.
    pub across: u32,
    /// Tiles down.
    pub down: u32,
}

impl Grid {
    pub fn new(width: u32, height: u32, side: u32) -> Self {
        Self {
            side,
            across: width.div_ceil(side),
            down: height.div_ceil(side),
        }
    }

    pub fn count(&self) -> usize {
        (self.across * self.down) as usize
    }

    /// The tiles a sample rectangle touches, as inclusive tile ranges.
    fn span(&self, r: &Rect) -> (u32, u32, u32, u32) {
        (
            r.x0 / self.side,
            r.y0 / self.side,
            (r.x1 - 1) / self.side,
            (r.y1 - 1) / self.side,
        )
    }
}

#[derive(Default)]
struct Chunk {
    /// `start[t]..start[t + 1]` indexes `items` for tile `t`.
    start: Vec<u32>,
    items: Vec<u32>,
}

/// For every tile, the indices of the primitives whose rectangle touches it, in order.
/// Refilled every frame, reusing its memory.
#[derive(Default)]
pub(crate) struct Bins {
    chunks: Vec<Chunk>,
}

impl Bins {
    /// Bins primitives by their sample rectangles (`None` for primitives that were culled)
    /// into the tiles of `grid`.
    pub fn fill(&mut self, rects: &[Option<Rect>], grid: &Grid) {
        let tiles = grid.count();
        self.chunks
            .resize_with(rects.len().div_ceil(CHUNK), Chunk::default);
        self.chunks
            .par_iter_mut()
            .zip(rects.par_chunks(CHUNK))
            .enumerate()
            .for_each(|(c, (bin, chunk))| {
                let start = &mut bin.start;
                start.clear();
                start.resize(tiles + 1, 0);
                let spans = chunk.iter().enumerate().filter_map(|(k, rect)| {
                    Some(((c * CHUNK + k) as u32, grid.span(rect.as_ref()?)))
                });
                for (_, (x0, y0, x1, y1)) in spans.clone() {
                    for ty in y0..=y1 {
                        for tx in x0..=x1 {
                            start[(ty * grid.across + tx) as usize + 1] += 1;
                        }
                    }
                }
                for t in 0..tiles {
                    start[t + 1] += start[t];
                }
                bin.items.clear();
                bin.items.resize(start[tiles] as usize, 0);
                // Fill by advancing each tile's start, then shift the starts back.
                for (index, (x0, y0, x1, y1)) in spans {
                    for ty in y0..=y1 {
                        for tx in x0..=x1 {
                            let slot = &mut start[(ty * grid.across + tx) as usize];
                            bin.items[*slot as usize] = index;
                            *slot += 1;
                        }
                    }
                }
                for t in (0..tiles).rev() {
                    start[t + 1] = start[t];
                }
                start[0] = 0;
            });
    }

    /// The primitives touching tile `t`, in draw-list order.
    pub fn tile(&self, t: usize) -> impl Iterator<Item = u32> + '_ {
        self.chunks.iter().flat_map(move |c| {
            c.items[c.start[t] as usize..c.start[t + 1] as usize]
                .iter()
                .copied()
        })
    }
}
