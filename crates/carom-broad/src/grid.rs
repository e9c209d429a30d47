//! Uniform grids: cells the size of the largest regular volume, dense, hashed or
//! periodic, with a separate path for oversized volumes.
//!
//! Each volume is assigned to the cell of its centre. With cells at least as wide as
//! the largest volume, two overlapping volumes sit in the same or in adjacent cells, so
//! each cell is tested against itself and against the "forward" half of its neighbours
//! (4 in 2D, 13 in 3D): every neighbouring cell pair is visited once.
//!
//! * **Cell size.** `oversize_ratio × median` (default 2) of the volumes' largest edge
//!   lengths (the median estimated from at most 1025 strided samples) separates regular
//!   volumes from oversized ones; the cell is the largest regular edge, grown by `2^-10`
//!   relative and `16 ε_T · scale` absolute so that no rounding can put two touching
//!   volumes two cells apart, even at `1e6` from the origin.
//! * **Bucketing.** `(bucket, index)` keys are radix-sorted, or insertion-sorted from the
//!   previous frame's order when the frame is coherent; `start[bucket]` is then filled
//!   in one pass over the sorted keys (on the rayon pool: disjoint runs of `start`, one
//!   per chunk of keys) and the volumes are gathered in bucket order. No per-cell
//!   `Vec`, and no random scatter over an array the size of the grid. Each volume's
//!   largest edge is computed once; the cell width, the coordinate scale and the
//!   bounding box of the centres come from one fused pass over the volumes.
//! * **Oversized volumes** stay out of the cells. From 32 of them on they form a coarser
//!   level: a grid of the same layout over just them, with its own median and cell size
//!   (and, recursively, its own coarser level; each level at least halves the count, so
//!   radii over many decades make a few levels, not a deep tree). A volume of a finer
//!   level is smaller than every volume of a coarser one and the coarser cells are as
//!   wide as their largest volume, so it finds its coarser partners in the `3^D` cells
//!   around its centre's cell on each coarser level. Fewer than 32 oversized volumes are
//!   instead tested against the regular volumes of the cells their box (grown by half a
//!   cell) covers, or against all of them when that is fewer, and meet each other in a
//!   sweep-and-prune (in a periodic domain, by brute force).
//! * **Layouts.** [`GridLayout::Dense`] spans the bounding box of this frame's centres
//!   with at most `8N + 64` cells (the cell grows if the scene is sparse), plus one
//!   empty padding cell on each side so that neighbours are fixed linear offsets;
//!   [`GridLayout::Hashed`] hashes integer cell coordinates into a table of about `2N`
//!   buckets, for unbounded or sparse worlds (a bucket can hold several cells, so each
//!   entry keeps its cell coordinates and only entries of the wanted cell are tested);
//!   [`GridLayout::Periodic`] tiles a periodic [`Border`] with whole cells and wraps the
//!   neighbours around (the cell lists of event-driven codes). A periodic box needs at
//!   least 3 cells per axis; a smaller one puts every volume on the brute-force path.
//!   In a periodic domain overlaps use the minimum image, which is unique while every
//!   volume is smaller than a third of the period; pairs are reported once.

use carom_geometry::{Aabb, Border};
use carom_math::{Real, Vector};

use crate::pairs::{Emitter, PairBuffers};
use crate::par::{fill_indexed, fold_indexed, try_map_in_place};
use crate::radix::{entry, entry_id, entry_key, insertion_sort_bounded, sort_by_key};
use crate::sweep::{SortPolicy, SweepCore};
use crate::volumes::{Proxy, Store, ensure_ratio, overlap, sampled_median};
use crate::{BroadPhase, Pair, Volumes};

/// How a [`UniformGrid`] lays its cells out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridLayout<T: Real, const D: usize> {
    /// A dense array over the bounding box of the current centres.
    Dense,
    /// A hash table of about `2N` buckets over unbounded integer cell coordinates.
    Hashed,
    /// A dense array tiling a periodic domain, with wrap-around neighbours.
    Periodic(Border<T, D>),
}

/// Cell coordinates are `i32`: the grid never has more than `2^30` cells per axis.
type Cell<const D: usize> = [i32; D];

const MAX_CELLS_PER_AXIS: f64 = (1u64 << 30) as f64;

/// The cell geometry of one update.
#[derive(Clone, Copy, Debug)]
struct Geometry<const D: usize> {
    origin: [f64; D],
    inv_cell: [f64; D],
    /// Cells per axis (dense and periodic).
    dims: [i64; D],
    /// Buckets: cells (dense, periodic) or the hash table size (a power of two).
    buckets: usize,
    hashed: bool,
    periodic: bool,
}

impl<const D: usize> Geometry<D> {
    /// `true` for the dense layout (open space, buckets are cells).
    fn is_dense(&self) -> bool {
        !self.hashed && !self.periodic
    }

    /// The cell of a point.
    #[inline]
    fn cell(&self, p: &[f64; D]) -> Cell<D> {
        core::array::from_fn(|k| {
            let u = floor_to_i64((p[k] - self.origin[k]) * self.inv_cell[k]);
            if self.periodic {
                u.rem_euclid(self.dims[k]) as i32
            } else if self.hashed {
                u as i32
            } else {
                // Dense: one empty padding cell on each side.
                (u.clamp(0, self.dims[k] - 3) + 1) as i32
            }
        })
    }

