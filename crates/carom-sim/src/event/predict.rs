//! Prediction: the earliest event of one ball.
//!
//! A ball's next event is the earliest of: its list rebuild (when it leaves its shell),
//! sliding off the face it rests on, its first border wall, its first box, and its first
//! collision with each partner. Each search is given the best time found so far as its
//! horizon, so later candidates stop early.

use carom_geometry::{Ball, Period};
use carom_math::{Real, Space, Vector};
use carom_toi::{
    Kinematics, Window, ball_ball, ball_border, ball_obb, level_crossing, relative_contact_time,
};
use nalgebra::Const;

use super::state::{Mode, Support};
use super::{EventEngine, Partners, Pending};

/// A rebuild is scheduled when the ball has moved this fraction of the shell, keeping a
/// margin far above rounding so a touching pair is always on each other's lists.
const SHELL_SAFETY: f64 = 1.0 - 1e-6;

impl<T: Real, const D: usize> EventEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    /// Predicts and schedules ball `i`'s next event (balls in clusters are scheduled by
    /// their cluster).
    pub(crate) fn predict(&mut self, i: usize) {
        if self.is_stuck(i) {
            self.pending[i] = Pending::None;
            self.calendar.cancel(i);
            return;
        }
        let mut best = self.own_event(i);
        let ball = self.ball_at(i, self.now);
        let kin =
            Kinematics::new_unchecked(self.balls.velocity_at(i, self.now), self.balls.accel(i));
        self.offer_surfaces(i, &ball, &kin, &mut best);
        if !self.clusters.is_empty() {
            self.predict_ball_vs_clusters(i, &mut best.time, &mut best.pending);
        }
        let mut gathered = core::mem::take(&mut self.gathered);
        self.offer_partners(i, &ball, &kin, &mut best, Near::Around, &mut gathered);
        self.gathered = gathered;
        self.pending[i] = best.pending;
        self.schedule(i, &ball, &kin, best.time);
    }

    /// Schedules ball `i`, whose pending event is due at `event`: with cell lists, at the
    /// earlier of that and its next crossing of a face of its cell.
    fn schedule(&mut self, i: usize, ball: &Ball<T, D>, kin: &Kinematics<T, D>, event: T) {
        let time = match &mut self.partners {
            Partners::Cells(cells) => {
                let crossing =
                    cells.next_crossing(i, &ball.center(), &kin.velocity(), &kin.acceleration());
                cells.record(i, self.now, event, crossing)
            }
            _ => event,
        };
        self.calendar.schedule(i, time);
    }

    /// Ball `i` crosses the face (`axis`, `upper`) of its cell (cell lists): it moves to
    /// the cell across, and is predicted against the balls of the cells its neighbourhood
    /// gains. Its pending event stays: it was the earliest against every other candidate,
    /// and the new ones are searched up to it. (A stale pending event is kept too: when it
    /// comes due, the ball is predicted afresh.)
    pub(crate) fn cross(&mut self, i: usize, axis: usize, upper: bool) {
        let Partners::Cells(cells) = &mut self.partners else {
            return;
        };
        cells.cross(i, axis, upper);
        let mut best = Best {
            time: cells.event_time(i),
            pending: self.pending[i],
        };
        let ball = self.ball_at(i, self.now);
        let kin =
            Kinematics::new_unchecked(self.balls.velocity_at(i, self.now), self.balls.accel(i));
        let mut gathered = core::mem::take(&mut self.gathered);
        let near = Near::Entering { axis, upper };
        self.offer_partners(i, &ball, &kin, &mut best, near, &mut gathered);
        self.gathered = gathered;
        self.pending[i] = best.pending;
        self.schedule(i, &ball, &kin, best.time);
    }

    /// The events of ball `i` alone: leaving its neighbour-list shell (or, pairing with
    /// every ball in a periodic box, moving far enough to need another image), sliding off
    /// the face it rests on.
    fn own_event(&self, i: usize) -> Best<T> {
        let now = self.now;
        let mut best = Best {
            time: T::INFINITY,
            pending: Pending::None,
        };
        if let Partners::Lists(lists) = &self.partners {
            let displacement = self.separation(lists.anchor(i), &self.balls.position_at(i, now));
            let velocity = self.balls.velocity_at(i, now);
            let s = exit_time(
                &displacement,
                &velocity,
                &self.balls.accel(i),
                lists.shell() * T::lit(SHELL_SAFETY),
            );
            best.offer(now + s, Pending::Rebuild);
        }
        if let Partners::All { roam: Some(roam) } = &self.partners {
            let s = exit_time(
                &Vector::zeros(),
                &self.balls.velocity_at(i, now),
                &self.balls.accel(i),
                *roam,
            );
            best.offer(now + s, Pending::Recheck);
        }
        if let Some(Support::BoxFace { k, axis, .. }) = self.support_of(i)
            && let Some(s) = self.face_exit_time(i, k, axis)
        {
            best.offer(now + s, Pending::LeaveSupport);
        }
        best
    }

    /// The box whose face ball `i` rests on, if it rests on one.
    fn support_box(&self, i: usize) -> Option<usize> {
        match self.support_of(i) {
            Some(Support::BoxFace { k, .. }) => Some(k),
            _ => None,
        }
    }

    /// The first contact of ball `i` (`ball`, moving with `kin`) with a border wall or a
    /// box other than the one it rests on.
    ///
    /// A ball resting on a face of a box cannot meet that box until it leaves the face
    /// (the box is convex), which [`EventEngine::face_exit_time`] schedules. Asked, the
    /// time of impact sees the ball's velocity and acceleration along a rotated face's
    /// normal, zero but for rounding, and finds the face due at once whenever that
    /// rounding points into the box; the response then had nothing to do, and the same
    /// event came due forever.
    fn offer_surfaces(
        &self,
        i: usize,
        ball: &Ball<T, D>,
        kin: &Kinematics<T, D>,
        best: &mut Best<T>,
    ) {
        let now = self.now;
        if let (Some(border), false) = (&self.border, self.periodic) {
            let toi = ball_border(ball, kin, border, &best.window(now));
            if let Some(s) = toi.hit_time() {
                let upper = toi.feature.side == carom_toi::Side::Upper;
                best.offer(
                    now + s,
                    Pending::Wall {
                        axis: toi.feature.axis as u8,
                        upper,
                    },
                );
            }
        }
        if self.boxes.is_empty() {
            return;
        }
        let support = self.support_box(i);
        for (k, b) in self.boxes.iter().enumerate() {
            if support == Some(k) {
                continue;
            }
            let obb = b.at(now);
            // In a periodic box, the image of the ball nearest the box.
            let image = if self.periodic {
                Ball::new_unchecked(
                    obb.center() - self.separation(&ball.center(), &obb.center()),
                    ball.radius(),
                )
            } else {
                *ball
            };
            let toi = ball_obb(
                &image,
                kin,
                &obb,
                &Kinematics::new_unchecked(b.vel, Vector::zeros()),
                &best.window(now),
            );
            if let Some(s) = toi.hit_time() {
                best.offer(now + s, Pending::Box { k: k as u32 });
            }
        }
    }

    /// The first collision of ball `i` with each of its partners `near` it (`gathered`:
    /// scratch for those of cell lists).
    fn offer_partners(
        &self,
        i: usize,
        ball: &Ball<T, D>,
        kin: &Kinematics<T, D>,
        best: &mut Best<T>,
        near: Near,
        gathered: &mut Vec<u32>,
    ) {
        let probe = Probe {
            i,
            now: self.now,
            ball,
            kin,
            period: self.period.as_ref(),
            clusters: !self.clusters.is_empty(),
            accelerated: self.balls.accelerated,
            reach: T::lit(2.0) * T::EPSILON * ball.center().amax(),
        };
        match (near, &self.partners) {
            (near, Partners::Cells(cells)) => {
                // Gathered before any is tested, whole rows at a time (no branch on a
                // cell's length), each partner's record asked for (`prefetch`) before the
                // first test, so that the records' cache misses overlap instead of each
                // test waiting for its own; tested in the order gathered (2D gas,
                // docs/event-engine.md: ×1.025–1.095 at 1e5 for the read-ahead, eleventh
                // session; whole rows 22 % fewer mispredictions, level, fortieth).
                gathered.clear();
                match near {
                    Near::Entering { axis, upper } => {
                        cells.gather_entering(i, axis, upper, gathered);
                    }
                    Near::Around => cells.gather_near(i, gathered),
                }
                for &j in gathered.iter() {
                    crate::prefetch::prefetch(&self.balls.motion[j as usize]);
                }
                for &j in gathered.iter() {
                    self.offer_partner(&probe, j as usize, best);
                }
            }
            (_, Partners::Lists(lists)) => {
                for j in lists.partners(i) {
                    self.offer_partner(&probe, j as usize, best);
                }
            }
            (_, Partners::All { .. }) => {
                for j in 0..self.balls.len() {
                    self.offer_partner(&probe, j, best);
                }
            }
        }
    }

    /// The first collision of the probed ball with ball `j`, if it comes before the best
    /// event so far: the inner loop of the engine, inlined into each way of visiting
    /// partners, with what it reads of the probed ball and the world read once
    /// ([`Probe`]). Inlined always: with a plain `#[inline]` the compiler kept it a call in
    /// the neighbour-list loop, 3 % more instructions per collision in the 3D gas
    /// (callgrind, N = 4,000).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn offer_partner(&self, probe: &Probe<'_, T, D>, j: usize, best: &mut Best<T>) {
        if j == probe.i || (probe.clusters && matches!(self.balls.mode[j], Mode::Stuck(_))) {
            return;
        }
        let now = probe.now;
        let radius = self.balls.motion[j].radius;
        let offset = self.balls.position_at(j, now) - probe.ball.center();
        let offset = match probe.period {
            Some(period) => period.minimum_image(&offset),
            None => offset,
        };
        let velocity_j = self.balls.velocity_at(j, now);
        let window = best.window(now);
        // A common acceleration (none, or the same gravity) cancels: the pair's relative
        // motion is linear, and only the time is needed.
        let hit = if !probe.accelerated || self.balls.accel[j] == probe.kin.acceleration() {
            relative_contact_time(
                &offset,
                &(velocity_j - probe.kin.velocity()),
                probe.ball.radius() + radius,
                &window,
                probe.reach,
            )
        } else {
            let other = Ball::new_unchecked(probe.ball.center() + offset, radius);
            let kin_j = Kinematics::new_unchecked(velocity_j, self.balls.accel[j]);
            ball_ball(probe.ball, probe.kin, &other, &kin_j, &window).hit_time()
        };
        if let Some(s) = hit {
            best.offer(
                now + s,
                Pending::Ball {
                    j: j as u32,
                    count: self.balls.count[j],
                },
            );
        }
    }

    /// When the centre of resting ball `i` leaves the face (axis `axis`) of box `k` it
    /// rests on: the first time a tangential box-local coordinate crosses `±h`.
    pub(crate) fn face_exit_time(&self, i: usize, k: usize, axis: usize) -> Option<T> {
        let b = &self.boxes[k];
        let obb = b.at(self.now);
        let local = obb.to_local(&self.balls.position_at(i, self.now));
        let rel_v = obb.vector_to_local(&(self.balls.velocity_at(i, self.now) - b.vel));
        let rel_a = obb.vector_to_local(&self.balls.accel(i));
        let h = obb.half_extents();
        let window = Window::unbounded(carom_toi::Direction::Forward);
        let mut first: Option<T> = None;
        for m in (0..D).filter(|&m| m != axis) {
            for level in [-h[m], h[m]] {
                let c = level_crossing(local[m], rel_v[m], rel_a[m], level, &window);
                // Only a crossing from inside the face to outside ends the support.
                let leaving = (level > T::zero()) == (c.to == carom_toi::Side::Upper);
                if let Some(t) = c.time.finite().then_some(c.time)
                    && leaving
                    && first.is_none_or(|f| t < f)
                {
                    first = Some(t);
                }
            }
        }
        first
    }
}

