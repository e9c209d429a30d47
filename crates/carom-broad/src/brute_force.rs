//! Brute force: every pair tested. The oracle of the tests, and the fastest choice for a
//! handful of volumes (no sorting, no structure, `N(N−1)/2` predicate calls).

use carom_geometry::{Aabb, Border};
use carom_math::{Real, Vector};

use crate::volumes::Store;
use crate::{BroadPhase, Pair, Volumes};

/// Tests every pair; open space or a periodic domain.
#[derive(Clone, Debug, Default)]
pub struct BruteForce<T: Real, const D: usize> {
    store: Store<T, D>,
    #[cfg(feature = "parallel")]
    chunks: Vec<Vec<Pair>>,
}

impl<T: Real, const D: usize> BruteForce<T, D> {
    /// A brute-force broad phase in open space.
    pub fn new() -> Self {
        Self {
            store: Store::default(),
            #[cfg(feature = "parallel")]
            chunks: Vec::new(),
        }
    }

    /// A brute-force broad phase in the periodic domain `border` (minimum image).
    pub fn periodic(border: &Border<T, D>) -> Self {
        let mut s = Self::new();
        s.store.set_period(Some(border));
        s
    }

    /// The pairs with first index in `rows`, appended in lexicographic order.
    fn rows(&self, rows: core::ops::Range<usize>, out: &mut Vec<Pair>) {
        let n = self.store.len();
        for i in rows {
            for j in i + 1..n {
                if self.store.overlap(i, j) {
                    out.push((i as u32, j as u32));
                }
            }
        }
    }
}

impl<T: Real, const D: usize> BroadPhase<T, D> for BruteForce<T, D> {
    fn update(&mut self, volumes: Volumes<'_, T, D>) {
        self.store.load(volumes, false);
    }

    fn len(&self) -> usize {
        self.store.len()
    }

    fn pairs(&mut self, out: &mut Vec<Pair>) {
        out.clear();
        self.rows(0..self.store.len(), out);
    }

    fn query_aabb(&self, query: &Aabb<T, D>, out: &mut Vec<u32>) {
        out.clear();
        out.extend(
            (0..self.store.len())
                .filter(|&j| self.store.hits_box(j, query))
                .map(|j| j as u32),
        );
    }

    fn query_ball(&self, center: &Vector<T, D>, radius: T, out: &mut Vec<u32>) {
        out.clear();
        out.extend(
            (0..self.store.len())
                .filter(|&j| self.store.hits_ball(j, center, radius))
                .map(|j| j as u32),
        );
    }
}

#[cfg(feature = "parallel")]
impl<T: Real, const D: usize> crate::ParallelBroadPhase<T, D> for BruteForce<T, D> {
    fn par_pairs(&mut self, out: &mut Vec<Pair>) {
        use rayon::prelude::*;
        let n = self.store.len();
        let chunks = crate::parallel_chunks();
        self.chunks.resize_with(chunks, Vec::new);
        // Row i costs n − 1 − i tests: cut the triangle into pieces of equal area, so
        // chunk c starts at the row where (n − i)² = n² (1 − c / chunks).
        let start = |c: usize| -> usize {
            let left = (n as f64) * (1.0 - c as f64 / chunks as f64).sqrt();
            n - (left.round() as usize).min(n)
        };
        let mut chunk_bufs = core::mem::take(&mut self.chunks);
        let this = &*self;
        chunk_bufs.par_iter_mut().enumerate().for_each(|(c, buf)| {
            buf.clear();
            this.rows(start(c)..start(c + 1), buf);
        });
        out.clear();
        for buf in &chunk_bufs {
            out.extend_from_slice(buf);
        }
        self.chunks = chunk_bufs;
    }
}