    /// The bucket of a cell (in range for dense and periodic cells).
    #[inline]
    fn bucket(&self, c: &Cell<D>) -> usize {
        if self.hashed {
            const PRIMES: [u64; 3] = [73_856_093, 19_349_663, 83_492_791];
            let h = (0..D).fold(0u64, |h, k| {
                h ^ (c[k] as u64).wrapping_mul(PRIMES[k % 3] << (k / 3))
            });
            let bits = self.buckets.trailing_zeros();
            (h.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits)) as usize
        } else {
            (0..D)
                .rev()
                .fold(0usize, |b, k| b * self.dims[k] as usize + c[k] as usize)
        }
    }

    /// The neighbour of `c` at `offset`, wrapped in a periodic grid; `None` outside a
    /// dense one.
    #[inline]
    fn neighbour(&self, c: &Cell<D>, offset: &Cell<D>) -> Option<Cell<D>> {
        let mut n = [0i32; D];
        for k in 0..D {
            let x = i64::from(c[k]) + i64::from(offset[k]);
            n[k] = if self.periodic {
                x.rem_euclid(self.dims[k]) as i32
            } else if self.hashed {
                x as i32
            } else if x < 0 || x >= self.dims[k] {
                return None;
            } else {
                x as i32
            };
        }
        Some(n)
    }

    /// The unwrapped cell-coordinate range covering `[lo, hi]` on every axis.
    fn range(&self, lo: &[f64; D], hi: &[f64; D]) -> ([i64; D], [i64; D]) {
        let pad = i64::from(!self.periodic && !self.hashed);
        let f = |p: &[f64; D], k: usize| {
            ((p[k] - self.origin[k]) * self.inv_cell[k])
                .floor()
                .clamp(-4e18, 4e18) as i64
                + pad
        };
        let mut a: [i64; D] = core::array::from_fn(|k| f(lo, k));
        let mut b: [i64; D] = core::array::from_fn(|k| f(hi, k));
        for k in 0..D {
            if self.periodic {
                if b[k] - a[k] + 1 >= self.dims[k] {
                    (a[k], b[k]) = (0, self.dims[k] - 1);
                }
            } else if !self.hashed {
                (a[k], b[k]) = (a[k].max(0), b[k].min(self.dims[k] - 1));
            }
        }
        (a, b)
    }
}

/// `⌊x⌋` as an integer (saturating), without a libm call: truncate, then step down for
/// negative non-integers.
#[inline]
fn floor_to_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// Fills `start` (resized to `buckets + 1`) so that `start[b]` is the first position in
/// the sorted `keys` whose bucket is `>= b` (`keys.len()` past the last one): one
/// sequential pass, or, on the rayon pool, one per chunk of keys, each writing the
/// disjoint run of `start` that its keys determine (so the result is the same).
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
fn fill_starts(start: &mut Vec<u32>, buckets: usize, keys: &[u64], parallel: bool) {
    start.resize(buckets + 1, 0);
    let n = keys.len();
    // Chunk [p, q) of the keys writes start[x] for x from (the bucket of key p − 1) + 1
    // up to the bucket of key q − 1, and the last chunk the rest of the array too.
    let fill = |run: &mut [u32], first: usize, p: usize, q: usize| {
        let mut b = first;
        for (k, &e) in keys[p..q].iter().enumerate() {
            // Keys of a bucket already started (here or in the previous chunk) add nothing.
            let end = entry_key(e) as usize + 1;
            if end > b {
                run[b - first..end - first].fill((p + k) as u32);
                b = end;
            }
        }
        run[b - first..].fill(q as u32);
    };
    let first_of = |p: usize| {
        if p == 0 {
            0
        } else {
            entry_key(keys[p - 1]) as usize + 1
        }
    };
    #[cfg(feature = "parallel")]
    if parallel && n >= crate::par::MIN_PARALLEL {
        use rayon::prelude::*;
        let chunks = crate::parallel_chunks();
        let mut runs = Vec::with_capacity(chunks);
        let mut rest = start.as_mut_slice();
        for c in 0..chunks {
            let range = crate::chunk_range(c, chunks, n);
            let (from, to) = (first_of(range.start), first_of(range.end));
            let (run, tail) = if c + 1 == chunks {
                (core::mem::take(&mut rest), &mut [][..])
            } else {
                rest.split_at_mut(to - from)
            };
            runs.push((run, from, range));
            rest = tail;
        }
        runs.into_par_iter()
            .for_each(|(run, from, range)| fill(run, from, range.start, range.end));
        return;
    }
    fill(start, 0, 0, n);
}

/// The forward half of the neighbour offsets: those whose last non-zero component is
/// positive (4 in 2D, 13 in 3D). With the cell itself they visit each adjacent pair of
/// cells once.
fn forward_offsets<const D: usize>() -> Vec<Cell<D>> {
    let mut out = Vec::new();
    for code in 0..3usize.pow(D as u32) {
        let mut rest = code;
        let o: Cell<D> = core::array::from_fn(|_| {
            let d = [-1, 0, 1][rest % 3];
            rest /= 3;
            d
        });
        if o.iter().rev().find(|&&d| d != 0) == Some(&1) {
            out.push(o);
        }
    }
    out
}

