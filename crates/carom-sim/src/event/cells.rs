//! Cell lists with crossing events, the event-driven engine's way to find partners in
//! gases of moderate density.
//!
//! The container (a walled or periodic box) is cut into a grid of cells at least as wide
//! as the largest ball's diameter (plus a margin for rounding). Every ball belongs to one
//! cell, and two balls that touch are then in the same cell or in neighbouring ones: a
//! ball's possible partners are the balls of the `3^D` cells around its own. Unlike a
//! neighbour list, nothing is rebuilt: a ball's cell changes at a scheduled *crossing*
//! event, when its centre reaches a face of its cell, and the crossing moves it to the
//! cell across that face (the cell index changes by one, it is never recomputed from the
//! position, so rounding cannot put a ball in two cells or none). This is Rapaport's
//! cell scheme for event-driven dynamics; Smallenburg (J. Chem. Phys. 2022) compares it
//! with neighbour lists.
//!
//! Which of the two is faster depends on how many candidates a prediction reads: `3^D`
//! cells of `ρ w^D` balls each here against the ~10 partners of a list, and crossings
//! (cheap: one cell row edited) against list rebuilds (a dozen rows edited). In 2D at
//! area fraction 0.3 a prediction reads about 3.4 other balls here; in 3D at packing
//! fraction 0.45 it would read about 23, and lists win (measured figures in
//! `docs/event-engine.md`; the engine's choice is `EventEngine::new`'s).
//!
//! Why a ball's true position may sit a little outside its cell: crossing times are
//! rounded, and a ball crosses when its predicted time comes, not when a rounded
//! position says so. The margin `CELL_MARGIN` in the cell width absorbs it: balls in
//! cells two apart stay more than a diameter apart as long as each is within
//! `CELL_MARGIN · w / 2` of its cell, far above rounding.
//!
//! Cells on the edge of a walled box extend to infinity outwards (no crossing leaves the
//! grid), so a ball starting partly outside the border still has its neighbours.

use carom_geometry::{Border, Period};
use carom_math::{Real, Vector, floor_to_i64};
use carom_toi::{Direction, Window, level_crossing};

use super::grid::{GridIndex, MAX_AROUND};
use super::rows::{IdRows, Quarter};
use crate::pages::Array;
use crate::prefetch::prefetch;

/// Balls kept in a cell's row: a 16-byte row, four to a cache line, so the three cells
/// of a grid row around a ball are one or two lines. At the widths used a cell holds
/// about 0.4 equal balls in 2D at area fraction 0.3 (at most 4; 8 in 3D); more spill.
const CELL_ROW: usize = 3;
/// The fewest cells per axis of a periodic box (see [`CellLists::images_are_unique`]).
pub const MIN_PERIODIC_CELLS: i64 = 5;
/// The relative margin by which a cell is wider than the largest diameter, at least (see
/// `CellLists::new` for the precision-dependent part).
const CELL_MARGIN: f64 = 1e-6;
/// How far inside an open face a ball's offset is clamped before its crossing is
/// computed, relative to the cell width, at least (and at least 16 ulps).
const FACE_INSET: f64 = 1e-9;

/// A ball's cell and its two scheduled times: its next crossing of a face of the cell
/// and its next other event (the engine's calendar holds the earlier of the two).
#[derive(Clone, Copy, Debug)]
struct Place<T: Real, const D: usize> {
    cell: [i32; D],
    /// When the ball crosses the face (`axis`, `upper`) of its cell (`∞` if never).
    crossing: T,
    /// When the ball's pending event (collision, wall, box...) comes due.
    event: T,
    axis: u8,
    upper: bool,
}

/// A ball's next crossing of a face of its cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crossing<T: Real> {
    /// Time from now.
    pub(crate) after: T,
    /// The axis of the face.
    pub(crate) axis: u8,
    /// `true` for the upper face.
    pub(crate) upper: bool,
}

