//! Holding a stack: every cluster and ball in contact with a cluster's resting contact,
//! and the walls, boxes and held balls under them, all at once.
//!
//! A contact of a stuck cluster whose chord still closes after its impulse (see `stick`)
//! holds the **stack** around it, found from the contact outwards: the clusters touching
//! a member of a cluster in the stack (or closing on one within the step), the free balls
//! touching a member, and what touches those. A free ball touching a cluster's member from
//! below, held in this step and not moving up into it, is no body of the stack but a
//! surface moving at its chord (shock propagation, as for a ball on a held ball in
//! `response`); walls and boxes are surfaces. A free ball takes part only with its walls,
//! boxes and held balls below: its contacts with other free balls are the balls' own
//! events, except in the hold of a wedged ball ([`Approach::Any`], see `wedge`), which
//! takes in the free balls touching it, and theirs, with every touching contact however
//! fast it approaches (answered one at a time, a 1 mg ball squeezed between two 1 kg
//! balls and a floor passes on a millionth of the push per contact). A free ball that
//! only closes on them within the step stays out, its contact a collision of its own: a
//! ball at 1e6 m/s closes on every ball it can reach, and took whole scenes into one
//! hold. Every body of the stack restarts at the contact's instant `s` free of earlier
//! holds of the step (see `clusters`: its physical state there, the force dropped), and
//! the stack's contacts are solved in two phases:
//!
//! 1. **Impacts.** The contacts touching now whose bodies approach at `s` (no faster than
//!    gravity adds in two steps: faster ones are collisions, left to their own events)
//!    get restitution-0 impulses on the velocities at `s`, all at once. This stops a ball
//!    landing slowly on a held cluster for good; without it the force below would turn
//!    the landing speed around, and the ball would bounce on forever.
//! 2. **The hold.** Every contact, touching or closing within the rest of the step `τ`
//!    (speculative: a gap `g` may close at `g/τ`, no faster), gets the impulse that stops
//!    its chords closing, all at once. These impulses are the step's **constant contact
//!    force** `F = P/(w τ)` (`w` the integrator's chord weight,
//!    `Integrator::chord_weight`): a body's chord changes by `P/m`, its end velocity by
//!    `P/(w m)` (twice the chord's with Verlet, RK4 and the exact integrator, as much with
//!    semi-implicit Euler), its velocity at `s` not at all; torques alike, a free
//!    ball's spin at the step's end by `Δω/w` and its contact points along the chord by
//!    `Δω` (`BallArrays::chord_spin`, [`spin_shares`]). So a ball
//!    resting on a cluster passes its whole load's torque to the end of the step, and
//!    what the ball and the cluster end the step with is what the force gave them: no
//!    correction of the end velocities afterwards. Explicit Euler's chords are the start
//!    velocities, which no force within the step moves (`w = 0`): its holds are impulses
//!    at `s`, like the impacts.
//!
//! **Exact impulses.** Each phase solves the contacts' linear complementarity problem
//! exactly (`lcp`: the impulses are non-negative, push only where a contact would close
//! beyond its margin, and leave none closing), whatever the mass ratios: a cluster a
//! million times heavier than the one it rests on is held in one solve. With friction the
//! normal impulses and the tangential ones (Coulomb's cone, projected Gauss–Seidel) are
//! solved in turn until they agree (staggered projections), up to 32 rounds (128 in a
//! hold solved sparsely at the step's start, 16 in one within the step; 128 in a pile's
//! hold solved exactly, its friction sweeps over-relaxed); under
//! gravity, rounds that end with friction still moving end with the normal impulses once
//! more, so that the hold leaves nothing closing. In a pile's hold each round after the
//! first solves again from the last one's passive set (`Lcp::resolve`: only the margins
//! changed), falling back to a solve from scratch where that leaves a contact closing,
//! and the first starts from the forces the same contacts took in the last hold
//! (`Warm`): friction converges linearly, slowly in a pile, and goes on converging from
//! hold to hold.
//!
//! **Piles.** Under gravity a pile of free balls (more than `piles::PILE_CONTACTS`
//! resting contacts) is held whole at the step's start ([`Approach::Resting`]: its free
//! balls bring in every free ball they touch or could reach in the step at twice the
//! speed of support, and its touching collisions with restitution below 1 are answered
//! in its impacts at once, each parting at `e` times its approach), and again the same
//! way after a contact of one of its balls. A hold of more than [`SPARSE_ROWS`] rows is
//! solved sparsely (`sparse`, `sparse_lcp`: projected conjugate gradients, to a
//! tolerance, not exactly, started from the forces the same rows took last).
//!
//! **Rotations.** A cluster's chords follow its rotation over the rest of the step, which
//! the problem sees to first order (`Δu = ΔV + ΔΩ × a`). What the first order leaves
//! closing (second order in the rotation the force adds) is added to the margins and the
//! hold solved again from the free state, until nothing closes beyond a fraction of the
//! resting floor; what it leaves opening is kept, so the first step of a tipping body
//! has its first instant's angular acceleration exactly.
//!
//! **Energy.** With the integrators exact for constant gravity (Verlet, RK4, exact), the
//! hold changes the energy at the step's end by `ΔE = 2 Σ P·u'` summed over the bodies
//! (`u'` the held chords, `P` the impulses), which is `−2 Σ λ g/τ <= 0` over the
//! contacts (a contact pushes only where its chords close exactly at its margin): the
//! hold never adds energy, to first order in the rotation, but where a margin is
//! negative: two balls sunk into each other deeper than the narrow phase's
//! floor lets a contact sink (`narrow::sunk`), or a ball sunk so into a wall or a box,
//! are aimed apart at their depth over the rest of the step (`−g/τ`), and the push that
//! does it adds `2 λ |g|/τ`. Friction adds nothing where its rounds converge (a sliding
//! row's impulse opposes its slip); rounds that end short of that can push along the
//! slip, and a hold whose work then exceeds its rows' tolerance keeps only the share of
//! its friction that fits (`Contacts::hold_work`). The impacts are
//! inelastic impulses at `s`, which only take energy.

use carom_geometry::Ball;
use carom_integrate::ForceField;
use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use carom_response::RigidCluster;

mod sparse;

pub(crate) use sparse::{SPARSE_ROWS, Warm};

use super::clusters::{FREE, Flight, Motion};
use super::lcp::Lcp;
use super::narrow::{Allowance, Target, sunk, time_resolved_gap, touch_tolerance};
use super::response::{Contacts, Effect};
use super::sparse_lcp::{SparseLcp, SparseMatrix};
use super::stick::Side;
use super::sweep::path_box;
use crate::engine::Angular;
use crate::prefetch::prefetch;
use crate::scene::coordinate_resolution;

type Inertia<T, const D: usize> = <Const<D> as Space<T, D>>::Inertia;

/// How a change `Δ` of a free ball's chord from in-step time `seg_t` on shows in its
/// velocity at `seg_t` and at the step's end, as multiples of `Δ`: a constant force over
/// the rest of the step, `(0, Integrator::end_per_chord)` (`Flight::end_per_chord`); with
/// explicit Euler, whose chords no force within the step moves, an impulse at `seg_t`,
/// `(1, 1)`.
pub(super) fn shares<T: Real, const D: usize, F: ForceField<T, D>>(
    flight: &Flight<'_, T, D, F>,
    inverse_mass: T,
    seg_t: T,
) -> (T, T)
where
    Const<D>: Space<T, D>,
{
    match flight.end_per_chord(inverse_mass, seg_t) {
        Some(end_share) => (T::zero(), end_share),
        None => (T::one(), T::one()),
    }
}

/// How a change `Δω` a hold's torque makes in a free ball's chord spin
/// (`BallArrays::chord_spin`) shows in its spin at `seg_t` and at the step's end, as
/// multiples of `Δω`, for an integrator of chord weight `w`: a constant torque over the
/// rest of the step, `(0, 1/w)`, as [`shares`] has a force, but undamped by any spin
/// drag, as a cluster's push is (`clusters::advance`: the drag acts on the free motion
/// alone). With explicit Euler (`w = 0`) an impulse at `seg_t`, `(1, 1)`. The hold's
/// problem reads contact points through the chord spin `seg_w + w (spin − seg_w)`, which
/// shares `(a, b)` change by `a Δω + w (b − a) Δω`: `Δω` for both pairs, whatever `w`,
/// as each of the hold's rounds counts on (it reads the chords after the last round's
/// push and takes that push off again).
///
/// Adding `Δω` to both spins instead, an impulse at `seg_t` for every integrator, let a
/// re-hold of the same step restart a ball with all of the last hold's spin and only
/// part of its push: the 3D pile draw's energy rise (`docs/stepped.md`, piles item 17).
fn spin_shares<T: Real>(w: T) -> (T, T) {
    if w > T::zero() {
        (T::zero(), T::one() / w)
    } else {
        (T::one(), T::one())
    }
}

/// Rounds of the hold against the rotation's second order (see the module
/// documentation): each removes what the one before left closing, which is of the order
/// of its square.
const HOLD_ROUNDS: usize = 8;

/// Rounds of normal and tangential impulses in turn, with friction.
const FRICTION_ROUNDS: usize = 32;

/// Rounds of normal and tangential impulses in turn in a pile's hold solved exactly
/// ([`Approach::Resting`], up to `SPARSE_ROWS` rows), each friction sweep
/// over-relaxed ([`PILE_OVER_RELAXATION`]). Friction converges slowly in a pile, and
/// rounds that stop before it has converged can leave balls of a settled pile moving
/// up at millimetres a second. Over 18 draws of the 96-ball drop of `stepped_resting`
/// (300 steps each), a step gained more energy than the narrow phase's allowance lets
/// the pile's weight do in 17 draws with 32 plain rounds (beyond it by up to 298 times
/// it, 6.5e-7 of the pile's energy), in 1 with 512 plain rounds (by a tenth of it; a
/// median 4.2 times the time) and in none with these (1.4 times the time; the 480-ball
/// pile's slowest landing step 10.8 s against 4.9 s, its 5 s 2 to 10 % longer). In the
/// test's own draw a third of the holds still end unsettled with 512 rounds, plain or
/// over-relaxed: more rounds narrow what friction leaves undone, they do not remove it
/// (`docs/stepped.md`, piles item 14).
const PILE_FRICTION_ROUNDS: usize = 128;

/// The over-relaxation `ω` of the friction sweeps of [`PILE_FRICTION_ROUNDS`]: each
/// row's tangential impulse moves `ω` times the change that would stop its slip, then is
/// projected onto its friction cone. With the normal impulses fixed, a sweep is
/// projected Gauss–Seidel on a convex quadratic programme (the contacts' kinetic energy
/// over the product of the rows' cones), on which projected successive over-relaxation
/// converges for any `0 < ω < 2` (Cryer 1971, for bounds: a 2D row's cone; in 3D the
/// step along the slip is a line search, not the row's exact minimum). With 32 rounds,
/// the 96-ball drop's draws with a step above the allowance: 17 of 18 plain (beyond it
/// by up to 298 times it), 8 of 18 at 1.8 (up to 42 times), 3 of 9 at 1.5 and 6 of 9
/// at 1.9 (up to 6 and 32 times); with 128 plain rounds 1 of 9 (15 times).
const PILE_OVER_RELAXATION: f64 = 1.8;

