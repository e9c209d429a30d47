//! Neighbour lists with a shell, the event-driven engine's way to find partners fast.
//!
//! Each ball `i` has an *anchor* `aᵢ` (its position when its list was last built) and a
//! shell `δ`. The list of `i` holds every `j` with `|aᵢ − aⱼ| < rᵢ + rⱼ + 2δ`. As long as
//! every ball stays within `δ` of its anchor, two balls that touch have
//! `|aᵢ − aⱼ| <= |xᵢ − xⱼ| + 2δ = rᵢ + rⱼ + 2δ`, so they are on each other's lists: only
//! list partners can collide. A ball rebuilds its list (a scheduled event) when it is
//! about to leave its shell; the relation is symmetric, so a rebuild also adds the ball
//! to its new partners' lists and removes it from the old ones (Smallenburg, J. Chem.
//! Phys. 2022, "Efficient event-driven simulations of hard spheres").
//!
//! Anchors are binned in a grid of cells at least `2 r_max + 2δ` wide, so a rebuild only
//! looks at the `3^D` cells around the anchor. Bounded domains (walls or periodic) index
//! cells directly (wrapping for periodic); unbounded ones hash the integer cell
//! coordinates into a table of about `2N` cells. A cell's balls, like a ball's partners,
//! are kept in a cache-aligned row (module `rows`; a linked list through the balls with a
//! per-ball stamp measured as fast, and needed more code). A cell met twice among the
//! `3^D` (hash clashes, fewer than 3 cells per periodic axis) is read once.
//!
//! Very mixed radii make the cells (sized by the largest ball) hold many small balls;
//! the lists stay exact, only rebuilds get slower.

use carom_geometry::{Border, Period};
use carom_math::{Real, Vector, floor_to_i64};

use super::grid::{GridIndex, MAX_AROUND};
use super::rows::IdRows;
use crate::pages::Array;
use crate::prefetch::prefetch;

/// Balls kept in a cell's row (a 64-byte row; a cell holds about 3 (2D) to 4 (3D) at the
/// engine's shell, more spill).
const CELL_ROW: usize = 15;
/// Partners kept in a ball's row (128 bytes; the engine aims at 10 (2D) to 16 (3D)).
const LIST_ROW: usize = 31;

/// A ball's anchor and radius, read together for each candidate of a rebuild.
#[derive(Clone, Copy, Debug)]
struct Anchored<T: Real, const D: usize> {
    anchor: Vector<T, D>,
    radius: T,
}

/// The domain the anchors live in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain<T: Real, const D: usize> {
    /// A box `[min, max]` that balls never leave (reflecting walls).
    Bounded {
        /// Lower corner.
        min: Vector<T, D>,
        /// Upper corner.
        max: Vector<T, D>,
    },
    /// A periodic box: separations use the minimum image.
    Periodic {
        /// Lower corner.
        min: Vector<T, D>,
        /// Upper corner.
        max: Vector<T, D>,
    },
    /// No container.
    Unbounded,
}

/// How anchors map to cell heads.
#[derive(Clone, Debug)]
enum Cells<T: Real, const D: usize> {
    /// Direct indexing into a grid over the box from `origin` (boxed: the grid's table
    /// of neighbour offsets is large beside the hashed variant).
    Direct {
        origin: Vector<T, D>,
        grid: Box<GridIndex<D>>,
    },
    /// Hashed integer coordinates into `heads.len()` (a power of two) buckets.
    Hashed,
}

/// Symmetric neighbour lists over anchored balls.
#[derive(Clone, Debug)]
pub struct NeighbourLists<T: Real, const D: usize> {
    shell: T,
    /// Inverse cell width per axis (periodic axes are tiled exactly by their cells).
    inv_cell: Vector<T, D>,
    cells: Cells<T, D>,
    /// The periods of a periodic box, for minimum images.
    period: Option<Period<T, D>>,
    /// The balls anchored in each cell.
    members: IdRows<CELL_ROW>,
    /// The cell of each ball's anchor.
    cell_of: Array<u32>,
    balls: Array<Anchored<T, D>>,
    lists: IdRows<LIST_ROW>,
    /// A rebuild's candidates (scratch, kept to avoid an allocation per rebuild).
    candidates: Vec<u32>,
}

