//! Stuck clusters in the time-stepped engine: balls fused by perfectly inelastic "stick"
//! collisions (`inelastic = "stick"`, pair restitution 0), moving as rigid bodies, in 2D
//! and 3D.
//!
//! A cluster is a carom-response [`RigidCluster`] (mass, centre of mass, orientation,
//! inertia with each ball's own disk or sphere inertia plus parallel axes, velocity,
//! angular momentum `L` about the centre), its members and their body-frame offsets `o`.
//! Like a ball (see `balls`), it has a segment within the step: its rigid state `start`
//! at in-step time `seg_t` and `end` at the step's end `h`. Each member ball's segment
//! runs from where it is at `seg_t` to its rigid place at `h`,
//!
//! ```text
//! x_end = c_end + R_end o,    v_end = v_end,com + ω_end × R_end o,    spin = ω_end,
//! ```
//!
//! along its straight chord, which is what the continuous collision detection sweeps: all
//! the broad- and narrow-phase machinery of single balls serves the members unchanged,
//! and "no overlap along the chords" holds for them too. Members of one cluster are never
//! tested against each other. At every step end the members are exactly (to rounding) in
//! their rigid places, so the distances between them are kept.
//!
//! **A held segment.** Contacts that hold a cluster (see `stack`) act as a constant force
//! and torque over its segment, kept as its *push*: the change they make to the
//! segment's mean motion, `(Δv, ΔL)`. The pose follows the *drive*, the start's motion
//! plus the push, the field and the drag acting on the start's motion alone ([`advance`]);
//! the end's motion has the push `1/w` times, `w` the integrator's chord weight
//! (`Integrator::chord_weight`: a constant acceleration `a` moves the chord by `w a τ`
//! and the end velocity by `a τ`), in the velocity `Integrator::end_per_chord` times
//! under drag; the start's motion has none of it. Within the
//! segment the motion is interpolated linearly between the start's and the end's, as a
//! ball's velocity is (`balls`): exact for a constant force, so a cluster restarted
//! within a held segment is at rest if it rests, not flying up at the push.
//!
//! **The motion over a segment of length `τ`** ([`advance`]):
//!
//! * the centre of mass is stepped by the engine's integrator under the same field as a
//!   ball (gravity, linear drag), so it keeps the integrator's order;
//! * the angular momentum about the centre is constant without drag (no torque: gravity
//!   acts at the centre of mass). The orientation follows `Ṙ = [ω]ₓ R` with
//!   `ω = R I_body⁻¹ Rᵀ L` recomputed from the current orientation: in 3D an asymmetric
//!   body precesses (its `ω` changes while `L` is kept). The update is the explicit
//!   midpoint rule on rotations, `R½ = exp(ω(R₀) τ/2) R₀`, `R₁ = exp(ω(R½) τ) R₀`, with
//!   the exponential map of a rotation vector (orthonormal to rounding at every step);
//!   its local error is `O((|ω| τ)³)`, so the orientation and the rotational kinetic
//!   energy `½ L·I_world⁻¹ L` are second-order accurate, with the exactly constant `L`.
//!   In 2D `ω` is constant and the update is exact.
//! * linear drag acts on each ball, `F_i = −b v_i` with `v_i = v + ω × a_i` (arms
//!   `a_i = R o_i`). Summed: `F = −b (k v + ω × A)`, torque `τ = −b (J ω + A × v)`, with
//!   `k` members, `A = Σ a_i` and `J = Σ (|a_i|² 𝟙 − a_i a_iᵀ)`. The integrator steps the
//!   main term `−b k v` (the ball field with inverse mass `k/M`); the coupling `−b ω × A`
//!   (zero when every member has the same mass) and the torque are added explicitly with
//!   the values at the segment start: first order in `b τ / m`.

use carom_geometry::Border;
use carom_integrate::{ForceField, Stepper, TimeStep};
use carom_math::{Real, Space, Vector};
use carom_response::RigidCluster;
use nalgebra::Const;

use super::balls::{BallArrays, SegmentEnd};
use crate::engine::Angular;

/// A member ball's cluster id when it is in no cluster.
pub(crate) const FREE: u32 = u32::MAX;

