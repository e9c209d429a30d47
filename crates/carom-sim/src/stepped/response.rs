//! What a contact does to the balls within a step: one physical impulse, the rest of the
//! step re-integrated, and, if the new paths still close on each other, a correction of
//! the paths (a resting contact).
//!
//! At a contact at in-step time `s` (see `docs/stepped.md` for the whole argument):
//!
//! 1. Each ball's segment is restarted at `s` (position on its chord, physical velocity
//!    and spin interpolated).
//! 2. **Collision.** carom-response's [`resolve`] acts on the physical velocities with the
//!    pair's restitution and the world's friction, after the guards:
//!    * ball–wall and ball–box: the [`RestingGuard`] with a minimum flight time of two
//!      steps — a bounce too small to fly for two steps under the normal component of
//!      gravity ends in rest (`e = 0`), which stops Zeno bouncing;
//!    * ball–ball: the [`CollapseGuard`] `ElasticBelow`: collisions approaching slower than
//!      what gravity adds in one step (or a millionth of the scene's speed scale without
//!      gravity) are elastic, which ends inelastic collapse within a step.
//!
//!    If an impulse was applied, each dynamic ball's remaining step `[s, h]` is
//!    re-integrated from its new velocity with the engine's integrator, so forces act on
//!    the motion after the collision (bounce heights keep the integrator's order).
//! 3. **Resting contact.** If the pair's chords still close on each other (gravity pulls a
//!    ball back into the floor within the rest of the step; a ball rests on another that
//!    rests on the floor), the chords get a second impulse, computed on the chord
//!    velocities, that stops them closing: restitution 0 against a wall or a box (the
//!    ball stays on it and slides or rolls, friction included) and 1 between two balls
//!    (the approach passes down a stack to whatever supports it, exactly as an elastic
//!    chain passes momentum: a column of `k` balls settles in `k(k+1)/2` contacts, where
//!    restitution 0 would only converge geometrically). The same change is applied to
//!    the physical velocity over the segment, whose component along the normal becomes
//!    the chord's: a ball held on a surface does not end the step moving into it (with
//!    Verlet, RK4 or the exact integrator the end velocity would otherwise keep half a
//!    step of gravity). The energy cost is at most the kinetic energy of the normal
//!    velocity, `½ m (g h)²` per resting ball per step; the ball's velocity does not
//!    grow step after step.
//!
//! After these, the pair no longer closes along its chords, so the same contact is not
//! found again; the event loop goes on with the next one.

use carom_geometry::Border;
use carom_integrate::{ForceField, Stepper, TimeStep};
use carom_math::{Real, Space, Vector};
use carom_response::guard::{Bounce, CollapseGuard, RestingGuard};
use carom_response::{Body, Coefficients, Contact, Response, normal_velocity, resolve};
use nalgebra::Const;

use super::balls::{BallArrays, SegmentEnd};
use super::clusters::{Clusters, FREE, Flight};
use super::narrow::{Allowance, Target, apart_speed, touch_tolerance};
use super::obstacles::BoxArrays;
use super::rest::{RestSet, Support, Touch};
use super::stack::{Groups, Solvers};
use super::sweep::Sweep;
use crate::engine::Angular;
use crate::prefetch::prefetch;
use crate::scene::{Inelastic, Scene, SceneError};

