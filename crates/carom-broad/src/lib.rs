//! Broad phases: find the pairs of bounding volumes that overlap, so that a narrow phase
//! looks only at those.
//!
//! Every broad phase implements [`BroadPhase`]: give it the current bounding volumes
//! ([`Volumes`]: a slice of [`Aabb`]s, or [`Balls`] as struct-of-arrays centres and
//! radii), then ask for the overlapping [`Pair`]s, query a box, or query a ball. The
//! crate knows indices and bounding volumes only, never shapes or bodies.
//!
//! | type | how | best for |
//! |---|---|---|
//! | [`BruteForce`] | every pair | a few dozen volumes; the oracle of the tests |
//! | [`SweepAndPrune`] | sort on the axis of largest variance, sweep | any density, mixed sizes, coherent frames |
//! | [`KdTree`] | kiddo k-d tree over centres, radius queries | balls of similar size, many queries |
//! | [`UniformGrid`] | cells the size of a typical volume: dense, hashed or periodic | dense scenes of similar sizes, periodic boxes |
//!
//! `docs/broad-phase.md` has the measured table and a guide to picking one.
//!
//! # Guarantees
//!
//! * **Exact.** Every implementation returns exactly the pairs the shared predicate
//!   accepts (see [`Volumes`]): boxes that overlap or touch, like
//!   [`BoundingVolume::intersects`](carom_geometry::BoundingVolume::intersects), or balls
//!   with `|c_i − c_j| <= r_i + r_j`. Culling is conservative; the final test is the same
//!   function everywhere.
//! * **Deterministic.** Pairs are `(i, j)` with `i < j`, sorted lexicographically, no
//!   duplicates. The same input gives the same `Vec` from every implementation,
//!   sequential or parallel, on any number of threads, whatever the history of earlier
//!   updates (the incremental sweep-and-prune included).
//! * **No allocation in steady state.** Output goes into a caller-owned `Vec` that is
//!   reused; internal buffers are kept between updates. (Exception: the k-d tree, whose
//!   kiddo tree is rebuilt, and so allocated, on every update.)
//! * **Periodic domains** (minimum image): [`UniformGrid::periodic`] and
//!   [`BruteForce::periodic`]. Sweep-and-prune and the k-d tree are for open space.
//!
//! With the `parallel` feature (default), [`ParallelBroadPhase::par_pairs`] finds the
//! pairs with rayon on the current thread pool and returns the same `Vec` as
//! [`BroadPhase::pairs`].
//!
//! [`scenes`] generates the random scenes the tests, benches and reports share.

mod brute_force;
mod grid;
mod kd_tree;
mod pairs;
mod par;
mod radix;
pub mod scenes;
mod sweep;
mod volumes;

pub use brute_force::BruteForce;
pub use carom_geometry::{Aabb, Border, InvalidValue, Real, Vector};
pub use grid::{GridLayout, UniformGrid};
pub use kd_tree::KdTree;
pub use pairs::{NeighbourLists, Pair};
pub use sweep::{SortKind, SortPolicy, SweepAndPrune};
pub use volumes::{Balls, Volumes};

/// A broad phase over `D`-dimensional bounding volumes with scalar `T`.
pub trait BroadPhase<T: Real, const D: usize> {
    /// Replaces the volumes with this frame's. Indices in pairs and query results refer
    /// to positions in `volumes`.
    fn update(&mut self, volumes: Volumes<'_, T, D>);

    /// The number of volumes of the last update.
    fn len(&self) -> usize;

    /// `true` if the last update had no volumes.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes every overlapping pair into `out` (cleared first), sorted
    /// lexicographically.
    fn pairs(&mut self, out: &mut Vec<Pair>);

    /// Writes the indices of the volumes that intersect `query` (touching counts) into
    /// `out` (cleared first), ascending.
    fn query_aabb(&self, query: &Aabb<T, D>, out: &mut Vec<u32>);

    /// Writes the indices of the volumes that intersect the ball `(center, radius)`
    /// (touching counts) into `out` (cleared first), ascending. A ball volume `j` is
    /// hit when `|c_j − center| <= r_j + radius`: querying ball `i` with
    /// `radius = r_i + shell` gives its neighbours within a shell. A negative or
    /// non-finite radius hits nothing.
    fn query_ball(&self, center: &Vector<T, D>, radius: T, out: &mut Vec<u32>);
}

/// A broad phase whose pair finding runs in parallel with rayon.
#[cfg(feature = "parallel")]
pub trait ParallelBroadPhase<T: Real, const D: usize>: BroadPhase<T, D> + Send {
    /// [`BroadPhase::update`] with its data-parallel passes on the current rayon thread
    /// pool; the broad phase ends in the same state (the default runs `update`).
    fn par_update(&mut self, volumes: Volumes<'_, T, D>) {
        self.update(volumes);
    }

    /// [`BroadPhase::pairs`] on the current rayon thread pool; the result is identical.
    fn par_pairs(&mut self, out: &mut Vec<Pair>);
}

/// How many chunks parallel traversals split their work into: a few per thread, so
/// that uneven chunks balance. The result never depends on it.
#[cfg(feature = "parallel")]
fn parallel_chunks() -> usize {
    4 * rayon::current_num_threads()
}

/// The `c`-th of `chunks` near-equal consecutive ranges of `0..n`.
fn chunk_range(c: usize, chunks: usize, n: usize) -> core::ops::Range<usize> {
    (c * n / chunks)..((c + 1) * n / chunks)
}

/// Concrete 2D broad phases, `f64` unless a scalar is given.
pub mod d2 {
    /// Every pair tested.
    pub type BruteForce<T = f64> = crate::BruteForce<T, 2>;
    /// Sweep-and-prune.
    pub type SweepAndPrune<T = f64> = crate::SweepAndPrune<T, 2>;
    /// k-d tree over centres.
    pub type KdTree<T = f64> = crate::KdTree<T, 2>;
    /// Uniform grid.
    pub type UniformGrid<T = f64> = crate::UniformGrid<T, 2>;
    /// Input volumes.
    pub type Volumes<'a, T = f64> = crate::Volumes<'a, T, 2>;
    /// Input balls.
    pub type Balls<'a, T = f64> = crate::Balls<'a, T, 2>;
}

/// Concrete 3D broad phases, `f64` unless a scalar is given.
pub mod d3 {
    /// Every pair tested.
    pub type BruteForce<T = f64> = crate::BruteForce<T, 3>;
    /// Sweep-and-prune.
    pub type SweepAndPrune<T = f64> = crate::SweepAndPrune<T, 3>;
    /// k-d tree over centres.
    pub type KdTree<T = f64> = crate::KdTree<T, 3>;
    /// Uniform grid.
    pub type UniformGrid<T = f64> = crate::UniformGrid<T, 3>;
    /// Input volumes.
    pub type Volumes<'a, T = f64> = crate::Volumes<'a, T, 3>;
    /// Input balls.
    pub type Balls<'a, T = f64> = crate::Balls<'a, T, 3>;
}