/// One rigid cluster of stuck balls and its segment within the step.
#[derive(Clone, Debug)]
pub(crate) struct StuckCluster<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The rigid state at the segment start `seg_t`: pose and physical motion.
    pub(crate) start: RigidCluster<T, D>,
    /// The constant contact force held over the segment, as the change it makes to the
    /// segment's mean motion (see the module documentation).
    pub(crate) push: Motion<T, D>,
    /// The in-step time the segment starts at.
    pub(crate) seg_t: T,
    /// The rigid state at the end of the step (the state between steps).
    pub(crate) end: RigidCluster<T, D>,
    /// The member balls.
    pub(crate) members: Vec<u32>,
    /// Their offsets from the centre of mass, in the body frame.
    pub(crate) offsets: Vec<Vector<T, D>>,
}

/// Every cluster of the run, in the order they formed (a fusion of two clusters keeps
/// the lower index and moves the last cluster into the freed slot: deterministic).
#[derive(Clone, Debug, Default)]
pub(crate) struct Clusters<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) list: Vec<StuckCluster<T, D>>,
    /// The smallest side of a periodic border: a cluster may span at most half of it
    /// (see [`Clusters::check_span`]).
    pub(crate) period: Option<T>,
}

/// A change of a rigid body's motion: the velocity of its centre of mass and its angular
/// momentum about the centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Motion<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) velocity: Vector<T, D>,
    pub(crate) momentum: Angular<T, D>,
}

impl<T: Real, const D: usize> Motion<T, D>
where
    Const<D>: Space<T, D>,
{
    /// No change.
    pub(crate) fn zero() -> Self {
        Self {
            velocity: Vector::zeros(),
            momentum: <Const<D> as Space<T, D>>::angular_zero(),
        }
    }

    /// `rigid` with this change of its motion, `k` times.
    pub(crate) fn added(&self, rigid: &RigidCluster<T, D>, k: T) -> RigidCluster<T, D> {
        rigid.with_motion(
            rigid.velocity() + self.velocity * k,
            rigid.angular_momentum() + self.momentum * k,
        )
    }
}

/// The arm `R o` of a member and its velocity `v + ω × R o` on `rigid`.
#[inline]
pub(crate) fn member_motion<T: Real, const D: usize>(
    rigid: &RigidCluster<T, D>,
    offset: &Vector<T, D>,
) -> (Vector<T, D>, Vector<T, D>, Angular<T, D>)
where
    Const<D>: Space<T, D>,
{
    let arm = rigid.orientation() * offset;
    let w = rigid.angular_velocity();
    (
        arm,
        rigid.velocity() + <Const<D> as Space<T, D>>::angular_cross(&w, &arm),
        w,
    )
}

/// What carries the clusters through the current step: the stepper, the signed linear
/// drag coefficient of its field (negative backward: see `forces`), the step's length
/// `h` and the internal time `t0` it started at.
pub(crate) struct Flight<'a, T: Real, const D: usize, F> {
    pub(crate) stepper: &'a Stepper<T, D, F>,
    pub(crate) drag: T,
    pub(crate) h: T,
    pub(crate) t0: T,
}

impl<'a, T: Real, const D: usize, F: ForceField<T, D>> Flight<'a, T, D, F>
where
    Const<D>: Space<T, D>,
{
    /// The step of length `h` from internal time `t0` under `stepper`.
    pub(crate) fn new(stepper: &'a Stepper<T, D, F>, h: T, t0: T) -> Self {
        let drag = (stepper.field().closed_form()).map_or_else(T::zero, |c| c.linear_drag);
        Self {
            stepper,
            drag,
            h,
            t0,
        }
    }

    /// What a constant force from in-step time `s` to the step's end adds to a body's end
    /// velocity per what it adds to its chord, for a body whose drag rate is the drag
    /// coefficient times `drag_share` (`1/m` for a ball, `k/M` for a cluster of `k`
    /// members): `1/w` without drag (`Integrator::end_per_chord`). `None` with explicit
    /// Euler, whose chords no force within the step moves.
    pub(crate) fn end_per_chord(&self, drag_share: T, s: T) -> Option<T> {
        let decay = self.drag * drag_share * (self.h - s);
        (self.stepper.integrator())
            .end_per_chord(decay.to_f64())
            .map(T::lit)
    }
}