/// Every offset in `{-1, 0, 1}^D`.
fn all_offsets<const D: usize>() -> Vec<Cell<D>> {
    (0..3usize.pow(D as u32))
        .map(|code| {
            let mut rest = code;
            core::array::from_fn(|_| {
                let d = [-1, 0, 1][rest % 3];
                rest /= 3;
                d
            })
        })
        .collect()
}

/// What the cell geometry needs from the regular volumes: their largest extent, the
/// largest `|centre|_∞ + extent` (the coordinate scale of roundings) and the bounding box
/// of their centres.
#[derive(Clone, Copy, Debug)]
struct RegularBounds<const D: usize> {
    width: f64,
    scale: f64,
    lo: [f64; D],
    hi: [f64; D],
}

impl<const D: usize> RegularBounds<D> {
    fn empty() -> Self {
        Self {
            width: 0.0,
            scale: 0.0,
            lo: [f64::INFINITY; D],
            hi: [f64::NEG_INFINITY; D],
        }
    }

    /// These bounds grown to cover a volume with largest edge `extent`.
    #[inline]
    fn with<T: Real>(mut self, p: &Proxy<T, D>, extent: f64) -> Self {
        self.width = self.width.max(extent);
        let mut amax = 0.0_f64;
        for k in 0..D {
            let c = p.center[k].to_f64();
            amax = amax.max(c.abs());
            self.lo[k] = self.lo[k].min(c);
            self.hi[k] = self.hi[k].max(c);
        }
        self.scale = self.scale.max(amax + extent);
        self
    }

    fn merge(a: Self, b: Self) -> Self {
        Self {
            width: a.width.max(b.width),
            scale: a.scale.max(b.scale),
            lo: core::array::from_fn(|k| a.lo[k].min(b.lo[k])),
            hi: core::array::from_fn(|k| a.hi[k].max(b.hi[k])),
        }
    }
}

/// One regular volume in bucket order.
#[derive(Clone, Copy, Debug)]
struct Entry<T: Real, const D: usize> {
    proxy: Proxy<T, D>,
    /// The caller's index (levels hold subsets; see `Store::gid`).
    id: u32,
}

/// A uniform-grid broad phase over boxes or balls.
#[derive(Clone, Debug)]
pub struct UniformGrid<T: Real, const D: usize> {
    store: Store<T, D>,
    layout: GridLayout<T, D>,
    oversize_ratio: f64,
    offsets: Vec<Cell<D>>,
    geometry: Option<Geometry<D>>,
    /// Half the cell width, rounded up: how far a regular centre can be from its box.
    reach: f64,
    start: Vec<u32>,
    entries: Vec<Entry<T, D>>,
    /// The cell of each entry, for the hashed layout (where a bucket can hold several
    /// cells) and the periodic one (whose search wraps cell coordinates); empty for the
    /// dense layout, whose buckets are its cells.
    cells: Vec<Cell<D>>,
    /// Sorted `(bucket, index)` keys of the regular volumes (kept for the next frame).
    keys: Vec<u64>,
    scratch: Vec<u64>,
    counts: Vec<usize>,
    /// Per volume: its largest edge length.
    extents: Vec<f64>,
    /// Per volume: `true` if it is in the cells this frame.
    in_cells: Vec<bool>,
    /// Per volume: its bucket, or `u32::MAX` when it is not in the cells.
    bucket_of: Vec<u32>,
    regular: Vec<u32>,
    oversized: Vec<u32>,
    oversized_sweep: SweepCore<T, D>,
    /// The grid over this level's oversized volumes, when there are enough of them.
    coarser: Option<Box<UniformGrid<T, D>>>,
    coarser_active: bool,
    /// All `3^D` neighbour offsets, the cell itself included (for lookups from finer levels).
    all_offsets: Vec<Cell<D>>,
    selection: Vec<f64>,
    buffers: PairBuffers,
}

/// From this many oversized volumes on, they get a coarser grid level of their own
/// instead of walking the cells of this one.
const COARSER_LEVEL_MIN: usize = 32;

impl<T: Real, const D: usize> UniformGrid<T, D> {
    /// A grid with the given layout and cells sized for volumes up to 2 × the median.
    pub fn new(layout: GridLayout<T, D>) -> Self {
        let mut store = Store::default();
        if let GridLayout::Periodic(border) = &layout {
            store.set_period(Some(border));
        }
        Self {
            store,
            layout,
            oversize_ratio: 2.0,
            offsets: forward_offsets(),
            geometry: None,
            reach: 0.0,
            start: Vec::new(),
            entries: Vec::new(),
            cells: Vec::new(),
            keys: Vec::new(),
            scratch: Vec::new(),
            counts: Vec::new(),
            extents: Vec::new(),
            in_cells: Vec::new(),
            bucket_of: Vec::new(),
            regular: Vec::new(),
            oversized: Vec::new(),
            oversized_sweep: SweepCore::default(),
            coarser: None,
            coarser_active: false,
            all_offsets: all_offsets(),
            selection: Vec::new(),
            buffers: PairBuffers::default(),
        }
    }

