//! A k-d tree over the centres (kiddo's `ImmutableKdTree`), queried within a radius.
//!
//! Every volume is a centre and a bounding radius `R` (a ball's radius, a box's half
//! diagonal). Two volumes can only overlap if their centres are within `R_i + R_j`, so
//! the pairs of volume `i` are among the centres within `R_i + R_max` of its own, where
//! `R_max` is the largest radius in the tree; kiddo finds those (squared Euclidean,
//! unsorted, visited without allocating) and the shared exact predicate keeps the true
//! ones. Each pair is reported by its smaller index only.
//!
//! # Precision
//!
//! kiddo is generic over its own axis types; carom stores the tree in `f64` for both
//! precisions. For `f32` input the conversion is exact, costs one pass over the centres
//! and doubles the tree's memory (16 or 24 bytes per point instead of 8 or 12). The
//! query radius is grown by `8 ε_T` relative and `8 ε_T · scale` absolute (scale: the
//! largest `|coordinate| + R`), which covers every rounding of the exact predicate in
//! `T`, so no pair is lost however far from the origin the scene is.
//!
//! # Very mixed radii
//!
//! One big volume makes every query as large as it is: with radii from `1e-3` to `1`,
//! each query for a tiny ball covers a ball of radius `1` and visits hundreds of
//! centres. So volumes with `R > oversize_ratio × median(R)` (default 4; the median estimated from at
//! most 1025 strided samples) are kept out of
//! the tree: they query the tree with their own radius (one large query each) and are
//! swept against each other by a sweep-and-prune. This keeps small-ball queries small;
//! when a large fraction of the volumes is oversized the sweep dominates, and
//! [`SweepAndPrune`](crate::SweepAndPrune) itself is the better choice.
//!
//! # Allocation
//!
//! kiddo has no way to rebuild an immutable tree in place, so every update allocates a
//! new tree (the other buffers are reused). The pair search itself does not allocate.
//! The k-d tree supports open space only (no periodic domain).

use carom_geometry::Aabb;
use carom_math::{Real, Vector};
use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::pairs::{Emitter, PairBuffers};
use crate::sweep::{SortPolicy, SweepCore};
use crate::volumes::{Store, sampled_median};
use crate::{BroadPhase, Pair, Volumes};

/// A k-d tree broad phase over boxes or balls, in open space.
#[derive(Debug)]
pub struct KdTree<T: Real, const D: usize> {
    store: Store<T, D>,
    oversize_ratio: f64,
    entries: Vec<(u32, [f64; D])>,
    tree: Option<ImmutableKdTree<f64, D>>,
    /// The largest bounding radius in the tree.
    tree_radius: f64,
    /// The absolute slack added to every query radius.
    slack: f64,
    in_tree: Vec<bool>,
    oversized: Vec<u32>,
    oversized_sweep: SweepCore<T, D>,
    radii: Vec<f64>,
    buffers: PairBuffers,
}

impl<T: Real, const D: usize> Default for KdTree<T, D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real, const D: usize> KdTree<T, D> {
    /// A k-d tree that keeps volumes larger than 4 × the median radius out of the tree.
    pub fn new() -> Self {
        Self {
            store: Store::default(),
            oversize_ratio: 4.0,
            entries: Vec::new(),
            tree: None,
            tree_radius: 0.0,
            slack: 0.0,
            in_tree: Vec::new(),
            oversized: Vec::new(),
            oversized_sweep: SweepCore::default(),
            radii: Vec::new(),
            buffers: PairBuffers::default(),
        }
    }

    /// The same with volumes larger than `ratio` × the median radius kept out of the
    /// tree; `f64::INFINITY` puts every volume in the tree (every query is then inflated
    /// by the largest radius).
    ///
    /// # Errors
    /// `ratio` if it is NaN or below 1.
    pub fn with_oversize_ratio(ratio: f64) -> Result<Self, carom_math::InvalidValue> {
        carom_math::ensure_in_range("ratio", ratio.min(f64::MAX), 1.0, f64::MAX)?;
        Ok(Self {
            oversize_ratio: ratio,
            ..Self::new()
        })
    }

    /// How many volumes the last update kept out of the tree.
    pub fn oversized(&self) -> usize {
        self.oversized.len()
    }

    /// The query radius around a centre whose own bounding radius is `radius`.
    fn reach(&self, radius: f64) -> f64 {
        let eps = T::EPSILON.to_f64();
        (radius + self.tree_radius) * (1.0 + 8.0 * eps) + self.slack
    }

    /// Calls `f` with every tree entry whose centre is within `reach` of `center`.
    fn visit_tree(&self, center: &[f64; D], reach: f64, mut f: impl FnMut(u32)) {
        if let Some(tree) = &self.tree {
            tree.query(center)
                .within::<SquaredEuclidean<f64>>(reach * reach)
                .unsorted()
                .visit(|hit| f(hit.item));
        }
    }

