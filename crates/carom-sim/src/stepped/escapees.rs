//! The escapees of the broad phase: balls whose paths left their entries, each with the
//! box its remaining path now lies in, and a lookup of the escapees whose boxes meet a
//! query box.
//!
//! Every prediction in a step asks which escapees its path can meet, and the list grows
//! to a sixteenth of the balls before the broad phase is rebuilt, so a scan of all of
//! them would cost each prediction hundreds of box tests. The boxes are therefore also
//! filed in **lanes**: equal slices of the first axis over the extent of the entries at
//! the last build. A box is filed in every lane its first-axis interval meets (clamped
//! to the first and last lane), or, spanning more than [`MAX_LANES_PER_BOX`] lanes, in a
//! short list of wide boxes that every lookup scans. Two boxes that overlap share a point
//! of the first axis, whose clamped lane holds both, so a lookup that reads the lanes of
//! the query and the wide list misses none. A box that changes is filed in the lanes its
//! escapee was not filed in yet (it keeps the hull of the lanes it was filed in, moving
//! to the wide list when that grows past [`MAX_LANES_PER_BOX`]); its old filings stay
//! until the next clear and only cost an extra test. So an escapee is filed at most
//! `MAX_LANES_PER_BOX + 1` times however often it changes: filing every change anew let
//! a ball at 1e6 m/s, whose box changes at each of its thousands of wall bounces in a
//! step, file itself thousands of times in the wide list that every lookup scans (a
//! 40-ball scene averaged 220 µs per contact over its first 30,000 contacts, 12 µs over
//! its first 1,000, and took over 100 s for its first step).
//!
//! In a periodic domain two boxes meet when any periodic images of them overlap. Along
//! each axis the minimum image of their centres' separation is the nearest, so if any
//! images overlap, the minimum images do: one test per box. A lookup also reads the
//! lanes of the query shifted one period either way along the first axis, where an
//! escapee reaching out through the far face is filed. (Compared plainly, a ball near
//! one side of the cell missed an escapee reaching out through the other: a fuzzed pair
//! sank 1.5e-3 m into each other through the boundary.)

use carom_geometry::{Aabb, Period};
use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use super::sweep::overlap;
use crate::prefetch::prefetch;

/// The most lanes a box is filed in; wider boxes go to the wide list.
const MAX_LANES_PER_BOX: usize = 8;

/// The lane count for `n` balls: about 64 balls' entries per lane, at least 1 and at
/// most 4096 lanes.
fn lane_count(n: usize) -> usize {
    (n / 64).clamp(1, 4096)
}

/// The `index` of a ball that has not escaped.
const NOT_ESCAPED: u32 = u32::MAX;

/// The escapees and their boxes (see the [module documentation](self)).
pub(crate) struct Escapees<T: Real, const D: usize> {
    /// The escapees, in the order they escaped.
    balls: Vec<u32>,
    /// Their boxes, side by side with `balls`.
    boxes: Vec<Aabb<T, D>>,
    /// Per ball: its index in `balls`, or [`NOT_ESCAPED`].
    index: Vec<u32>,
    /// Side by side with `balls`: the lanes each is filed in (their hull), or `None` once
    /// it is in the wide list.
    filed: Vec<Option<core::ops::Range<usize>>>,
    /// Per lane: indices into `balls` of the boxes filed there.
    lanes: Vec<Vec<u32>>,
    /// The lanes holding something (to clear).
    used: Vec<u32>,
    /// Indices into `balls` of the boxes too wide for lanes.
    wide: Vec<u32>,
    /// The first axis' start of lane 0.
    origin: T,
    /// Lanes per metre of the first axis.
    density: T,
    /// The periods of a periodic domain (boxes then meet through its faces).
    period: Option<Period<T, D>>,
}