/// Rounds of normal and tangential impulses in turn in a hold solved sparsely (above
/// [`SPARSE_ROWS`] rows: a large pile's). Friction converges slowly in a pile (after
/// 128 rounds a sweep still changes a median 9e-5 of the fastest slip), and rounds
/// that end before it has converged leave it pushing along the slip on many rows once
/// the last normal solve has moved the chords: with 32 rounds the 480-ball pile's one
/// hold at the start of a step (980 rows) added 7.6 J (its tangential impulses' power
/// over the rows +19.3 where positive, −7.8 where negative), and 5 of its first 300
/// steps gained more than 1 mJ. With 128 no step of five runs of it gained 1 mJ (the
/// largest rise 4e-6 J in one, 1.2e-4 J in another, 3.5e-9 of its energy). A round
/// there costs a few triangular solves and a sweep (the factorisation is kept, and a
/// guess near the factored one is solved on it, `sparse_lcp`): 128 cost 265 s for the
/// pile's 300 steps against 116 s with 32 when each new guess was factored, 154–164 s
/// since (`docs/stepped.md`).
const SPARSE_FRICTION_ROUNDS: usize = 128;

/// The rounds of a hold solved sparsely within the step (`s > 0`: after a contact of
/// one of its balls, a pile held again), which start from the forces the same rows took
/// last (`Warm`, where they have any): friction goes on converging from hold to hold,
/// and the next step's first hold runs all [`SPARSE_FRICTION_ROUNDS`]. While the
/// 480-ball pile lands it is held again 18 to 131 times a step (steps 40–60), and with 128
/// rounds each such hold ran nearly all of them: its 300 steps took 336 s, 129 s with
/// 16 (the landing 309 s and 99 s). What it costs: friction that has not converged
/// adds a little energy now and then (the largest rise in a step 2.1e-4 J against
/// 1.2e-4 J, in a variant with friction 0.5 two steps above 1 mJ, up to 4.3 mJ of
/// 3.4e4 J; none above 1 mJ there since `Warm` keeps forces over at least half a step;
/// `docs/stepped.md`).
const SPARSE_REHOLD_FRICTION_ROUNDS: usize = 16;

/// Halvings of the interval searched for the share of an unconverged friction solution
/// a hold keeps (`Contacts::fit_friction`): the share is found to
/// 1/64, and a hold whose friction does not fit within its tolerance even at 1/64 is held
/// without friction.
const FRICTION_SHARE_HALVINGS: usize = 6;

/// A body of a stack: a free ball or a cluster, restarted at the hold's instant.
struct Part<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    side: Side,
    inverse_mass: T,
    inverse_inertia: Inertia<T, D>,
    /// The centre of mass at the hold's instant.
    centre: Vector<T, D>,
    /// The state before the hold's force, which each round applies it to.
    free: Free<T, D>,
}

/// A body's state before the hold's force (see [`Contacts::save_free`]).
#[derive(Clone, Copy, Debug)]
enum Free<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Not saved yet.
    Unsaved,
    /// A free ball's segment: velocity at its start, chord, end velocity, start and end
    /// spins.
    Ball([Vector<T, D>; 3], [Angular<T, D>; 2]),
    /// A cluster's rigid state at its segment start.
    Cluster(RigidCluster<T, D>),
}

/// One end of a contact on a body of the stack.
#[derive(Clone, Copy, Debug)]
struct End<T: Real, const D: usize> {
    /// The body.
    part: usize,
    /// Its ball that touches.
    ball: usize,
    /// From the body's centre of mass to the contact point.
    arm: Vector<T, D>,
    /// From the ball's centre to the contact point.
    lever: Vector<T, D>,
}

/// What the other end of a contact is.
#[derive(Clone, Copy, Debug)]
enum Other<T: Real, const D: usize> {
    /// A wall or a box, moving at this velocity.
    Surface(Vector<T, D>),
    /// A held free ball below, moving at its chord (shock propagation).
    Held(usize),
    /// A body of the stack.
    Part(End<T, D>),
}

/// A contact of the stack: `end` touches `other` along the unit `normal` (from the ball
/// into the other) across `gap`; `target` is what the narrow phase calls the other.
#[derive(Clone, Copy, Debug)]
struct Row<T: Real, const D: usize> {
    end: End<T, D>,
    other: Other<T, D>,
    target: Target,
    normal: Vector<T, D>,
    gap: T,
}

/// The bodies and contacts of a stack.
struct Stack<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The hold's instant (in-step time).
    s: T,
    /// Which approaching contacts it takes in; with [`Approach::Any`] its free balls
    /// bring in the free balls they touch too.
    approach: Approach,
    parts: Vec<Part<T, D>>,
    rows: Vec<Row<T, D>>,
}

impl<T: Real, const D: usize> Stack<T, D>
where
    Const<D>: Space<T, D>,
{
    fn find(&self, side: Side) -> Option<usize> {
        self.parts.iter().position(|p| p.side == side)
    }

    /// What [`time_resolved_gap`] takes for the step's length `h` in this stack's hold:
    /// `h` in a wedge's, zero in another (which leaves gaps as they are).
    fn wedge_step(&self, h: T) -> T {
        match self.approach {
            Approach::Any => h,
            Approach::Slow | Approach::Resting => T::zero(),
        }
    }

    /// The Delassus matrix of `rows`, dense up to [`SPARSE_ROWS`] rows, sparse beyond
    /// (see `sparse`).
    fn delassus(&self, rows: &[usize], push: Push) -> Delassus {
        if rows.len() > SPARSE_ROWS {
            Delassus::Sparse(self.sparse_delassus(rows, push))
        } else {
            Delassus::Dense(self.dense_delassus(rows, push))
        }
    }

    /// The Delassus matrix of `rows` (row-major, `rows.len()` square):
    /// `A_cd = Σ over shared bodies σ_c σ_d (n_c·n_d/m + (a_c × n_c)·I⁻¹(a_d × n_d))`,
    /// how a unit push along row `d`'s normal changes the approach at row `c`; pushed
    /// through the centres of mass, the angular term drops. The linear term and the sum
    /// over bodies are computed in `f64`, the angular term in `T` (see [`Wide`]).
    fn dense_delassus(&self, rows: &[usize], push: Push) -> Vec<f64> {
        let n = rows.len();
        let mut a = vec![0.0; n * n];
        for (r, &c) in rows.iter().enumerate() {
            for (q, &d) in rows.iter().enumerate().skip(r) {
                let sum = self.coupling(c, d, push);
                a[r * n + q] = sum;
                a[q * n + r] = sum;
            }
        }
        a
    }

    /// The entry of rows `c` and `d` of the Delassus matrix (see [`Self::delassus`]).
    fn coupling(&self, c: usize, d: usize, push: Push) -> f64 {
        let (nc, nd) = (&self.rows[c].normal, &self.rows[d].normal);
        let mut sum = 0.0;
        for (ec, sc) in self.ends(c) {
            for (ed, sd) in self.ends(d).filter(|(e, _)| e.part == ec.part) {
                let part = &self.parts[ec.part];
                let angular = match push {
                    Push::ThroughCentres => T::zero(),
                    Push::AtContacts => {
                        let ac = <Const<D> as Space<T, D>>::cross(&ec.arm, nc);
                        let ad = <Const<D> as Space<T, D>>::cross(&ed.arm, nd);
                        <Const<D> as Space<T, D>>::angular_dot(
                            &ac,
                            &<Const<D> as Space<T, D>>::inertia_apply(&part.inverse_inertia, &ad),
                        )
                    }
                };
                // The linear term in `f64` too: rounded in `f32`, `n_c·n_d/m` of the
                // light ball hid the heavy ball's part (see `Wide`).
                let linear = wide(nc).dot(&wide(nd)) * part.inverse_mass.to_f64();
                sum += (sc * sd).to_f64() * (linear + angular.to_f64());
            }
        }
        sum
    }

    /// The ends of row `c` with their signs: `+1` for the end a push moves along `−n`.
    fn ends(&self, c: usize) -> impl Iterator<Item = (End<T, D>, T)> + '_ {
        let row = &self.rows[c];
        let other = match row.other {
            Other::Part(e) => Some((e, -T::one())),
            Other::Surface(_) | Other::Held(_) => None,
        };
        core::iter::once((row.end, T::one())).chain(other)
    }
}

/// The bodies held together in the current step: those a hold's force connects (its
/// contacts between two bodies that push). A body's force is half of an interaction, so
/// whenever one of them restarts (a collision, another hold) the whole group is held
/// again: otherwise one side would keep the force the other lost, and momentum would
/// not be kept.
#[derive(Clone, Debug, Default)]
pub(crate) struct Groups {
    /// Per ball: its group, or [`NONE`].
    of: Vec<u32>,
    /// Per group: its balls (a cluster's members all).
    balls: Vec<Vec<u32>>,
    /// Per ball: what its last hold in this step left ([`Groups::last_hold`]), `None` if
    /// no hold took it in. One entry per ball, however many holds a step makes.
    last_hold: Vec<Option<f64>>,
    /// The balls with an entry in `last_hold`, to forget at the step's start.
    held: Vec<u32>,
    /// Per ball: whether it is in a pile held at the step's start (see `piles`).
    piled: Vec<bool>,
    /// The balls marked in `piled`, to forget at the step's start.
    piles: Vec<u32>,
}

/// A ball in no group.
const NONE: u32 = u32::MAX;

impl Groups {
    /// No groups, for `n` balls.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            of: vec![NONE; n],
            balls: Vec::new(),
            last_hold: vec![None; n],
            held: Vec::new(),
            piled: vec![false; n],
            piles: Vec::new(),
        }
    }

    /// Forgets every group (at the start of a step).
    pub(crate) fn clear(&mut self) {
        for group in &self.balls {
            for &b in group {
                self.of[b as usize] = NONE;
            }
        }
        self.balls.clear();
        for &b in &self.held {
            self.last_hold[b as usize] = None;
        }
        self.held.clear();
        for &b in &self.piles {
            self.piled[b as usize] = false;
        }
        self.piles.clear();
    }

    /// Marks `balls` as a pile held at the step's start (see `piles`).
    pub(crate) fn note_pile(&mut self, balls: &[usize]) {
        for &b in balls {
            if !self.piled[b] {
                self.piled[b] = true;
                self.piles.push(b as u32);
            }
        }
    }

    /// Whether ball `i` is in a pile held at the step's start (see `piles`).
    pub(crate) fn piled(&self, i: usize) -> bool {
        self.piled[i]
    }

    /// What the last hold of ball `i` in this step left: `None` if no hold took it in;
    /// `Some(speed)` if one did, `speed` how fast it left one of its rows closing beyond
    /// its target where that exceeded the resting floor, 0 if it stopped them all. The
    /// hold's impulses are exact (`lcp`), so a speed shows that no impulses could stop
    /// the contacts it held, as when a kinematic box closes on a ball against the
    /// border. A 0 says nothing of contacts the hold did not take in: one that approaches
    /// fast and does not touch yet is left to its own collision. A stuck cluster's
    /// contacts are answered one at a time unless its chords still close after an
    /// impulse (fuzzed: a cluster's member between the left wall and a box's face closing
    /// on it at 35 m/s, crushed without a hold in that step).
    pub(crate) fn last_hold(&self, i: usize) -> Option<f64> {
        self.last_hold[i]
    }

    /// Notes that ball `b` was held, the hold leaving a row closing at `speed` (see
    /// [`Groups::last_hold`]).
    fn note_held(&mut self, b: u32, speed: f64) {
        let entry = &mut self.last_hold[b as usize];
        if entry.is_none() {
            self.held.push(b);
        }
        *entry = Some(speed);
    }

    /// Prefetches ball `i`'s group (see `prefetch`): every contact reads it.
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.of[i]);
    }

    /// Whether ball `i` is held with other bodies in this step.
    pub(crate) fn grouped(&self, i: usize) -> bool {
        self.of[i] != NONE
    }
}