/// Which partners a prediction searches.
#[derive(Clone, Copy, Debug)]
enum Near {
    /// All of them.
    Around,
    /// Those a ball's neighbourhood gained when it crossed the face (`axis`, `upper`)
    /// into its cell (cell lists).
    Entering { axis: usize, upper: bool },
}

/// What a prediction of ball `i` against its partners reads once, not once per partner.
struct Probe<'a, T: Real, const D: usize> {
    i: usize,
    now: T,
    ball: &'a Ball<T, D>,
    kin: &'a Kinematics<T, D>,
    /// The periods of a periodic border.
    period: Option<&'a Period<T, D>>,
    /// `true` while stuck clusters exist (a partner's mode is read only then).
    clusters: bool,
    /// `true` under gravity (accelerations are read only then).
    accelerated: bool,
    /// The resolution of positions here, four roundings of the ball's largest coordinate
    /// (its partners' are about the same): a contact time is accepted without its
    /// double-double check when its error moves the pair by less (carom-toi's
    /// `relative_contact_time`).
    reach: T,
}

/// The earliest candidate event so far; later searches use its time as their horizon.
struct Best<T: Real> {
    time: T,
    pending: Pending,
}

impl<T: Real> Best<T> {
    /// Keeps `pending` at `time` if it is earlier (ties keep the first offered).
    #[inline]
    fn offer(&mut self, time: T, pending: Pending) {
        if time < self.time {
            self.time = time;
            self.pending = pending;
        }
    }

