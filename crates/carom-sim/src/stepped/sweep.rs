//! The broad phase: which balls (and boxes) can meet within a step, kept valid over
//! several steps, and exact while collisions change the balls' paths.
//!
//! Each ball is entered as its **reach box**: the axis-aligned box around the ball of
//! radius `r + max(|u|, ū) τ` centred at its position when the broad phase is built, with
//! `u` its chord velocity, `ū` the mean chord speed and `τ` the reach time. In open space
//! `τ` is `K` steps, with `K` chosen at each build so that the mean ball travels half the
//! mean radius in `τ` (`1 <= K <= 16`): slow scenes rebuild rarely, fast ones every step,
//! and the boxes grow by about half a radius, which adds few pairs; in a periodic domain
//! `τ` is the window. A box holds the ball's path for that long, and every path that
//! leaves from a point of the chord at no more than the same speed, so a ball that
//! bounces back stays inside. Boxes (walls,
//! paddles) are entered as the box swept over the same time, except in a periodic domain,
//! where boxes are tested against every ball with their periodic images (see `narrow`).
//! carom-broad returns the overlapping pairs; the narrow phase computes a time of impact
//! for each, every step.
//!
//! At the start of each step every ball's path for the step is checked against its entry
//! (in parallel). A ball whose path left its entry, or whose path leaves it later in the
//! step after a collision (it was hit by a faster ball), is an **escapee**: its path box is
//! kept in a short list, and every prediction for it queries the broad phase and scans the
//! list. The invariant that makes this exact: every ball's remaining path lies in its
//! entry or, for an escapee, in its listed box. A prediction for a ball that has not
//! escaped reads its **partner list** (the pairs, turned into per-ball lists at each
//! build): a ball that can touch its path has its own path in its entry, which then meets
//! this ball's entry, or is an escapee; a prediction for an escapee queries the broad
//! phase with its path box. Both scan the escapees (in a periodic domain through its faces
//! too, see `escapees`), so no pair that can touch is missed. When
//! the list grows past a bound (a sixteenth of the balls, at least 64), the broad phase is
//! rebuilt: at the start of a step, or mid-step by ending the window at the current time
//! (bounded work; see `StepStats::windows` and `StepStats::rebuilds`).

use carom_broad::{BruteForce, KdTree, ParallelBroadPhase, SweepAndPrune, UniformGrid, Volumes};
use carom_geometry::{Aabb, Border};
use carom_math::{Real, Space, Vector};
use nalgebra::Const;
use rayon::prelude::*;

use super::balls::BallArrays;
use super::escapees::Escapees;
use super::obstacles::BoxArrays;
use crate::plan::BroadChoice;
use crate::prefetch::prefetch;

/// Balls per parallel chunk of the data-parallel passes.
pub(crate) const CHUNK: usize = 1024;

/// The most steps of travel a reach box holds in open space.
pub(crate) const MAX_REACH_STEPS: usize = 16;

/// The broad phase and its buffers.
pub(crate) struct Sweep<T: Real, const D: usize> {
    phase: Box<dyn ParallelBroadPhase<T, D> + Sync>,
    choice: BroadChoice,
    /// Boxes take part (open space); in a periodic domain they are tested separately.
    boxes_inside: bool,
    /// The entries are built and may serve the next step (open space only).
    built: bool,
    /// The number of balls (volumes past it are boxes).
    balls: usize,
    /// Per ball: the box its centre must stay in for its path to fit its entry (the
    /// entry shrunk by the radius and a rounding allowance).
    cores: Vec<Aabb<T, D>>,
    /// Per chunk of balls: those whose paths leave their entries at the start of a step
    /// (scratch).
    misfits: Vec<Vec<u32>>,
    /// Per-chunk sums (scratch).
    sums: Vec<T>,
    /// Builds so far.
    builds: u64,
    /// Reach boxes of the balls, then (open space) the swept boxes.
    volumes: Vec<Aabb<T, D>>,
    /// This window's overlapping pairs.
    pub(crate) pairs: Vec<(u32, u32)>,
    /// The pairs as adjacency lists: ball `i`'s partners (balls, and boxes as `n + k`)
    /// are `partners[partner_start[i]..partner_start[i + 1]]`.
    partner_start: Vec<usize>,
    partners: Vec<u32>,
    /// The balls whose paths left their entries.
    escapees: Escapees<T, D>,
}

