//! The balls as struct-of-arrays: properties, the state between steps, and the motion
//! within the current step as one straight segment per ball.
//!
//! Between steps the state is `pos`, `vel`, `spin` (at the engine's current time). During
//! a step of length `h` these arrays hold the state **at the end of the step** as known
//! so far, and each ball moves on a segment: from `seg_x` at in-step time `seg_t`, along
//! the chord velocity `chord`, to `pos` at `h`:
//!
//! ```text
//! x(s) = seg_x + chord · (s − seg_t),          seg_t <= s <= h
//! v(s) = seg_v + (vel − seg_v) · (s − seg_t)/(h − seg_t)    (physical velocity)
//! ```
//!
//! At the start of a step every segment is the integrator's step: `seg_x` the old
//! position, `pos` the integrated one, `chord` the integrator's displacement over `h`. A
//! collision at `s` restarts the segment at `s` ([`BallArrays::restart`]) and replaces
//! its end.
//!
//! **Remainders.** A ball's place is rounded to the coordinates at every new segment, and
//! a motion of less than half a unit in the last place per segment would be dropped
//! there: in `f32` 5e4 m from the origin (units of 3.9e-3 m) a ball moving 1.7e-3 m a
//! step stood still while a box moved on into it, and a ball restarted 87 times within
//! one step by a light ball's collisions lost 0.08 m of its 0.10 m. So each segment
//! start keeps what its rounding dropped, `seg_r` (compensated summation): the ball is at
//! `seg_x + seg_r` at `seg_t`, a restart adds the travel to the remainder before it
//! rounds, the integrator's step is taken as a displacement (from the origin: the
//! engine's forces do not depend on the position) added to the remainder, and the next
//! step starts from what the end of the last one could not hold. Everything
//! else (times of impact, holds) reads the rounded `seg_x`, which is within half a unit
//! of the ball: the touch tolerance covers that. The
//! physical velocity is interpolated linearly, which is exact for constant acceleration
//! (gravity) and first-order otherwise; positions follow the chord, which is what the
//! continuous collision detection sweeps, so "no overlap along the chords" is exactly
//! what the engine guarantees.

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use super::clusters::FREE;
use crate::engine::Angular;
use crate::prefetch::prefetch;
use crate::scene::{Scene, SceneError};

/// Every ball's properties, state and current segment, in scene order.
#[derive(Clone, Debug)]
pub(crate) struct BallArrays<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Radii.
    pub(crate) radius: Vec<T>,
    /// Masses.
    pub(crate) mass: Vec<T>,
    /// `1/m`.
    pub(crate) inverse_mass: Vec<T>,
    /// `1/I` of the ball about its centre (`I = f m r²`, disk or solid sphere).
    pub(crate) inverse_inertia: Vec<T>,
    /// Each ball's restitution (its override, or the world's).
    pub(crate) restitution: Vec<T>,
    /// Position at the end of the step (the state between steps).
    pub(crate) pos: Vec<Vector<T, D>>,
    /// Velocity at the end of the step.
    pub(crate) vel: Vec<Vector<T, D>>,
    /// Angular velocity at the end of the step.
    pub(crate) spin: Vec<Angular<T, D>>,
    /// In-step time the current segment starts at.
    pub(crate) seg_t: Vec<T>,
    /// Position at `seg_t`, rounded to the coordinates.
    pub(crate) seg_x: Vec<Vector<T, D>>,
    /// What the rounding of `seg_x` dropped: the ball is at `seg_x + seg_r` at `seg_t`.
    pub(crate) seg_r: Vec<Vector<T, D>>,
    /// Physical velocity at `seg_t`.
    pub(crate) seg_v: Vec<Vector<T, D>>,
    /// Angular velocity at `seg_t`.
    pub(crate) seg_w: Vec<Angular<T, D>>,
    /// The segment's constant velocity.
    pub(crate) chord: Vec<Vector<T, D>>,
    /// Bumped whenever the segment changes: events predicted before are stale.
    pub(crate) version: Vec<u32>,
    /// Resting on an immovable surface, directly or through other supported balls, in
    /// the current step (see `response`: shock propagation).
    pub(crate) supported: Vec<bool>,
    /// The stuck cluster each ball belongs to, or [`FREE`] (see `clusters`).
    pub(crate) cluster: Vec<u32>,
}

