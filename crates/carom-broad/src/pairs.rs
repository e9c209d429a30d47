//! Pair output: from whatever order a traversal finds pairs in to one documented order.
//!
//! A pair is `(i, j)` with `i < j`, two `u32` indices into the volumes of the update
//! (`u32` halves the memory of `usize` pairs; a broad phase holds at most `u32::MAX`
//! volumes, which [`Volumes`](crate::Volumes) checks). Every broad phase returns its
//! pairs **sorted lexicographically** (by `i`, then `j`), without duplicates, so all
//! implementations, sequential or parallel, on any number of threads, return the same
//! `Vec` for the same input.
//!
//! Traversals emit pairs in their own order into per-producer buffers, already split
//! into blocks of `2^shift` consecutive `i` values. Sorting is then a counting sort by
//! `i` within each block (`O(P + N)`, no comparisons) followed by a small sort of the
//! `j`s of each `i` (a ball has a handful of neighbours). Blocks are independent, so
//! the parallel path sorts them on separate threads into disjoint parts of the output:
//! the result cannot depend on thread timing. All buffers are kept between frames, so
//! a steady-state update does not allocate.

/// An overlapping pair `(i, j)`, `i < j`.
pub type Pair = (u32, u32);

/// Where one producer (a chunk of a traversal) puts the pairs it finds.
pub(crate) struct Emitter<'a> {
    blocks: &'a mut [Vec<Pair>],
    shift: u32,
}

impl Emitter<'_> {
    /// Records the pair `{a, b}` (`a != b`), in either order.
    #[inline]
    pub(crate) fn push(&mut self, a: u32, b: u32) {
        let pair = if a < b { (a, b) } else { (b, a) };
        // `blocks` has one entry per block of `2^shift` first indices.
        self.blocks[(pair.0 >> self.shift) as usize].push(pair);
    }
}

/// Reusable buffers: per producer, per block, the pairs found; per block, the counts.
#[derive(Debug, Default, Clone)]
pub(crate) struct PairBuffers {
    shift: u32,
    n: usize,
    producers: Vec<Vec<Vec<Pair>>>,
    counts: Vec<Vec<usize>>,
    sizes: Vec<usize>,
}

impl PairBuffers {
    /// Empties the buffers for `producers` producers over `n` volumes, split into about
    /// `blocks` blocks of first indices.
    pub(crate) fn prepare(&mut self, n: usize, producers: usize, blocks: usize) {
        let per_block = n.div_ceil(blocks.max(1)).max(1);
        self.shift = per_block.next_power_of_two().trailing_zeros();
        self.n = n;
        let block_count = (n >> self.shift) + 1;
        self.producers.resize_with(producers.max(1), Vec::new);
        for parts in &mut self.producers {
            parts.resize_with(block_count, Vec::new);
            parts.truncate(block_count);
            parts.iter_mut().for_each(Vec::clear);
        }
        self.counts.resize_with(block_count, Vec::new);
        self.counts.truncate(block_count);
    }

    /// The emitter of producer 0 (sequential traversals).
    pub(crate) fn emitter(&mut self) -> Emitter<'_> {
        Emitter {
            blocks: &mut self.producers[0],
            shift: self.shift,
        }
    }

    /// One emitter per producer, for parallel traversals.
    #[cfg(feature = "parallel")]
    pub(crate) fn emitters(&mut self) -> Vec<Emitter<'_>> {
        let shift = self.shift;
        self.producers
            .iter_mut()
            .map(|blocks| Emitter { blocks, shift })
            .collect()
    }

    /// Writes every emitted pair into `out` in lexicographic order.
    pub(crate) fn sort_into(&mut self, out: &mut Vec<Pair>) {
        self.measure_blocks();
        out.clear();
        out.resize(self.sizes.iter().sum(), (0, 0));
        let mut rest = out.as_mut_slice();
        for (b, (&size, counts)) in self.sizes.iter().zip(&mut self.counts).enumerate() {
            let (block_out, tail) = rest.split_at_mut(size);
            rest = tail;
            sort_block(&self.producers, b, self.shift, self.n, counts, block_out);
        }
    }

    /// [`PairBuffers::sort_into`] with the blocks sorted in parallel.
    #[cfg(feature = "parallel")]
    pub(crate) fn par_sort_into(&mut self, out: &mut Vec<Pair>) {
        use rayon::prelude::*;
        self.measure_blocks();
        out.clear();
        out.resize(self.sizes.iter().sum(), (0, 0));
        // One slice per block: a few dozen pointers, the only per-frame allocation.
        let mut slices = Vec::with_capacity(self.sizes.len());
        let mut rest = out.as_mut_slice();
        for &size in &self.sizes {
            let (block_out, tail) = rest.split_at_mut(size);
            slices.push(block_out);
            rest = tail;
        }
        let (producers, shift, n) = (&self.producers, self.shift, self.n);
        self.counts
            .par_iter_mut()
            .zip(slices)
            .enumerate()
            .for_each(|(b, (counts, block_out))| {
                sort_block(producers, b, shift, n, counts, block_out);
            });
    }

    fn measure_blocks(&mut self) {
        let producers = &self.producers;
        self.sizes.clear();
        self.sizes.extend(
            (0..self.counts.len()).map(|b| producers.iter().map(|p| p[b].len()).sum::<usize>()),
        );
    }
}