impl<T: Real, const D: usize> Sweep<T, D>
where
    Const<D>: Space<T, D>,
{
    /// A broad phase of kind `choice` (already resolved, never `Auto`) for `n` balls, in
    /// the periodic domain `periodic` if given.
    pub(crate) fn new(choice: BroadChoice, n: usize, periodic: Option<&Border<T, D>>) -> Self {
        let phase: Box<dyn ParallelBroadPhase<T, D> + Sync> = match (choice, periodic) {
            (BroadChoice::Brute | BroadChoice::Auto, None) => Box::new(BruteForce::new()),
            (BroadChoice::Brute | BroadChoice::Auto, Some(b)) => Box::new(BruteForce::periodic(b)),
            (BroadChoice::Sap, _) => Box::new(SweepAndPrune::new()),
            (BroadChoice::Kd, _) => Box::new(KdTree::new()),
            (BroadChoice::Grid, None) => Box::new(UniformGrid::dense()),
            (BroadChoice::Grid, Some(b)) => Box::new(UniformGrid::periodic(*b)),
        };
        Self {
            phase,
            choice,
            boxes_inside: periodic.is_none(),
            built: false,
            balls: n,
            cores: Vec::with_capacity(n),
            misfits: Vec::new(),
            sums: Vec::new(),
            builds: 0,
            volumes: Vec::with_capacity(n),
            pairs: Vec::new(),
            partner_start: Vec::with_capacity(n + 1),
            partners: Vec::new(),
            escapees: Escapees::new(n, periodic.map(Border::period)),
        }
    }

    /// The pipeline name of this broad phase.
    pub(crate) fn name(&self) -> &'static str {
        match self.choice {
            BroadChoice::Brute | BroadChoice::Auto => "broad:brute-force",
            BroadChoice::Sap => "broad:sweep-and-prune",
            BroadChoice::Kd => "broad:kd-tree",
            BroadChoice::Grid => "broad:uniform-grid",
        }
    }

    /// Whether boxes are volumes of this broad phase (index `n + k` for box `k`).
    pub(crate) fn boxes_inside(&self) -> bool {
        self.boxes_inside
    }

    /// Makes the broad phase valid for a step of length `h` whose paths start at in-step
    /// time 0: keeps the entries if every box's sweep still fits and fewer than
    /// `escape_bound` balls' paths do not (those become escapees, to be predicted by
    /// query), rebuilds them otherwise (no escapees).
    pub(crate) fn begin_step(
        &mut self,
        balls: &BallArrays<T, D>,
        boxes: &BoxArrays<T, D>,
        h: T,
        escape_bound: usize,
        parallel: bool,
    ) {
        self.escapees.clear();
        if self.built && self.boxes_fit(boxes, h) {
            let n = balls.len();
            let chunks = n.div_ceil(CHUNK);
            let mut misfits = core::mem::take(&mut self.misfits);
            misfits.resize_with(chunks, Vec::new);
            let cores = &self.cores;
            let collect = |c: usize, out: &mut Vec<u32>| {
                out.clear();
                let (first, last) = (c * CHUNK, ((c + 1) * CHUNK).min(n));
                let (start, end) = (&balls.seg_x[first..last], &balls.pos[first..last]);
                for (i, ((core, x), p)) in
                    (first..).zip(cores[first..last].iter().zip(start).zip(end))
                {
                    if !(core.contains_point(x) & core.contains_point(p)) {
                        out.push(i as u32);
                    }
                }
            };
            if parallel {
                misfits[..chunks]
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(c, out)| collect(c, out));
            } else {
                for (c, out) in misfits[..chunks].iter_mut().enumerate() {
                    collect(c, out);
                }
            }
            let count: usize = misfits[..chunks].iter().map(Vec::len).sum();
            if count < escape_bound {
                for &i in misfits[..chunks].iter().flatten() {
                    let i = i as usize;
                    let path = path_box(&balls.seg_x[i], &balls.pos[i], balls.radius[i]);
                    self.escapees.set(i, path);
                }
            }
            self.misfits = misfits;
            if count < escape_bound {
                return;
            }
        }
        let steps = self.reach_steps(balls, h, parallel);
        self.build(balls, boxes, T::zero(), h * T::from_count(steps), parallel);
    }

    /// How many steps `K` a reach box should hold: the mean ball travels half the mean
    /// radius in `K` steps (`1 <= K <= MAX_REACH_STEPS`).
    pub(crate) fn reach_steps(&mut self, balls: &BallArrays<T, D>, h: T, parallel: bool) -> usize {
        let n = T::from_count(balls.len().max(1));
        let travel = chunked_sum(&balls.chord, parallel, &mut self.sums, Vector::norm) / n * h;
        let radius = chunked_sum(&balls.radius, parallel, &mut self.sums, |r: &T| *r) / n;
        let steps = (T::lit(0.5) * radius / travel).floor().to_f64();
        if steps.is_finite() {
            (steps as usize).clamp(1, MAX_REACH_STEPS)
        } else {
            MAX_REACH_STEPS
        }
    }

    fn boxes_fit(&self, boxes: &BoxArrays<T, D>, h: T) -> bool {
        !self.boxes_inside
            || (0..boxes.len())
                .all(|k| contains(&self.volumes[self.balls + k], &boxes.swept(k, T::zero(), h)))
    }

    /// Rebuilds from the balls' paths at in-step time `a`, each ball reaching as far as
    /// it travels in `reach` (at least the mean travel), plus the boxes swept over the
    /// same time (open space only), and finds the pairs.
    pub(crate) fn build(
        &mut self,
        balls: &BallArrays<T, D>,
        boxes: &BoxArrays<T, D>,
        a: T,
        reach: T,
        parallel: bool,
    ) {
        let n = balls.len();
        let mean = chunked_sum(&balls.chord, parallel, &mut self.sums, Vector::norm)
            / T::from_count(n.max(1));
        self.volumes
            .resize(n, Aabb::new_unchecked(Vector::zeros(), Vector::zeros()));
        let entry = |i: usize| {
            let x = balls.position_at(i, a);
            reach_box(&x, balls.radius[i], balls.chord[i].norm().max(mean) * reach)
        };
        fill(&mut self.volumes, parallel, entry);
        self.cores
            .resize(n, Aabb::new_unchecked(Vector::zeros(), Vector::zeros()));
        let core = |i: usize| {
            let x = balls.position_at(i, a);
            let (r, travel) = (balls.radius[i], balls.chord[i].norm().max(mean) * reach);
            // Any path box of a segment with both ends within `travel − δ` of `x` lies in
            // the entry: δ covers path_box's own rounding allowance twice over.
            let slack = T::lit(16.0) * T::EPSILON * (x.amax() + r + travel);
            let half = Vector::<T, D>::repeat((travel - slack).max(T::zero()));
            Aabb::new_unchecked(x - half, x + half)
        };
        fill(&mut self.cores, parallel, core);
        if self.boxes_inside {
            self.volumes
                .extend((0..boxes.len()).map(|k| boxes.swept(k, a, a + reach)));
        }
        let (lo, hi) = first_axis_extent(&self.volumes, parallel);
        self.escapees.span(lo, hi);
        // Counts below u32::MAX are checked when the engine is built.
        let volumes = Volumes::Boxes(&self.volumes);
        if parallel {
            self.phase.par_update(volumes);
            self.phase.par_pairs(&mut self.pairs);
        } else {
            self.phase.update(volumes);
            self.phase.pairs(&mut self.pairs);
        }
        self.link_partners();
        self.built = self.boxes_inside;
        self.builds += 1;
    }

    /// Builds so far.
    pub(crate) fn builds(&self) -> u64 {
        self.builds
    }

    /// Turns the pair list into per-ball partner lists (a counting sort: both balls of a
    /// pair list each other; a ball lists a box, never the reverse; two boxes, nothing).
    fn link_partners(&mut self) {
        let n = self.balls;
        self.partner_start.clear();
        self.partner_start.resize(n + 1, 0);
        for &(i, j) in &self.pairs {
            for ball in [i, j] {
                if (ball as usize) < n {
                    self.partner_start[ball as usize + 1] += 1;
                }
            }
        }
        for i in 0..n {
            self.partner_start[i + 1] += self.partner_start[i];
        }
        self.partners.resize(self.partner_start[n], 0);
        // `next[i]` runs from `partner_start[i]` up as ball i's list fills.
        let mut next = core::mem::take(&mut self.partner_start);
        for &(i, j) in &self.pairs {
            for (ball, other) in [(i, j), (j, i)] {
                if (ball as usize) < n {
                    self.partners[next[ball as usize]] = other;
                    next[ball as usize] += 1;
                }
            }
        }
        // Each `next[i]` ended at ball i's end, which is ball i + 1's start.
        next.rotate_right(1);
        next[0] = 0;
        self.partner_start = next;
    }

    /// Prefetches what `candidates` first reads for ball `i`: its entry, its escapee
    /// slot and where its partner list starts (see `prefetch`).
    pub(crate) fn prefetch_entry(&self, i: usize) {
        prefetch(&self.volumes[i]);
        prefetch(&self.partner_start[i]);
        self.escapees.prefetch(i);
    }

    /// Prefetches ball `i`'s partner list (its start should be cached by now).
    pub(crate) fn prefetch_partner_list(&self, i: usize) {
        // One prefetch per cache line of 16 partners.
        for k in (self.partner_start[i]..self.partner_start[i + 1]).step_by(16) {
            prefetch(&self.partners[k]);
        }
    }

    /// Prefetches the fields a prediction reads of each of ball `i`'s partners (its list
    /// should be cached by now).
    pub(crate) fn prefetch_partner_rows(&self, i: usize, balls: &BallArrays<T, D>) {
        let partners = &self.partners[self.partner_start[i]..self.partner_start[i + 1]];
        for &p in partners.iter().filter(|&&p| (p as usize) < self.balls) {
            let p = p as usize;
            prefetch(&balls.seg_x[p]);
            prefetch(&balls.chord[p]);
            prefetch(&balls.seg_t[p]);
            prefetch(&balls.radius[p]);
            prefetch(&balls.version[p]);
            prefetch(&balls.cluster[p]);
        }
    }

    /// Whether `path` (a ball's remaining path box) lies in ball `i`'s entry.
    fn holds(&self, i: usize, path: &Aabb<T, D>) -> bool {
        contains(self.box_of(i), path)
    }

    /// Ball `i`'s escapee box if it escaped, its entry otherwise.
    fn box_of(&self, i: usize) -> &Aabb<T, D> {
        self.escapees.box_of(i).unwrap_or(&self.volumes[i])
    }

    /// Records that ball `i`'s remaining path now has the box `path`: if it leaves the
    /// ball's entry, the ball becomes (or stays) an escapee with that box. Returns the
    /// number of escapees.
    pub(crate) fn moved(&mut self, i: usize, path: Aabb<T, D>) -> usize {
        if !self.holds(i, &path) {
            self.escapees.set(i, path);
        }
        self.escapees.len()
    }

    /// The balls' entries (then the boxes').
    pub(crate) fn entries(&self) -> &[Aabb<T, D>] {
        &self.volumes
    }

    /// The escapees, in the order they escaped.
    pub(crate) fn escapees(&self) -> &[u32] {
        self.escapees.balls()
    }

    /// The candidates ball `i`, whose remaining path (or a box around it) is `path`, can
    /// meet: indices of balls (`< n`, possibly `i` itself) and boxes (`n + k`, open space
    /// only), then the escapees whose boxes overlap `path`, into `out` (cleared first;
    /// may repeat).
    ///
    /// If `path` lies in ball `i`'s entry, the candidates are its partners: a ball that
    /// can touch `path` keeps its own path in its entry (or is an escapee), so its entry
    /// meets `i`'s and the two are a pair. Otherwise the broad phase is queried.
    pub(crate) fn candidates(&self, i: usize, path: &Aabb<T, D>, out: &mut Vec<u32>) {
        if self.escapees.box_of(i).is_none() && contains(&self.volumes[i], path) {
            out.clear();
            out.extend_from_slice(&self.partners[self.partner_start[i]..self.partner_start[i + 1]]);
        } else {
            self.phase.query_aabb(path, out);
        }
        self.escapees.meeting(path, out);
    }
}