impl<T: Real, const D: usize> Escapees<T, D>
where
    Const<D>: Space<T, D>,
{
    /// No escapees among `n` balls in open space, or in the periodic domain of `period`,
    /// with one lane until [`Escapees::span`] is called.
    pub(crate) fn new(n: usize, period: Option<Period<T, D>>) -> Self {
        Self {
            balls: Vec::new(),
            boxes: Vec::new(),
            index: vec![NOT_ESCAPED; n],
            filed: Vec::new(),
            lanes: vec![Vec::new(); lane_count(n)],
            used: Vec::new(),
            wide: Vec::new(),
            origin: T::zero(),
            density: T::zero(),
            period,
        }
    }

    /// Lays the lanes over `[lo, hi]` of the first axis and forgets every escapee.
    pub(crate) fn span(&mut self, lo: T, hi: T) {
        self.clear();
        let width = hi - lo;
        self.origin = lo;
        self.density = if width > T::zero() && width.finite() {
            T::from_count(self.lanes.len()) / width
        } else {
            T::zero()
        };
    }

    /// Forgets every escapee.
    pub(crate) fn clear(&mut self) {
        for &e in &self.balls {
            self.index[e as usize] = NOT_ESCAPED;
        }
        self.balls.clear();
        self.boxes.clear();
        self.filed.clear();
        for &lane in &self.used {
            self.lanes[lane as usize].clear();
        }
        self.used.clear();
        self.wide.clear();
    }

    /// The number of escapees.
    pub(crate) fn len(&self) -> usize {
        self.balls.len()
    }

    /// The escapees, in the order they escaped.
    pub(crate) fn balls(&self) -> &[u32] {
        &self.balls
    }

    /// Ball `i`'s box if it escaped.
    pub(crate) fn box_of(&self, i: usize) -> Option<&Aabb<T, D>> {
        match self.index[i] {
            NOT_ESCAPED => None,
            k => Some(&self.boxes[k as usize]),
        }
    }

    /// Prefetches ball `i`'s slot (see `prefetch`).
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.index[i]);
    }

    /// Makes ball `i` an escapee (or keeps it one) with the box `path`.
    pub(crate) fn set(&mut self, i: usize, path: Aabb<T, D>) {
        let lanes = self.lanes_of(&path);
        let (k, old) = match self.index[i] {
            NOT_ESCAPED => {
                // Escapees are fewer than the balls, whose count fits in u32.
                let k = self.balls.len() as u32;
                self.index[i] = k;
                self.balls.push(i as u32);
                self.boxes.push(path);
                self.filed.push(Some(lanes.start..lanes.start));
                (k, lanes.start..lanes.start)
            }
            k => {
                self.boxes[k as usize] = path;
                match &self.filed[k as usize] {
                    None => return,
                    Some(old) => (k, old.clone()),
                }
            }
        };
        let hull = if old.is_empty() {
            lanes
        } else {
            old.start.min(lanes.start)..old.end.max(lanes.end)
        };
        if hull.len() > MAX_LANES_PER_BOX {
            self.wide.push(k);
            self.filed[k as usize] = None;
            return;
        }
        for lane in (hull.start..old.start).chain(old.end.max(hull.start)..hull.end) {
            if self.lanes[lane].is_empty() {
                self.used.push(lane as u32);
            }
            self.lanes[lane].push(k);
        }
        self.filed[k as usize] = Some(hull);
    }

    /// Appends to `out` every escapee whose box meets `query` (some more than once).
    pub(crate) fn meeting(&self, query: &Aabb<T, D>, out: &mut Vec<u32>) {
        let mut test = |k: u32| {
            if self.meet(&self.boxes[k as usize], query) {
                out.push(self.balls[k as usize]);
            }
        };
        let mut lanes = [self.lanes_of(query), 0..0, 0..0];
        if let Some(period) = &self.period {
            let length = period.length()[0];
            for (image, sign) in lanes[1..].iter_mut().zip([T::one(), -T::one()]) {
                let shift =
                    Vector::<T, D>::from_fn(|k, _| if k == 0 { length * sign } else { T::zero() });
                *image = self.lanes_of(&query.translated(&shift));
            }
        }
        if lanes.iter().map(ExactSizeIterator::len).sum::<usize>() > MAX_LANES_PER_BOX {
            // A wide query tests every escapee once.
            (0..self.balls.len() as u32).for_each(test);
            return;
        }
        let filed = lanes
            .into_iter()
            .flat_map(|l| self.lanes[l].iter().flatten());
        for &k in self.wide.iter().chain(filed) {
            test(k);
        }
    }

    /// Whether boxes `a` and `b` meet: overlap, or in a periodic domain overlap as their
    /// minimum images (see the module documentation).
    fn meet(&self, a: &Aabb<T, D>, b: &Aabb<T, D>) -> bool {
        let Some(period) = &self.period else {
            return overlap(a, b);
        };
        let half = T::lit(0.5);
        let apart = period.minimum_image(&((b.min() + b.max() - a.min() - a.max()) * half));
        let reach = (a.extents() + b.extents()) * half;
        (0..D).all(|k| apart[k].abs() <= reach[k])
    }

    /// The lanes the first-axis interval of `b` meets, clamped to the lanes there are.
    fn lanes_of(&self, b: &Aabb<T, D>) -> core::ops::Range<usize> {
        let last = self.lanes.len() - 1;
        let lane = |x: T| {
            let at = ((x - self.origin) * self.density).floor();
            if at >= T::zero() {
                // NaN-free boxes; `as` saturates past the last lane.
                (at.to_f64() as usize).min(last)
            } else {
                0
            }
        };
        lane(b.min()[0])..lane(b.max()[0]) + 1
    }
}