/// The rigid body `rigid` (members at `offsets`) advanced by `tau` from in-step time `s`
/// of `flight` under its field and drag, held by the constant force whose push is `push`
/// (see the module documentation).
///
/// The push moves the pose exactly as the hold's problem counts it, `Δv τ` on the centre
/// and `ΔL` on the angular momentum, whatever the drag: the field and the drag act on the
/// free motion `rigid` alone. This is how a held ball's chord takes its push too
/// (`P/m`, `stack`). Advancing the pushed motion `rigid + push` under drag instead decays
/// the push with the free motion, by `φ₁(−kτ) = (1 − e^{−kτ})/(kτ)` with the exact
/// integrator. Measured in a fuzzed scene: a cluster of three balls (9.58 kg) spinning
/// at 1,733 rad/s, held over sub-steps of 6.2e-6 s with `kτ` = 2.4e-7, took 150 m/s
/// pushes 1.8e-5 m/s short, and its member kept closing on the wall it pressed on
/// (1.76e-4 m/s before and after each hold), 16,384 times: a crush error. Without drag
/// both are the same, every integrator being linear in the start velocity.
pub(crate) fn advance<T: Real, const D: usize, F: ForceField<T, D>>(
    rigid: &RigidCluster<T, D>,
    push: &Motion<T, D>,
    offsets: &[Vector<T, D>],
    flight: &Flight<'_, T, D, F>,
    s: T,
    tau: T,
) -> RigidCluster<T, D>
where
    Const<D>: Space<T, D>,
{
    let drive = push.added(rigid, T::one());
    let drag = flight.drag;
    let Ok(dt) = TimeStep::new(tau) else {
        return drive;
    };
    let mass = rigid.mass();
    let (mut c, mut v) = (rigid.center(), rigid.velocity());
    let mut unused_spin = <Const<D> as Space<T, D>>::angular_zero();
    let drag_share = T::from_count(offsets.len()) / mass;
    (flight.stepper).step_ball(
        &mut c,
        &mut v,
        &mut unused_spin,
        drag_share,
        flight.t0 + s,
        dt,
    );
    c += push.velocity * tau;
    v += push.velocity;
    let r0 = rigid.orientation();
    let l0 = drive.angular_momentum();
    let w0 = drive.angular_velocity();
    let mut l1 = l0;
    if drag != T::zero() {
        let free_w = rigid.angular_velocity();
        let mut j = <Const<D> as Space<T, D>>::inertia_isotropic(T::zero());
        let mut a = Vector::<T, D>::zeros();
        for o in offsets {
            let arm = r0 * o;
            j = j + <Const<D> as Space<T, D>>::inertia_parallel_axis(T::one(), &arm);
            a += arm;
        }
        let torque = <Const<D> as Space<T, D>>::inertia_apply(&j, &free_w)
            + <Const<D> as Space<T, D>>::cross(&a, &rigid.velocity());
        l1 = l0 - torque * (drag * tau);
        v -= <Const<D> as Space<T, D>>::angular_cross(&free_w, &a) * (drag * tau / mass);
    }
    // Explicit midpoint on SO(D): ω at the half-step orientation and half-step momentum.
    let half = T::lit(0.5);
    let r_half = <Const<D> as Space<T, D>>::rotation_from_angular(&w0, tau * half) * r0;
    let w_half = rigid
        .with_pose(rigid.center(), r_half)
        .with_motion(rigid.velocity(), (l0 + l1) * half)
        .angular_velocity();
    let r1 = <Const<D> as Space<T, D>>::rotation_from_angular(&w_half, tau) * r0;
    rigid.with_pose(c, r1).with_motion(v, l1)
}