/// The smallest and largest first coordinates of `boxes` (exact in any order).
fn first_axis_extent<T: Real, const D: usize>(boxes: &[Aabb<T, D>], parallel: bool) -> (T, T) {
    let extent = |part: &[Aabb<T, D>]| {
        part.iter()
            .fold((T::INFINITY, -T::INFINITY), |(lo, hi), b| {
                (lo.min(b.min()[0]), hi.max(b.max()[0]))
            })
    };
    let merge = |a: (T, T), b: (T, T)| (a.0.min(b.0), a.1.max(b.1));
    if parallel {
        boxes
            .par_chunks(CHUNK)
            .map(extent)
            .reduce(|| (T::INFINITY, -T::INFINITY), merge)
    } else {
        extent(boxes)
    }
}

/// `out[i] = f(i)` for every entry, in parallel chunks if asked.
fn fill<V: Send>(out: &mut [V], parallel: bool, f: impl Fn(usize) -> V + Sync) {
    if parallel {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, part)| {
            for (k, v) in part.iter_mut().enumerate() {
                *v = f(c * CHUNK + k);
            }
        });
    } else {
        for (i, v) in out.iter_mut().enumerate() {
            *v = f(i);
        }
    }
}

/// `Σ f(x)` over `items`, summed in fixed chunks of [`CHUNK`] and then in chunk order:
/// the same bits on any number of threads.
pub(crate) fn chunked_sum<X: Sync, T: Real>(
    items: &[X],
    parallel: bool,
    scratch: &mut Vec<T>,
    f: impl Fn(&X) -> T + Sync,
) -> T {
    let part = |c: &[X]| c.iter().fold(T::zero(), |sum, x| sum + f(x));
    if parallel {
        items.par_chunks(CHUNK).map(part).collect_into_vec(scratch);
        scratch.iter().fold(T::zero(), |sum, &x| sum + x)
    } else {
        items
            .chunks(CHUNK)
            .map(part)
            .fold(T::zero(), |sum, x| sum + x)
    }
}