/// A grid of cells over a walled or periodic box, each holding the balls whose (logical)
/// cell it is.
#[derive(Clone, Debug)]
pub struct CellLists<T: Real, const D: usize> {
    /// The lower corner of cell `(0, …, 0)`.
    origin: Vector<T, D>,
    /// The width of the cells per axis (each axis is cut into whole cells).
    width: Vector<T, D>,
    /// The grid's shape: cells per axis, neighbourhoods (boxed: its tables of offsets are
    /// large beside the engine's other ways of finding partners).
    grid: Box<GridIndex<D>>,
    /// The periodic box, for minimum images and wrapping cell coordinates.
    period: Option<Period<T, D>>,
    /// Per axis, how far inside an open face a ball's offset is clamped before its
    /// crossing is computed (`FACE_INSET` of the width, and at least 16 ulps).
    inset: Vector<T, D>,
    /// The balls in each cell.
    members: IdRows<CELL_ROW, Quarter>,
    /// Each ball's cell and scheduled times.
    places: Array<Place<T, D>>,
}

impl<T: Real, const D: usize> CellLists<T, D> {
    /// Cells over the box `[min, max]` (periodic or walled) for balls at `positions`, the
    /// largest of radius `r_max`. Cells are at least `2 r_max (1 + margin)` wide, and
    /// widened where a sparse box would need more than about `4 n` of them. The margin
    /// is `10⁻⁶`, or more where the coordinates' rounding (`256 ε` of the box's largest
    /// coordinate, a diameter's worth of which in `f32` is a hundred times that) could
    /// reach it.
    pub fn new(
        positions: &[Vector<T, D>],
        r_max: T,
        min: Vector<T, D>,
        max: Vector<T, D>,
        periodic: bool,
    ) -> Self {
        let n = positions.len();
        let ext = max - min;
        let budget = T::from_count((4 * n).max(64));
        let needed = (ext.product() / budget).powf(T::one() / T::from_count(D));
        let reach = min.amax().max(max.amax());
        let rounding = T::lit(256.0) * T::EPSILON * reach / (r_max * T::lit(2.0));
        let margin = rounding.max(T::lit(CELL_MARGIN));
        let cell = (r_max * T::lit(2.0) * (T::one() + margin)).max(needed);
        let counts: [i64; D] =
            core::array::from_fn(|k| ((ext[k] / cell).floor().to_f64() as i64).max(1));
        let width = Vector::<T, D>::from_fn(|k, _| ext[k] / T::from_count(counts[k] as usize));
        let grid = Box::new(GridIndex::new(counts, periodic));
        let mut cells = Self {
            origin: min,
            width,
            members: IdRows::new(grid.len()),
            grid,
            period: periodic.then(|| {
                Border::new(min, max)
                    .expect("a periodic box is a valid box")
                    .period()
            }),
            inset: width.map(|w| w * T::lit(FACE_INSET).max(T::lit(16.0) * T::EPSILON)),
            places: Array::filled(n, |i| Place {
                cell: core::array::from_fn(|k| {
                    let c = floor_to_i64((positions[i][k] - min[k]) / width[k]);
                    let c = if periodic {
                        c.rem_euclid(counts[k])
                    } else {
                        c.clamp(0, counts[k] - 1)
                    };
                    c as i32
                }),
                crossing: T::INFINITY,
                event: T::INFINITY,
                axis: 0,
                upper: false,
            }),
        };
        for i in 0..n {
            let c = cells.places[i].cell.map(i64::from);
            cells.members.push(cells.grid.index(c), i as u32);
        }
        cells
    }

    /// The number of other balls a prediction reads on average from the `3^D` cells
    /// around a ball, for `n` balls spread evenly.
    pub fn candidates_per_prediction(&self, n: usize) -> T {
        let cells = T::from_count(self.members.count());
        let around = T::from_count(3usize.pow(D as u32).min(self.members.count()));
        T::from_count(n) / cells * around - T::one()
    }

    /// `true` unless the box is periodic with fewer than [`MIN_PERIODIC_CELLS`] cells on
    /// some axis. Balls in neighbouring cells are less than two cell widths apart
    /// (plus the margin), and the minimum image is then theirs only if every period is
    /// longer than four widths: with five cells or more it is, with margin to spare.
    pub fn images_are_unique(&self) -> bool {
        self.period.is_none() || self.grid.counts().iter().all(|&c| c >= MIN_PERIODIC_CELLS)
    }