    /// Emits the pairs found by the tree queries of volumes `ids` (a tree volume keeps
    /// only larger tree indices; an oversized one keeps every tree hit), and by the
    /// sweep of the oversized volumes at sorted positions `oversized`.
    fn search(
        &self,
        ids: core::ops::Range<usize>,
        oversized: core::ops::Range<usize>,
        emit: &mut Emitter<'_>,
    ) {
        let proxies = &self.store.proxies;
        for i in ids {
            let p = &proxies[i];
            let center = p.center.map(Real::to_f64).into();
            let i32 = i as u32;
            let regular = self.in_tree[i];
            self.visit_tree(&center, self.reach(p.radius.to_f64()), |j| {
                // Tree-tree pairs are found from both ends: keep the smaller index's.
                if (!regular || j > i32) && self.store.overlap(i, j as usize) {
                    emit.push(i32, j);
                }
            });
        }
        self.oversized_sweep
            .sweep(oversized, self.store.balls, emit);
    }

    fn query(
        &self,
        center: &Vector<T, D>,
        radius: f64,
        hit: impl Fn(usize) -> bool,
        lo_hi: (T, T),
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let c = center.map(Real::to_f64).into();
        self.visit_tree(&c, self.reach(radius), |j| {
            if hit(j as usize) {
                out.push(j);
            }
        });
        self.oversized_sweep.candidates(lo_hi.0, lo_hi.1, |j| {
            if hit(j as usize) {
                out.push(j);
            }
        });
        out.sort_unstable();
    }
}

impl<T: Real, const D: usize> BroadPhase<T, D> for KdTree<T, D> {
    fn update(&mut self, volumes: Volumes<'_, T, D>) {
        self.store.load(volumes, false);
        let proxies = &self.store.proxies;
        let n = proxies.len();

        let median = sampled_median(n, |i| proxies[i].radius.to_f64(), &mut self.radii);
        let threshold = self.oversize_ratio * median;

        // kiddo rejects coordinates equal to f64::MAX; such volumes go to the sweep.
        let storable = |c: &Vector<T, D>| c.iter().all(|x| x.to_f64().abs() < f64::MAX / 4.0);
        self.in_tree.clear();
        self.oversized.clear();
        self.entries.clear();
        let (mut tree_radius, mut scale) = (0.0_f64, 0.0_f64);
        for (i, p) in proxies.iter().enumerate() {
            let r = p.radius.to_f64();
            scale = scale.max(p.center.amax().to_f64() + r);
            let regular = r <= threshold && storable(&p.center);
            self.in_tree.push(regular);
            if regular {
                tree_radius = tree_radius.max(r);
                self.entries
                    .push((i as u32, p.center.map(Real::to_f64).into()));
            } else {
                self.oversized.push(i as u32);
            }
        }
        self.tree_radius = tree_radius;
        self.slack = 8.0 * T::EPSILON.to_f64() * scale;
        self.tree = if self.entries.is_empty() {
            None
        } else {
            // An immutable tree from explicit entries cannot fail (kiddo's errors are for
            // generated indices and mutable buckets); if it ever did, every volume would
            // go to the sweep instead, which is still exact.
            ImmutableKdTree::new_from_entries(&self.entries).ok()
        };
        if self.tree.is_none() && !self.entries.is_empty() {
            self.in_tree.iter_mut().for_each(|r| *r = false);
            self.oversized.clear();
            self.oversized.extend(0..n as u32);
        }
        self.oversized_sweep
            .build(&self.store, Some(&self.oversized), SortPolicy::Radix, false);
    }

    fn len(&self) -> usize {
        self.store.len()
    }

    fn pairs(&mut self, out: &mut Vec<Pair>) {
        let n = self.store.len();
        // The buffers are moved out (three pointers) while `search` reads the rest.
        let mut buffers = core::mem::take(&mut self.buffers);
        buffers.prepare(n, 1, 1);
        self.search(0..n, 0..self.oversized_sweep.len(), &mut buffers.emitter());
        buffers.sort_into(out);
        self.buffers = buffers;
    }

    fn query_aabb(&self, query: &Aabb<T, D>, out: &mut Vec<u32>) {
        use carom_geometry::BoundingVolume;
        let radius = query.half_extents().map(Real::to_f64).norm();
        let axis = self.oversized_sweep.axis();
        self.query(
            &query.center(),
            radius,
            |j| self.store.hits_box(j, query),
            (query.min()[axis], query.max()[axis]),
            out,
        );
    }

    fn query_ball(&self, center: &Vector<T, D>, radius: T, out: &mut Vec<u32>) {
        if !radius.finite() || radius < T::zero() {
            out.clear();
            return;
        }
        let axis = self.oversized_sweep.axis();
        self.query(
            center,
            radius.to_f64(),
            |j| self.store.hits_ball(j, center, radius),
            (center[axis] - radius, center[axis] + radius),
            out,
        );
    }
}

#[cfg(feature = "parallel")]
impl<T: Real, const D: usize> crate::ParallelBroadPhase<T, D> for KdTree<T, D> {
    fn par_pairs(&mut self, out: &mut Vec<Pair>) {
        use rayon::prelude::*;
        let (n, m) = (self.store.len(), self.oversized_sweep.len());
        let chunks = crate::parallel_chunks();
        let mut buffers = core::mem::take(&mut self.buffers);
        buffers.prepare(n, chunks, chunks);
        let this = &*self;
        buffers
            .emitters()
            .into_par_iter()
            .enumerate()
            .for_each(|(c, mut emit)| {
                let ids = crate::chunk_range(c, chunks, n);
                this.search(ids, crate::chunk_range(c, chunks, m), &mut emit);
            });
        buffers.par_sort_into(out);
        self.buffers = buffers;
    }
}