/// Whether `entry` lies strictly inside `border`: a ball whose path is in it does not
/// reach a wall.
pub(crate) fn clear_of<T: Real, const D: usize>(entry: &Aabb<T, D>, border: &Border<T, D>) -> bool {
    (0..D).all(|k| border.min()[k] < entry.min()[k] && entry.max()[k] < border.max()[k])
}

/// Whether `inner` lies in `outer`.
fn contains<T: Real, const D: usize>(outer: &Aabb<T, D>, inner: &Aabb<T, D>) -> bool {
    (0..D).all(|k| outer.min()[k] <= inner.min()[k] && inner.max()[k] <= outer.max()[k])
}

/// Whether two boxes overlap or touch.
pub(crate) fn overlap<T: Real, const D: usize>(a: &Aabb<T, D>, b: &Aabb<T, D>) -> bool {
    (0..D).all(|k| a.min()[k] <= b.max()[k] && b.min()[k] <= a.max()[k])
}

/// Rounding allowance of a box around `center` of half size `half`: positions computed
/// as `x + u·s` may land a few ulps outside the exact box.
fn pad<T: Real, const D: usize>(center: &Vector<T, D>, half: T) -> T {
    T::lit(8.0) * T::EPSILON * (center.amax() + half)
}

/// The box around the ball of radius `r + reach` centred at `x`.
pub(crate) fn reach_box<T: Real, const D: usize>(x: &Vector<T, D>, r: T, reach: T) -> Aabb<T, D> {
    let half = r + reach;
    let h = Vector::<T, D>::repeat(half + pad(x, half));
    Aabb::new_unchecked(x - h, x + h)
}