    /// A dense grid over the bounding box of each frame's centres.
    pub fn dense() -> Self {
        Self::new(GridLayout::Dense)
    }

    /// A hashed grid for unbounded worlds.
    pub fn hashed() -> Self {
        Self::new(GridLayout::Hashed)
    }

    /// A grid tiling the periodic domain `border` (minimum image).
    pub fn periodic(border: Border<T, D>) -> Self {
        Self::new(GridLayout::Periodic(border))
    }

    /// The same grid with volumes larger than `ratio` × the median edge length kept
    /// out of the cells (`f64::INFINITY`: none; the cells then fit the largest volume).
    ///
    /// # Errors
    /// `ratio` if it is NaN or below 1.
    pub fn with_oversize_ratio(mut self, ratio: f64) -> Result<Self, carom_math::InvalidValue> {
        self.oversize_ratio = ensure_ratio(ratio)?;
        Ok(self)
    }

    /// The layout.
    pub fn layout(&self) -> &GridLayout<T, D> {
        &self.layout
    }

    /// How many volumes the last update kept out of the finest cells.
    pub fn oversized(&self) -> usize {
        self.oversized.len()
    }

    /// How many grid levels the last update built: 1, plus one per coarser level made
    /// for the oversized volumes of the level below (each at least halves the count).
    pub fn levels(&self) -> usize {
        1 + self.coarser_level().map_or(0, Self::levels)
    }

    /// The cell counts per axis of the last update (dense and periodic layouts).
    pub fn dims(&self) -> Option<[usize; D]> {
        let g = self.geometry.as_ref().filter(|g| !g.hashed)?;
        // Dense grids carry one padding cell on each side.
        let pad = if g.periodic { 0 } else { 2 };
        Some(g.dims.map(|d| (d - pad) as usize))
    }

    /// Chooses the cell geometry for the regular volumes, or `None` when there is no
    /// usable grid (no regular volume, or a periodic box under 3 cells wide).
    fn choose_geometry(&self, bounds: &RegularBounds<D>, scale: f64) -> Option<Geometry<D>> {
        let n = self.regular.len();
        let cell_width = bounds.width;
        if n == 0 {
            return None;
        }
        let eps = T::EPSILON.to_f64();
        let mut width = cell_width * (1.0 + 1.0 / 1024.0) + 16.0 * eps * scale;
        if width.is_nan() || width <= 0.0 {
            width = 1.0;
        }
        let max_cells = (8 * n + 64) as f64;
        match &self.layout {
            GridLayout::Periodic(border) => {
                let (origin, len) = (border.min(), border.extents());
                let mut dims: [i64; D] = core::array::from_fn(|k| {
                    (len[k].to_f64() / width).floor().min(MAX_CELLS_PER_AXIS) as i64
                });
                let total: f64 = dims.iter().map(|&d| d.max(1) as f64).product();
                if total > max_cells {
                    let shrink = (total / max_cells).powf(1.0 / D as f64) * 1.01;
                    dims = dims.map(|d| (d as f64 / shrink).floor() as i64);
                }
                if dims.iter().any(|&d| d < 3) {
                    return None;
                }
                Some(Geometry {
                    origin: core::array::from_fn(|k| origin[k].to_f64()),
                    inv_cell: core::array::from_fn(|k| dims[k] as f64 / len[k].to_f64()),
                    buckets: dims.iter().map(|&d| d as usize).product(),
                    dims,
                    hashed: false,
                    periodic: true,
                })
            }
            layout => {
                let hashed = matches!(layout, GridLayout::Hashed);
                let (lo, hi) = (bounds.lo, bounds.hi);
                let span = (0..D).fold(0.0_f64, |s, k| s.max(hi[k] - lo[k]));
                width = width.max(span / MAX_CELLS_PER_AXIS);
                // Dense grids get an empty padding cell on each side, so that every
                // neighbour of an occupied cell exists.
                let pad = if hashed { 1 } else { 3 };
                let dims_for = |w: f64| -> [i64; D] {
                    core::array::from_fn(|k| ((hi[k] - lo[k]) / w).floor() as i64 + pad)
                };
                let mut dims = dims_for(width);
                if !hashed {
                    let total: f64 = dims.iter().map(|&d| d as f64).product();
                    if total > max_cells {
                        width *= (total / max_cells).powf(1.0 / D as f64) * 1.01;
                        dims = dims_for(width);
                    }
                }
                Some(Geometry {
                    origin: lo,
                    inv_cell: [1.0 / width; D],
                    buckets: if hashed {
                        (2 * n).next_power_of_two().max(16)
                    } else {
                        dims.iter().map(|&d| d as usize).product()
                    },
                    dims,
                    hashed,
                    periodic: false,
                })
            }
        }
    }