impl<T: Real, const D: usize> StuckCluster<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The motion the pose follows over the segment: the start's plus the push.
    pub(crate) fn drive(&self) -> RigidCluster<T, D> {
        self.push.added(&self.start, T::one())
    }

    /// The rigid state at in-step time `s >= seg_t` of `flight`: the orientation advanced along the drive, the centre of
    /// mass on the chord between the segment's ends, the motion interpolated linearly
    /// between the start's and the end's (see the module documentation); and the drive's
    /// motion there less that motion (the push of the rest of the segment).
    ///
    /// The centre is where the members' chords put it (the mass-weighted mean of their
    /// positions on their chords), as a ball restarts on its chord (`BallArrays::restart`):
    /// the integrator's own sub-step from the segment start lies off the chord (by up to
    /// `|g| τ²/8` under gravity, τ the segment's length: 3.4e-4 m at `h = 1/60 s`), and a
    /// cluster restarted there at a contact jumped by that much, away from a support it
    /// rests on (hovering, then falling onto it again every step) or into it.
    fn state_at<F: ForceField<T, D>>(
        &self,
        s: T,
        flight: &Flight<'_, T, D, F>,
    ) -> (RigidCluster<T, D>, Motion<T, D>) {
        if s <= self.seg_t {
            return (self.start, self.push);
        }
        let drive = advance(
            &self.start,
            &self.push,
            &self.offsets,
            flight,
            self.seg_t,
            s - self.seg_t,
        );
        let span = flight.h - self.seg_t;
        if span <= T::zero() {
            return (drive, Motion::zero());
        }
        let f = ((s - self.seg_t) / span).min(T::one());
        let (a, b) = (&self.start, &self.end);
        let rigid = drive
            .with_pose(
                a.center() + (b.center() - a.center()) * f,
                drive.orientation(),
            )
            .with_motion(
                a.velocity() + (b.velocity() - a.velocity()) * f,
                a.angular_momentum() + (b.angular_momentum() - a.angular_momentum()) * f,
            );
        let push = Motion {
            velocity: drive.velocity() - rigid.velocity(),
            momentum: drive.angular_momentum() - rigid.angular_momentum(),
        };
        (rigid, push)
    }

    /// The rigid state at in-step time `s` (see [`Self::state_at`]).
    pub(crate) fn at<F: ForceField<T, D>>(
        &self,
        s: T,
        flight: &Flight<'_, T, D, F>,
    ) -> RigidCluster<T, D> {
        self.state_at(s, flight).0
    }

    /// Restarts the segment at `s` on the same motion: it starts from the state there,
    /// the push is what the drive has beyond it, the end is unchanged; the members
    /// restart on their chords. Returns the state at `s`.
    pub(crate) fn restart_at<F: ForceField<T, D>>(
        &mut self,
        balls: &mut BallArrays<T, D>,
        s: T,
        flight: &Flight<'_, T, D, F>,
    ) -> RigidCluster<T, D> {
        let (rigid, push) = self.state_at(s, flight);
        self.restart_members(balls, &rigid, s, flight.h);
        self.start = rigid;
        self.push = push;
        self.seg_t = s;
        rigid
    }

    /// Starts a new segment at `s` from the rigid state `rigid` (the state at `s`,
    /// possibly after an impulse): the members restart where their chords are at `s`,
    /// moving at their rigid velocities, and the cluster and its members are integrated
    /// to the end of the step.
    pub(crate) fn restart_from<F: ForceField<T, D>>(
        &mut self,
        balls: &mut BallArrays<T, D>,
        rigid: RigidCluster<T, D>,
        s: T,
        flight: &Flight<'_, T, D, F>,
    ) {
        self.restart_members(balls, &rigid, s, flight.h);
        self.start = rigid;
        self.seg_t = s;
        self.hold(balls, Motion::zero(), flight);
    }

    /// Holds the segment with the constant force whose push is `push` (see the module
    /// documentation): the pose follows the drive to the end of the step, whose motion
    /// has the push `1/w` times (`w` the integrator's chord weight, `w > 0` for a push);
    /// the members' chords follow.
    pub(crate) fn hold<F: ForceField<T, D>>(
        &mut self,
        balls: &mut BallArrays<T, D>,
        push: Motion<T, D>,
        flight: &Flight<'_, T, D, F>,
    ) {
        self.push = push;
        let (s, h) = (self.seg_t, flight.h);
        let end = advance(&self.start, &push, &self.offsets, flight, s, h - s);
        self.end = if push == Motion::zero() {
            end
        } else {
            // The drive's end has the push once; the force's end has it `end_per_chord`
            // times in the velocity (drag counted) and `1/w` times in the angular momentum
            // (the drag torque is first order, and zero on a body at rest).
            let drag_share = T::from_count(self.offsets.len()) / self.start.mass();
            let per_chord = |share| flight.end_per_chord(share, s).unwrap_or_else(T::one);
            Motion {
                velocity: push.velocity * (per_chord(drag_share) - T::one()),
                momentum: push.momentum * (per_chord(T::zero()) - T::one()),
            }
            .added(&end, T::one())
        };
        self.set_member_ends(balls, h);
    }

    /// Restarts every member's segment at `s` where its chord is, moving at its velocity
    /// on `rigid` (the cluster's state at `s`); the ends are unchanged.
    pub(crate) fn restart_members(
        &self,
        balls: &mut BallArrays<T, D>,
        rigid: &RigidCluster<T, D>,
        s: T,
        h: T,
    ) {
        for (&m, o) in self.members.iter().zip(&self.offsets) {
            let m = m as usize;
            balls.restart(m, s, h);
            let (_, v, w) = member_motion(rigid, o);
            balls.seg_v[m] = v;
            balls.seg_w[m] = w;
        }
    }

    /// Sets every member's segment end to its rigid place at the end of the step.
    pub(crate) fn set_member_ends(&self, balls: &mut BallArrays<T, D>, h: T) {
        for (&m, o) in self.members.iter().zip(&self.offsets) {
            let (arm, v, w) = member_motion(&self.end, o);
            balls.set_end(
                m as usize,
                h,
                SegmentEnd::Place(self.end.center() + arm),
                v,
                w,
            );
        }
    }
}