/// The box swept by a ball of radius `r` moving straight from `from` to `to`.
pub(crate) fn path_box<T: Real, const D: usize>(
    from: &Vector<T, D>,
    to: &Vector<T, D>,
    r: T,
) -> Aabb<T, D> {
    let half = r + pad(from, r).max(pad(to, r));
    let h = Vector::<T, D>::repeat(half);
    Aabb::new_unchecked(from.inf(to) - h, from.sup(to) + h)
}

#[cfg(test)]
mod tests {
    use carom_geometry::Obb;
    use carom_math::Vector;

    use super::*;
    use crate::scene::BoxSpec;
    use crate::scenes::gas::{GasParams, gas};

    /// A dense gas with two boxes, its arrays, and a grid built over `reach`.
    fn built(reach: f64) -> (BallArrays<f64, 2>, Sweep<f64, 2>) {
        let mut scene = gas::<2>(&GasParams {
            n: 2000,
            fraction: 0.3,
            speed: 3.0,
            ..GasParams::default()
        })
        .unwrap();
        // Two of the boxes overlap: a box–box pair lists nothing.
        for (x, angle) in [(-5.0, 0.3), (6.0, 0.0), (6.3, 0.5)] {
            scene.boxes.push(BoxSpec {
                shape: Obb::from_angle(Vector::from([x, 1.0]), Vector::from([0.2, 3.0]), angle)
                    .unwrap(),
                vel: Vector::from([0.5, 0.0]),
                restitution: 1.0,
            });
        }
        let mut balls = BallArrays::from_scene(&scene, 1.0).unwrap();
        for i in 0..balls.len() {
            balls.seg_x[i] = balls.pos[i];
            balls.chord[i] = balls.vel[i];
        }
        let boxes = BoxArrays::new(&scene.boxes, 1.0);
        let mut sweep = Sweep::new(BroadChoice::Grid, balls.len(), None);
        sweep.build(&balls, &boxes, 0.0, reach, false);
        (balls, sweep)
    }