impl<T: Real, const D: usize> BallArrays<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The balls of a validated `scene`, velocities multiplied by `sign` (−1 for a
    /// backward run), at rest spinning.
    ///
    /// # Errors
    /// `balls[i]` if `m r²` is out of the range of the precision (its inverse would not
    /// be finite and positive).
    pub(crate) fn from_scene(scene: &Scene<T, D>, sign: T) -> Result<Self, SceneError> {
        let n = scene.balls.len();
        let inertia = <Const<D> as Space<T, D>>::ball_inertia_factor();
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        let balls = Self {
            radius: scene.balls.iter().map(|b| b.radius).collect(),
            mass: scene.balls.iter().map(|b| b.mass).collect(),
            inverse_mass: scene.balls.iter().map(|b| T::one() / b.mass).collect(),
            inverse_inertia: scene
                .balls
                .iter()
                .map(|b| T::one() / (inertia * b.mass * b.radius * b.radius))
                .collect(),
            restitution: scene
                .balls
                .iter()
                .map(|b| b.restitution.unwrap_or(scene.world.restitution))
                .collect(),
            pos: scene.balls.iter().map(|b| b.pos).collect(),
            vel: scene.balls.iter().map(|b| b.vel * sign).collect(),
            spin: vec![zero_spin; n],
            seg_t: vec![T::zero(); n],
            // An empty segment ending where the ball is: no remainder to carry.
            seg_x: scene.balls.iter().map(|b| b.pos).collect(),
            seg_r: vec![Vector::zeros(); n],
            seg_v: vec![Vector::zeros(); n],
            seg_w: vec![zero_spin; n],
            chord: vec![Vector::zeros(); n],
            version: vec![0; n],
            supported: vec![false; n],
            cluster: vec![FREE; n],
        };
        let bad = |x: &T| !(x.finite() && *x > T::zero());
        let bad_mass = balls.inverse_mass.iter().position(bad);
        match bad_mass.or_else(|| balls.inverse_inertia.iter().position(bad)) {
            Some(i) => Err(SceneError::new(
                format!("balls[{i}]"),
                "mass and mass · radius² must have finite positive inverses in this precision",
            )),
            None => Ok(balls),
        }
    }

    /// The number of balls.
    pub(crate) fn len(&self) -> usize {
        self.radius.len()
    }

    /// The restitution of a contact between balls `i` and `j`: the smaller of theirs (the
    /// scene contract's pair rule, `Scene::pair_restitution`).
    pub(crate) fn pair_restitution(&self, i: usize, j: usize) -> T {
        self.restitution[i].min(self.restitution[j])
    }

    /// Prefetches what a prediction against ball `i` reads of it
    /// (`narrow::Narrow::ball_ball`): its cluster, segment, chord, radius and version.
    #[inline]
    pub(crate) fn prefetch_partner(&self, i: usize) {
        prefetch(&self.cluster[i]);
        prefetch(&self.seg_x[i]);
        prefetch(&self.seg_t[i]);
        prefetch(&self.chord[i]);
        prefetch(&self.radius[i]);
        prefetch(&self.version[i]);
    }

    /// Prefetches every field of ball `i` (see `prefetch`): what a prediction reads
    /// ([`Self::prefetch_partner`]) and the rest.
    pub(crate) fn prefetch_row(&self, i: usize) {
        self.prefetch_partner(i);
        prefetch(&self.mass[i]);
        prefetch(&self.inverse_mass[i]);
        prefetch(&self.inverse_inertia[i]);
        prefetch(&self.restitution[i]);
        prefetch(&self.pos[i]);
        prefetch(&self.vel[i]);
        prefetch(&self.spin[i]);
        prefetch(&self.seg_r[i]);
        prefetch(&self.seg_v[i]);
        prefetch(&self.seg_w[i]);
        prefetch(&self.supported[i]);
    }

    /// Position of ball `i` at in-step time `s` on its segment.
    #[inline]
    pub(crate) fn position_at(&self, i: usize, s: T) -> Vector<T, D> {
        self.seg_x[i] + self.chord[i] * (s - self.seg_t[i])
    }

    /// The fraction of the segment of ball `i` elapsed at `s` (0 for an empty segment).
    #[inline]
    fn fraction(&self, i: usize, s: T, h: T) -> T {
        let span = h - self.seg_t[i];
        if span > T::zero() {
            ((s - self.seg_t[i]) / span).min(T::one())
        } else {
            T::zero()
        }
    }

    /// Physical velocity and spin of ball `i` at `s` (step length `h`).
    #[inline]
    pub(crate) fn velocity_at(&self, i: usize, s: T, h: T) -> (Vector<T, D>, Angular<T, D>) {
        let f = self.fraction(i, s, h);
        (
            self.seg_v[i] + (self.vel[i] - self.seg_v[i]) * f,
            self.seg_w[i] + (self.spin[i] - self.seg_w[i]) * f,
        )
    }

    /// The spin ball `i`'s contact points read along its chord (the spin's analogue of
    /// the chord, which no array keeps: a sphere's orientation is not tracked), for an
    /// integrator of chord weight `weight` (`Integrator::chord_weight`): the start spin
    /// plus `weight` times the segment's change, `seg_w + w (spin − seg_w)`.
    ///
    /// A hold's torque shows in the spins as its force does in the velocities (see
    /// `stack::spin_shares`): the start spin unchanged and the end spin by `Δω / w`, or
    /// both by `Δω` for explicit Euler (`w = 0`), and either way this reading by `Δω`,
    /// which is what the hold's problem counts on. A free ball's spin is constant
    /// without drag, and this is its spin.
    #[inline]
    pub(crate) fn chord_spin(&self, i: usize, weight: T) -> Angular<T, D> {
        self.seg_w[i] + (self.spin[i] - self.seg_w[i]) * weight
    }

    /// Starts a new segment of ball `i` at `s`, on the same chord and with the same end:
    /// the travel is added to the remainder before it rounds, and what the rounding
    /// dropped is the new remainder (`x − seg_x` is exact when the two lie within a
    /// factor two of each other, as far from the origin; otherwise it is rounded like
    /// the travel itself).
    pub(crate) fn restart(&mut self, i: usize, s: T, h: T) {
        let travel = self.seg_r[i] + self.chord[i] * (s - self.seg_t[i]);
        let x = self.seg_x[i] + travel;
        let (v, w) = self.velocity_at(i, s, h);
        self.seg_r[i] = travel - (x - self.seg_x[i]);
        self.seg_x[i] = x;
        self.seg_v[i] = v;
        self.seg_w[i] = w;
        self.seg_t[i] = s;
    }

    /// Where ball `i`'s segment ends at `h`, rounded once.
    #[inline]
    fn end(&self, i: usize, h: T) -> Vector<T, D> {
        self.seg_x[i] + (self.seg_r[i] + self.chord[i] * (h - self.seg_t[i]))
    }

    /// Sets the end of the segment of ball `i` (length `h − seg_t > 0`, else the chord
    /// is `v`), and the chord: given as a place or as a displacement ([`SegmentEnd`]).
    pub(crate) fn set_end(
        &mut self,
        i: usize,
        h: T,
        end: SegmentEnd<T, D>,
        v: Vector<T, D>,
        w: Angular<T, D>,
    ) {
        let (moved, end) = match end {
            SegmentEnd::Place(x) => ((x - self.seg_x[i]) - self.seg_r[i], x),
            SegmentEnd::Moved(moved) => (moved, self.seg_x[i] + (self.seg_r[i] + moved)),
        };
        let span = h - self.seg_t[i];
        self.chord[i] = if span > T::zero() { moved / span } else { v };
        self.pos[i] = end;
        self.vel[i] = v;
        self.spin[i] = w;
    }

    /// Changes ball `i`'s velocity by `dv` (and spin by `dw`) from the segment start on,
    /// without re-integrating: the chord and the physical velocity shift alike.
    pub(crate) fn nudge(&mut self, i: usize, h: T, dv: &Vector<T, D>, dw: &Angular<T, D>) {
        self.chord[i] += dv;
        self.seg_v[i] += dv;
        self.vel[i] += dv;
        self.seg_w[i] += *dw;
        self.spin[i] += *dw;
        self.pos[i] = self.end(i, h);
    }

    /// Holds ball `i` on several supports: its chord becomes `u` from the segment start
    /// on, and so does its physical velocity (the forces of the rest of the step are
    /// what the supports cancel).
    pub(crate) fn hold(&mut self, i: usize, h: T, u: Vector<T, D>) {
        self.chord[i] = u;
        self.seg_v[i] = u;
        self.vel[i] = u;
        self.pos[i] = self.end(i, h);
    }

    /// Sets the segment of ball `i` from its start on: the velocity at its start, its
    /// chord and its end velocity `[seg_v, chord, vel]`, its start and end spins.
    pub(crate) fn set_segment(
        &mut self,
        i: usize,
        h: T,
        [seg_v, chord, vel]: [Vector<T, D>; 3],
        [seg_w, spin]: [Angular<T, D>; 2],
    ) {
        self.seg_v[i] = seg_v;
        self.chord[i] = chord;
        self.vel[i] = vel;
        self.seg_w[i] = seg_w;
        self.spin[i] = spin;
        self.pos[i] = self.end(i, h);
    }

    /// Changes the chord of ball `i` by `du` (and its spin by `dw`) from the segment start
    /// on, for a resting contact along the unit normal `n`: the velocity and spin at the
    /// segment's start and end shift by the `(start, end)` shares of the change
    /// (`stack::shares`), and the velocity at the segment's start takes the chord's
    /// component along `n`. So does the end velocity when the change is a force over the
    /// rest of the step (`start` 0), so that a ball held on a surface does not end the
    /// step moving into it. An impulse at the segment's start (`start` 1: explicit Euler,
    /// whose chords no force within the step moves) leaves the end velocity the start's
    /// plus the rest of the step's forces, as the integrator has it: a resting ball ends
    /// each step moving into its support at `g h`, and the next step's hold stops that
    /// approach with its friction. Setting the end's component to the chord's took the
    /// same normal impulse without friction, and only every other step found the contact
    /// (the next one starts with no approach): a disk sliding on the floor slowed at
    /// `μ g / 2`.
    pub(crate) fn shift_chord(
        &mut self,
        i: usize,
        h: T,
        du: &Vector<T, D>,
        dw: &Angular<T, D>,
        n: &Vector<T, D>,
        (start, end): (T, T),
    ) {
        self.chord[i] += du;
        let along = self.chord[i].dot(n);
        let held_end = start == T::zero();
        for (v, share, held) in [
            (&mut self.seg_v[i], start, true),
            (&mut self.vel[i], end, held_end),
        ] {
            *v += du * share;
            if held {
                *v += n * (along - v.dot(n));
            }
        }
        self.seg_w[i] += *dw * start;
        self.spin[i] += *dw * end;
        self.pos[i] = self.end(i, h);
    }
}

/// Where a segment ends ([`BallArrays::set_end`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum SegmentEnd<T: Real, const D: usize> {
    /// A place given in coordinates (a cluster member's rigid place).
    Place(Vector<T, D>),
    /// A displacement from the segment's start (an integrator's step), added to the
    /// start's remainder before it rounds.
    Moved(Vector<T, D>),
}