/// The rules of a scene's contacts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rules<T: Real, const D: usize> {
    /// Coulomb coefficient of every ball contact.
    pub(crate) friction: T,
    /// Ball–wall restitution of the reflecting border.
    pub(crate) border_restitution: T,
    /// Gravity (the acceleration the resting guard projects on the normal).
    pub(crate) gravity: Vector<T, D>,
    /// Gravity's unit direction (zero without gravity).
    pub(crate) down: Vector<T, D>,
    /// The Zeno guard of ball–surface bounces.
    pub(crate) resting: RestingGuard<T>,
    /// The inelastic-collapse guard of ball–ball collisions.
    pub(crate) collapse: CollapseGuard<T>,
    /// `|g| h`: an impulse approaching no faster than gravity adds in one step is support
    /// of a resting contact, not a collision to report.
    pub(crate) support_speed: T,
    /// Speeds below this are rounding or residue of resting corrections: a millionth of
    /// what gravity adds in a step plus `64 ε` times the scene's speed scale (the fastest
    /// ball or box at the start).
    pub(crate) floor: T,
    /// The part of [`Rules::floor`] gravity sets, a millionth of what it adds in a step:
    /// the floor below which the narrow phase takes a contact for resting, which counts
    /// the rounding of the contact's own speeds itself ([`Rules::allowance`]).
    /// With the whole floor, a ball resting on the floor next to a 4.2e4 m/s ball in `f32`
    /// (where `64 ε` of that speed is 0.32 m/s) approached it at `g h` = 0.098 m/s, which
    /// was no contact, and fell through it (7.2e-2 m in 0.5 s).
    pub(crate) contact_floor: T,
    /// `inelastic = "stick"`: two balls whose pair restitution is 0 fuse (see `stick`).
    pub(crate) stick: bool,
}

impl<T: Real, const D: usize> Rules<T, D> {
    /// The rules of `scene` stepped at `h`: the scene's friction and border restitution,
    /// the resting guard with a minimum flight of two steps, the collapse guard elastic
    /// below what gravity adds in a step (at least a millionth of the fastest ball or box
    /// of the scene).
    ///
    /// # Errors
    /// `--dt` if the guards' parameters are not representable (a step near the limits
    /// of the precision).
    pub(crate) fn for_scene(scene: &Scene<T, D>, h: T) -> Result<Self, SceneError> {
        let world = &scene.world;
        let g = world.gravity.norm();
        let speed = scene
            .balls
            .iter()
            .map(|b| b.vel.norm())
            .chain(scene.boxes.iter().map(|b| b.vel.norm()))
            .fold(g * h, T::max);
        let collapse_speed = (g * h).max(T::lit(1e-6) * speed).max(T::MIN_POSITIVE);
        let contact_floor = T::lit(1e-6) * g * h;
        let bad_step = |e: carom_math::InvalidValue| SceneError::new("--dt", e.to_string());
        Ok(Self {
            friction: world.friction,
            border_restitution: world.border.as_ref().map_or_else(T::one, |b| b.restitution),
            gravity: world.gravity,
            down: if g > T::zero() {
                world.gravity / g
            } else {
                Vector::zeros()
            },
            resting: RestingGuard::new(T::lit(2.0) * h).map_err(bad_step)?,
            collapse: CollapseGuard::elastic_below(collapse_speed).map_err(bad_step)?,
            support_speed: T::lit(2.0) * g * h,
            floor: contact_floor + T::lit(64.0) * T::EPSILON * speed,
            contact_floor,
            stick: world.inelastic == Inelastic::Stick,
        })
    }

    /// Whether the scene has gravity.
    pub(crate) fn has_gravity(&self) -> bool {
        self.gravity != Vector::<T, D>::zeros()
    }

    /// How fast a contact may approach in a step of length `h` and be no contact: the
    /// narrow phase's events and the holds' aim (see [`Allowance`]).
    pub(crate) fn allowance(&self, h: T) -> Allowance<T, D> {
        Allowance {
            resting_floor: self.contact_floor,
            down: self.down,
            step: h,
        }
    }

    /// Whether ball `lower` (centre and radius) lies below ball `upper` along gravity, so
    /// that it can hold it up (shock propagation): its centre lower by more than the
    /// rounding of both balls' contacts ([`touch_tolerance`]) plus [`SIDE_BY_SIDE`]
    /// times the distance between the centres. Two balls side by side on a floor hold
    /// each other up neither way: taking a neighbour 1e-10 m lower for an immovable
    /// support stopped a ball rolling slowly into it dead (its momentum and energy
    /// lost), and one 3e-10 m lower made a ball a kinematic box pushed into it look
    /// crushed (a fuzzed scene).
    pub(crate) fn lies_below(&self, upper: (&Vector<T, D>, T), lower: (&Vector<T, D>, T)) -> bool {
        let offset = lower.0 - upper.0;
        let margin = touch_tolerance(upper.0, upper.1)
            + touch_tolerance(lower.0, lower.1)
            + T::lit(SIDE_BY_SIDE) * offset.norm();
        self.gravity.dot(&offset) > self.gravity.norm() * margin
    }
}