    /// The volumes whose entries meet `query`, by brute force (ball `i` left out).
    fn brute(sweep: &Sweep<f64, 2>, i: usize, query: &Aabb<f64, 2>) -> Vec<u32> {
        (0..sweep.volumes.len())
            .filter(|&j| j != i && overlap(&sweep.volumes[j], query))
            .map(|j| j as u32)
            .collect()
    }

    fn sorted(mut v: Vec<u32>) -> Vec<u32> {
        v.sort_unstable();
        v.dedup();
        v
    }

    #[test]
    fn partner_lists_are_the_pairs_of_each_ball() {
        let (balls, sweep) = built(0.2);
        let mut partners = 0;
        for i in 0..balls.len() {
            let list = sweep.partners[sweep.partner_start[i]..sweep.partner_start[i + 1]].to_vec();
            let expected = brute(&sweep, i, &sweep.volumes[i]);
            partners += list.len();
            assert_eq!(
                sorted(list.clone()).len(),
                list.len(),
                "ball {i} lists a partner twice"
            );
            assert_eq!(sorted(list), expected, "ball {i}");
        }
        // A dense gas: each ball has a few partners, not all the others.
        assert!(
            balls.len() < partners && partners < 20 * balls.len(),
            "{partners} partners"
        );
    }

    /// The candidates of a path inside a ball's entry (its partners) and of a path
    /// outside it (a query) hold every volume and every escapee the path meets.
    #[test]
    fn candidates_hold_everything_a_path_meets() {
        let (balls, mut sweep) = built(0.2);
        let n = balls.len();
        // Ten balls escape: their paths now reach three metres to the right, among
        // other balls.
        let escapees: Vec<usize> = (0..10).map(|k| 7 + 97 * k).collect();
        for &e in &escapees {
            let x = balls.position_at(e, 0.0);
            sweep.moved(e, path_box(&x, &(x + Vector::from([3.0, 0.0])), 0.5));
        }
        assert_eq!(sweep.escapees().len(), escapees.len());
        let mut out = Vec::new();
        let mut through_partners = 0;
        for i in 0..n {
            let path = if escapees.contains(&i) {
                *sweep.box_of(i)
            } else {
                reach_box(&balls.position_at(i, 0.0), balls.radius[i], 0.1)
            };
            through_partners += usize::from(contains(&sweep.volumes[i], &path));
            sweep.candidates(i, &path, &mut out);
            let got = sorted(out.iter().copied().filter(|&c| c as usize != i).collect());
            let mut expected = brute(&sweep, i, &path);
            expected.extend(
                escapees
                    .iter()
                    .filter(|&&e| e != i && overlap(sweep.box_of(e), &path))
                    .map(|&e| e as u32),
            );
            let expected = sorted(expected);
            let missing: Vec<_> = expected
                .iter()
                .filter(|c| got.binary_search(c).is_err())
                .collect();
            assert!(missing.is_empty(), "ball {i} misses {missing:?}");
        }
        assert_eq!(through_partners, n - escapees.len());
    }