    /// The cells around ball `i`'s (its own and its neighbours, each once) written to the
    /// start of `around`; returns their number.
    #[inline]
    fn around(&self, i: usize, around: &mut [usize; MAX_AROUND]) -> usize {
        self.grid.around(self.cell(i), around)
    }

    /// Calls `f` with every ball in the cells around ball `i`'s, `i` included.
    #[inline]
    pub(crate) fn for_each_near(&self, i: usize, mut f: impl FnMut(usize)) {
        let mut around = [0; MAX_AROUND];
        let count = self.around(i, &mut around);
        for &c in &around[..count] {
            for j in self.members.of(c) {
                f(j as usize);
            }
        }
    }

    /// Appends every ball in the cells around ball `i`'s, `i` included, to `out`, in the
    /// order of [`Self::for_each_near`], copying whole rows (`IdRows::append_to`: no
    /// branch on a cell's length).
    #[inline]
    pub(crate) fn gather_near(&self, i: usize, out: &mut Vec<u32>) {
        let mut around = [0; MAX_AROUND];
        let count = self.around(i, &mut around);
        for &c in &around[..count] {
            self.members.append_to(c, out);
        }
    }

    /// Asks for ball `i`'s cell and times to be brought into the cache.
    #[inline]
    pub(crate) fn prefetch_place(&self, i: usize) {
        prefetch(&self.places[i]);
    }