/// How far below the horizontal (as the sine of the angle) the line from a ball's centre
/// to another's must dip for the other to hold it up ([`Rules::lies_below`]). Balls
/// resting on one floor differ in height by what they sank at landing: up to 2.2e-8 m
/// (measured: a ball sliding on the floor of a fuzzed scene, exact integrator, `h =
/// 0.01`), 1.1e-7 of the distance between two centres 0.2 m apart; `f32` rounds
/// coordinates near 2 m to 2.4e-7 m. A contact within 1e-4 rad of the horizontal takes
/// at most 1e-4 of its push as support: it is a side contact, not a support.
pub(crate) const SIDE_BY_SIDE: f64 = 1e-4;

/// What a processed contact did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Effect {
    /// An impulse faster than support was applied: a collision to report.
    pub(crate) collided: bool,
}

/// The other side of a ball's contact.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Surface<T: Real, const D: usize> {
    /// A wall of the border.
    Wall,
    /// Box `k`, moving at its velocity.
    Box(usize, Vector<T, D>),
}

/// The support constraints of the balls held at the current instant, sparse.
#[derive(Clone, Debug, Default)]
pub(crate) struct RestSets<T: Real, const D: usize> {
    /// Per ball: its entry in `sets`, or `u32::MAX`.
    slot: Vec<u32>,
    sets: Vec<(u32, RestSet<T, D>)>,
}

impl<T: Real, const D: usize> RestSets<T, D> {
    /// Empty sets for `n` balls.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            slot: vec![u32::MAX; n],
            sets: Vec::new(),
        }
    }

    /// Forgets every set (at the start of a step).
    pub(crate) fn clear(&mut self) {
        for (ball, _) in &self.sets {
            self.slot[*ball as usize] = u32::MAX;
        }
        self.sets.clear();
    }

    /// Prefetches ball `i`'s entry in the sparse index (see `prefetch`): every contact
    /// reads it.
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.slot[i]);
    }

    /// Ball `i`'s set for the instant `s`, started afresh from `chord` if it was for
    /// another instant (or `fresh` asks for it: the chord changed by other means).
    pub(super) fn at(
        &mut self,
        i: usize,
        s: T,
        tolerance: T,
        chord: Vector<T, D>,
        fresh: bool,
    ) -> &mut RestSet<T, D> {
        let k = match self.slot[i] {
            u32::MAX => {
                self.slot[i] = self.sets.len() as u32;
                self.sets.push((i as u32, RestSet::new(s, chord)));
                self.sets.len() - 1
            }
            k => k as usize,
        };
        let set = &mut self.sets[k].1;
        if fresh || !set.is_at(s, tolerance) {
            *set = RestSet::new(s, chord);
        }
        set
    }

    /// Ball `i`'s chord changed other than by a resting correction at `s`.
    pub(super) fn restart(&mut self, i: usize, s: T, chord: Vector<T, D>) {
        if self.slot[i] != u32::MAX {
            self.at(i, s, T::zero(), chord, true);
        }
    }
}