/// Counting sort of block `b`'s pairs (from every producer, in producer order) by the
/// first index, then a sort of each run of second indices.
fn sort_block(
    producers: &[Vec<Vec<Pair>>],
    b: usize,
    shift: u32,
    n: usize,
    counts: &mut Vec<usize>,
    out: &mut [Pair],
) {
    if out.is_empty() {
        return;
    }
    let lo = b << shift;
    let width = (1usize << shift).min(n.saturating_sub(lo)).max(1);
    counts.clear();
    counts.resize(width + 1, 0);
    for p in producers {
        for &(i, _) in &p[b] {
            counts[i as usize - lo + 1] += 1;
        }
    }
    for k in 1..=width {
        counts[k] += counts[k - 1];
    }
    for p in producers {
        for &pair in &p[b] {
            let slot = &mut counts[pair.0 as usize - lo];
            out[*slot] = pair;
            *slot += 1;
        }
    }
    // counts[k] is now the end of the run of first index lo + k.
    let mut start = 0;
    for &end in &counts[..width] {
        if end - start > 1 {
            out[start..end].sort_unstable_by_key(|p| p.1);
        }
        start = end;
    }
}

/// Neighbour lists in compressed form, built from a sorted pair list: for each index,
/// every index it is paired with, ascending.
///
/// With [`Balls::with_margin`](crate::Balls::with_margin) set to half a shell, these are
/// the neighbour lists of event-driven codes (`|c_i − c_j| <= r_i + r_j + shell`).
#[derive(Clone, Debug, Default)]
pub struct NeighbourLists {
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
}

impl NeighbourLists {
    /// Empty lists.
    pub fn new() -> Self {
        Self::default()
    }

    /// Rebuilds the lists of `n` indices from `pairs` (reusing the buffers).
    ///
    /// `pairs` must come from a broad phase over `n` volumes (sorted, `i < j < n`);
    /// pairs naming an index `>= n` are ignored.
    pub fn rebuild(&mut self, n: usize, pairs: &[Pair]) {
        let n32 = u32::try_from(n).unwrap_or(u32::MAX);
        let valid = |&&(i, j): &&Pair| i < n32 && j < n32;
        self.offsets.clear();
        self.offsets.resize(n + 1, 0);
        for &(i, j) in pairs.iter().filter(valid) {
            self.offsets[i as usize + 1] += 1;
            self.offsets[j as usize + 1] += 1;
        }
        for k in 1..=n {
            self.offsets[k] += self.offsets[k - 1];
        }
        self.neighbours.clear();
        self.neighbours.resize(self.offsets[n] as usize, 0);
        // Pairs are sorted by first index, so each list receives its smaller neighbours
        // (as the second element) before its larger ones, both ascending.
        let mut cursor = std::mem::take(&mut self.offsets);
        for &(i, j) in pairs.iter().filter(valid) {
            self.neighbours[cursor[i as usize] as usize] = j;
            cursor[i as usize] += 1;
            self.neighbours[cursor[j as usize] as usize] = i;
            cursor[j as usize] += 1;
        }
        // cursor[k] is now the end of list k, the start of list k + 1.
        cursor.pop();
        cursor.insert(0, 0);
        self.offsets = cursor;
    }

    /// The number of indices.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// `true` if there are no indices.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The neighbours of `i`, ascending (empty if `i` is out of range).
    pub fn of(&self, i: usize) -> &[u32] {
        match (self.offsets.get(i), self.offsets.get(i + 1)) {
            (Some(&a), Some(&b)) => &self.neighbours[a as usize..b as usize],
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_come_out_sorted_from_any_emission_order() {
        let mut buffers = PairBuffers::default();
        buffers.prepare(10, 1, 3);
        let mut e = buffers.emitter();
        for (a, b) in [(9, 2), (0, 5), (2, 3), (0, 1), (7, 8), (5, 4)] {
            e.push(a, b);
        }
        let mut out = Vec::new();
        buffers.sort_into(&mut out);
        assert_eq!(out, vec![(0, 1), (0, 5), (2, 3), (2, 9), (4, 5), (7, 8)]);
    }

    #[test]
    fn neighbour_lists_are_symmetric_and_ascending() {
        let mut lists = NeighbourLists::new();
        lists.rebuild(5, &[(0, 3), (1, 3), (3, 4)]);
        assert_eq!(lists.of(3), &[0, 1, 4]);
        assert_eq!(lists.of(0), &[3]);
        assert_eq!(lists.of(2), &[] as &[u32]);
        assert_eq!(lists.of(7), &[] as &[u32]);
        assert_eq!(lists.len(), 5);
    }
}