    /// Calls `f` with the position (in `entries`) of every regular volume whose cell
    /// lies in the cell range covering `[lo, hi]`, or of every regular volume when that
    /// range has more cells than there are volumes.
    fn for_each_regular_near(&self, lo: &[f64; D], hi: &[f64; D], mut f: impl FnMut(usize)) {
        let Some(g) = &self.geometry else { return };
        let (a, b) = g.range(lo, hi);
        let count = (0..D).try_fold(1u64, |acc, k| {
            let span = u64::try_from(b[k] - a[k] + 1).unwrap_or(0);
            acc.checked_mul(span)
        });
        match count {
            Some(0) => {}
            Some(c) if c <= self.entries.len() as u64 => {
                let mut cur = a;
                'cells: loop {
                    let cell: Cell<D> = core::array::from_fn(|k| {
                        if g.periodic {
                            cur[k].rem_euclid(g.dims[k]) as i32
                        } else {
                            cur[k] as i32
                        }
                    });
                    let bucket = g.bucket(&cell);
                    for m in self.start[bucket] as usize..self.start[bucket + 1] as usize {
                        if !g.hashed || self.cells[m] == cell {
                            f(m);
                        }
                    }
                    for k in 0..D {
                        if cur[k] < b[k] {
                            cur[k] += 1;
                            continue 'cells;
                        }
                        cur[k] = a[k];
                    }
                    break;
                }
            }
            _ => (0..self.entries.len()).for_each(f),
        }
    }

    /// Emits share `c` of `chunks` of this level's pairs and of every coarser level's:
    /// the regular pairs of this level, the pairs of this level's regular volumes with
    /// coarser levels, and recursively the coarser levels' own (or, without a coarser
    /// level, the pairs of the oversized volumes).
    fn search(&self, c: usize, chunks: usize, emit: &mut Emitter<'_>) {
        let regular = crate::chunk_range(c, chunks, self.entries.len());
        match &self.geometry {
            Some(g) if g.is_dense() => self.search_dense(g, regular.clone(), emit),
            Some(g) => self.search_general(g, regular.clone(), emit),
            None => {}
        }
        match self.coarser_level() {
            Some(coarser) => {
                let (balls, period) = (self.store.balls, self.store.period.as_ref());
                for a in &self.entries[regular] {
                    let center = a.proxy.center.map(Real::to_f64).into();
                    coarser.for_each_near(&center, &mut |p, id| {
                        if overlap(&a.proxy, p, balls, period) {
                            emit.push(a.id, id);
                        }
                    });
                }
                coarser.search(c, chunks, emit);
            }
            None => {
                self.search_oversized(crate::chunk_range(c, chunks, self.oversized.len()), emit);
            }
        }
    }

    /// The coarser level, when this update built one.
    fn coarser_level(&self) -> Option<&Self> {
        self.coarser.as_deref().filter(|_| self.coarser_active)
    }

    /// Calls `f` with every volume of this level and the coarser ones that can overlap a
    /// volume centred at `center` no larger than this level's volumes (its proxy and
    /// caller index): the `3^D` cells around the centre's cell, then the coarser level
    /// (or, without one, every oversized volume). A finer volume is smaller than every
    /// volume here, and cells are as wide as the largest, so the centres of overlapping
    /// volumes are at most one cell apart.
    fn for_each_near(&self, center: &[f64; D], f: &mut dyn FnMut(&Proxy<T, D>, u32)) {
        if let Some(g) = &self.geometry {
            let cell = g.cell(center);
            for offset in &self.all_offsets {
                let Some(n) = g.neighbour(&cell, offset) else {
                    continue;
                };
                let bucket = g.bucket(&n);
                for m in self.start[bucket] as usize..self.start[bucket + 1] as usize {
                    if !g.hashed || self.cells[m] == n {
                        let e = &self.entries[m];
                        f(&e.proxy, e.id);
                    }
                }
            }
        }
        match self.coarser_level() {
            Some(coarser) => coarser.for_each_near(center, f),
            None => {
                for &i in &self.oversized {
                    f(&self.store.proxies[i as usize], self.store.gid(i));
                }
            }
        }
    }

    /// The regular pairs of a dense grid: thanks to the padding, the forward neighbours
    /// of the cell with bucket `b` are the buckets `b + o` for fixed linear offsets `o`.
    fn search_dense(
        &self,
        g: &Geometry<D>,
        regular: core::ops::Range<usize>,
        emit: &mut Emitter<'_>,
    ) {
        let balls = self.store.balls;
        let mut linear = [0isize; 13];
        for (l, offset) in linear.iter_mut().zip(&self.offsets) {
            let mut stride = 1isize;
            for (&o, &dim) in offset.iter().zip(&g.dims) {
                *l += o as isize * stride;
                stride *= dim as isize;
            }
        }
        let linear = &linear[..self.offsets.len()];
        for k in regular {
            let a = &self.entries[k];
            let base = entry_key(self.keys[k]) as usize;
            for b in &self.entries[k + 1..self.start[base + 1] as usize] {
                if overlap(&a.proxy, &b.proxy, balls, None) {
                    emit.push(a.id, b.id);
                }
            }
            for &offset in linear {
                let bucket = base.wrapping_add_signed(offset);
                let (from, to) = (self.start[bucket] as usize, self.start[bucket + 1] as usize);
                for b in &self.entries[from..to] {
                    if overlap(&a.proxy, &b.proxy, balls, None) {
                        emit.push(a.id, b.id);
                    }
                }
            }
        }
    }

    /// The regular pairs of a hashed or periodic grid (wrapped neighbours, colliding
    /// cells told apart by their coordinates).
    fn search_general(
        &self,
        g: &Geometry<D>,
        regular: core::ops::Range<usize>,
        emit: &mut Emitter<'_>,
    ) {
        let (balls, period) = (self.store.balls, self.store.period.as_ref());
        for k in regular {
            let (a, a_cell) = (&self.entries[k], &self.cells[k]);
            let end = self.start[g.bucket(a_cell) + 1] as usize;
            for m in k + 1..end {
                let b = &self.entries[m];
                if self.cells[m] == *a_cell && overlap(&a.proxy, &b.proxy, balls, period) {
                    emit.push(a.id, b.id);
                }
            }
            for offset in &self.offsets {
                let Some(cell) = g.neighbour(a_cell, offset) else {
                    continue;
                };
                let bucket = g.bucket(&cell);
                for m in self.start[bucket] as usize..self.start[bucket + 1] as usize {
                    let b = &self.entries[m];
                    if self.cells[m] == cell && overlap(&a.proxy, &b.proxy, balls, period) {
                        emit.push(a.id, b.id);
                    }
                }
            }
        }
    }

    /// The pairs of the oversized volumes at list positions `oversized`: with the
    /// regular volumes near them, and with each other.
    fn search_oversized(&self, oversized: core::ops::Range<usize>, emit: &mut Emitter<'_>) {
        let (balls, period) = (self.store.balls, self.store.period.as_ref());
        for &i in &self.oversized[oversized.clone()] {
            let p = &self.store.proxies[i as usize];
            let lo = core::array::from_fn(|k| p.aabb.min()[k].to_f64() - self.reach);
            let hi = core::array::from_fn(|k| p.aabb.max()[k].to_f64() + self.reach);
            let gi = self.store.gid(i);
            self.for_each_regular_near(&lo, &hi, |m| {
                let b = &self.entries[m];
                if overlap(p, &b.proxy, balls, period) {
                    emit.push(gi, b.id);
                }
            });
        }
        if period.is_some() {
            for (x, &i) in self
                .oversized
                .iter()
                .enumerate()
                .skip(oversized.start)
                .take(oversized.len())
            {
                for &j in &self.oversized[x + 1..] {
                    if self.store.overlap(i as usize, j as usize) {
                        emit.push(self.store.gid(i), self.store.gid(j));
                    }
                }
            }
        } else {
            // The sweep sorted exactly the oversized list: split its positions the same way.
            self.oversized_sweep
                .sweep(oversized, balls, &self.store.global, emit);
        }
    }

    /// Calls `f` with the caller index of every volume, on this level and the coarser
    /// ones, that may meet the box `[lo, hi]`: regular volumes of the cells near it, then
    /// the coarser level's candidates, or this level's oversized volumes.
    fn candidates(&self, lo: &[f64; D], hi: &[f64; D], f: &mut dyn FnMut(u32)) {
        let lo_reach = core::array::from_fn(|k| lo[k] - self.reach);
        let hi_reach = core::array::from_fn(|k| hi[k] + self.reach);
        self.for_each_regular_near(&lo_reach, &hi_reach, |m| f(self.entries[m].id));
        match self.coarser_level() {
            Some(coarser) => coarser.candidates(lo, hi, f),
            None if self.store.period.is_some() => {
                for &i in &self.oversized {
                    f(self.store.gid(i));
                }
            }
            None => {
                let axis = self.oversized_sweep.axis();
                self.oversized_sweep
                    .candidates(lo[axis], hi[axis], |i| f(self.store.gid(i)));
            }
        }
    }

    /// Query helper: the candidates near `[lo, hi]` that pass `hit`, ascending.
    fn query(
        &self,
        lo: &Vector<T, D>,
        hi: &Vector<T, D>,
        hit: impl Fn(usize) -> bool,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let lo64 = core::array::from_fn(|k| lo[k].to_f64());
        let hi64 = core::array::from_fn(|k| hi[k].to_f64());
        self.candidates(&lo64, &hi64, &mut |id| {
            if hit(id as usize) {
                out.push(id);
            }
        });
        out.sort_unstable();
    }
}