#[cfg(test)]
mod tests {
    use carom_math::Vector;

    use super::*;
    use crate::scenes::SplitMix64;

    /// A box of half size `half` around `(x, y)`.
    fn square(x: f64, y: f64, half: f64) -> Aabb<f64, 2> {
        let h = Vector::from([half, half]);
        let c = Vector::from([x, y]);
        Aabb::new_unchecked(c - h, c + h)
    }

    /// A random box: mostly small, some wide, some outside the span `[0, 100]`.
    fn random_box(g: &mut SplitMix64) -> Aabb<f64, 2> {
        let half = match g.next_u64() % 10 {
            0 => g.range(10.0, 80.0),
            1 => 0.0,
            _ => g.range(0.1, 3.0),
        };
        square(g.range(-20.0, 120.0), g.range(0.0, 100.0), half)
    }

    /// Lookups find exactly the escapees whose current boxes meet the query (after
    /// repeats are removed), for boxes in one lane, several, the wide list, past either
    /// end of the span, points, and boxes that changed.
    #[test]
    fn lookups_match_brute_force() {
        let n = 2000;
        let mut g = SplitMix64::new(99);
        let mut escapees = Escapees::<f64, 2>::new(n, None);
        escapees.span(0.0, 100.0);
        let mut current = vec![None; n];
        for step in 0..600 {
            let i = (g.next_u64() % n as u64) as usize;
            let b = random_box(&mut g);
            escapees.set(i, b);
            current[i] = Some(b);
            if step % 3 != 0 {
                continue;
            }
            let query = random_box(&mut g);
            let mut found = Vec::new();
            escapees.meeting(&query, &mut found);
            found.sort_unstable();
            found.dedup();
            let expected: Vec<u32> = (0..n)
                .filter(|&k| current[k].is_some_and(|b| overlap(&b, &query)))
                .map(|k| k as u32)
                .collect();
            assert_eq!(found, expected, "query {query:?} after {step} escapes");
        }
        assert!(!escapees.wide.is_empty() && escapees.len() > 400);
        escapees.clear();
        let mut found = Vec::new();
        escapees.meeting(&square(50.0, 50.0, 100.0), &mut found);
        assert!(found.is_empty() && escapees.len() == 0);
        assert!(escapees.lanes.iter().all(Vec::is_empty));
    }

    /// An escapee whose box changes thousands of times (a fast ball bouncing between
    /// walls) is filed at most `MAX_LANES_PER_BOX + 1` times, and lookups still find it
    /// where its box is now.
    #[test]
    fn an_escapee_changing_its_box_often_is_filed_a_bounded_number_of_times() {
        let mut escapees = Escapees::<f64, 2>::new(640, None);
        escapees.span(0.0, 100.0);
        let filings =
            |e: &Escapees<f64, 2>| e.wide.len() + e.lanes.iter().map(Vec::len).sum::<usize>();
        // Back and forth between two lanes, then across the span and wide.
        for k in 0..1000 {
            let x = if k % 2 == 0 { 5.0 } else { 15.0 };
            escapees.set(7, square(x, 50.0, 0.5));
            let mut found = Vec::new();
            escapees.meeting(&square(x, 50.0, 0.1), &mut found);
            assert_eq!(found, [7], "change {k}");
            escapees.meeting(&square(25.0 - x, 50.0, 0.1), &mut found);
            assert_eq!(found, [7], "change {k}: found only where its box is now");
        }
        assert_eq!(filings(&escapees), 2);
        for k in 0..1000 {
            let x = f64::from(k % 100);
            escapees.set(7, square(x, 50.0, if k % 3 == 0 { 60.0 } else { 0.5 }));
        }
        assert!(filings(&escapees) <= MAX_LANES_PER_BOX + 1 + 2);
        assert_eq!(escapees.wide.len(), 1);
        let mut found = Vec::new();
        escapees.meeting(&square(99.0, 50.0, 0.1), &mut found);
        assert_eq!(found, [7]);
    }

    /// Without a usable span (one point, or nothing) every box shares lane 0.
    #[test]
    fn a_degenerate_span_keeps_one_lane() {
        let mut escapees = Escapees::<f64, 2>::new(200, None);
        escapees.span(f64::INFINITY, f64::NEG_INFINITY);
        escapees.set(3, square(5.0, 5.0, 1.0));
        escapees.set(4, square(-5.0, 5.0, 1.0));
        let mut found = Vec::new();
        escapees.meeting(&square(5.5, 5.0, 0.1), &mut found);
        assert_eq!(found, [3]);
        assert_eq!(escapees.box_of(4), Some(&square(-5.0, 5.0, 1.0)));
        assert_eq!(escapees.box_of(5), None);
    }
}