impl<T: Real, const D: usize> NeighbourLists<T, D> {
    /// Lists for balls at `positions` with `radii`, shell `shell > 0`, in `domain`.
    /// Every ball's anchor is its current position.
    pub fn new(positions: &[Vector<T, D>], radii: &[T], shell: T, domain: Domain<T, D>) -> Self {
        assert_eq!(positions.len(), radii.len());
        assert!(
            shell > T::zero() && shell.finite(),
            "shell must be positive"
        );
        let n = positions.len();
        let r_max = radii.iter().copied().fold(T::zero(), T::max);
        let mut cell = (r_max + shell) * T::lit(2.0);
        let (cells, period, table, width) = match domain {
            Domain::Bounded { min, max } | Domain::Periodic { min, max } => {
                let periodic = matches!(domain, Domain::Periodic { .. });
                let ext = max - min;
                // Cap the table near 4N cells by widening cells in sparse boxes.
                let budget = T::from_count((4 * n).max(64));
                let needed = (ext.product() / budget).powf(T::one() / T::from_count(D));
                cell = cell.max(needed);
                let counts: [i64; D] =
                    core::array::from_fn(|k| ((ext[k] / cell).floor().to_f64() as i64).max(1));
                // Each axis is cut into whole cells, each at least `cell` wide: on a
                // periodic axis a partial last cell would break the wrap-around.
                let width =
                    Vector::<T, D>::from_fn(|k, _| ext[k] / T::from_count(counts[k] as usize));
                let total: i64 = counts.iter().product();
                (
                    Cells::Direct {
                        origin: min,
                        grid: Box::new(GridIndex::new(counts, periodic)),
                    },
                    periodic.then(|| {
                        Border::new(min, max)
                            .expect("a periodic domain is a valid box")
                            .period()
                    }),
                    total as usize,
                    width,
                )
            }
            Domain::Unbounded => (
                Cells::Hashed,
                None,
                (2 * n).next_power_of_two().max(64),
                Vector::repeat(cell),
            ),
        };
        let mut lists = Self {
            shell,
            inv_cell: width.map(|w| T::one() / w),
            cells,
            period,
            members: IdRows::new(table),
            cell_of: Array::filled(n, |_| 0),
            balls: Array::filled(n, |i| Anchored {
                anchor: positions[i],
                radius: radii[i],
            }),
            lists: IdRows::new(n),
            candidates: Vec::new(),
        };
        for i in 0..n {
            let c = lists.cell_index(&lists.balls[i].anchor);
            lists.members.push(c, i as u32);
            lists.cell_of[i] = c as u32;
        }
        let mut around = [0; MAX_AROUND];
        for i in 0..n {
            let count = lists.cells_around(&lists.balls[i].anchor, &mut around);
            let image = lists.image_around(&lists.balls[i].anchor);
            lists.collect_partners(i, &around[..count], true, image);
        }
        lists
    }

    /// The shell width `δ`.
    pub fn shell(&self) -> T {
        self.shell
    }

    /// The anchor of ball `i`.
    pub fn anchor(&self, i: usize) -> &Vector<T, D> {
        &self.balls[i].anchor
    }