    /// A forward window from `now` to the best time so far.
    #[inline]
    fn window(&self, now: T) -> Window<T> {
        Window::forward(self.time - now)
            .unwrap_or_else(|_| Window::forward(T::zero()).expect("0 is a valid horizon"))
    }
}

/// The time a point at `d` from its anchor, moving with velocity `v` and acceleration
/// `a`, first reaches distance `radius` (it starts inside; 0 if it is not).
///
/// Without acceleration this is the exact root of `|d + v s|² = ρ²`, written without
/// cancellation: with `b = d·v`, `c = |d|² − ρ² ≤ 0`, `Δ = b² − |v|² c`, the positive
/// root is `(−b + √Δ)/|v|²`, equal to `−c / (b + √Δ)` when `b > 0`. With acceleration,
/// the bound `|d| + |v| s + |a| s²/2 = ρ` gives a time at which the point is certainly
/// still inside: `s = 2 (ρ − |d|) / (|v| + √(|v|² + 2 |a| (ρ − |d|)))`.
pub(crate) fn exit_time<T: Real, const D: usize>(
    d: &Vector<T, D>,
    v: &Vector<T, D>,
    a: &Vector<T, D>,
    radius: T,
) -> T {
    let room = radius - d.norm();
    if room <= T::zero() {
        return T::zero();
    }
    if a.iter().all(|x| *x == T::zero()) {
        let vv = v.norm_squared();
        if vv == T::zero() {
            return T::INFINITY;
        }
        let b = d.dot(v);
        let c = (d.norm() - radius) * (d.norm() + radius);
        let root = (b * b - vv * c).max(T::zero()).sqrt();
        return if b > T::zero() {
            -c / (b + root)
        } else {
            (root - b) / vv
        };
    }
    let (speed, accel) = (v.norm(), a.norm());
    let two = T::lit(2.0);
    two * room / (speed + (speed * speed + two * accel * room).sqrt())
}