/// The balls, the integrator and the rules, for processing contacts.
pub(crate) struct Contacts<'a, T: Real, const D: usize, F>
where
    Const<D>: Space<T, D>,
{
    pub(crate) balls: &'a mut BallArrays<T, D>,
    /// Balls changed beyond the contact's own (and their clusters' members): a hold's
    /// whole stack (see `stack`).
    pub(crate) changed: &'a mut Vec<u32>,
    pub(crate) boxes: &'a BoxArrays<T, D>,
    /// The reflecting border, if any.
    pub(crate) border: Option<&'a Border<T, D>>,
    pub(crate) stepper: &'a Stepper<T, D, F>,
    pub(crate) rules: &'a Rules<T, D>,
    pub(crate) rest: &'a mut RestSets<T, D>,
    /// The stuck clusters (see `stick`).
    pub(crate) clusters: &'a mut Clusters<T, D>,
    /// The periodic domain, if any.
    pub(crate) periodic: Option<&'a Border<T, D>>,
    /// The broad phase, for the neighbours of a stack's balls (see `stack`).
    pub(crate) sweep: &'a Sweep<T, D>,
    /// Scratch for the broad phase's candidates.
    pub(crate) candidates: &'a mut Vec<u32>,
    /// The stacks' complementarity solvers (see `stack`).
    pub(crate) solvers: &'a mut Solvers<D>,
    /// The bodies held together in this step (see `stack`).
    pub(crate) groups: &'a mut Groups,
    /// The supports the contact's balls touch now: `(ball, touches)` (gathered only
    /// under gravity; see `rest_on`).
    pub(crate) touching: [(usize, &'a [Touch<T, D>]); 2],
    /// The step's length.
    pub(crate) h: T,
    /// The internal time of the step's start (for time-dependent fields).
    pub(crate) t0: T,
}

impl<'a, T: Real, const D: usize, F: ForceField<T, D>> Contacts<'a, T, D, F>
where
    Const<D>: Space<T, D>,
{
    /// The step the contacts are in, for the clusters.
    pub(super) fn flight(&self) -> Flight<'a, T, D, F> {
        Flight::new(self.stepper, self.h, self.t0)
    }

    /// The integrator's chord weight `w` (`Integrator::chord_weight`).
    pub(super) fn chord_weight(&self) -> T {
        T::lit(self.stepper.integrator().chord_weight())
    }

    /// The spin ball `i`'s contact points read along its chord
    /// ([`BallArrays::chord_spin`] at this integrator's chord weight).
    pub(super) fn chord_spin(&self, i: usize) -> Angular<T, D> {
        self.balls.chord_spin(i, self.chord_weight())
    }

    pub(super) fn body(&self, i: usize, v: Vector<T, D>, w: Angular<T, D>) -> Body<T, D> {
        let b = &*self.balls;
        Body::new_unchecked(
            b.inverse_mass[i],
            <Const<D> as Space<T, D>>::inertia_isotropic(b.inverse_inertia[i]),
            v,
            w,
        )
    }

    /// Ball `i` as a single support's hold solves it (along `n`, against a support
    /// moving at `velocity` and spinning at `spin`), its correction taken as a constant
    /// force over the rest of the step whose chord and end `shares` are `(0, e)`
    /// (`stack::shares`): the chord's approach along `n`, and across it the slip the end
    /// of the step would have without friction, over `e`, so that a stick leaves the
    /// contact point at rest at the step's end (the chord's slip `s₀ (1 − 1/e)`, the
    /// mean of a slip falling linearly from `s₀` to 0). Aiming the stick at the chord's
    /// slip with the end moved `e` times the chord flips the end's slip each step
    /// (`s₀ → (1 − e) s₀`): a disk rolling on with Verlet stopped at 2.019 m/s with its
    /// contact point slipping at 5.7e-2 m/s and no friction acting. With shares `(1, 1)`
    /// (explicit Euler: an impulse at the segment's start) the chord and the spin at the
    /// segment's start, as they are.
    fn body_for_rest(
        &self,
        i: usize,
        n: &Vector<T, D>,
        velocity: Vector<T, D>,
        spin: Angular<T, D>,
        (start, end): (T, T),
    ) -> Body<T, D> {
        let b = &*self.balls;
        if start != T::zero() || end <= T::zero() {
            return self.body(i, b.chord[i], self.chord_spin(i));
        }
        let across = |v: Vector<T, D>| v - n * v.dot(n);
        let slip = across(b.vel[i] - velocity) / end;
        let v = n * b.chord[i].dot(n) + across(velocity) + slip;
        let w = spin + (b.spin[i] - spin) * (T::one() / end);
        self.body(i, v, w)
    }

    /// Re-integrates ball `i` from its segment start to the end of the step, as a
    /// displacement from the origin (the forces do not depend on the position; see
    /// `balls`: remainders).
    pub(super) fn reintegrate(&mut self, i: usize) {
        let b = &mut *self.balls;
        let (mut moved, mut v, mut w) = (Vector::zeros(), b.seg_v[i], b.seg_w[i]);
        let s = b.seg_t[i];
        if let Ok(dt) = TimeStep::new(self.h - s) {
            (self.stepper).step_ball(
                &mut moved,
                &mut v,
                &mut w,
                b.inverse_mass[i],
                self.t0 + s,
                dt,
            );
        }
        b.set_end(i, self.h, SegmentEnd::Moved(moved), v, w);
    }

    /// Applies a collision's new physical velocities to ball `i` and re-integrates it:
    /// it is no longer supported.
    pub(super) fn collide(&mut self, i: usize, s: T, v: Vector<T, D>, w: Angular<T, D>) {
        self.balls.seg_v[i] = v;
        self.balls.seg_w[i] = w;
        self.reintegrate(i);
        self.balls.supported[i] = false;
        self.rest.restart(i, s, self.balls.chord[i]);
    }

    /// Two balls `i`, `j` (j's position shifted by `shift`) touching at `s`.
    pub(crate) fn ball_ball(
        &mut self,
        i: usize,
        j: usize,
        shift: &Vector<T, D>,
        s: T,
        fallback_normal: &Vector<T, D>,
    ) -> Effect {
        let h = self.h;
        self.balls.restart(i, s, h);
        self.balls.restart(j, s, h);
        let b = &*self.balls;
        let offset = b.seg_x[j] + shift - b.seg_x[i];
        let length = offset.norm();
        let n = if length > T::zero() && length.finite() {
            offset / length
        } else {
            *fallback_normal
        };
        let Ok(contact) = Contact::new(n, n * b.radius[i], n * -b.radius[j]) else {
            return Effect::default();
        };
        let (bi, bj) = (
            self.body(i, b.seg_v[i], b.seg_w[i]),
            self.body(j, b.seg_v[j], b.seg_w[j]),
        );
        let nominal = b.pair_restitution(i, j);
        let (approach, r) = self.pair_collision(&bi, &bj, &contact, nominal);
        let slow = approach <= self.rules.support_speed;
        // A slow contact onto a support (a ball holding the other up, see `holds_up`) is
        // resting: no impulse, only the correction below.
        let onto_support = slow && (self.holds_up(i, j, s) || self.holds_up(j, i, s));
        let effect = Effect {
            collided: r.applied() && !slow,
        };
        if r.applied() && !onto_support {
            for (k, ball, body) in [(0, i, bi), (1, j, bj)] {
                let (v, w) = (r.velocity[k], r.angular_velocity[k]);
                if slow {
                    // Support-sized: no re-integration (it would add this step's gravity
                    // again to balls the supports already hold).
                    let dw = w - body.angular_velocity();
                    self.balls.nudge(ball, h, &(v - body.velocity()), &dw);
                    self.settle_on_surfaces(ball);
                    self.rest.restart(ball, s, self.balls.chord[ball]);
                } else {
                    self.collide(ball, s, v, w);
                }
            }
        }
        let b = &*self.balls;
        if (b.chord[j] - b.chord[i]).dot(&n) >= T::zero() || s >= h {
            return effect;
        }
        // A pair sunk deeper than the narrow phase lets a contact sink is held apart at
        // its depth over the rest of the step (see `Allowance`): the support is taken to
        // recede at that speed.
        // Both balls restarted at `s`: their segments start where they are now.
        let apart = apart_speed(
            &self.rules.allowance(h),
            (&b.seg_x[i], b.radius[i]),
            (&(b.seg_x[j] + shift), b.radius[j]),
            h - s,
        );
        // Shock propagation: a ball resting on a supported ball below it, that does not
        // move towards it, is held as by an immovable surface, and is supported in turn.
        if self.holds_up(i, j, s) {
            let support = b.chord[j] - n * apart;
            self.rest_on(
                i,
                Support::Ball(j as u32),
                &n,
                support,
                self.chord_spin(j),
                s,
            );
        } else if self.holds_up(j, i, s) {
            let support = b.chord[i] + n * apart;
            self.rest_on(
                j,
                Support::Ball(i as u32),
                &-n,
                support,
                self.chord_spin(i),
                s,
            );
        } else {
            // Two free balls closing along their chords: a perfectly inelastic correction
            // (momentum kept, energy never added).
            let (ci, cj) = (
                self.body(i, b.chord[i], self.chord_spin(i)),
                self.body(j, b.chord[j], self.chord_spin(j)),
            );
            let r = self.stop_closing(&ci, &cj, &contact);
            if r.applied() {
                for (k, ball, body) in [(0, i, ci), (1, j, cj)] {
                    let du = r.velocity[k] - body.velocity();
                    let dw = r.angular_velocity[k] - body.angular_velocity();
                    // Both balls' velocities shift with their chords: the pair keeps its
                    // momentum, and (gravity shifting both velocities alike from the
                    // chords) its energy changes as the chords' does, never up. Setting
                    // the normal component to the chord's, as a ball held on a surface
                    // does, would add the step's remaining gravity `g (h − s)` along the
                    // normal at every such contact (a milligram ball pressed between two
                    // kilogram balls gave them 2 J in one step).
                    self.balls.nudge(ball, h, &du, &dw);
                    self.settle_on_surfaces(ball);
                    self.rest.restart(ball, s, self.balls.chord[ball]);
                }
            }
        }
        effect
    }

    /// Stops ball `i`, whose chord a contact with another ball has just changed, closing
    /// on a wall or box it touches now (`touching`) by no more than the narrow phase
    /// allows that contact ([`Allowance`]): the surface takes that part of the change.
    ///
    /// The narrow phase answers no slower approach, and nothing lifts a ball out of a
    /// surface again, so each such push sank the ball for the rest of its step, step after
    /// step: a 0.63 kg ball held on the floor at every step's start, pushed into it at
    /// 1.5e-8 to 1.1e-7 m/s by a 1.5 mg ball falling back onto it (their inelastic
    /// correction, below the floor's 9.8e-8 m/s), sank 2.7e-9 m in seven steps, where
    /// the allowance times the step is 9.8e-10 m (a fuzzed scene). Faster pushes are
    /// contacts the narrow phase finds and answers. A wall's normal is an axis, so the
    /// chord's component along it is set to zero exactly; the velocities shift with the
    /// chord, as the push itself shifted them.
    fn settle_on_surfaces(&mut self, i: usize) {
        let allowance = self.rules.allowance(self.h);
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        for (ball, touches) in self.touching {
            if ball != i {
                continue;
            }
            for t in touches {
                let target = match t.support {
                    Support::Wall(..) => Target::Border,
                    Support::Box(k) => Target::Box(k),
                    Support::Ball(_) => continue,
                };
                let u = self.balls.chord[i];
                let closing = (u - t.velocity).dot(&t.normal);
                let allowed = allowance.of(self.balls, i, target, &u, &t.velocity, &t.normal);
                if closing > T::zero() && closing <= allowed {
                    self.balls
                        .nudge(i, self.h, &(t.normal * -closing), &zero_spin);
                }
            }
        }
    }

    /// Holds ball `i` on an immovable support it touches along `n` (from the ball into
    /// the support), moving at `velocity` and spinning at `spin`: one support is a
    /// restitution-0 impulse with friction on the chord; several at the same instant (the
    /// ones corrected before, and every other support the ball touches now: walls, boxes,
    /// supported balls below it) are the exact projection of the chord onto all of them
    /// (see `rest`).
    fn rest_on(
        &mut self,
        i: usize,
        support: Support,
        n: &Vector<T, D>,
        velocity: Vector<T, D>,
        spin: Angular<T, D>,
        s: T,
    ) {
        let h = self.h;
        let chord = self.balls.chord[i];
        let set = self.rest.at(i, s, h * T::lit(1e-6), chord, false);
        set.add(support, -n, -velocity.dot(n));
        // Every other support the ball touches right now holds it too: all of them at
        // once, so that it does not slide off one onto the next.
        for (ball, touches) in self.touching {
            if ball == i {
                for t in touches.iter().filter(|t| t.support != support) {
                    set.add(t.support, -t.normal, -t.velocity.dot(&t.normal));
                }
            }
        }
        let several = set.len() > 1;
        let projected = if several { set.project() } else { None };
        if let Some(u) = projected {
            self.balls.hold(i, h, u);
        } else {
            let b = &*self.balls;
            let Ok(contact) = Contact::new(*n, n * b.radius[i], Vector::zeros()) else {
                return;
            };
            let other = Body::kinematic(velocity, spin).unwrap_or_else(|_| Body::fixed());
            let shares = super::stack::shares(&self.flight(), b.inverse_mass[i], b.seg_t[i]);
            let ball = self.body_for_rest(i, n, velocity, spin, shares);
            let r = self.stop_closing(&ball, &other, &contact);
            if r.applied() {
                let du = r.velocity[0] - ball.velocity();
                let dw = r.angular_velocity[0] - ball.angular_velocity();
                self.balls.shift_chord(i, h, &du, &dw, n, shares);
            }
        }
        self.balls.supported[i] = true;
    }

    /// The restitution-0 impulse, with the world's friction, between `a` and `b` at
    /// `contact`: what stops two bodies closing along their chords (momentum kept,
    /// energy never added).
    pub(super) fn stop_closing(
        &self,
        a: &Body<T, D>,
        b: &Body<T, D>,
        contact: &Contact<T, D>,
    ) -> Response<T, D> {
        resolve(
            a,
            b,
            contact,
            &Coefficients::new_unchecked(T::zero(), self.rules.friction),
        )
    }

    /// The approach speed of two dynamic bodies at `contact` and their collision with
    /// the pair restitution `nominal` through the collapse guard (elastic below what
    /// gravity adds in a step).
    pub(super) fn pair_collision(
        &self,
        a: &Body<T, D>,
        b: &Body<T, D>,
        contact: &Contact<T, D>,
        nominal: T,
    ) -> (T, Response<T, D>) {
        let approach = -normal_velocity(a, b, contact);
        let e = self
            .rules
            .collapse
            .restitution(nominal, approach, [T::INFINITY, T::INFINITY]);
        let r = resolve(
            a,
            b,
            contact,
            &Coefficients::new_unchecked(e, self.rules.friction),
        );
        (approach, r)
    }

    /// The collision of `body` (body `a`) with the immovable surface `other` at `contact`
    /// (normal into the surface), or `None` for a support-sized approach (a resting
    /// contact: only the correction of the chords) or a pair that does not close. The
    /// resting guard decides between the surface's restitution `nominal` and rest.
    pub(super) fn surface_collision(
        &self,
        body: &Body<T, D>,
        other: &Body<T, D>,
        contact: &Contact<T, D>,
        nominal: T,
    ) -> Option<Response<T, D>> {
        let approach = -normal_velocity(body, other, contact);
        if approach <= self.rules.support_speed {
            return None;
        }
        let e = match self.rules.resting.decide(
            approach,
            nominal,
            self.rules.gravity.dot(&contact.normal()),
        ) {
            Bounce::Rebound => nominal,
            Bounce::Rest => T::zero(),
        };
        let r = resolve(
            body,
            other,
            contact,
            &Coefficients::new_unchecked(e, self.rules.friction),
        );
        r.applied().then_some(r)
    }

    /// Of balls `i` and `j` meeting at `s`, the one that meets a held ball of a pile from
    /// above, and that ball: `(upper, lower)`, where the lower one is in a pile held at
    /// the step's start (see `piles`) and holds the upper one up
    /// ([`Contacts::holds_up`]).
    pub(crate) fn onto_held_pile(&self, i: usize, j: usize, s: T) -> Option<(usize, usize)> {
        let onto = |upper: usize, lower: usize| {
            self.groups.piled(lower)
                && self.balls.cluster[upper] == FREE
                && self.holds_up(upper, lower, s)
        };
        if onto(i, j) {
            Some((i, j))
        } else if onto(j, i) {
            Some((j, i))
        } else {
            None
        }
    }

    /// Ball `upper` meeting ball `lower` of a held pile below it at `s` (see
    /// [`Self::onto_held_pile`]; `n` the unit normal from `upper` into `lower`): the pile's
    /// ball is an immovable surface moving at its chord (shock propagation), so the
    /// collision and the rest that follows change `upper` alone, and the pile keeps its
    /// hold.
    ///
    /// A pile rests on the floor, and its balls' weight and every push they take goes
    /// down to it: a ball landing on it meets, in effect, a body as heavy as the pile and
    /// the floor. Answered between the two balls alone, the struck ball was pushed into
    /// the pile, which had to be held again as a whole, at every bounce of every ball
    /// landing on it: a 480-ball pile made several hundred holds of hundreds of balls a
    /// step while its rows landed.
    pub(crate) fn onto_pile(
        &mut self,
        upper: usize,
        lower: usize,
        n: &Vector<T, D>,
        s: T,
    ) -> Effect {
        let h = self.h;
        self.balls.restart(upper, s, h);
        let b = &*self.balls;
        let spin = self.chord_spin(lower);
        let surface = b.chord[lower]
            + <Const<D> as Space<T, D>>::angular_cross(&spin, &(n * -b.radius[lower]));
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        let other = Body::kinematic(surface, zero_spin).unwrap_or_else(|_| Body::fixed());
        let Ok(contact) = Contact::new(*n, n * b.radius[upper], Vector::zeros()) else {
            return Effect::default();
        };
        let ball = self.body(upper, b.seg_v[upper], b.seg_w[upper]);
        let nominal = b.pair_restitution(upper, lower);
        let mut effect = Effect::default();
        if let Some(r) = self.surface_collision(&ball, &other, &contact, nominal) {
            effect.collided = true;
            self.collide(upper, s, r.velocity[0], r.angular_velocity[0]);
        }
        if (surface - self.balls.chord[upper]).dot(n) < T::zero() && s < h {
            self.rest_on(upper, Support::Ball(lower as u32), n, surface, zero_spin, s);
        }
        effect
    }

    /// Ball `i` touching a wall or a box along `n` (from the ball into the surface) at `s`.
    pub(crate) fn ball_surface(
        &mut self,
        i: usize,
        surface: Surface<T, D>,
        n: &Vector<T, D>,
        s: T,
    ) -> Effect {
        let h = self.h;
        self.balls.restart(i, s, h);
        let (surface_velocity, nominal, support) = match surface {
            Surface::Wall => {
                let axis = n.iamax();
                (
                    Vector::zeros(),
                    self.rules.border_restitution,
                    Support::Wall(axis, n[axis] > T::zero()),
                )
            }
            Surface::Box(k, v) => (v, self.boxes.restitution[k], Support::Box(k as u32)),
        };
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        let other = Body::kinematic(surface_velocity, zero_spin).unwrap_or_else(|_| Body::fixed());
        let b = &*self.balls;
        let Ok(contact) = Contact::new(*n, n * b.radius[i], Vector::zeros()) else {
            return Effect::default();
        };
        let ball = self.body(i, b.seg_v[i], b.seg_w[i]);
        let mut effect = Effect::default();
        if let Some(r) = self.surface_collision(&ball, &other, &contact, nominal) {
            effect.collided = true;
            self.collide(i, s, r.velocity[0], r.angular_velocity[0]);
        }
        if (surface_velocity - self.balls.chord[i]).dot(n) < T::zero() && s < h {
            self.rest_on(i, support, n, surface_velocity, zero_spin, s);
        }
        effect
    }
}