    /// The partners of ball `i`, in no particular order.
    pub fn partners(&self, i: usize) -> impl Iterator<Item = u32> + '_ {
        self.lists.of(i)
    }

    /// Asks for ball `i`'s anchor and list to be brought into the cache (see
    /// `crate::prefetch`).
    #[inline]
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.balls[i]);
        self.lists.prefetch(i);
    }

    /// The integer coordinates of the neighbour `offset` (`0..3^D`) of cell `base`.
    fn around(base: [i64; D], offset: usize) -> [i64; D] {
        let mut rest = offset;
        core::array::from_fn(|k| {
            let o = (rest % 3) as i64 - 1;
            rest /= 3;
            base[k] + o
        })
    }

    /// The separation `b − a`, as the minimum image in a periodic domain.
    #[inline]
    pub fn separation(&self, a: &Vector<T, D>, b: &Vector<T, D>) -> Vector<T, D> {
        match &self.period {
            Some(period) => period.minimum_image(&(b - a)),
            None => b - a,
        }
    }

    /// Re-anchors ball `i` at `position` and rebuilds its list (and its place in its
    /// partners' lists).
    pub fn rebuild(&mut self, i: usize, position: Vector<T, D>) {
        // The cells around the new anchor are read after the old partners' lists are
        // edited: asked for first, both sets of misses overlap.
        let mut around = [0; MAX_AROUND];
        let count = self.cells_around(&position, &mut around);
        for &c in &around[..count] {
            self.members.prefetch(c);
        }
        self.lists.unlink(i);
        self.members.remove(self.cell_of[i] as usize, i as u32);
        self.balls[i].anchor = position;
        let c = self.cell_index(&position);
        self.members.push(c, i as u32);
        self.cell_of[i] = c as u32;
        let image = self.image_around(&position);
        self.collect_partners(i, &around[..count], false, image);
    }

    /// The periods for minimum images between the anchor at `p` and anchors in the cells
    /// around it: none when they cannot wrap (an interior cell of a grid of four cells or
    /// more per axis, most of them in a large box), so the rebuild skips the comparisons.
    fn image_around(&self, p: &Vector<T, D>) -> Option<Period<T, D>> {
        match &self.cells {
            Cells::Direct { grid, .. } if grid.needs_no_image(self.cell_coords(p)) => None,
            _ => self.period,
        }
    }

    /// Finds the partners of `i` in the cells `around` its anchor, separations taken as
    /// minimum images over `image`. With `only_higher` (the initial build) each pair is
    /// found once from its lower index.
    fn collect_partners(
        &mut self,
        i: usize,
        around: &[usize],
        only_higher: bool,
        image: Option<Period<T, D>>,
    ) {
        let Anchored { anchor: a, radius } = self.balls[i];
        // Gathered, screened and linked in passes without an unpredictable branch: a
        // cell's length and a candidate's distance go either way, and a mispredicted
        // branch also discards the reads after it (docs/event-engine.md, fortieth
        // session: 3D 1.08x, bit-identical lists). The
        // candidates' anchors are misses of their own: asked for all at once first.
        self.candidates.clear();
        for &c in around {
            self.members.append_to(c, &mut self.candidates);
        }
        for &j in &self.candidates {
            prefetch(&self.balls[j as usize]);
        }
        let shells = self.shell * T::lit(2.0);
        let mut kept = 0;
        for k in 0..self.candidates.len() {
            let j = self.candidates[k];
            let other = &self.balls[j as usize];
            let within = radius + other.radius + shells;
            let d = other.anchor - a;
            let d = match &image {
                Some(period) => period.minimum_image(&d),
                None => d,
            };
            let ju = j as usize;
            let partner = ju != i && (!only_higher || ju > i);
            self.candidates[kept] = j;
            kept += usize::from(partner & (d.norm_squared() < within * within));
        }
        for &j in &self.candidates[..kept] {
            self.lists.push(i, j);
            self.lists.push(j as usize, i as u32);
        }
    }

    /// Writes the cells around the cell of `p` (its neighbours and itself, each once) to
    /// the start of `around`, and returns their number.
    fn cells_around(&self, p: &Vector<T, D>, around: &mut [usize; MAX_AROUND]) -> usize {
        let base = self.cell_coords(p);
        match &self.cells {
            Cells::Direct { grid, .. } => grid.around(base, around),
            Cells::Hashed => {
                let mut count = 0;
                for offset in 0..3usize.pow(D as u32) {
                    let c = self.hashed(Self::around(base, offset));
                    if !around[..count].contains(&c) {
                        around[count] = c;
                        count += 1;
                    }
                }
                count
            }
        }
    }

    /// The integer coordinates of the cell of `p`: in the grid for direct indexing (a
    /// periodic axis wraps, a walled one extends its edge cells to infinity, so a point
    /// just outside, by rounding, lands in the edge cell), unbounded when hashed.
    /// Saturating casts keep far-away points finite.
    fn cell_coords(&self, p: &Vector<T, D>) -> [i64; D] {
        match &self.cells {
            Cells::Direct { origin, grid } => core::array::from_fn(|k| {
                let c = floor_to_i64((p[k] - origin[k]) * self.inv_cell[k]);
                let n = grid.counts()[k];
                if self.period.is_some() {
                    c.rem_euclid(n)
                } else {
                    c.clamp(0, n - 1)
                }
            }),
            Cells::Hashed => core::array::from_fn(|k| floor_to_i64(p[k] * self.inv_cell[k])),
        }
    }

    /// The bucket of the (unbounded) cell `c` in the hashed table: FNV-style mixing of the
    /// coordinates; clashes only cost extra candidates.
    fn hashed(&self, c: [i64; D]) -> usize {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for &x in &c {
            h = (h ^ (x as u64)).wrapping_mul(0x0000_0100_0000_01b3);
            h ^= h >> 29;
        }
        (h as usize) & (self.members.count() - 1)
    }

    /// The row index of the cell of `p`.
    fn cell_index(&self, p: &Vector<T, D>) -> usize {
        let c = self.cell_coords(p);
        match &self.cells {
            Cells::Direct { grid, .. } => grid.index(c),
            Cells::Hashed => self.hashed(c),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SplitMix64;
    use nalgebra::{Vector2, Vector3};
    use std::collections::BTreeSet;

    /// Every pair within reach, by brute force.
    fn brute<const D: usize>(l: &NeighbourLists<f64, D>) -> BTreeSet<(usize, usize)> {
        let n = l.balls.len();
        let mut s = BTreeSet::new();
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (&l.balls[i], &l.balls[j]);
                let reach = a.radius + b.radius + 2.0 * l.shell;
                if l.separation(&a.anchor, &b.anchor).norm_squared() < reach * reach {
                    s.insert((i, j));
                }
            }
        }
        s
    }

    fn listed<const D: usize>(l: &NeighbourLists<f64, D>) -> BTreeSet<(usize, usize)> {
        let mut s = BTreeSet::new();
        for i in 0..l.balls.len() {
            for j in l.partners(i) {
                let j = j as usize;
                assert!(
                    l.partners(j).any(|x| x as usize == i),
                    "lists are symmetric"
                );
                assert!(s.insert((i.min(j), i.max(j))) || i > j, "no duplicates");
            }
        }
        s
    }

    fn random_points<const D: usize>(
        n: usize,
        side: f64,
        seed: u64,
    ) -> (Vec<Vector<f64, D>>, Vec<f64>) {
        let mut g = SplitMix64::new(seed);
        let p = (0..n)
            .map(|_| Vector::<f64, D>::from_fn(|_, _| side * g.next_f64()))
            .collect();
        let r = (0..n).map(|_| 0.05 + 0.2 * g.next_f64()).collect();
        (p, r)
    }

    #[test]
    fn lists_match_brute_force_in_every_domain_after_many_rebuilds() {
        for (domain_kind, seed) in [(0, 1u64), (1, 2), (2, 3)] {
            let side = 6.0;
            let (pos, rad) = random_points::<3>(300, side, seed);
            let (lo, hi) = (Vector3::zeros(), Vector3::repeat(side));
            let domain = match domain_kind {
                0 => Domain::Bounded { min: lo, max: hi },
                1 => Domain::Periodic { min: lo, max: hi },
                _ => Domain::Unbounded,
            };
            let mut l = NeighbourLists::new(&pos, &rad, 0.1, domain);
            assert_eq!(listed(&l), brute(&l), "initial build, domain {domain_kind}");
            let mut g = SplitMix64::new(seed + 100);
            for _ in 0..500 {
                let i = (g.next_u64() % 300) as usize;
                let p = Vector3::from_fn(|_, _| side * g.next_f64());
                l.rebuild(i, p);
            }
            assert_eq!(
                listed(&l),
                brute(&l),
                "after rebuilds, domain {domain_kind}"
            );
        }
    }

    #[test]
    fn a_periodic_box_with_unequal_sides_wraps_partners_across_every_face() {
        // Sides 6.0 × 2.3: with cells of at least 0.6 the short axis has 3 cells of 0.767,
        // the long one 10 of 0.6. Pairs straddling each face must be found.
        let (mut pos, rad) = random_points::<2>(200, 1.0, 5);
        let mut g = SplitMix64::new(6);
        for p in &mut pos {
            *p = Vector2::new(6.0 * g.next_f64(), 2.3 * g.next_f64());
        }
        let rad: Vec<f64> = rad.iter().map(|r| r.min(0.25)).collect();
        let l = NeighbourLists::new(
            &pos,
            &rad,
            0.05,
            Domain::Periodic {
                min: Vector2::zeros(),
                max: Vector2::new(6.0, 2.3),
            },
        );
        assert_eq!(listed(&l), brute(&l));
    }

    #[test]
    fn a_small_periodic_box_with_fewer_than_three_cells_finds_each_partner_once() {
        let (pos, rad) = random_points::<2>(20, 1.5, 9);
        let l = NeighbourLists::new(
            &pos,
            &rad,
            0.05,
            Domain::Periodic {
                min: Vector2::zeros(),
                max: Vector2::repeat(1.5),
            },
        );
        assert_eq!(listed(&l), brute(&l));
    }

    #[test]
    fn balls_outside_a_bounded_domain_still_find_their_partners() {
        let pos = vec![
            Vector2::new(-5.0, 0.5),
            Vector2::new(-5.1, 0.5),
            Vector2::new(0.5, 0.5),
        ];
        let l = NeighbourLists::new(
            &pos,
            &[0.1, 0.1, 0.1],
            0.01,
            Domain::Bounded {
                min: Vector2::zeros(),
                max: Vector2::repeat(3.0),
            },
        );
        assert_eq!(listed(&l), brute(&l));
        assert_eq!(l.partners(0).collect::<Vec<_>>(), [1]);
    }

    #[test]
    fn far_away_balls_in_an_unbounded_domain_are_not_partners() {
        let pos = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1e12, 0.0),
            Vector2::new(0.21, 0.0),
        ];
        let l = NeighbourLists::new(&pos, &[0.1, 0.1, 0.1], 0.01, Domain::Unbounded);
        assert_eq!(l.partners(0).collect::<Vec<_>>(), [2]);
        assert_eq!(l.partners(1).count(), 0);
    }
}