    /// In a periodic domain the escapees a path meets through the boundary are
    /// candidates too: balls whose paths leave the cell through its top (or its right
    /// face, the axis the escapees' lanes slice) are found by the balls at its bottom
    /// (its left face).
    #[test]
    fn in_a_periodic_domain_candidates_hold_the_escapees_a_path_meets_through_the_boundary() {
        let scene = gas::<2>(&GasParams {
            n: 2000,
            fraction: 0.3,
            speed: 3.0,
            periodic: true,
            ..GasParams::default()
        })
        .unwrap();
        let border = scene.world.border.unwrap().border;
        let (lo, hi, size) = (border.min(), border.max(), border.extents());
        let mut balls = BallArrays::from_scene(&scene, 1.0).unwrap();
        for i in 0..balls.len() {
            balls.seg_x[i] = balls.pos[i];
            balls.chord[i] = balls.vel[i];
        }
        // Every periodic image of `a` tested against `b`, by brute force.
        let meet = |a: &Aabb<f64, 2>, b: &Aabb<f64, 2>| {
            [-1.0, 0.0, 1.0].iter().any(|&kx| {
                [-1.0, 0.0, 1.0].iter().any(|&ky| {
                    let shift = Vector::from([kx * size[0], ky * size[1]]);
                    overlap(&Aabb::new_unchecked(a.min() + shift, a.max() + shift), b)
                })
            })
        };
        for axis in [1, 0] {
            let mut sweep = Sweep::new(BroadChoice::Grid, balls.len(), Some(&border));
            sweep.build(&balls, &BoxArrays::new(&[], 1.0), 0.0, 0.2, false);
            // The balls between four and five metres inside the upper face escape: their
            // paths now reach 5 m out through it, far from their entries.
            let escapees: Vec<usize> = (0..balls.len())
                .filter(|&i| (4.0..5.0).contains(&(hi[axis] - balls.pos[i][axis])))
                .collect();
            let mut out_through = Vector::zeros();
            out_through[axis] = 5.0;
            for &e in &escapees {
                let x = balls.pos[e];
                sweep.moved(e, path_box(&x, &(x + out_through), 0.5));
            }
            let mut out = Vec::new();
            let mut through_the_boundary = 0;
            for i in (0..balls.len()).filter(|&i| balls.pos[i][axis] < lo[axis] + 2.0) {
                let path = reach_box(&balls.pos[i], balls.radius[i], 0.1);
                sweep.candidates(i, &path, &mut out);
                for &e in &escapees {
                    if meet(&path, sweep.box_of(e)) {
                        through_the_boundary += 1;
                        assert!(
                            out.contains(&(e as u32)),
                            "axis {axis}: ball {i} misses escapee {e}"
                        );
                    }
                }
            }
            assert!(
                through_the_boundary > 10,
                "axis {axis}: {through_the_boundary} meetings"
            );
        }
    }
}