/// A free ball whose chord [`Contacts::settle_on_walls`] set on walls of the border.
struct Settled<T, const D: usize> {
    ball: usize,
    /// The axes of the walls it was set on.
    axes: [bool; D],
    /// The largest change of a component it took.
    moved: T,
}

/// The contact a hold is for: ball `ball` touching `other`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Seed<T: Real, const D: usize> {
    pub(crate) ball: usize,
    pub(crate) other: SeedOther<T, D>,
}

/// What the ball of a [`Seed`] touches.
#[derive(Clone, Copy, Debug)]
pub(crate) enum SeedOther<T: Real, const D: usize> {
    /// Another ball.
    Ball(usize),
    /// A wall or a box, along this unit normal from the ball into it.
    Surface(Vector<T, D>),
}

impl<T: Real, const D: usize> Seed<T, D> {
    /// Whether `row` is this contact (either way round).
    fn is(&self, row: &Row<T, D>) -> bool {
        match (self.other, row.other) {
            (SeedOther::Ball(j), Other::Part(e)) => {
                (row.end.ball, e.ball) == (self.ball, j) || (row.end.ball, e.ball) == (j, self.ball)
            }
            (SeedOther::Ball(j), Other::Held(k)) => {
                (row.end.ball, k) == (self.ball, j) || (row.end.ball, k) == (j, self.ball)
            }
            (SeedOther::Surface(n), Other::Surface(_)) => {
                row.end.ball == self.ball && (row.normal - n).norm() <= T::lit(1e-9)
            }
            _ => false,
        }
    }
}

/// Which of a stack's approaching contacts a hold takes in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Approach {
    /// Those no faster than support (and the seed): faster ones are collisions, each
    /// answered by its own event with its restitution.
    Slow,
    /// All that touch (and the slow ones closing within the step): the stack's balls
    /// are wedged (see `wedge`), and answering its contacts one at a time would not end.
    Any,
    /// Those no faster than support (and those a collision with restitution below 1
    /// strikes now), its free balls bringing in the free balls they touch or could
    /// reach within the step: a pile held at the step's start
    /// ([`Contacts::hold_resting`]) and again after a contact of one of its balls,
    /// whose contacts answered one at a time would each hold the pile again.
    Resting,
}

impl Approach {
    /// How far beyond touching a contact is taken in, for a ball whose chord could close
    /// a gap at `support_speed` over `rest`, the rest of the step: a pile's hold also
    /// takes the gaps its balls could close within the step at twice the speed of
    /// support (speculative contacts: a row whose gap stays open pushes nothing).
    fn speculative<T: Real>(self, support_speed: T, rest: T) -> T {
        match self {
            Approach::Resting => T::lit(2.0) * support_speed * rest,
            Approach::Slow | Approach::Any => T::zero(),
        }
    }

    /// Whether a free ball a stack's cluster does not touch enters the stack, `touching`
    /// or not: in a pile's hold, yes; in a wedge's, only touching (one closing within the
    /// step is a collision of its own: a ball at 1e6 m/s closes on every ball it could
    /// reach in the step); in others, no.
    fn enters_free_ball(self, touching: bool) -> bool {
        match self {
            Approach::Slow => false,
            Approach::Any => touching,
            Approach::Resting => true,
        }
    }
}

/// Where a stack's impulses act on its bodies (see [`Stack::delassus`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Push {
    /// At the contact points: force and torque.
    AtContacts,
    /// Through the centres of mass: force only (`Contacts::central`).
    ThroughCentres,
}

/// A stack's Delassus matrix: dense (solved exactly, `lcp`) or sparse (solved by
/// projected conjugate gradients, `sparse_lcp`), by the stack's size.
enum Delassus {
    Dense(Vec<f64>),
    Sparse(SparseMatrix),
}

/// The stacks' solvers and what they keep between holds.
#[derive(Clone, Debug, Default)]
pub(crate) struct Solvers<const D: usize> {
    /// Scratch of the dense exact solves.
    dense: Lcp,
    /// Scratch of the sparse solves.
    sparse: SparseLcp,
    /// The impulses the sparse solves found, to start the next from.
    pub(crate) warm: Warm<D>,
}

impl<const D: usize> Solvers<D> {
    /// The most contacts of any problem solved so far.
    pub(crate) fn largest(&self) -> usize {
        self.dense.largest().max(self.sparse.largest())
    }

    /// Solves the contacts' problem with matrix `a` (see `lcp`); a sparse solve starts
    /// from the impulses `lambda` holds, a dense one from none, or, `again` (the last
    /// solve had the same matrix), from the last one's passive set.
    fn solve(&mut self, a: &Delassus, q: &[f64], tolerance: f64, lambda: &mut [f64], again: bool) {
        match a {
            // A solve again that leaves a margin closing (dependent contacts whose last
            // passive set no longer fits) is solved from scratch, as it would have been.
            Delassus::Dense(a) if again => {
                if !self.dense.resolve(a, q, tolerance, lambda) {
                    self.dense.solve(a, q, tolerance, lambda);
                }
            }
            Delassus::Dense(a) => {
                self.dense.solve(a, q, tolerance, lambda);
            }
            Delassus::Sparse(a) => {
                self.sparse.solve(a, q, tolerance, lambda);
            }
        }
    }
}

/// Which velocities a phase acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// The physical velocities at the hold's instant.
    Start,
    /// The chords.
    Chord,
}

/// A linear impulse of a stack's solve, in `f64` whatever the scene's precision.
///
/// A light ball pressed by a heavy one into a wall takes two impulses of the heavy
/// ball's momentum that cancel to its own: in `f32`, with a mass ratio `r` beyond `1/ε`,
/// the Delassus entry `1/m_light + 1/m_heavy` rounds to `1/m_light`, the problem loses
/// the heavy ball and the hold leaves it closing (a false crush error: a 100 t ball
/// dropped onto a 1 g ball on the floor, `docs/open-scenes/`), and the two impulses,
/// each rounded to `ε` of the heavy ball's momentum, leave the light ball with an error
/// of `ε r` times its speed. The stack therefore computes the Delassus matrix's linear
/// terms (`n_c·n_d/m`, from the rows' normals as they are) and sums them, solves the
/// problem ([`Lcp`]) and sums each body's impulses in `f64`, and turns a sum into a
/// velocity change in `T` only once it is divided by the body's mass. (Rounded to `f32`,
/// the light ball's `n_c·n_d/m` of three rows on its two degrees of freedom hid the
/// heavy ball's part, a 1.8e8th of it, and the solve left the light ball closing on a
/// wall at 363 m/s: the fourth campaign's s29.) In `f64` scenes this changes nothing.
type Wide<const D: usize> = Vector<f64, D>;

/// `v` in `f64`.
fn wide<T: Real, const D: usize>(v: &Vector<T, D>) -> Wide<D> {
    v.map(Real::to_f64)
}

/// `v` back in the precision `T`.
fn to_precision<T: Real, const D: usize>(v: &Wide<D>) -> Vector<T, D> {
    v.map(T::lit)
}

/// The velocity changes of the bodies of a stack under a set of impulses.
struct Changes<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Per body: linear impulse (in `f64`, see [`Wide`]) and angular impulse about its
    /// centre.
    impulse: Vec<(Wide<D>, Angular<T, D>)>,
}

impl<T: Real, const D: usize> Changes<T, D>
where
    Const<D>: Space<T, D>,
{
    fn new(parts: usize) -> Self {
        Self {
            impulse: vec![(Wide::zeros(), <Const<D> as Space<T, D>>::angular_zero()); parts],
        }
    }

    /// Adds the impulse `p` at end `e` (sign `sign`: `p` acts on the row's ball, `−p` on
    /// the other end).
    fn add(&mut self, e: &End<T, D>, sign: T, p: &Wide<D>) {
        let p = p * sign.to_f64();
        let (linear, angular) = &mut self.impulse[e.part];
        *linear += p;
        *angular += <Const<D> as Space<T, D>>::cross(&e.arm, &to_precision(&p));
    }

    /// Adds the impulse `p` at row `c`'s ball end and `−p` at its other end, if a body.
    fn add_at_row(&mut self, stack: &Stack<T, D>, c: usize, p: &Wide<D>) {
        for (e, sign) in stack.ends(c) {
            self.add(&e, sign, p);
        }
    }

    /// The changes the impulses `tangential[k] − n λ[k]` at `rows[k]` make.
    fn of_rows(
        stack: &Stack<T, D>,
        rows: &[usize],
        lambda: &[f64],
        tangential: &[Wide<D>],
    ) -> Self {
        let mut changes = Self::new(stack.parts.len());
        for (k, &c) in rows.iter().enumerate() {
            let p = tangential[k] - wide(&stack.rows[c].normal) * lambda[k];
            changes.add_at_row(stack, c, &p);
        }
        changes
    }

    /// The change of row `c`'s relative velocity (its ball end's contact point against
    /// the other end's).
    fn across(&self, stack: &Stack<T, D>, c: usize) -> Vector<T, D> {
        (stack.ends(c)).fold(Vector::zeros(), |sum, (e, sign)| {
            sum + self.at(stack, &e) * sign
        })
    }

    /// The velocity change of body `part`'s centre under the linear impulse `linear`.
    fn linear_change(part: &Part<T, D>, linear: &Wide<D>) -> Vector<T, D> {
        to_precision(&(linear * part.inverse_mass.to_f64()))
    }

    /// The velocity change of the point at end `e`.
    fn at(&self, stack: &Stack<T, D>, e: &End<T, D>) -> Vector<T, D> {
        let part = &stack.parts[e.part];
        let (linear, angular) = &self.impulse[e.part];
        let dw = <Const<D> as Space<T, D>>::inertia_apply(&part.inverse_inertia, angular);
        Self::linear_change(part, linear) + <Const<D> as Space<T, D>>::angular_cross(&dw, &e.arm)
    }
}

/// The inverse effective mass of end `e` of body `part` along the unit `d`.
fn stiffness<T: Real, const D: usize>(part: &Part<T, D>, e: &End<T, D>, d: &Vector<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    let ad = <Const<D> as Space<T, D>>::cross(&e.arm, d);
    part.inverse_mass
        + <Const<D> as Space<T, D>>::angular_dot(
            &ad,
            &<Const<D> as Space<T, D>>::inertia_apply(&part.inverse_inertia, &ad),
        )
}