impl<T: Real, const D: usize> UniformGrid<T, D> {
    /// The update, its element-wise passes on the rayon pool when `parallel`.
    fn rebuild(&mut self, volumes: Volumes<'_, T, D>, parallel: bool) {
        self.store.load(volumes, parallel);
        self.rebuild_stored(parallel, 0.0);
    }

    /// Builds this level from the volumes already in the store; `scale_floor` is the
    /// coordinate scale of the finer levels, whose centres look up cells here.
    fn rebuild_stored(&mut self, parallel: bool, scale_floor: f64) {
        let n = self.store.len();
        let proxies = &self.store.proxies;

        // Regular volumes (in the cells) and oversized ones, from each volume's largest
        // edge, computed once.
        fill_indexed(&mut self.extents, n, parallel, |i| {
            proxies[i].extent().to_f64()
        });
        let extents = &self.extents;
        let threshold =
            self.oversize_ratio * sampled_median(n, |i| extents[i], &mut self.selection);
        fill_indexed(&mut self.in_cells, n, parallel, |i| extents[i] <= threshold);
        // One pass over the regular volumes for the cell width, the coordinate scale and
        // the bounding box of the centres (maxima and minima: exact in any order).
        let in_cells = &self.in_cells;
        let bounds = fold_indexed(
            n,
            parallel,
            RegularBounds::empty,
            |b, i| {
                if in_cells[i] {
                    b.with(&proxies[i], extents[i])
                } else {
                    b
                }
            },
            RegularBounds::merge,
        );
        self.regular.clear();
        self.oversized.clear();
        for (i, &inside) in self.in_cells.iter().enumerate() {
            if inside {
                self.regular.push(i as u32);
            } else {
                self.oversized.push(i as u32);
            }
        }
        let scale = bounds.scale.max(scale_floor);
        self.geometry = self.choose_geometry(&bounds, scale);
        if self.geometry.is_none() {
            self.oversized.clear();
            self.oversized.extend(0..n as u32);
            self.regular.clear();
            self.in_cells.fill(false);
        }
        self.reach = match &self.geometry {
            Some(g) => (0..D).fold(0.0_f64, |r, k| r.max(0.5 / g.inv_cell[k])) * (1.0 + 1e-9),
            None => 0.0,
        };

        if let Some(g) = self.geometry {
            self.sort_into_cells(&g, parallel);
        } else {
            self.keys.clear();
            self.entries.clear();
            self.cells.clear();
            self.start.clear();
        }
        self.build_oversized(parallel, scale);
    }