    /// Asks for ball `i`'s cell and times and the rows of the cells around it to be
    /// brought into the cache.
    #[inline]
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.places[i]);
        let mut around = [0; MAX_AROUND];
        let count = self.around(i, &mut around);
        for &c in &around[..count] {
            self.members.prefetch(c);
        }
    }

    /// The lower corner of ball `i`'s cell.
    fn corner(&self, i: usize) -> Vector<T, D> {
        let c = self.cell(i);
        Vector::<T, D>::from_fn(|k, _| {
            self.origin[k] + self.width[k] * T::from_count(c[k] as usize)
        })
    }

    /// The first time (from now) at which ball `i`, at `position` with velocity `v` and
    /// acceleration `a`, reaches a face of its cell that has a cell behind it; `None` if
    /// it never does.
    ///
    /// Where a face is open, the ball's offset from it is first clamped to at least
    /// `10⁻⁹ w` (16 ulps in `f32`) inside: a ball that rounding left just past the face it last crossed, or
    /// just short of it, is then always crossing outwards from inside, never twice at
    /// one instant (the clamp moves the crossing by far less than the cells' margin).
    pub(crate) fn next_crossing(
        &self,
        i: usize,
        position: &Vector<T, D>,
        v: &Vector<T, D>,
        a: &Vector<T, D>,
    ) -> Option<Crossing<T>> {
        let corner = self.corner(i);
        let offset = match &self.period {
            Some(period) => period.minimum_image(&(position - corner)),
            None => position - corner,
        };
        let c = self.cell(i);
        let periodic = self.period.is_some();
        let window = Window::unbounded(Direction::Forward);
        let mut first: Option<Crossing<T>> = None;
        for k in 0..D {
            let (w, inset) = (self.width[k], self.inset[k]);
            let lower_open = periodic || c[k] > 0;
            let upper_open = periodic || c[k] + 1 < self.grid.counts()[k];
            let mut x = offset[k];
            if lower_open {
                x = x.max(inset);
            }
            if upper_open {
                x = x.min(w - inset);
            }
            let mut offer = |s: T, upper: bool| {
                if s.finite() && first.is_none_or(|f| s < f.after) {
                    first = Some(Crossing {
                        after: s,
                        axis: k as u8,
                        upper,
                    });
                }
            };
            if a[k] == T::zero() {
                // Straight flight: only the face ahead is reached, at (level − x) / v.
                if v[k] > T::zero() && upper_open {
                    offer((w - x) / v[k], true);
                } else if v[k] < T::zero() && lower_open {
                    offer(-x / v[k], false);
                }
            } else {
                // From inside, the first crossing of a face's level is outwards.
                if upper_open {
                    offer(level_crossing(x, v[k], a[k], w, &window).time, true);
                }
                if lower_open {
                    offer(
                        level_crossing(x, v[k], a[k], T::zero(), &window).time,
                        false,
                    );
                }
            }
        }
        first
    }

    /// Moves ball `i` to the cell across the face (`axis`, `upper`) of its cell.
    pub(crate) fn cross(&mut self, i: usize, axis: usize, upper: bool) {
        let from = self.cell(i);
        let mut to = from;
        let n = self.grid.counts()[axis];
        to[axis] = if upper {
            from[axis] + 1
        } else {
            from[axis] - 1
        };
        if self.period.is_some() {
            to[axis] = to[axis].rem_euclid(n);
        } else {
            to[axis] = to[axis].clamp(0, n - 1);
        }
        let (a, b) = (self.grid.index(from), self.grid.index(to));
        if a != b {
            self.members.remove(a, i as u32);
            self.members.push(b, i as u32);
        }
        self.places[i].cell = to.map(|x| x as i32);
    }

    /// Appends to `out` every ball in the cells that ball `i`'s neighbourhood gained when it
    /// crossed the face (`axis`, `upper`) into its cell: the row of `3^(D−1)` cells one
    /// further along `axis`. Whole rows are copied (`IdRows::append_to`).
    pub(crate) fn gather_entering(&self, i: usize, axis: usize, upper: bool, out: &mut Vec<u32>) {
        let mut slab = [0usize; MAX_AROUND];
        let count = self.grid.slab(self.cell(i), axis, upper, &mut slab);
        for &c in &slab[..count] {
            self.members.append_to(c, out);
        }
    }

    /// Records ball `i`'s next event time and next crossing (`after` from `now`), and
    /// returns the earlier of the two: the ball's time in the calendar.
    pub(crate) fn record(
        &mut self,
        i: usize,
        now: T,
        event: T,
        crossing: Option<Crossing<T>>,
    ) -> T {
        let place = &mut self.places[i];
        place.event = event;
        match crossing {
            Some(c) => {
                place.crossing = now + c.after;
                place.axis = c.axis;
                place.upper = c.upper;
            }
            None => place.crossing = T::INFINITY,
        }
        place.crossing.min(event)
    }

    /// The face ball `i` crosses now, if its crossing (not its other event) is what
    /// came due; a crossing goes first when both are due at once.
    #[inline]
    pub(crate) fn crossing_due(&self, i: usize) -> Option<(usize, bool)> {
        let place = &self.places[i];
        (place.crossing <= place.event).then_some((place.axis as usize, place.upper))
    }

    /// The time of ball `i`'s pending event other than a crossing.
    #[inline]
    pub(crate) fn event_time(&self, i: usize) -> T {
        self.places[i].event
    }

    /// The coordinates of ball `i`'s cell.
    #[inline]
    fn cell(&self, i: usize) -> [i64; D] {
        self.places[i].cell.map(i64::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SplitMix64;
    use nalgebra::{Vector2, Vector3};
    use std::collections::BTreeSet;

    /// The balls near `i`, each met once, gathered as visited and in the same order.
    fn near<const D: usize>(cells: &CellLists<f64, D>, i: usize) -> BTreeSet<usize> {
        let mut s = BTreeSet::new();
        let mut visited = Vec::new();
        cells.for_each_near(i, |j| {
            assert!(s.insert(j), "ball {j} met twice");
            visited.push(j as u32);
        });
        let mut gathered = vec![u32::MAX];
        cells.gather_near(i, &mut gathered);
        assert_eq!(gathered[0], u32::MAX, "appended after what was there");
        assert_eq!(gathered[1..], visited[..], "gathered as visited");
        s
    }

    /// Follows ball 0 along a straight line through the grid crossing after crossing:
    /// its cell is always the one its position is in (to the clamp's 1e-9 of a width),
    /// and the balls a crossing adds are exactly those of the new neighbourhood that the
    /// old one lacked.
    fn follow<const D: usize>(periodic: bool, counts: usize, velocity: Vector<f64, D>, seed: u64) {
        let side = 0.5 * counts as f64 * (1.0 + 2.0 * CELL_MARGIN);
        let mut g = SplitMix64::new(seed);
        let positions: Vec<Vector<f64, D>> = (0..120)
            .map(|_| Vector::<f64, D>::from_fn(|_, _| side * g.next_f64()))
            .collect();
        let (lo, hi) = (Vector::zeros(), Vector::repeat(side));
        let mut cells = CellLists::new(&positions, 0.25, lo, hi, periodic);
        assert_eq!(cells.grid.counts(), &[counts as i64; D]);
        let border = Border::new(lo, hi).unwrap();
        let mut p = positions[0];
        let mut crossings = 0;
        while let Some(c) = cells.next_crossing(0, &p, &velocity, &Vector::zeros()) {
            if crossings == 200 {
                break;
            }
            let before = near(&cells, 0);
            p += velocity * c.after;
            cells.cross(0, c.axis as usize, c.upper);
            crossings += 1;
            let q = if periodic { border.wrap(&p) } else { p };
            for k in 0..D {
                let expected = (q[k] / cells.width[k]).floor();
                let got = f64::from(cells.places[0].cell[k]);
                let off = (q[k] - got * cells.width[k]) / cells.width[k];
                assert!(
                    got == expected.clamp(0.0, counts as f64 - 1.0)
                        || off.abs() < 1e-8
                        || (off - 1.0).abs() < 1e-8
                        || (periodic && (off + counts as f64 - 1.0).abs() < 1e-8)
                        || (periodic && (off - counts as f64).abs() < 1e-8),
                    "axis {k}: cell {got} for position {} (offset {off})",
                    q[k]
                );
            }
            let after = near(&cells, 0);
            let mut gathered = Vec::new();
            cells.gather_entering(0, c.axis as usize, c.upper, &mut gathered);
            let entering: BTreeSet<usize> = gathered.iter().map(|&j| j as usize).collect();
            assert_eq!(entering.len(), gathered.len(), "a ball gathered twice");
            if counts >= 3 {
                let gained: BTreeSet<usize> = after.difference(&before).copied().collect();
                assert_eq!(entering, gained, "crossing {crossings}");
            } else {
                assert!(entering.is_subset(&after));
            }
        }
        // One walled cell has no face with a cell behind it.
        assert_eq!(crossings > 0, periodic || counts > 1);
        if !periodic {
            // Walled: the ball leaves the grid's last cell never.
            assert!(crossings < 200);
        }
    }

    #[test]
    fn a_ball_crosses_from_cell_to_cell_and_meets_exactly_the_balls_it_gains() {
        for (periodic, counts) in [(true, 5), (true, 7), (false, 6), (true, 2), (false, 1)] {
            follow::<2>(periodic, counts, Vector2::new(0.731, -0.419), 3);
            follow::<3>(periodic, counts, Vector3::new(-0.21, 0.93, 0.377), 4);
        }
    }

    #[test]
    fn under_acceleration_a_ball_crosses_back_into_the_cell_it_left() {
        // Thrown up at 1 m/s under g = 2 from 0.8 of the way up its cell (cell 2): it
        // rises 0.25, past the face at 3 w (w at least 0.5), and falls back.
        let (lo, hi) = (Vector2::zeros(), Vector2::repeat(5.0));
        let w = CellLists::new(&[Vector2::zeros()], 0.25, lo, hi, false).width[1];
        let y0 = 2.8 * w;
        let mut cells = CellLists::new(&[Vector2::new(1.2, y0)], 0.25, lo, hi, false);
        let a = Vector2::new(0.0, -2.0);
        let up = cells
            .next_crossing(0, &Vector2::new(1.2, y0), &Vector2::new(0.0, 1.0), &a)
            .expect("it rises past the face");
        // y0 + s − s² = 3 w.
        assert_eq!((up.axis, up.upper), (1, true));
        let s = (1.0 - (1.0f64 - 4.0 * (3.0 * w - y0)).sqrt()) / 2.0;
        assert!((up.after - s).abs() < 1e-12, "{} against {s}", up.after);
        cells.cross(0, 1, true);
        let top = Vector2::new(1.2, 3.0 * w);
        let down = cells
            .next_crossing(0, &top, &Vector2::new(0.0, 1.0 - 2.0 * s), &a)
            .expect("it falls back");
        assert_eq!((down.axis, down.upper), (1, false));
        // Back through the same face at the parabola's symmetric time.
        assert!(
            (down.after - (1.0 - 2.0 * s)).abs() < 1e-8,
            "{}",
            down.after
        );
    }
}