impl<T: Real, const D: usize, F: ForceField<T, D>> Contacts<'_, T, D, F>
where
    Const<D>: Space<T, D>,
{
    /// Free ball `i`, wedged at in-step time `s` (see `wedge`), touching `other`: the stack
    /// around the contact held with every touching contact taken in ([`Approach::Any`]).
    pub(crate) fn wedged(&mut self, i: usize, other: SeedOther<T, D>, s: T) -> Effect {
        if s < self.h {
            self.hold_stack(Seed { ball: i, other }, s, Approach::Any);
        }
        Effect::default()
    }

    /// Holds the stack around the contact `seed` at in-step time `s`, taking in the
    /// contacts `approach` says (see the module documentation).
    pub(crate) fn hold_stack(&mut self, seed: Seed<T, D>, s: T, approach: Approach) {
        let mut stack = Stack {
            s,
            approach,
            parts: Vec::new(),
            rows: Vec::new(),
        };
        // The contact's bodies; a free ball held below a cluster's member it touches is
        // that member's support (see `rows_of`), not a body of the stack.
        let (i, j) = match seed.other {
            SeedOther::Ball(j) => (seed.ball, j),
            SeedOther::Surface(_) => (seed.ball, seed.ball),
        };
        for (ball, other) in [(i, j), (j, i)] {
            let free = self.balls.cluster[ball] == FREE;
            if !(free && self.balls.cluster[other] != FREE && self.holds_up(other, ball, s)) {
                self.enter(&mut stack, self.side(ball), s);
            }
        }
        self.hold_entered(stack, Some(&seed));
    }

    /// Holds the free balls `balls` at the step's start with every body they touch, and
    /// what touches those (see [`Approach::Resting`]).
    pub(crate) fn hold_resting(&mut self, balls: &[usize]) {
        let mut stack = Stack {
            s: T::zero(),
            approach: Approach::Resting,
            parts: Vec::new(),
            rows: Vec::new(),
        };
        for &b in balls {
            self.enter(&mut stack, self.side(b), T::zero());
        }
        self.hold_entered(stack, None);
    }

    /// Holds `stack`, its first bodies entered: finds their rows (entering the bodies
    /// they bring in), then the impacts and the hold. `seed` is the contact the hold is
    /// for, if any.
    fn hold_entered(&mut self, mut stack: Stack<T, D>, seed: Option<&Seed<T, D>>) {
        let s = stack.s;
        let mut k = 0;
        while k < stack.parts.len() {
            let balls: Vec<usize> = match stack.parts[k].side {
                Side::Ball(i) => vec![i],
                Side::Cluster(c) => (self.clusters.list[c].members.iter())
                    .map(|&m| m as usize)
                    .collect(),
            };
            for x in balls {
                self.rows_of(&mut stack, k, x, s);
            }
            k += 1;
        }
        if stack.rows.is_empty() {
            return;
        }
        let b = &*self.balls;
        // Touching: within rounding of the ball's size, or of what an approach at the
        // resting floor closes in the rest of the step (the narrow phase tells neither
        // from a contact).
        let reach = self.rules.floor * (self.h - s);
        let tolerance = |c: usize| {
            let row = &stack.rows[c];
            let r = b.radius[row.end.ball];
            touch_tolerance(&b.seg_x[row.end.ball], r) + reach
        };
        let start: Vec<_> = (0..stack.rows.len())
            .map(|c| self.relative(&stack, c, Phase::Start))
            .collect();
        let start_approach: Vec<_> = (0..stack.rows.len())
            .map(|c| self.approach(&stack, c, Phase::Start))
            .collect();
        // A contact approaching faster than support is a collision, its own event: left
        // out, unless it is the contact the hold is for (whose collision has been
        // answered: what it left closing, a cluster turning into a floor it struck, is
        // stopped here), or it touches in a wedge's hold (whose contacts answer each other
        // at one instant).
        let fast: Vec<bool> = (stack.rows.iter().zip(&start_approach).enumerate())
            .map(|(c, (row, &u))| {
                let skip = match stack.approach {
                    Approach::Slow | Approach::Resting => !seed.is_some_and(|seed| seed.is(row)),
                    Approach::Any => row.gap > tolerance(c),
                };
                skip && u > self.rules.support_speed
            })
            .collect();
        // In a pile's hold, a collision that touches now with restitution below 1 is
        // answered with the others at once (its margin `−e u`: it parts at `e` times its
        // approach), so that a ball landing on a pile is passed down it in one hold, not
        // in a collision per contact of the pile, each holding the pile again. Elastic
        // ones stay events of their own: one at a time is the textbook answer (Newton's
        // cradle), which simultaneous impulses are not.
        let struck: Vec<bool> = (0..stack.rows.len())
            .map(|c| {
                stack.approach == Approach::Resting
                    && fast[c]
                    && stack.rows[c].gap <= tolerance(c)
                    && self.row_restitution(&stack.rows[c]) < T::one()
            })
            .collect();
        // 1. Impacts: restitution 0 on the velocities at s (the struck ones' own),
        // touching contacts only.
        let touching: Vec<usize> = (0..stack.rows.len())
            .filter(|&c| (!fast[c] || struck[c]) && stack.rows[c].gap <= tolerance(c))
            .collect();
        let parting: Vec<T> = (touching.iter())
            .map(|&c| {
                if struck[c] {
                    -self.row_restitution(&stack.rows[c]) * start_approach[c]
                } else {
                    T::zero()
                }
            })
            .collect();
        let impacts = self.impulses(
            &stack,
            &touching,
            (&start, &start_approach, &parting),
            false,
        );
        let mut pushed = vec![false; stack.rows.len()];
        if impacts.iter().any(|p| *p != Wide::<D>::zeros()) {
            let changes = Self::changes(&stack, &touching, &impacts, &mut pushed);
            self.strike(&stack, &changes);
        }
        // 2. The hold: the chords, as a constant force over the rest of the step.
        let held: Vec<usize> = (0..stack.rows.len())
            .filter(|&c| !fast[c] || struck[c])
            .collect();
        self.save_free(&mut stack);
        let mut forced = vec![false; stack.rows.len()];
        self.hold(&mut stack, &held, s, &mut forced);
        for (p, f) in pushed.iter_mut().zip(&forced) {
            *p |= *f;
        }
        self.mark_held(&stack, &pushed);
        self.regroup(&stack, &forced);
    }

    /// The restitution of row `row`'s contact: the pair's, the border's or the box's.
    fn row_restitution(&self, row: &Row<T, D>) -> T {
        match row.target {
            Target::Ball(j) => self.balls.pair_restitution(row.end.ball, j as usize),
            Target::Border => self.rules.border_restitution,
            Target::Box(k) => self.boxes.restitution[k as usize],
        }
    }

    /// Phase 2 of [`Self::hold_stack`] on the rows `held`, rounds against the rotation's
    /// second order included; marks the rows that push in `pushed`.
    ///
    /// The first round is the first-order hold. Each next one takes the chords the force
    /// of the last one left, removes that force from them to first order (what the
    /// chords would be without it, seen from where the bodies turn to now) and solves the
    /// whole problem again from there: Newton's method on the contacts' complementarity
    /// conditions, so that a contact the last round pushed too hard gets less (a rocking
    /// cluster on three members) and one it left closing more.
    fn hold(&mut self, stack: &mut Stack<T, D>, held: &[usize], s: T, pushed: &mut [bool]) {
        let rest = self.h - s;
        let targets: Vec<T> = held.iter().map(|&c| stack.rows[c].gap / rest).collect();
        self.hold_rounds(stack, held, &targets, pushed);
        let closing: Vec<usize> = self.closing(stack, held, &targets).collect();
        if closing.is_empty() {
            self.settle_on_walls(stack, held, &targets);
            self.note_hold(stack, held, &targets);
            return;
        }
        // Jammed: the rotation over the rest of the step brings members into surfaces on
        // several sides, which neither the rounds nor a push through the centres can
        // stop. The bodies of the rows still closing stop at `s` (an inelastic impulse:
        // energy only falls), and the hold starts again from there; a body at rest turns
        // only as fast as the step's forces turn it, which the rounds hold.
        let mut stop = Changes::new(stack.parts.len());
        for &c in &closing {
            for (e, _) in stack.ends(c) {
                stop.impulse[e.part] = match stack.parts[e.part].side {
                    Side::Ball(i) => (
                        -wide(&self.balls.seg_v[i]) * self.balls.mass[i].to_f64(),
                        <Const<D> as Space<T, D>>::angular_zero(),
                    ),
                    Side::Cluster(k) => {
                        let start = &self.clusters.list[k].start;
                        (
                            -wide(&start.velocity()) * start.mass().to_f64(),
                            -start.angular_momentum(),
                        )
                    }
                };
            }
        }
        self.strike(stack, &stop);
        self.save_free(stack);
        self.hold_rounds(stack, held, &targets, pushed);
        self.settle_on_walls(stack, held, &targets);
        self.note_hold(stack, held, &targets);
    }

    /// Notes every ball of `stack` as held, with how fast the hold left a row of `held`
    /// closing beyond its target where that exceeds the resting floor, or 0
    /// ([`Groups::last_hold`]).
    fn note_hold(&mut self, stack: &Stack<T, D>, held: &[usize], targets: &[T]) {
        let fastest = (self.excess(stack, held, targets).into_iter()).fold(T::zero(), T::max);
        let speed = if fastest > self.rules.floor {
            fastest.to_f64()
        } else {
            0.0
        };
        for part in &stack.parts {
            match part.side {
                Side::Ball(i) => self.groups.note_held(i as u32, speed),
                Side::Cluster(c) => {
                    for &m in &self.clusters.list[c].members {
                        self.groups.note_held(m, speed);
                    }
                }
            }
        }
    }

    /// Sets the chord of every free ball the hold left closing on a wall of the border,
    /// by no more than [`Self::done`] or the rounding of the hold's change to its chord
    /// (64 `ε` of the chord's speed before and after the hold), to close at exactly its
    /// target.
    ///
    /// The narrow phase counts no rounding in a wall's approach (see
    /// [`Allowance`](super::narrow::Allowance)), so a free ball's chord left closing on
    /// it by the rounding of the hold's sums (8.5e-19 m/s after a hold of a 1 g ball
    /// moving at 175 m/s along the wall) was the same contact again, 16,384 times, and a
    /// false crush error. A wall's normal is an axis: the chord's component along it is set
    /// exactly, and the velocities follow as a held force's would ([`shares`]). A body that rests on the wall can show no such
    /// residue in its position (less than the coordinates' resolution over the step).
    ///
    /// In `f32` that rounding can exceed [`Self::done`] by far: a 4.2 g ball struck at
    /// 750 m/s into a wall by a 72 t ball at a slant was squeezed out along the wall at
    /// 4,918 m/s, and the hold left its chord closing on the wall by 2.7e-4 m/s (`ε` of
    /// the 733 m/s the hold took from it), where a quarter of the floor was 2.4e-8 m/s:
    /// the same contact again, 16,384 times, and a false crush error (the fourth
    /// campaign's s59 with semi-implicit Euler, `f32`).
    ///
    /// Where setting a wall's component closes another of the ball's contacts again (a
    /// face at a slant beside the wall), [`Self::settle_beside_walls`] opens it.
    fn settle_on_walls(&mut self, stack: &Stack<T, D>, held: &[usize], targets: &[T]) {
        let flight = self.flight();
        // The rows' excesses as the hold left them, read before the first setting.
        let mut before: Option<Vec<T>> = None;
        let mut settled: Vec<Settled<T, D>> = Vec::new();
        for (&c, &target) in held.iter().zip(targets) {
            let row = &stack.rows[c];
            let (Target::Border, Side::Ball(i)) = (row.target, stack.parts[row.end.part].side)
            else {
                continue;
            };
            let Some(axis) = (0..D).find(|&a| row.normal[a] != T::zero()) else {
                continue;
            };
            let sign = row.normal[axis];
            let excess = self.balls.chord[i][axis] * sign - target;
            let free_chord = match stack.parts[row.end.part].free {
                Free::Ball([_, chord, _], _) => chord.norm(),
                Free::Cluster(_) | Free::Unsaved => T::zero(),
            };
            let rounding = T::lit(64.0) * T::EPSILON * (free_chord + self.balls.chord[i].norm());
            if excess <= T::zero() || excess > self.done(stack, c).max(rounding) {
                continue;
            }
            let mut chord = self.balls.chord[i];
            chord[axis] = target * sign;
            let moved = (chord[axis] - self.balls.chord[i][axis]).abs();
            if before.is_none() {
                before = Some(self.excess(stack, held, targets));
            }
            self.set_chord(&flight, i, chord);
            let k = settled.iter().position(|e| e.ball == i).unwrap_or_else(|| {
                settled.push(Settled {
                    ball: i,
                    axes: [false; D],
                    moved: T::zero(),
                });
                settled.len() - 1
            });
            let entry = &mut settled[k];
            entry.axes[axis] = true;
            entry.moved = entry.moved.max(moved);
        }
        if let Some(before) = before {
            self.settle_beside_walls(stack, held, targets, &before, &settled);
        }
    }

    /// Turns the rows of `held` that [`Self::settle_on_walls`] left closing past their
    /// targets (by more than [`Self::done`], where the hold had left them within it:
    /// `before`, the rows' excesses then) to open by a hair, by changing the chord of
    /// the settled ball across its settled walls' axes only.
    ///
    /// A hold may leave a ball closing on a wall by less than [`Self::done`] (a quarter
    /// of the floor there), which setting the wall's component exactly removes; where
    /// the ball also rests on a face at a slant, that moves it back into the face. A
    /// 0.17 g ball pressed into the corner of a wall and a slanted box by a 9.8 kg ball,
    /// without gravity, was held with its box contact opening at 2.5e-105 m/s and its
    /// wall contact closing at 6.5e-105 m/s; setting the wall's component left the box
    /// contact closing at 2.9e-105 m/s, which the narrow phase, whose allowance is
    /// relative to those speeds, found again: hold after hold at the same instant, the
    /// chord fell to 1e-168 m/s, whose norm underflows, and a false crush error after
    /// 16,641 contacts (`stepped_fuzz --seed 2026`'s s59, `f64`, semi-implicit Euler).
    ///
    /// The change for a row with normal `g` on the ball's chord (the row's normal,
    /// reversed where the ball is its other end) is `−d (excess + margin)/|d|²`, `d`
    /// being `g` with the settled axes' components dropped: the walls' components stay
    /// exact, and the row's approach falls to its target less the margin, up to the
    /// rounding of the change. That rounding is a few `ε` of the two ends' velocities,
    /// whose largest components the margin takes 8 times (their norms underflow at such
    /// speeds). In two dimensions this slides the ball along the face, out of the
    /// corner. A change larger than the settling's own (a face nearly along the wall,
    /// `|d|` near 0) is not made: the row is left as the settling left it.
    fn settle_beside_walls(
        &mut self,
        stack: &Stack<T, D>,
        held: &[usize],
        targets: &[T],
        before: &[T],
        settled: &[Settled<T, D>],
    ) {
        let flight = self.flight();
        for (k, (&c, &target)) in held.iter().zip(targets).enumerate() {
            let row = &stack.rows[c];
            if row.target == Target::Border || before[k] > self.done(stack, c) {
                continue;
            }
            // The row's ball ends, each with the sign of its chord in the approach.
            let other_end = match row.other {
                Other::Part(e) => Some((e.ball, -T::one())),
                Other::Held(_) | Other::Surface(_) => None,
            };
            for (i, sign) in core::iter::once((row.end.ball, T::one())).chain(other_end) {
                let Some(ball) = settled.iter().find(|e| e.ball == i) else {
                    continue;
                };
                let excess = self.approach(stack, c, Phase::Chord) - target;
                if excess <= self.done(stack, c) {
                    break;
                }
                let mut d = row.normal * sign;
                for (axis, &set) in ball.axes.iter().enumerate() {
                    if set {
                        d[axis] = T::zero();
                    }
                }
                let across = d.norm_squared();
                let speeds =
                    self.balls.chord[row.end.ball].amax() + self.other_velocity(row).amax();
                let change = d * ((excess + T::lit(8.0) * T::EPSILON * speeds) / across);
                // A face nearly along the wall would need a fast slide: left as it was.
                if across > T::zero() && change.amax() <= ball.moved {
                    let chord = self.balls.chord[i] - change;
                    self.set_chord(&flight, i, chord);
                }
            }
        }
    }

    /// Sets free ball `i`'s chord to `chord` as a held force over the rest of the step
    /// would ([`shares`]): its velocities at the segment's start and end follow.
    /// Components the chord keeps are left as they are in the velocities too (a `-0`
    /// stays `-0`).
    fn set_chord(&mut self, flight: &Flight<'_, T, D, F>, i: usize, chord: Vector<T, D>) {
        let b = &*self.balls;
        let (start_share, end_share) = shares(flight, b.inverse_mass[i], b.seg_t[i]);
        let (mut seg_v, mut vel) = (b.seg_v[i], b.vel[i]);
        for a in 0..D {
            let change = chord[a] - b.chord[i][a];
            if change != T::zero() {
                seg_v[a] += change * start_share;
                vel[a] += change * end_share;
            }
        }
        let (seg_w, spin) = (b.seg_w[i], b.spin[i]);
        self.balls
            .set_segment(i, self.h, [seg_v, chord, vel], [seg_w, spin]);
    }

    /// The velocity of row `row`'s other end as the narrow phase reads it: a surface's
    /// own, a ball's chord.
    fn other_velocity(&self, row: &Row<T, D>) -> Vector<T, D> {
        match row.other {
            Other::Surface(v) => v,
            Other::Held(j) => self.balls.chord[j],
            Other::Part(e) => self.balls.chord[e.ball],
        }
    }

    /// How much faster than its target (the speed that closes its gap over the rest of
    /// the step) each row of `held` closes along its chords now.
    fn excess(&self, stack: &Stack<T, D>, held: &[usize], targets: &[T]) -> Vec<T> {
        (held.iter().zip(targets))
            .map(|(&c, &t)| self.approach(stack, c, Phase::Chord) - t)
            .collect()
    }

    /// How much faster than its target row `c` may still close when the hold is done: a
    /// quarter of what the narrow phase allows its contact ([`Rules::allowance`]), so that
    /// no contact a hold leaves is found again at the same instant. Where that allows
    /// nothing or more than the floor, a quarter of the floor, as for every row before: a
    /// free ball against a wall without gravity is allowed no approach at all, which no
    /// hold's rounding can promise.
    ///
    /// [`Rules::allowance`]: super::response::Rules::allowance
    fn done(&self, stack: &Stack<T, D>, c: usize) -> T {
        self.allowed(stack, c) * T::lit(0.25)
    }

    /// What [`Self::done`] is a quarter of: the narrow phase's allowance of row `c`, or
    /// the floor where that allows nothing or more.
    fn allowed(&self, stack: &Stack<T, D>, c: usize) -> T {
        let row = &stack.rows[c];
        let b = &*self.balls;
        let other = self.other_velocity(row);
        let ball = row.end.ball;
        let allowed = (self.rules.allowance(self.h)).of(
            b,
            ball,
            row.target,
            &b.chord[ball],
            &other,
            &row.normal,
        );
        let floor = self.rules.floor;
        if allowed > T::zero() {
            allowed.min(floor)
        } else {
            floor
        }
    }

    /// The speed below which the complementarity problem of `rows` takes a closing for
    /// rounding (`Lcp::solve`'s tolerance): a thousandth of the least any of them is
    /// [`Self::allowed`], as it was a thousandth of the floor when the floor was every
    /// row's allowance. A thousandth of the floor alone (64 ε of the scene's fastest
    /// speed) lets rows close past [`Self::done`] where a contact's own speeds are far
    /// below the scene's: a 0.16 kg ball spinning at 922,802 rad/s, left by its collision
    /// with a 211,605 kg ball closing on it at 5.8e-13 m/s (allowed 5.0e-13 m/s), took that
    /// for rounding beside the floor's 1.7e-12 m/s (a scene whose balls started at 1.2e5
    /// m/s). No round pushed, and the hold's last resort stopped both balls dead.
    fn tolerance(&self, stack: &Stack<T, D>, rows: &[usize]) -> T {
        let least = (rows.iter()).fold(self.rules.floor, |m, &c| m.min(self.allowed(stack, c)));
        least * T::lit(1e-3)
    }

    /// The rows of `held` closing faster than their targets by more than [`Self::done`].
    fn closing<'a>(
        &'a self,
        stack: &'a Stack<T, D>,
        held: &'a [usize],
        targets: &[T],
    ) -> impl Iterator<Item = usize> + 'a {
        let excess = self.excess(stack, held, targets);
        (held.iter().zip(excess))
            .filter(move |&(&c, u)| u > self.done(stack, c))
            .map(|(&c, _)| c)
    }

    /// The rounds of [`Self::hold`] towards `targets` until no row exceeds its target by
    /// more than [`Self::done`], then [`Self::central`].
    fn hold_rounds(
        &mut self,
        stack: &Stack<T, D>,
        held: &[usize],
        targets: &[T],
        pushed: &mut [bool],
    ) {
        let mut total = vec![Wide::<D>::zeros(); held.len()];
        let mut unused = vec![false; stack.rows.len()];
        for _ in 0..HOLD_ROUNDS {
            let mut chords: Vec<_> = (0..stack.rows.len())
                .map(|c| self.relative(stack, c, Phase::Chord))
                .collect();
            let mut approach: Vec<_> = (0..stack.rows.len())
                .map(|c| self.approach(stack, c, Phase::Chord))
                .collect();
            let closing =
                (held.iter().zip(targets)).any(|(&c, &t)| approach[c] - t > self.done(stack, c));
            if !closing {
                break;
            }
            let force = Self::changes(stack, held, &total, &mut unused);
            for &c in held {
                let moved = force.across(stack, c);
                chords[c] -= moved;
                approach[c] -= moved.dot(&stack.rows[c].normal);
            }
            let last = core::mem::replace(
                &mut total,
                self.impulses(stack, held, (&chords, &approach, targets), true),
            );
            if total == last {
                // The round solved what the last one did (rows left closing by what no
                // round changes, such as friction's last sweep without gravity) and
                // pushed to the same chords: every further round would too.
                break;
            }
            let changes = Self::changes(stack, held, &total, &mut unused);
            self.push(stack, &changes);
        }
        let mut changes = Self::changes(stack, held, &total, pushed);
        if self.central(stack, held, targets, &mut changes, pushed) {
            self.push(stack, &changes);
        }
    }

    /// The hold's last resort, when its rounds leave a row of `held` closing faster than
    /// its target by more than [`Self::done`]: pushes through the centres of mass, added to
    /// `changes`; returns whether it pushed.
    ///
    /// The rounds converge while the rotation the force adds over the rest of the step
    /// is small. A body that turns through a large angle in it (a cluster struck at
    /// hundreds of m/s, spinning at thousands of rad/s) can leave a chord closing that
    /// the first order does not see: its member touches a wall and moves away from it
    /// now, but its rotation brings it back within the step. A push through a body's
    /// centre of mass moves the chords of all its points by the same `P/m`, exactly (its
    /// rotation does not see it), so one exact solve of that linear problem stops every
    /// such row. Every hold must end with nothing closing beyond the floor: a hold
    /// restarts its bodies free of earlier holds, so a row it left closing would be found
    /// again at the same instant and held the same way, without end. The push gives no
    /// torque, so it is no contact force; it acts only where the rounds fail.
    fn central(
        &mut self,
        stack: &Stack<T, D>,
        held: &[usize],
        targets: &[T],
        changes: &mut Changes<T, D>,
        pushed: &mut [bool],
    ) -> bool {
        let excess = self.excess(stack, held, targets);
        if (held.iter().zip(&excess)).all(|(&c, &u)| u <= self.done(stack, c)) {
            return false;
        }
        let a = stack.delassus(held, Push::ThroughCentres);
        let q: Vec<f64> = excess.iter().map(|&u| -u.to_f64()).collect();
        let mut lambda = vec![0.0; held.len()];
        let tolerance = self.tolerance(stack, held).to_f64();
        self.solvers.solve(&a, &q, tolerance, &mut lambda, false);
        for (&c, &l) in held.iter().zip(&lambda) {
            if l <= 0.0 {
                continue;
            }
            let p = -wide(&stack.rows[c].normal) * l;
            for (e, sign) in stack.ends(c) {
                changes.impulse[e.part].0 += p * sign.to_f64();
            }
            pushed[c] = true;
        }
        true
    }

    /// Enters `side` into the stack (once), restarted at `s` free of the step's earlier
    /// holds; returns its index.
    fn enter(&mut self, stack: &mut Stack<T, D>, side: Side, s: T) -> usize {
        if let Some(k) = stack.find(side) {
            return k;
        }
        let part = match side {
            Side::Ball(i) => {
                self.balls.restart(i, s, self.h);
                self.reintegrate(i);
                self.balls.supported[i] = false;
                self.rest.restart(i, s, self.balls.chord[i]);
                let b = &*self.balls;
                Part {
                    side,
                    inverse_mass: b.inverse_mass[i],
                    inverse_inertia: <Const<D> as Space<T, D>>::inertia_isotropic(
                        b.inverse_inertia[i],
                    ),
                    centre: b.seg_x[i],
                    free: Free::Unsaved,
                }
            }
            Side::Cluster(c) => {
                let rigid = self.begin_cluster(c, s);
                self.finish_cluster(c, rigid);
                Part {
                    side,
                    inverse_mass: T::one() / rigid.mass(),
                    inverse_inertia: rigid.world_inverse_inertia(),
                    centre: rigid.center(),
                    free: Free::Unsaved,
                }
            }
        };
        let balls = match side {
            Side::Ball(i) => vec![i as u32],
            Side::Cluster(c) => self.clusters.list[c].members.clone(),
        };
        self.changed.extend_from_slice(&balls);
        stack.parts.push(part);
        let k = stack.parts.len() - 1;
        // The bodies held with it in this step are held again with it (a cluster fused
        // in this step may hold the groups of both its parts).
        for b in balls {
            let group = self.groups.of[b as usize];
            if group == NONE {
                continue;
            }
            let others = core::mem::take(&mut self.groups.balls[group as usize]);
            for &o in &others {
                let side = self.side(o as usize);
                self.enter(stack, side, s);
            }
            self.groups.balls[group as usize] = others;
        }
        k
    }

    /// Groups the bodies of `stack` that the hold's force connects (rows between two
    /// bodies that push, `pushed`), after forgetting their earlier groups (all of which
    /// the stack holds).
    fn regroup(&mut self, stack: &Stack<T, D>, pushed: &[bool]) {
        let balls_of = |this: &Self, side: Side| -> Vec<u32> {
            match side {
                Side::Ball(i) => vec![i as u32],
                Side::Cluster(c) => this.clusters.list[c].members.clone(),
            }
        };
        for part in &stack.parts {
            for b in balls_of(self, part.side) {
                self.groups.of[b as usize] = NONE;
            }
        }
        // Components by repeated relabelling (stacks are small).
        let mut label: Vec<usize> = (0..stack.parts.len()).collect();
        let mut changed = true;
        while changed {
            changed = false;
            for (row, _) in stack.rows.iter().zip(pushed).filter(|(_, p)| **p) {
                if let Other::Part(e) = row.other {
                    let low = label[row.end.part].min(label[e.part]);
                    for k in [row.end.part, e.part] {
                        if label[k] != low {
                            label[k] = low;
                            changed = true;
                        }
                    }
                }
            }
        }
        for root in 0..stack.parts.len() {
            let members: Vec<usize> = (0..stack.parts.len())
                .filter(|&k| label[k] == root)
                .collect();
            if members.len() < 2 {
                continue;
            }
            let id = self.groups.balls.len() as u32;
            let mut balls = Vec::new();
            for k in members {
                for b in balls_of(self, stack.parts[k].side) {
                    self.groups.of[b as usize] = id;
                    balls.push(b);
                }
            }
            self.groups.balls.push(balls);
        }
    }

    /// Calls `f` with every wall and box ball `x` could touch at `s`: `(the surface,
    /// unit normal from the ball into it, its velocity, gap)` for every wall of the
    /// border and the nearest point of every box (at its periodic image nearest the ball).
    pub(super) fn for_each_surface(
        &self,
        x: usize,
        s: T,
        mut f: impl FnMut(Target, Vector<T, D>, Vector<T, D>, T),
    ) {
        let b = &*self.balls;
        let (p, r) = (b.position_at(x, s), b.radius[x]);
        if let Some(border) = self.border {
            let gaps = border.wall_gaps(&Ball::new_unchecked(p, r));
            for (axis, (below, above)) in gaps.into_iter().enumerate() {
                for (sign, gap) in [(-T::one(), below), (T::one(), above)] {
                    let mut n = Vector::zeros();
                    n[axis] = sign;
                    f(Target::Border, n, Vector::zeros(), gap);
                }
            }
        }
        for k in 0..self.boxes.len() {
            if let Some((n, d)) = self.boxes.nearest(k, s, &p, self.periodic) {
                f(Target::Box(k as u32), n, self.boxes.vel[k], d - r);
            }
        }
    }

    /// Adds the contacts of ball `x` of body `k` of the stack at `s` that touch or close
    /// within the rest of the step: its walls and boxes, the held free balls below it,
    /// and the bodies it touches (entered into the stack if new; a contact between two
    /// bodies is added once, from the first).
    fn rows_of(&mut self, stack: &mut Stack<T, D>, k: usize, x: usize, s: T) {
        let rest = self.h - s;
        let b = &*self.balls;
        let (p, r, chord) = (b.position_at(x, s), b.radius[x], b.chord[x]);
        let tolerance = touch_tolerance(&p, r);
        let reach = tolerance.max(stack.approach.speculative(self.rules.support_speed, rest));
        let near = |gap: T, closing: T| gap <= reach || closing * rest > gap;
        // A wedge's hold takes a gap the time of impact cannot resolve for none.
        let (wedge_h, speed) = (stack.wedge_step(self.h), chord.norm());
        let centre = stack.parts[k].centre;
        let end = |n: &Vector<T, D>| End {
            part: k,
            ball: x,
            arm: p + n * r - centre,
            lever: n * r,
        };
        let allowance = self.rules.allowance(self.h);
        self.for_each_surface(x, s, |target, n, v, gap| {
            let held_gap = held_surface_gap(&allowance, (&p, r), gap, wedge_h, speed + v.norm());
            if near(held_gap, (chord - v).dot(&n)) {
                stack.rows.push(Row {
                    end: end(&n),
                    other: Other::Surface(v),
                    target,
                    normal: n,
                    gap: held_gap,
                });
            }
        });
        let mut candidates = core::mem::take(self.candidates);
        let path = path_box(&p, &self.balls.pos[x], r + tolerance);
        self.sweep.candidates(x, &path, &mut candidates);
        candidates.sort_unstable();
        candidates.dedup();
        let n_balls = self.balls.len();
        let cluster_body = matches!(stack.parts[k].side, Side::Cluster(_));
        for &j in &candidates {
            let j = j as usize;
            if j >= n_balls || j == x || self.side(j) == self.side(x) {
                continue;
            }
            let b = &*self.balls;
            let y = b.position_at(j, s);
            let y = self
                .periodic
                .map_or(y, |border| p + border.minimum_image(&(y - p)));
            let d = (y - p).norm();
            if d <= T::zero() {
                continue;
            }
            let n = (y - p) / d;
            // A gap within the resolution of the centres' coordinates is none: the time
            // of impact calls such a pair touching (its distance rounds to the sum of the
            // radii) and takes any approach past the allowance for a contact now, where
            // the gap over the rest of the step would let the hold leave one (a 1 g ball
            // in a corner, its neighbour one ulp off, 2.8e-17 m, left closing at 3.2e-14
            // m/s against 4.8e-14 over 5.8e-4 s, was found again 16,384 times). Nor, in a
            // wedge's hold, is one the in-step time cannot resolve at their speeds.
            let gap = d - r - b.radius[j];
            let gap = if gap <= coordinate_resolution(p.amax().max(y.amax())) {
                T::zero()
            } else {
                time_resolved_gap(gap, wedge_h, speed + b.chord[j].norm())
            };
            if !near(gap, (chord - b.chord[j]).dot(&n)) {
                continue;
            }
            // Overlapping: held closing at most to touching, unless sunk deeper than the
            // floor lets a contact sink (see `Allowance`), where the narrow phase answers
            // any approach beyond rounding: such a pair is aimed apart over the rest of
            // the step, so that no hold leaves it closing.
            let held_gap = match sunk(&allowance, (&p, r), (&y, b.radius[j])) {
                Some(depth) => -depth,
                None => gap,
            };
            let side = self.side(j);
            let other = match (stack.find(side), side) {
                (Some(o), _) if o <= k => continue,
                (Some(o), _) => o,
                (None, Side::Ball(_)) if self.holds_up(x, j, s) => {
                    stack.rows.push(Row {
                        end: end(&n),
                        other: Other::Held(j),
                        target: Target::Ball(j as u32),
                        normal: n,
                        gap: held_gap,
                    });
                    continue;
                }
                (None, Side::Ball(_))
                    if !cluster_body && !stack.approach.enters_free_ball(gap <= tolerance) =>
                {
                    continue;
                }
                (None, _) => self.enter(stack, side, s),
            };
            // The contact point, on ball x's surface; ball j's position moved to x's image.
            let point = p + n * r;
            let shift = y - self.balls.position_at(j, s);
            stack.rows.push(Row {
                end: end(&n),
                target: Target::Ball(j as u32),
                other: Other::Part(End {
                    part: other,
                    ball: j,
                    arm: point - (stack.parts[other].centre + shift),
                    lever: point - y,
                }),
                normal: n,
                gap: held_gap,
            });
        }
        *self.candidates = candidates;
    }

    /// Whether free ball `j` holds ball `x` up at `s` as an immovable surface moving at its
    /// chord: it lies below `x` along gravity (not side by side, see
    /// [`Rules::lies_below`](super::response::Rules::lies_below)), is held in this step and does not move up into it (shock
    /// propagation).
    pub(super) fn holds_up(&self, x: usize, j: usize, s: T) -> bool {
        let b = &*self.balls;
        let (p, y) = (b.position_at(x, s), b.position_at(j, s));
        let y = self
            .periodic
            .map_or(y, |border| p + border.minimum_image(&(y - p)));
        let n = y - p;
        x != j
            && b.supported[j]
            && self.rules.lies_below((&p, b.radius[x]), (&y, b.radius[j]))
            && b.chord[j].dot(&n) >= -self.rules.floor * n.norm()
    }

    /// One Gauss–Seidel sweep of friction over `rows` (their velocities `relative`
    /// before any impulse): each row's accumulated tangential impulse `tangential` moves
    /// `relaxation` times the change that stops its slip under the normal impulses
    /// `lambda` (1: stops it), within `|F_t| <= μ λ`. Whether the sweep changed no row's
    /// slip beyond rounding (1e-12 of the fastest).
    fn friction_sweep(
        &self,
        stack: &Stack<T, D>,
        rows: &[usize],
        relative: &[Vector<T, D>],
        lambda: &[f64],
        relaxation: f64,
        tangential: &mut [Wide<D>],
    ) -> bool {
        let friction = self.rules.friction;
        let mut change = T::zero();
        let mut scale = T::zero();
        let mut changes = Changes::of_rows(stack, rows, lambda, tangential);
        for (k, &c) in rows.iter().enumerate() {
            let row = &stack.rows[c];
            let u = relative[c] + changes.across(stack, c);
            let slip = u - row.normal * u.dot(&row.normal);
            let speed = slip.norm();
            scale = scale.max(relative[c].norm());
            if speed <= T::zero() {
                continue;
            }
            let t = slip / speed;
            let k_t = stack.ends(c).fold(T::zero(), |sum, (e, _)| {
                sum + stiffness(&stack.parts[e.part], &e, &t)
            });
            let wanted = tangential[k] - wide(&t) * ((speed / k_t).to_f64() * relaxation);
            let bound = friction.to_f64() * lambda[k];
            let clamped = if wanted.norm() > bound {
                wanted * (bound / wanted.norm())
            } else {
                wanted
            };
            let step = clamped - tangential[k];
            tangential[k] = clamped;
            changes.add_at_row(stack, c, &step);
            change = change.max(T::lit(step.norm()) * k_t);
        }
        change <= T::lit(1e-12) * scale
    }

    /// The velocity of the contact point at end `e` in `phase`.
    fn end_velocity(&self, stack: &Stack<T, D>, e: &End<T, D>, phase: Phase) -> Vector<T, D> {
        let b = &*self.balls;
        match stack.parts[e.part].side {
            Side::Ball(i) => {
                let (v, w) = match phase {
                    Phase::Start => (b.seg_v[i], b.seg_w[i]),
                    Phase::Chord => (b.chord[i], self.chord_spin(i)),
                };
                v + <Const<D> as Space<T, D>>::angular_cross(&w, &e.lever)
            }
            Side::Cluster(c) => {
                let cluster = &self.clusters.list[c];
                match phase {
                    Phase::Start => {
                        let r = &cluster.start;
                        r.velocity()
                            + <Const<D> as Space<T, D>>::angular_cross(
                                &r.angular_velocity(),
                                &e.arm,
                            )
                    }
                    Phase::Chord => {
                        let w = cluster.drive().angular_velocity();
                        b.chord[e.ball] + <Const<D> as Space<T, D>>::angular_cross(&w, &e.lever)
                    }
                }
            }
        }
    }

    /// The velocity of row `c`'s ball's contact point relative to the other end, in
    /// `phase`: its slip, for friction. Its normal component is the approach speed, read
    /// to the rounding of the spins' surface speeds: [`Self::approach`] reads it exactly.
    fn relative(&self, stack: &Stack<T, D>, c: usize, phase: Phase) -> Vector<T, D> {
        self.between(stack, c, phase, Self::end_velocity)
    }

    /// The velocity of row `c`'s ball end relative to its other end in `phase`, each
    /// end's read by `velocity` (a contact point's or a centre's); a surface's and a held
    /// ball's are their own.
    fn between(
        &self,
        stack: &Stack<T, D>,
        c: usize,
        phase: Phase,
        velocity: impl Fn(&Self, &Stack<T, D>, &End<T, D>, Phase) -> Vector<T, D>,
    ) -> Vector<T, D> {
        let row = &stack.rows[c];
        let other = match row.other {
            Other::Surface(v) => v,
            Other::Held(j) => match phase {
                Phase::Start => self.balls.velocity_at(j, stack.s, self.h).0,
                Phase::Chord => self.balls.chord[j],
            },
            Other::Part(e) => velocity(self, stack, &e, phase),
        };
        velocity(self, stack, &row.end, phase) - other
    }

    /// How fast row `c` closes in `phase`: the velocities of the two touching balls'
    /// centres along its normal, as the narrow phase reads the chords.
    ///
    /// The contact point lies on the normal through each ball's centre (`End::lever`),
    /// so a spin moves it across the normal only: the approach is the centres'. Read from
    /// the contact points' velocities ([`Self::relative`]), it carries the rounding of
    /// the spins' surface speeds, which neither the narrow phase nor its
    /// [`Allowance`](super::narrow::Allowance) sees. A 211,605 kg ball met at 5 m/s by a
    /// 960,600 kg ball spinning at 93,722 rad/s (6,957 m/s at its surface, whose last
    /// place is 9e-13 m/s) was left closing along the chords at 2.3e-13 m/s, past the
    /// allowance (9.9e-14 m/s), while the hold read 0 and did nothing: the same contact
    /// again, 16,384 times, and a false crush error (a fuzzed scene). In the same scene a
    /// 0.16 kg ball spinning at 925,314 rad/s (19,364 m/s at its surface) against a 1 kg
    /// ball read 1.4e-12 m/s through every round, which no push changed, and
    /// [`Self::hold`]'s last resort stopped both balls dead.
    fn approach(&self, stack: &Stack<T, D>, c: usize, phase: Phase) -> T {
        (self.between(stack, c, phase, Self::centre_velocity)).dot(&stack.rows[c].normal)
    }

    /// The velocity of the centre of the ball at end `e` in `phase` (its contact point's,
    /// [`Self::end_velocity`], without the spin about that centre).
    fn centre_velocity(&self, stack: &Stack<T, D>, e: &End<T, D>, phase: Phase) -> Vector<T, D> {
        let b = &*self.balls;
        match (stack.parts[e.part].side, phase) {
            (Side::Ball(i), Phase::Start) => b.seg_v[i],
            (_, Phase::Chord) => b.chord[e.ball],
            (Side::Cluster(c), Phase::Start) => {
                let r = &self.clusters.list[c].start;
                r.velocity()
                    + <Const<D> as Space<T, D>>::angular_cross(
                        &r.angular_velocity(),
                        &(e.arm - e.lever),
                    )
            }
        }
    }

    /// The impulses on the ball ends of `rows` (the other ends take the opposite) that
    /// stop each closing faster than its `margins` entry, from the relative velocities
    /// `relative` and the approach speeds `approach` (both indexed by row, see
    /// [`Self::approach`]): normal impulses exactly (`lcp`), with friction the tangential
    /// ones within Coulomb's cone in turn. `hold`: the rows are a hold's (chords held over
    /// the rest of the step, [`Self::hold_work`] kept within its tolerance), not impacts
    /// at an instant.
    fn impulses(
        &mut self,
        stack: &Stack<T, D>,
        rows: &[usize],
        (relative, approach, margins): (&[Vector<T, D>], &[T], &[T]),
        hold: bool,
    ) -> Vec<Wide<D>> {
        let n = rows.len();
        if n == 0 {
            return Vec::new();
        }
        let a = stack.delassus(rows, Push::AtContacts);
        let approach: Vec<T> = rows.iter().map(|&c| approach[c]).collect();
        let tolerance = self.tolerance(stack, rows).to_f64();
        let mut lambda = vec![0.0; n];
        let mut tangential = vec![Wide::<D>::zeros(); n];
        let friction = self.rules.friction;
        let rest = (self.h - stack.s).to_f64();
        // A pile's holds (and every sparse one) start from the forces the same rows took
        // last: friction's rounds converge linearly, and a pile held step after step
        // goes on converging from where the last hold left it instead of starting
        // from no friction each time (see `stack::Warm`).
        let sparse = matches!(a, Delassus::Sparse(_));
        let pile = stack.approach == Approach::Resting;
        let warm = hold && (sparse || pile) && rest > 0.0;
        if warm {
            let rows = rows.iter().map(|&c| &stack.rows[c]);
            (self.solvers.warm).start(
                rows,
                rest,
                friction > T::zero(),
                &mut lambda,
                &mut tangential,
            );
        }
        // The normal impulses against the approach the tangential ones leave.
        let mut again = false;
        let mut normal = |this: &mut Self, lambda: &mut [f64], tangential: &[Wide<D>]| {
            let mut changes = Changes::new(stack.parts.len());
            for (k, &c) in rows.iter().enumerate() {
                changes.add_at_row(stack, c, &tangential[k]);
            }
            let q: Vec<f64> = (rows.iter().enumerate())
                .map(|(k, &c)| {
                    let moved = changes.across(stack, c).dot(&stack.rows[c].normal);
                    (margins[k] - approach[k] - moved).to_f64()
                })
                .collect();
            this.solvers.solve(&a, &q, tolerance, lambda, again);
            // A pile's friction rounds solve again from the last round's passive set;
            // other holds from scratch (their numbers as before `resolve` existed).
            again = pile;
        };
        let mut settled = friction <= T::zero();
        let (most_rounds, relaxation) = match (sparse, stack.s > T::zero()) {
            (true, true) => (SPARSE_REHOLD_FRICTION_ROUNDS, 1.0),
            (true, false) => (SPARSE_FRICTION_ROUNDS, 1.0),
            (false, _) if pile => (PILE_FRICTION_ROUNDS, PILE_OVER_RELAXATION),
            (false, _) => (FRICTION_ROUNDS, 1.0),
        };
        for _ in 0..most_rounds {
            normal(self, &mut lambda, &tangential);
            if settled {
                break;
            }
            if self.friction_sweep(stack, rows, relative, &lambda, relaxation, &mut tangential) {
                settled = true;
                break;
            }
        }
        // Rounds that end with friction still moving (they converge linearly: in a pile's
        // hold of over 200 contacts the sweep's change fell only from 0.2 to 0.017 of the
        // fastest slip over 32 rounds) leave the last sweep's change in the approaches. Under
        // gravity the normal impulses are solved again, so that what the hold leaves
        // closing is the solve's tolerance, not friction's last change. Without this,
        // each round of a pile's `hold_rounds` found the same rows closing, solved the
        // same problem again (8 times), and the hold ended in its last resort, the push
        // through the centres; with it only in piles, the smaller holds of a landing
        // pile left their friction's change and a step gained 1.2e-4 J. Without gravity
        // holds are left as they were: there this turned 5 completed runs of fuzzed
        // kinematic-box squeezes into crush errors not yet told real or false
        // (`docs/stepped.md`). A sparse solve, a few steps from the impulses it has, is
        // solved again whenever there is friction.
        if (self.rules.has_gravity() && !settled) || (sparse && friction > T::zero()) {
            normal(self, &mut lambda, &tangential);
        }
        if hold && !settled {
            let held = (relative, margins);
            self.fit_friction(stack, rows, held, (&mut lambda, &mut tangential), normal);
        }
        if warm {
            let rows = rows.iter().map(|&c| &stack.rows[c]);
            let step = self.h.to_f64();
            self.solvers
                .warm
                .keep(rows, (rest, step), &lambda, &tangential);
        }
        (rows.iter().zip(lambda.iter().zip(&tangential)))
            .map(|(&c, (&l, t))| t - wide(&stack.rows[c].normal) * l)
            .collect()
    }

    /// Where a hold's friction, left unconverged by its rounds, makes the hold's work
    /// ([`Self::hold_work`]) exceed its rows' tolerance: scales the tangential impulses
    /// by the largest share, found by halving ([`FRICTION_SHARE_HALVINGS`]), whose hold
    /// stays within it, the normal impulses solved again by `normal` for each share; by
    /// 0 where none does (a hold without friction only takes energy).
    fn fit_friction(
        &mut self,
        stack: &Stack<T, D>,
        rows: &[usize],
        held: (&[Vector<T, D>], &[T]),
        (lambda, tangential): (&mut Vec<f64>, &mut Vec<Wide<D>>),
        mut normal: impl FnMut(&mut Self, &mut [f64], &[Wide<D>]),
    ) {
        let done: Vec<f64> = rows.iter().map(|&c| self.done(stack, c).to_f64()).collect();
        let held = (held.0, held.1, &done[..]);
        let (work, allowed) = Self::hold_work(stack, rows, held, lambda, tangential);
        if work <= allowed {
            return;
        }
        let full = core::mem::take(tangential);
        let (mut kept, mut refused) = (0.0, 1.0);
        let mut best = None;
        for _ in 0..FRICTION_SHARE_HALVINGS {
            let share = 0.5 * (kept + refused);
            let t: Vec<Wide<D>> = full.iter().map(|f| f * share).collect();
            let mut l = lambda.clone();
            normal(self, &mut l, &t);
            let (work, allowed) = Self::hold_work(stack, rows, held, &l, &t);
            if work <= allowed {
                kept = share;
                best = Some((l, t));
            } else {
                refused = share;
            }
        }
        (*lambda, *tangential) = best.unwrap_or_else(|| {
            let t = vec![Wide::<D>::zeros(); full.len()];
            normal(self, lambda, &t);
            (core::mem::take(lambda), t)
        });
    }

    /// The work of a hold's impulses on `rows` (normal `lambda`, tangential `tangential`)
    /// against the chords they leave, and the most its rows' tolerance lets it be: `(Σ
    /// P·u', Σ λ done)`, `done[k]` row `rows[k]`'s [`Self::done`], the normal part left out where a row's margin is negative (a
    /// sunk contact, aimed apart: its push adds energy by design, see the module
    /// documentation).
    ///
    /// Why this measures the energy a hold adds: a force held over the rest `τ` of the
    /// step changes a body's chord by `Δc = P/m` and its end velocity by `Δc/w`. With an
    /// integrator exact for constant gravity (`w = ½`: the end velocity is `c + g τ/2`,
    /// the end position moves by `τ Δc`), the energy at the step's end changes by
    /// `m (2 Δc·(c + g τ/2) + 2 Δc²) − m g·τ Δc = 2 m Δc·(c + Δc) = 2 P·c'`, the spins'
    /// alike (`spin_shares`); summed over the bodies and written per contact, `2 Σ P·u'`.
    /// An exact Coulomb solution makes every term `≤ 0`: a normal impulse pushes only
    /// where its row closes at its margin (`−λ g/τ`), a sliding row's friction opposes its
    /// slip and a sticking row's does not slip. Friction whose rounds stopped short of
    /// that (they converge linearly, slowly in a pile, and the last normal solve moves
    /// the slips again) can push along the slip: in a sloshing pile's hold friction added
    /// 5.6e-5 J and the normal impulses took 1.5e-5 J, and the step rose by 11 times what
    /// the narrow phase's allowance lets the pile's weight do
    /// (`docs/stepped.md`, piles item 19). The bound `Σ λ done` is what rows left closing
    /// within [`Self::done`] may take; with semi-implicit Euler (`w = 1`) the same sum
    /// bounds the chords' own kinetic energy change, `P·(u + u')/2 <= P·u'`.
    fn hold_work(
        stack: &Stack<T, D>,
        rows: &[usize],
        (relative, margins, done): (&[Vector<T, D>], &[T], &[f64]),
        lambda: &[f64],
        tangential: &[Wide<D>],
    ) -> (f64, f64) {
        let changes = Changes::of_rows(stack, rows, lambda, tangential);
        let (mut work, mut allowed) = (0.0, 0.0);
        for (k, &c) in rows.iter().enumerate() {
            let normal = wide(&stack.rows[c].normal);
            let u = wide(&(relative[c] + changes.across(stack, c)));
            let along = u.dot(&normal);
            work += tangential[k].dot(&(u - normal * along));
            if margins[k] >= T::zero() {
                work -= lambda[k] * along;
            }
            allowed += lambda[k] * done[k];
        }
        (work, allowed)
    }

    /// The bodies' impulses of `impulses` on `rows`; marks the rows that push.
    fn changes(
        stack: &Stack<T, D>,
        rows: &[usize],
        impulses: &[Wide<D>],
        pushed: &mut [bool],
    ) -> Changes<T, D> {
        let mut changes = Changes::new(stack.parts.len());
        for (&c, p) in rows.iter().zip(impulses) {
            changes.add_at_row(stack, c, p);
            if p.dot(&wide(&stack.rows[c].normal)) < 0.0 {
                pushed[c] = true;
            }
        }
        changes
    }

    /// Applies `changes` as impulses at the bodies' segment starts (the hold's instant):
    /// velocities, chords and ends alike.
    fn strike(&mut self, stack: &Stack<T, D>, changes: &Changes<T, D>) {
        for (part, (linear, angular)) in stack.parts.iter().zip(&changes.impulse) {
            match part.side {
                Side::Ball(i) => {
                    let dw =
                        <Const<D> as Space<T, D>>::inertia_apply(&part.inverse_inertia, angular);
                    self.balls
                        .nudge(i, self.h, &Changes::linear_change(part, linear), &dw);
                    self.rest
                        .restart(i, self.balls.seg_t[i], self.balls.chord[i]);
                }
                Side::Cluster(c) => {
                    let rigid = Motion {
                        velocity: Changes::linear_change(part, linear),
                        momentum: *angular,
                    }
                    .added(&self.clusters.list[c].start, T::one());
                    self.finish_cluster(c, rigid);
                }
            }
        }
    }

    /// Keeps each body's state before the hold's force.
    fn save_free(&self, stack: &mut Stack<T, D>) {
        let b = &*self.balls;
        for part in &mut stack.parts {
            part.free = match part.side {
                Side::Ball(i) => {
                    Free::Ball([b.seg_v[i], b.chord[i], b.vel[i]], [b.seg_w[i], b.spin[i]])
                }
                Side::Cluster(c) => Free::Cluster(self.clusters.list[c].start),
            };
        }
    }

    /// Applies `changes` as the constant force of the rest of the step (see the module
    /// documentation), to the state before the hold: chords by `P/m`, end velocities by
    /// `P/(w m)` (`Integrator::end_per_chord` times `P/m` under drag), the velocities at
    /// the segment start unchanged; spins alike, by [`spin_shares`]. With explicit Euler
    /// (`w = 0`) no force within the step moves a chord: impulses at the segment start.
    fn push(&mut self, stack: &Stack<T, D>, changes: &Changes<T, D>) {
        let w = self.chord_weight();
        let (spin_start, spin_end) = spin_shares(w);
        let flight = self.flight();
        for (part, (linear, angular)) in stack.parts.iter().zip(&changes.impulse) {
            let dv = Changes::linear_change(part, linear);
            match (part.side, part.free) {
                (Side::Ball(i), Free::Ball([seg_v, chord, vel], [seg_w, spin])) => {
                    let (start_share, end_share) =
                        shares(&flight, part.inverse_mass, self.balls.seg_t[i]);
                    let dw =
                        <Const<D> as Space<T, D>>::inertia_apply(&part.inverse_inertia, angular);
                    self.balls.set_segment(
                        i,
                        self.h,
                        [seg_v + dv * start_share, chord + dv, vel + dv * end_share],
                        [seg_w + dw * spin_start, spin + dw * spin_end],
                    );
                    self.rest
                        .restart(i, self.balls.seg_t[i], self.balls.chord[i]);
                }
                (Side::Cluster(c), Free::Cluster(start)) => {
                    let push = Motion {
                        velocity: dv,
                        momentum: *angular,
                    };
                    if w > T::zero() {
                        self.clusters.list[c].hold(self.balls, push, &flight);
                    } else {
                        self.finish_cluster(c, push.added(&start, T::one()));
                    }
                }
                _ => debug_assert!(false, "a stack body without its free state"),
            }
        }
    }

    /// Marks the bodies held: those that reach a wall, a box or a held ball through
    /// contacts that push (`pushed`); their balls count as held (see `onto_held`).
    fn mark_held(&mut self, stack: &Stack<T, D>, pushed: &[bool]) {
        let mut held = vec![false; stack.parts.len()];
        let mut changed = true;
        while changed {
            changed = false;
            for (row, _) in stack.rows.iter().zip(pushed).filter(|(_, p)| **p) {
                let a = row.end.part;
                let reached = match row.other {
                    Other::Surface(_) | Other::Held(_) => true,
                    Other::Part(e) => held[e.part],
                };
                if reached && !held[a] {
                    held[a] = true;
                    changed = true;
                }
                if let Other::Part(e) = row.other
                    && held[a]
                    && !held[e.part]
                {
                    held[e.part] = true;
                    changed = true;
                }
            }
        }
        for (part, &h) in stack.parts.iter().zip(&held) {
            match part.side {
                Side::Ball(i) => self.balls.supported[i] = h,
                Side::Cluster(c) => {
                    for &m in &self.clusters.list[c].members {
                        self.balls.supported[m as usize] = h;
                    }
                }
            }
        }
    }
}

/// The gap a hold keeps between a ball (centre and radius) and a surface, given their
/// `gap` (negative when overlapping): none in a wedge's hold where the in-step time
/// cannot resolve it at their `speed` ([`time_resolved_gap`]), none when overlapping,
/// but the (negative) gap itself for a ball sunk into the surface deeper than the floor
/// lets a contact sink ([`Allowance::sunk_depth`], the surface's rounding taken where
/// the ball is, which the ball's own touch tolerance covers): such a ball is aimed out
/// over the rest of the step, as a sunk pair is aimed apart. Only stopping its approach
/// left a wedged ball where a chain of contacts had ratcheted it, 7.3e-8 m into a wall
/// (docs/stepped.md).
fn held_surface_gap<T: Real, const D: usize>(
    allowance: &Allowance<T, D>,
    (x, r): (&Vector<T, D>, T),
    gap: T,
    wedge_h: T,
    speed: T,
) -> T
where
    Const<D>: Space<T, D>,
{
    if -gap > allowance.sunk_depth(x, r, x, T::zero()) {
        gap
    } else {
        time_resolved_gap(gap, wedge_h, speed).max(T::zero())
    }
}