    /// Sorts the regular volumes by bucket as (bucket, index) keys: an insertion sort
    /// from the previous frame's order when the set of regular volumes is unchanged
    /// (coherent frames: few volumes change cells), a radix sort otherwise. Both give
    /// the same order; unlike a counting sort straight into the bucket array, neither
    /// scatters at random over memory the size of the grid. Then fills `start` and
    /// gathers the entries in bucket order.
    fn sort_into_cells(&mut self, g: &Geometry<D>, parallel: bool) {
        let n = self.store.len();
        let proxies = &self.store.proxies;
        let cell_of = |id: u32| g.cell(&proxies[id as usize].center.map(Real::to_f64).into());
        // Buckets in index order, a sequential pass over the volumes, so that the
        // re-keying in sorted order below reads 4 bytes per volume at random, not a
        // whole volume.
        let in_cells = &self.in_cells;
        fill_indexed(&mut self.bucket_of, n, parallel, |i| {
            if in_cells[i] {
                g.bucket(&cell_of(i as u32)) as u32
            } else {
                u32::MAX
            }
        });
        let bucket_of = &self.bucket_of;
        let regular = self.regular.len();
        // The previous keys name exactly this frame's regular volumes when there are as
        // many and each is regular (coarser levels renumber their volumes every frame,
        // so an index may also be out of range).
        let coherent = self.keys.len() == regular
            && try_map_in_place(&mut self.keys, parallel, |e| {
                match bucket_of.get(entry_id(e) as usize) {
                    Some(&b) if b != u32::MAX => Some(entry(b, entry_id(e))),
                    _ => None,
                }
            })
            && insertion_sort_bounded(&mut self.keys, 4 * regular);
        if !coherent {
            let ids = &self.regular;
            fill_indexed(&mut self.keys, regular, parallel, |x| {
                entry(bucket_of[ids[x] as usize], ids[x])
            });
            sort_by_key(
                &mut self.keys,
                &mut self.scratch,
                &mut self.counts,
                parallel,
            );
        }
        fill_starts(&mut self.start, g.buckets, &self.keys, parallel);
        let (keys, store) = (&self.keys, &self.store);
        fill_indexed(&mut self.entries, regular, parallel, |k| {
            let id = entry_id(keys[k]);
            Entry {
                proxy: proxies[id as usize],
                id: store.gid(id),
            }
        });
        if g.is_dense() {
            self.cells.clear();
        } else {
            fill_indexed(&mut self.cells, regular, parallel, |k| {
                cell_of(entry_id(keys[k]))
            });
        }
    }

    /// Puts the oversized volumes in a coarser level when there are enough of them (and
    /// this level has cells), or sorts them for their sweep (open space).
    fn build_oversized(&mut self, parallel: bool, scale: f64) {
        self.coarser_active = self.geometry.is_some() && self.oversized.len() >= COARSER_LEVEL_MIN;
        if self.coarser_active {
            let coarser = self
                .coarser
                .get_or_insert_with(|| Box::new(Self::new(self.layout)));
            coarser.oversize_ratio = self.oversize_ratio;
            coarser
                .store
                .load_subset(&self.store, &self.oversized, parallel);
            coarser.rebuild_stored(parallel, scale);
        } else if self.store.period.is_none() {
            self.oversized_sweep.build(
                &self.store,
                Some(&self.oversized),
                SortPolicy::Radix,
                parallel,
            );
        }
    }
}