#[cfg(test)]
mod tests {
    use super::exit_time;
    use nalgebra::Vector2;

    #[test]
    fn exit_time_is_exact_without_acceleration_and_conservative_with_it() {
        let z = Vector2::<f64>::zeros();
        assert_eq!(exit_time(&z, &Vector2::new(2.0, 0.0), &z, 1.0), 0.5);
        // Starting at 0.6 moving away and towards: 0.4 and 1.6 to the circle.
        assert!(
            (exit_time(&Vector2::new(0.6, 0.0), &Vector2::new(1.0, 0.0), &z, 1.0) - 0.4).abs()
                < 1e-15
        );
        assert!(
            (exit_time(&Vector2::new(0.6, 0.0), &Vector2::new(-1.0, 0.0), &z, 1.0) - 1.6).abs()
                < 1e-15
        );
        assert_eq!(exit_time(&z, &z, &z, 1.0), f64::INFINITY);
        assert_eq!(exit_time(&Vector2::new(2.0, 0.0), &z, &z, 1.0), 0.0);
        // Falling from rest under g = 2: |d| = s² reaches 1 at s = 1; the bound is exact here.
        let s = exit_time(&z, &z, &Vector2::new(0.0, -2.0), 1.0);
        assert!((s - 1.0).abs() < 1e-15);
        // Thrown sideways under gravity: the bound is earlier than the true exit.
        let (v, a) = (Vector2::new(1.0, 0.0), Vector2::new(0.0, -1.0));
        let s = exit_time(&z, &v, &a, 1.0);
        let p = v * s + a * (0.5 * s * s);
        assert!(p.norm() <= 1.0 + 1e-15);
    }
}