impl<T: Real, const D: usize> Clusters<T, D>
where
    Const<D>: Space<T, D>,
{
    /// No clusters yet, for a run in a periodic border whose smallest side is `period`.
    pub(crate) fn new(period: Option<T>) -> Self {
        Self {
            list: Vec::new(),
            period,
        }
    }

    /// Refuses a cluster that spans half the smallest period or more: its members could
    /// then meet their own periodic images and the minimum image of a partner would be
    /// ambiguous, neither of which the engine models, so the run stops with an error
    /// naming the border instead of going on silently wrong. `span` is twice the largest
    /// distance from the centre of mass to a member's surface.
    pub(crate) fn check_span(&self, members: usize, span: T) -> Result<(), String> {
        match self.period {
            Some(period) if span + span >= period => Err(format!(
                "world.border: a stuck cluster of {members} balls spans {:e}, at least half the periodic box's smallest side {:e}; its members would meet their own images, which the stepped engine does not model (make the box larger or the run shorter)",
                span.to_f64(),
                period.to_f64()
            )),
            _ => Ok(()),
        }
    }

    /// Integrates every cluster over the whole step of `flight` and sets its members'
    /// segments (after the balls' own integration, which it overrides).
    pub(crate) fn integrate<F: ForceField<T, D>>(
        &mut self,
        balls: &mut BallArrays<T, D>,
        flight: &Flight<'_, T, D, F>,
    ) {
        for cluster in &mut self.list {
            let rigid = cluster.end;
            cluster.start = rigid;
            cluster.seg_t = T::zero();
            cluster.push = Motion::zero();
            cluster.end = advance(
                &rigid,
                &Motion::zero(),
                &cluster.offsets,
                flight,
                T::zero(),
                flight.h,
            );
            cluster.set_member_ends(balls, flight.h);
        }
    }

    /// Stops every cluster at in-step time `s` for the rest of the step (velocity and
    /// angular momentum kept), as the event budget does to every ball.
    pub(crate) fn freeze<F: ForceField<T, D>>(&mut self, s: T, flight: &Flight<'_, T, D, F>) {
        for cluster in &mut self.list {
            let rigid = cluster.at(s, flight);
            cluster.start = rigid;
            cluster.push = Motion::zero();
            cluster.seg_t = s;
            cluster.end = rigid;
        }
    }

    /// Moves every cluster whose centre of mass at in-step time `s` left the periodic
    /// cell `border` by the period(s) that bring it back, members included.
    pub(crate) fn wrap<F: ForceField<T, D>>(
        &mut self,
        balls: &mut BallArrays<T, D>,
        border: &Border<T, D>,
        s: T,
        flight: &Flight<'_, T, D, F>,
    ) {
        for cluster in &mut self.list {
            let c = cluster.at(s, flight).center();
            let shift = border.wrap(&c) - c;
            if shift == Vector::<T, D>::zeros() {
                continue;
            }
            let rigid = cluster.restart_at(balls, s, flight);
            for &m in &cluster.members {
                balls.seg_x[m as usize] += shift;
                balls.pos[m as usize] += shift;
            }
            cluster.start = rigid.with_pose(c + shift, rigid.orientation());
            let end = &cluster.end;
            cluster.end = end.with_pose(end.center() + shift, end.orientation());
        }
    }

    /// The cluster of member `i`, if any.
    #[inline]
    pub(crate) fn of(balls: &BallArrays<T, D>, i: usize) -> Option<usize> {
        match balls.cluster[i] {
            FREE => None,
            c => Some(c as usize),
        }
    }
}