impl<T: Real, const D: usize> BroadPhase<T, D> for UniformGrid<T, D> {
    fn update(&mut self, volumes: Volumes<'_, T, D>) {
        self.rebuild(volumes, false);
    }

    fn len(&self) -> usize {
        self.store.len()
    }

    fn pairs(&mut self, out: &mut Vec<Pair>) {
        let n = self.store.len();
        let mut buffers = core::mem::take(&mut self.buffers);
        buffers.prepare(n, 1, 1);
        self.search(0, 1, &mut buffers.emitter());
        buffers.sort_into(out);
        self.buffers = buffers;
    }

    fn query_aabb(&self, query: &Aabb<T, D>, out: &mut Vec<u32>) {
        self.query(
            &query.min(),
            &query.max(),
            |j| self.store.hits_box(j, query),
            out,
        );
    }

    fn query_ball(&self, center: &Vector<T, D>, radius: T, out: &mut Vec<u32>) {
        if !radius.finite() || radius < T::zero() {
            out.clear();
            return;
        }
        let r = Vector::<T, D>::repeat(radius);
        self.query(
            &(center - r),
            &(center + r),
            |j| self.store.hits_ball(j, center, radius),
            out,
        );
    }
}

#[cfg(feature = "parallel")]
impl<T: Real, const D: usize> crate::ParallelBroadPhase<T, D> for UniformGrid<T, D> {
    fn par_update(&mut self, volumes: Volumes<'_, T, D>) {
        self.rebuild(volumes, true);
    }

    fn par_pairs(&mut self, out: &mut Vec<Pair>) {
        use rayon::prelude::*;
        let n = self.store.len();
        let chunks = crate::parallel_chunks();
        let mut buffers = core::mem::take(&mut self.buffers);
        buffers.prepare(n, chunks, chunks);
        let this = &*self;
        buffers
            .emitters()
            .into_par_iter()
            .enumerate()
            .for_each(|(c, mut emit)| this.search(c, chunks, &mut emit));
        buffers.par_sort_into(out);
        self.buffers = buffers;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BruteForce;
    use crate::scenes::Scene;

    fn brute_pairs<const D: usize>(
        volumes: Volumes<'_, f64, D>,
        border: Option<&Border<f64, D>>,
    ) -> Vec<Pair> {
        let mut brute = border.map_or_else(BruteForce::new, BruteForce::periodic);
        brute.update(volumes);
        let mut pairs = Vec::new();
        brute.pairs(&mut pairs);
        pairs
    }

    #[test]
    fn mixed_radii_build_coarser_levels_that_find_every_pair() {
        let scene = Scene::<f64, 3>::mixed(3000, 1e-3, 1.0, 0.2, 11);
        let expected = brute_pairs(scene.balls(), None);
        for mut grid in [UniformGrid::dense(), UniformGrid::hashed()] {
            grid.update(scene.balls());
            assert!(grid.levels() >= 3, "{} levels", grid.levels());
            let mut pairs = Vec::new();
            grid.pairs(&mut pairs);
            assert_eq!(pairs, expected);
        }
        // Periodic: the scene's cube as the domain.
        let scene = Scene::<f64, 2>::mixed(2000, 1e-2, 1.0, 0.3, 12);
        let expected = brute_pairs(scene.balls(), Some(&scene.domain));
        let mut grid = UniformGrid::periodic(scene.domain);
        grid.update(scene.balls());
        assert!(grid.levels() >= 2, "{} levels", grid.levels());
        let mut pairs = Vec::new();
        grid.pairs(&mut pairs);
        assert_eq!(pairs, expected);
    }

    #[test]
    #[cfg(feature = "parallel")]
    fn start_fill_is_the_same_sequentially_and_in_parallel() {
        // Sorted keys with runs that straddle chunk boundaries (dense buckets) and
        // long gaps (sparse ones), above the size where the fill goes parallel.
        for (n, buckets) in [(20_000usize, 3_000usize), (20_000, 200_000), (9_000, 1)] {
            let mut state = n as u64 ^ buckets as u64;
            let mut keys: Vec<u64> = (0..n as u32)
                .map(|id| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    entry(((state >> 33) % buckets as u64) as u32, id)
                })
                .collect();
            keys.sort_unstable();
            // The definition: the first position whose bucket is >= b.
            let expected: Vec<u32> = (0..=buckets)
                .map(|b| keys.partition_point(|&e| (entry_key(e) as usize) < b) as u32)
                .collect();
            let mut start = vec![7; 5];
            fill_starts(&mut start, buckets, &keys, false);
            assert_eq!(start, expected);
            for threads in [1, 2, 3] {
                let mut start = Vec::new();
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| fill_starts(&mut start, buckets, &keys, true));
                assert_eq!(start, expected, "{threads} threads");
            }
        }
    }

    #[test]
    fn forward_offsets_are_half_of_the_neighbours() {
        assert_eq!(forward_offsets::<2>().len(), 4);
        assert_eq!(forward_offsets::<3>().len(), 13);
        let o = forward_offsets::<2>();
        for a in &o {
            assert!(!o.contains(&[-a[0], -a[1]]), "{a:?} and its opposite");
        }
    }
}
