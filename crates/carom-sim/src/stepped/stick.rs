//! Contacts that involve stuck clusters: fusion, rigid-body impulses at a member's contact
//! point, and the resting correction of a cluster's chords.
//!
//! At a contact at in-step time `s` of a member ball of cluster `C` (see `clusters`):
//!
//! 1. The cluster's segment restarts at `s`: its rigid state there ([`StuckCluster::at`]),
//!    its members where their chords are, moving at their rigid velocities.
//! 2. **Stick.** Two balls whose pair restitution is 0 under `inelastic = "stick"` (free
//!    or members of different clusters) fuse: carom-response's [`RigidCluster::fuse`]
//!    keeps linear and angular momentum, with each ball's own inertia plus parallel axes.
//!    The fused cluster's body frame is the world frame at `s`.
//! 3. **Collision.** Otherwise the contact is a rigid-body impulse ([`resolve`]) between
//!    the cluster (inverse mass `1/M`, world inverse inertia `R I_body⁻¹ Rᵀ`, contact
//!    offset from its centre of mass) and the other side (a ball, another cluster, a wall
//!    or a box), with the same guards as a ball's contact (`response`): the collapse
//!    guard between bodies, the resting guard against surfaces, and approaches no faster
//!    than gravity adds in a step are support, not collisions. The impulse `P` at offset
//!    `r` changes `v += P/M`, `L += r × P`, and the cluster's remaining step is
//!    integrated again; its members' chords follow.
//! 4. **Resting correction.** If the member's chord still closes on the other side (gravity
//!    pulls a cluster back into the floor within the rest of the step), a restitution-0
//!    impulse with friction is computed on the chord velocities (the member's chord as
//!    the velocity of its centre, the cluster's angular velocity) and applied as a
//!    physical impulse at `s`, and the step integrated again. With the engine's default
//!    integrator (semi-implicit Euler) the chord then stops closing to first order in
//!    the rotation it adds; what is left (second order) is found again as a contact and
//!    corrected, converging geometrically, as do several members resting at once (a flat
//!    cluster on the floor: each correction at one member changes the other's approach by
//!    a factor below one).
//! 5. **Stacks** (under gravity). A cluster held on its surfaces in the step (its
//!    members count as held, as a ball on the floor does in `response`) takes a free
//!    ball resting on it without the collapse guard's elastic impulse (which juggled the
//!    ball, gaining energy): the ball's load and the cluster's surfaces are solved
//!    together ([`Contacts::load_cluster`]), so that the surfaces carry the load, or the
//!    cluster tips if its supports cannot. A member resting on a held free ball is held
//!    by it as by an immovable surface moving at its chord (shock propagation, as for a
//!    ball on a ball), with every held ball under the cluster's members at once.

use carom_integrate::ForceField;
use carom_math::{Real, Space, Vector};
use carom_response::{Body, Contact, Response, RigidCluster};
use nalgebra::Const;

use super::balls::BallArrays;
use super::clusters::{Clusters, FREE, StuckCluster};
use super::response::{Contacts, Effect, Surface};
use super::rest::Support;
use crate::engine::Angular;

/// A member near a surface: `(member, unit normal into the surface, surface velocity,
/// gap)`.
type Touching<T, const D: usize> = (usize, Vector<T, D>, Vector<T, D>, T);

/// An orthonormal basis of the span of unit `normals` (Gram–Schmidt; nearly dependent
/// ones dropped).
fn span<T: Real, const D: usize>(normals: impl Iterator<Item = Vector<T, D>>) -> Vec<Vector<T, D>> {
    let mut basis: Vec<Vector<T, D>> = Vec::with_capacity(D);
    for n in normals {
        let e = basis.iter().fold(n, |e, b| e - b * b.dot(&e));
        let length = e.norm();
        if length > T::lit(1e-6) && basis.len() < D {
            basis.push(e / length);
        }
    }
    basis
}

/// Which side of a ball–cluster contact rests on the other (see `Contacts::resting`).
#[derive(Clone, Copy, Debug)]
enum Resting<T: Real, const D: usize> {
    /// Free ball `ball` on `member` of a held cluster.
    BallOnCluster { ball: usize, member: usize },
    /// `member` of cluster `c` on a held free ball, along `normal` (from the member into
    /// the ball).
    ClusterOnBall {
        c: usize,
        member: usize,
        normal: Vector<T, D>,
    },
}

/// A surface holding a cluster: `(member, unit normal from the ball into the surface,
/// surface velocity)`.
type Held<T, const D: usize> = (usize, Vector<T, D>, Vector<T, D>);

/// A free ball resting on members of a cluster: the ball, and for each member
/// `(member, unit normal from the ball into it, gap)` (see `Contacts::load_cluster`).
struct Load<T: Real, const D: usize> {
    ball: usize,
    under: Vec<(usize, Vector<T, D>, T)>,
}

/// The change of a rigid body's velocities during a projected Gauss–Seidel solve.
struct Delta<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    inverse_mass: T,
    inverse_inertia: <Const<D> as Space<T, D>>::Inertia,
    /// Of the centre of mass.
    dv: Vector<T, D>,
    dw: Angular<T, D>,
}

impl<T: Real, const D: usize> Delta<T, D>
where
    Const<D>: Space<T, D>,
{
    fn new(rigid: &RigidCluster<T, D>) -> Self {
        Self {
            inverse_mass: T::one() / rigid.mass(),
            inverse_inertia: rigid.world_inverse_inertia(),
            dv: Vector::zeros(),
            dw: <Const<D> as Space<T, D>>::angular_zero(),
        }
    }

    /// Applies the impulse `p` at arm `a` (from the centre of mass).
    fn push(&mut self, p: &Vector<T, D>, a: &Vector<T, D>) {
        self.dv += p * self.inverse_mass;
        self.dw += <Const<D> as Space<T, D>>::inertia_apply(
            &self.inverse_inertia,
            &<Const<D> as Space<T, D>>::cross(a, p),
        );
    }

    /// The change of the velocity of the point at arm `a`.
    fn at(&self, a: &Vector<T, D>) -> Vector<T, D> {
        self.dv + <Const<D> as Space<T, D>>::angular_cross(&self.dw, a)
    }

    /// Friction at arm `a` (normal `n`, relative velocity `u`): the accumulated
    /// tangential impulse `total` stops the slip, within the cone `|F_t| <= bound`; returns
    /// the velocity change it made.
    fn friction(
        &mut self,
        total: &mut Vector<T, D>,
        u: &Vector<T, D>,
        n: &Vector<T, D>,
        a: &Vector<T, D>,
        bound: T,
    ) -> T {
        let slip = u - n * u.dot(n);
        let speed = slip.norm();
        if speed <= T::zero() {
            return T::zero();
        }
        let t = slip / speed;
        let wanted = *total - t * (speed / self.stiffness(a, &t));
        let clamped = if wanted.norm() > bound {
            wanted * (bound / wanted.norm())
        } else {
            wanted
        };
        let change = clamped - *total;
        *total = clamped;
        self.push(&change, a);
        change.norm() * self.stiffness(a, &t)
    }

    /// The inverse effective mass at arm `a` along unit `d`.
    fn stiffness(&self, a: &Vector<T, D>, d: &Vector<T, D>) -> T {
        let ad = <Const<D> as Space<T, D>>::cross(a, d);
        self.inverse_mass
            + <Const<D> as Space<T, D>>::angular_dot(
                &ad,
                &<Const<D> as Space<T, D>>::inertia_apply(&self.inverse_inertia, &ad),
            )
    }
}

/// One side of a contact: a free ball or a cluster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Ball(usize),
    Cluster(usize),
}

impl<T: Real, const D: usize, F: ForceField<T, D>> Contacts<'_, T, D, F>
where
    Const<D>: Space<T, D>,
{
    fn side(&self, i: usize) -> Side {
        Clusters::of(self.balls, i).map_or(Side::Ball(i), Side::Cluster)
    }

    /// Restarts cluster `c`'s segment at `s` (members on their chords, at their rigid
    /// velocities; the end of the step unchanged) and returns its rigid state there.
    fn begin_cluster(&mut self, c: usize, s: T) -> RigidCluster<T, D> {
        let drag = self.clusters.drag;
        let cluster = &mut self.clusters.list[c];
        let rigid = cluster.at(s, self.h, self.stepper, drag, self.t0);
        cluster.restart_members(self.balls, &rigid, s, self.h);
        cluster.start = rigid;
        cluster.seg_t = s;
        rigid
    }

    /// Cluster `c` continues from `rigid` at its segment start: the rest of the step is
    /// integrated again and the members' chords follow.
    fn finish_cluster(&mut self, c: usize, rigid: RigidCluster<T, D>) {
        let drag = self.clusters.drag;
        let cluster = &mut self.clusters.list[c];
        let s = cluster.seg_t;
        cluster.restart_from(self.balls, rigid, s, self.h, self.stepper, drag, self.t0);
        for &m in &cluster.members {
            self.balls.supported[m as usize] = false;
        }
    }

    /// Restarts `side` at `s`: its collision body and centre of mass there.
    fn begin(&mut self, side: Side, s: T) -> (Body<T, D>, Vector<T, D>) {
        match side {
            Side::Ball(i) => {
                self.balls.restart(i, s, self.h);
                let b = &*self.balls;
                (self.body(i, b.seg_v[i], b.seg_w[i]), b.seg_x[i])
            }
            Side::Cluster(c) => {
                let rigid = self.begin_cluster(c, s);
                (rigid.body(), rigid.center())
            }
        }
    }

    /// The body `side` presents to a resting correction: member `i`'s chord as the
    /// velocity of its centre, with the angular velocity at the segment start.
    fn chord_body(&self, side: Side, i: usize) -> Body<T, D> {
        let b = &*self.balls;
        match side {
            Side::Ball(_) => self.body(i, b.chord[i], b.seg_w[i]),
            Side::Cluster(c) => {
                let rigid = &self.clusters.list[c].start;
                let w = rigid.angular_velocity();
                let arm = b.seg_x[i] - rigid.center();
                let body = rigid.body();
                body.with_velocities(
                    b.chord[i] - <Const<D> as Space<T, D>>::angular_cross(&w, &arm),
                    w,
                )
            }
        }
    }

    /// Applies body `k` (0 or 1) of `response` to `side`, which presented `body` at its
    /// segment start `s`, and integrates its rest of the step again.
    fn apply(
        &mut self,
        side: Side,
        k: usize,
        body: &Body<T, D>,
        response: &Response<T, D>,
        contact: &Contact<T, D>,
        s: T,
    ) {
        match side {
            Side::Ball(i) => {
                let dv = response.velocity[k] - body.velocity();
                let dw = response.angular_velocity[k] - body.angular_velocity();
                let (v, w) = (self.balls.seg_v[i] + dv, self.balls.seg_w[i] + dw);
                self.collide(i, s, v, w);
            }
            Side::Cluster(c) => {
                let (impulse, offset) = if k == 0 {
                    (-response.impulse, contact.offset_a())
                } else {
                    (response.impulse, contact.offset_b())
                };
                let rigid = self.clusters.list[c].start.with_impulse(&impulse, &offset);
                self.finish_cluster(c, rigid);
            }
        }
    }

    /// Two balls `i`, `j` (j's position shifted by `shift`) touching at `s`, at least one
    /// of them in a cluster or the pair sticking.
    ///
    /// # Errors
    /// A message if a fusion overflows the precision.
    pub(crate) fn stuck_pair(
        &mut self,
        i: usize,
        j: usize,
        shift: &Vector<T, D>,
        s: T,
        fallback_normal: &Vector<T, D>,
    ) -> Result<Effect, String> {
        let (a, b) = (self.side(i), self.side(j));
        let (body_a, centre_a) = self.begin(a, s);
        let (body_b, centre_b) = self.begin(b, s);
        let balls = &*self.balls;
        let (xi, xj) = (balls.seg_x[i], balls.seg_x[j] + shift);
        let offset = xj - xi;
        let length = offset.norm();
        let n = if length > T::zero() && length.finite() {
            offset / length
        } else {
            *fallback_normal
        };
        let nominal = balls.restitution[i].min(balls.restitution[j]);
        if self.rules.stick && nominal == T::zero() {
            self.fuse(a, b, shift, s)?;
            return Ok(Effect { collided: true });
        }
        let Ok(contact) = Contact::new(
            n,
            xi + n * balls.radius[i] - centre_a,
            xj - n * balls.radius[j] - (centre_b + shift),
        ) else {
            return Ok(Effect::default());
        };
        let (approach, r) = self.pair_collision(&body_a, &body_b, &contact, nominal);
        let slow = approach <= self.rules.support_speed;
        // A slow contact onto a held side is resting: no impulse (the collapse guard's
        // elastic one would juggle a ball on a resting cluster, gaining energy), only the
        // correction below.
        let onto_support = slow && self.resting(a, i, b, j, &n).is_some();
        let effect = Effect {
            collided: r.applied() && !slow,
        };
        if r.applied() && !onto_support {
            self.apply(a, 0, &body_a, &r, &contact, s);
            self.apply(b, 1, &body_b, &r, &contact, s);
        }
        let balls = &*self.balls;
        if (balls.chord[j] - balls.chord[i]).dot(&n) < T::zero() && s < self.h {
            match self.resting(a, i, b, j, &n) {
                Some(Resting::ClusterOnBall { c, member, normal }) => {
                    let ball = if member == i { j } else { i };
                    let support = (member, normal, self.balls.chord[ball], T::zero());
                    self.rest_cluster(c, Some(support), None);
                }
                Some(Resting::BallOnCluster { ball, member }) => {
                    // The cluster's members moved to the ball's periodic image.
                    let (normal, shift) = if ball == i { (n, *shift) } else { (-n, -shift) };
                    self.load_cluster(ball, member, &normal, &shift, s);
                }
                None => {
                    // Two free bodies closing along their chords: a perfectly inelastic
                    // correction.
                    let (ca, cb) = (self.chord_body(a, i), self.chord_body(b, j));
                    let r = self.stop_closing(&ca, &cb, &contact);
                    if r.applied() {
                        self.apply(a, 0, &ca, &r, &contact, s);
                        self.apply(b, 1, &cb, &r, &contact, s);
                    }
                }
            }
        }
        Ok(effect)
    }

    /// Whether one side of the contact of balls `i` (side `a`) and `j` (side `b`), along
    /// `n` from `i` to `j`, rests on the other: a free ball on a member of a held cluster
    /// (one that rests on surfaces in this step), or a member of a cluster on a free ball
    /// that is held in turn and does not move up into it; the lower one lies below along
    /// gravity.
    fn resting(
        &self,
        a: Side,
        i: usize,
        b: Side,
        j: usize,
        n: &Vector<T, D>,
    ) -> Option<Resting<T, D>> {
        let balls = &*self.balls;
        let floor = self.rules.floor;
        let down = self.rules.gravity.dot(n);
        // (upper, lower, normal from the upper into the lower) for each orientation.
        let (upper, lower, normal) = if down > T::zero() {
            ((a, i), (b, j), *n)
        } else if down < T::zero() {
            ((b, j), (a, i), -n)
        } else {
            return None;
        };
        let (lower_side, low) = lower;
        if !balls.supported[low] {
            return None;
        }
        match (upper, lower_side) {
            // The cluster takes the ball's load and carries it (`load_cluster`), also when
            // it slides or turns into it.
            ((Side::Ball(ball), _), Side::Cluster(_)) => {
                Some(Resting::BallOnCluster { ball, member: low })
            }
            // The ball holds the cluster as an immovable support: not if it moves into it.
            ((Side::Cluster(c), member), Side::Ball(_))
                if balls.chord[low].dot(&normal) >= -floor =>
            {
                Some(Resting::ClusterOnBall { c, member, normal })
            }
            _ => None,
        }
    }

    /// Free ball `q` resting on `member` of a held cluster along `n` (unit, from the ball
    /// into the member), both segments started at `s`, the cluster's members moved by
    /// `shift` to the ball's periodic image: the ball's load goes into the cluster, which
    /// its surfaces hold, so that a ball beyond the cluster's supports tips it; then the
    /// ball is held on what holds it.
    ///
    /// The ball rests on every member of that cluster below it that it touches or would
    /// reach along the chords within the step (a ball in the hollow between two members
    /// rests on both at once; one at a time, each tilted contact would push the cluster
    /// sideways and the ball would rock in the hollow). Those contacts and the cluster's
    /// surfaces are solved together ([`Self::rest_cluster`] with the load: projected
    /// Gauss–Seidel with accumulated normal impulses, so that an impulse that overshot is
    /// taken back), restitution 0, the ball's gap `g` closing at `g/τ` (speculative). What
    /// the sweeps leave (a ball far heavier than the cluster converges slowly) is removed
    /// by holding the ball on the members as on immovable supports, all at once with
    /// whatever else it touches (see `rest`), as a ball on a held ball is in `response`.
    /// The impulses between the ball and the cluster are normal: friction between them
    /// acts in that last hold only. No part adds energy.
    fn load_cluster(
        &mut self,
        q: usize,
        member: usize,
        n: &Vector<T, D>,
        shift: &Vector<T, D>,
        s: T,
    ) {
        const SOLVES: usize = 8;
        let Some(c) = Clusters::of(self.balls, member) else {
            return;
        };
        let h = self.h;
        let rest = h - s;
        let under = self.members_under(q, c, member, n, shift, rest);
        // How fast the ball closes on member m beyond its gap.
        let excess = |b: &BallArrays<T, D>, &(m, n, gap): &(usize, Vector<T, D>, T)| {
            (b.chord[q] - b.chord[m]).dot(&n) - gap / rest
        };
        // The sweeps see the members' chords to first order in the rotation the impulses
        // add; integrated again, the cluster turns a little more or less (second order),
        // so the solve is repeated on what is left while that shrinks.
        let largest = |b: &BallArrays<T, D>, under: &[(usize, Vector<T, D>, T)]| {
            under.iter().map(|t| excess(b, t)).fold(T::zero(), T::max)
        };
        let load = Load { ball: q, under };
        let done = T::lit(4.0) * T::EPSILON * largest(self.balls, &load.under);
        let mut held = Vec::new();
        for _ in 0..SOLVES {
            held = self.rest_cluster(c, None, Some(&load));
            if largest(self.balls, &load.under) <= done {
                break;
            }
        }
        let under = load.under;
        // Below `floor` a closing is no event: held now, or the ball would sink into the
        // cluster at that speed step after step.
        let before = self.balls.vel[q];
        if under.iter().any(|t| excess(self.balls, t) > T::zero()) {
            self.hold_on_members(q, c, &under, s);
        } else {
            self.rest.restart(q, s, self.balls.chord[q]);
        }
        self.end_on_members(q, c, &under, before, held);
    }

    /// The members of cluster `c` that ball `q` rests on, `member` (along `n`, from the
    /// ball into it) first: every member below it that it touches or would reach along
    /// the chords within the `rest` of the step, as `(member, unit normal from the ball
    /// into it, gap)`; the members moved by `shift` to the ball's periodic image.
    fn members_under(
        &self,
        q: usize,
        c: usize,
        member: usize,
        n: &Vector<T, D>,
        shift: &Vector<T, D>,
        rest: T,
    ) -> Vec<(usize, Vector<T, D>, T)> {
        let mut under = vec![(member, *n, T::zero())];
        let b = &*self.balls;
        let (x, r) = (b.seg_x[q], b.radius[q]);
        let tolerance = T::lit(1e-9) * r + T::lit(16.0) * T::EPSILON * (x.amax() + r);
        for &m in &self.clusters.list[c].members {
            let m = m as usize;
            let offset = b.seg_x[m] + shift - x;
            let d = offset.norm();
            if m == member || d <= T::zero() {
                continue;
            }
            let (n, gap) = (offset / d, d - r - b.radius[m]);
            let closing = (b.chord[q] - b.chord[m]).dot(&n) * rest;
            if self.rules.gravity.dot(&n) > T::zero() && (gap <= tolerance || closing > gap) {
                under.push((m, n, gap.max(T::zero())));
            }
        }
        under
    }

    /// Holds ball `q` at `s` on the members `under` of cluster `c` as on immovable
    /// supports, at their chords now, all at once with whatever else holds it (see
    /// `rest`): the projection of its chord, frictionless.
    fn hold_on_members(&mut self, q: usize, c: usize, under: &[(usize, Vector<T, D>, T)], s: T) {
        let h = self.h;
        let rest = h - s;
        let b = &*self.balls;
        let chord = b.chord[q];
        let set = self.rest.at(q, s, h * T::lit(1e-6), chord, true);
        for &(m, n, gap) in under {
            let speed = b.chord[m].dot(&n) + gap / rest;
            set.add(Support::Ball(m as u32), -n, -speed);
        }
        for (ball, touches) in self.touching {
            for t in touches.iter().filter(|_| ball == q) {
                let member = matches!(t.support, Support::Ball(j)
                    if Clusters::of(b, j as usize) == Some(c));
                if !member {
                    set.add(t.support, -t.normal, -t.velocity.dot(&t.normal));
                }
            }
        }
        if let Some(u) = set.project() {
            let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
            self.balls.nudge(q, h, &(u - chord), &zero_spin);
        }
    }

    /// Ball `q`, held on the members `under` of cluster `c` (which its surfaces `held`
    /// hold), ends the step as held (its end velocity was `before` the last hold).
    fn end_on_members(
        &mut self,
        q: usize,
        c: usize,
        under: &[(usize, Vector<T, D>, T)],
        before: Vector<T, D>,
        mut held: Vec<Held<T, D>>,
    ) {
        let h = self.h;
        // The ball ends the step moving along the members' normals as its chord does
        // (`BallArrays::shift_chord`: with Verlet, RK4 or the exact integrator its end
        // velocity keeps half a step of gravity otherwise). The cluster's end velocity
        // takes the momentum of that and of the hold above (their parts along the
        // members' normals), less what its surfaces take ([`Self::hold_end_velocity`]):
        // the rest (sideways, off a tilted contact) moves it from the next step on.
        // Taken at the centre of mass, without its torque: an end-of-step torque that the
        // surfaces do not see set a resting cluster rocking (tried); so with those
        // integrators a ball passes half its load's torque to the cluster it tips (see
        // `docs/stepped.md`). Neither chord changes: the momentum of the velocities and
        // that of the motion are both kept.
        let basis = span(under.iter().map(|t| t.1));
        let saved = (
            self.balls.seg_v[q],
            self.balls.vel[q],
            self.clusters.list[c].end,
            self.clusters.list[c].kick,
        );
        let energy = |this: &Self| {
            let b = &*this.balls;
            let end = &this.clusters.list[c].end;
            let spin = <Const<D> as Space<T, D>>::angular_dot(
                &end.angular_momentum(),
                &end.angular_velocity(),
            );
            (b.mass[q] * b.vel[q].norm_squared()
                + end.mass() * end.velocity().norm_squared()
                + spin)
                * T::lit(0.5)
        };
        let energy_before = energy(self);
        let b = &mut *self.balls;
        for v in [&mut b.seg_v[q], &mut b.vel[q]] {
            let off = *v - b.chord[q];
            *v -= basis
                .iter()
                .fold(Vector::<T, D>::zeros(), |sum, e| sum + e * e.dot(&off));
        }
        b.supported[q] = true;
        let change = (b.vel[q] - before) * b.mass[q];
        let reaction = -basis
            .iter()
            .fold(Vector::<T, D>::zeros(), |sum, e| sum + e * e.dot(&change));
        if reaction != Vector::<T, D>::zeros() {
            if held.is_empty() {
                held = self.rest_cluster(c, None, None);
            }
            let cluster = &mut self.clusters.list[c];
            let end = cluster.end;
            let kicked = end.velocity() + reaction / end.mass();
            cluster.end = end.with_motion(kicked, end.angular_momentum());
            self.hold_end_velocity(c, &held);
            // What the surfaces took is theirs: the cluster keeps the rest if its step is
            // integrated again.
            let cluster = &mut self.clusters.list[c];
            cluster.kick += reaction - (kicked - cluster.end.velocity()) * end.mass();
        }
        // A bookkeeping of the step's end, not an impulse between the two: undone if the
        // cluster moves along the reaction fast enough for the pair to gain energy (while
        // it bounces; resting, it never does), the ball carrying the rest of its step's
        // gravity into the next step instead.
        if energy(self) > energy_before {
            let (seg_v, vel, end, kick) = saved;
            self.balls.seg_v[q] = seg_v;
            self.balls.vel[q] = vel;
            let cluster = &mut self.clusters.list[c];
            cluster.end = end;
            cluster.kick = kick;
            cluster.set_member_ends(self.balls, h);
        }
        // Held again on its surfaces if it still closes on them at all, however slowly:
        // below the resting floor that is no event, and a cluster carrying a ball would
        // sink at that speed step after step (the solves above see the rotation their
        // impulses add to first order only, and leave the rest).
        let b = &*self.balls;
        if held
            .iter()
            .any(|&(m, n, v)| (b.chord[m] - v).dot(&n) > T::zero())
        {
            self.rest_cluster(c, None, None);
        }
    }

    /// Member `i` of cluster `c` touching a wall or a box along `n` (from the ball into the
    /// surface) at `s`.
    pub(crate) fn cluster_surface(
        &mut self,
        c: usize,
        i: usize,
        surface: Surface<T, D>,
        n: &Vector<T, D>,
        s: T,
    ) -> Effect {
        let rigid = self.begin_cluster(c, s);
        let (surface_velocity, nominal) = match surface {
            Surface::Wall => (Vector::zeros(), self.rules.border_restitution),
            Surface::Box(k, v) => (v, self.boxes.restitution[k]),
        };
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        let other = Body::kinematic(surface_velocity, zero_spin).unwrap_or_else(|_| Body::fixed());
        let point = self.balls.seg_x[i] + n * self.balls.radius[i];
        let point = self.reaction_point(c, &point, n, surface_velocity);
        let Ok(contact) = Contact::new(*n, point - rigid.center(), Vector::zeros()) else {
            return Effect::default();
        };
        let body = rigid.body();
        let mut effect = Effect::default();
        if let Some(r) = self.surface_collision(&body, &other, &contact, nominal) {
            effect.collided = true;
            self.apply(Side::Cluster(c), 0, &body, &r, &contact, s);
        }
        if (surface_velocity - self.balls.chord[i]).dot(n) < T::zero() && s < self.h {
            self.rest_cluster(c, Some((i, *n, surface_velocity, T::zero())), None);
        }
        effect
    }

    /// Where a surface with normal `n` (into it) reacts on cluster `c` whose member touches
    /// it at `point`: several members can touch the same surface at once (a cluster landing
    /// flat), and one impulse at a time would alternate between them; as in the event
    /// engine, the surface reacts at the point of the contact points' bounding box nearest
    /// the centre of mass, projected on the contact plane (a flat cluster bounces without
    /// spin).
    fn reaction_point(
        &self,
        c: usize,
        point: &Vector<T, D>,
        n: &Vector<T, D>,
        surface_velocity: Vector<T, D>,
    ) -> Vector<T, D> {
        let b = &*self.balls;
        let (mut lo, mut hi) = (*point, *point);
        let mut several = false;
        for (m, normal, v, gap) in self.touching(c, None, false) {
            let tolerance = T::lit(1e-9) * b.radius[m];
            if gap > tolerance || v != surface_velocity || (normal - n).norm() > T::lit(1e-9) {
                continue;
            }
            let q = b.seg_x[m] + n * b.radius[m];
            lo = lo.inf(&q);
            hi = hi.sup(&q);
            several = true;
        }
        if !several {
            return *point;
        }
        let com = self.clusters.list[c].start.center();
        let nearest = com.sup(&lo).inf(&hi);
        nearest - n * (nearest - point).dot(n)
    }

    /// The surfaces the members of cluster `c` touch at its segment start (within `1e-9`
    /// of their radii) or close on along their chords within the rest of the step:
    /// `(member, unit normal from the ball into the surface, surface velocity, gap)`,
    /// after `first`; with `balls`, also the held free balls below the members (see
    /// `Contacts::member_supports`), as surfaces moving at their chords.
    fn touching(
        &self,
        c: usize,
        first: Option<Touching<T, D>>,
        balls: bool,
    ) -> Vec<Touching<T, D>> {
        let b = &*self.balls;
        let cluster = &self.clusters.list[c];
        let s = cluster.seg_t;
        let mut out: Vec<_> = first.into_iter().collect();
        for &m in &cluster.members {
            let m = m as usize;
            let (x, r) = (b.seg_x[m], b.radius[m]);
            let tolerance = T::lit(1e-9) * r + T::lit(16.0) * T::EPSILON * (x.amax() + r);
            let rest = self.h - s;
            let mut push = |n: Vector<T, D>, v: Vector<T, D>, gap: T| {
                let closing = (b.chord[m] - v).dot(&n) * rest;
                let near = gap <= tolerance || closing > gap;
                let new = out
                    .iter()
                    .all(|t| t.0 != m || (t.1 - n).norm() > T::lit(1e-6));
                if near && new {
                    out.push((m, n, v, gap.max(T::zero())));
                }
            };
            if let Some(border) = self.border {
                for axis in 0..D {
                    for (upper, gap) in [
                        (false, x[axis] - r - border.min()[axis]),
                        (true, border.max()[axis] - x[axis] - r),
                    ] {
                        let mut n = Vector::zeros();
                        n[axis] = if upper { T::one() } else { -T::one() };
                        push(n, Vector::zeros(), gap);
                    }
                }
            }
            for k in 0..self.boxes.len() {
                let obb = self.boxes.at(k, s);
                let local = obb.to_local(&x);
                let h = obb.half_extents();
                let q = obb.to_world(&local.inf(&h).sup(&-h));
                let d = (q - x).norm();
                if d > T::zero() {
                    push((q - x) / d, self.boxes.vel[k], d - r);
                }
            }
            if !balls {
                continue;
            }
            for support in self
                .member_supports
                .iter()
                .filter(|t| t.member as usize == m)
            {
                let p = support.ball as usize;
                let y = b.position_at(p, s) + support.shift;
                let d = (y - x).norm();
                if !b.supported[p] || d <= T::zero() {
                    continue;
                }
                // A held ball below the member, not moving up into it (within rounding),
                // holds it as a surface moving at the ball's chord (shock propagation, as
                // for a ball on a ball in `response`).
                let n = (y - x) / d;
                if self.rules.gravity.dot(&n) > T::zero() && b.chord[p].dot(&n) >= -self.rules.floor
                {
                    push(n, b.chord[p], d - r - b.radius[p]);
                }
            }
        }
        out
    }

    /// Holds cluster `c`, whose member `i` touches a surface along `n` moving at
    /// `surface_velocity` and closes on it along its chord, on every surface its members
    /// touch now or would reach along their chords within the step (speculative contacts:
    /// a member may close its gap `g` at `g/τ`, no faster): restitution-0 impulses with
    /// Coulomb friction, computed on the chords
    /// (the member chords as the velocities of their centres, changed by the impulses
    /// through the rigid body: `Δu_m = ΔV + ΔΩ × a_m`), all contacts at once by projected
    /// Gauss–Seidel (accumulated normal impulses kept `>= 0`, tangential ones within the
    /// friction cone), then applied as physical impulses at the segment start and the
    /// step integrated again. Sequential impulses one contact at a time would make a flat
    /// cluster on the floor rock: each correction at one member lifts the other. The
    /// surfaces include the held free balls below the members (a cluster resting on
    /// balls), and `first`, the contact that called for the correction, if any. A cluster
    /// held this way ends the step moving along the surfaces' normals as its centre's
    /// chord does ([`Self::hold_end_velocity`]) and its members count as held (a ball
    /// on them rests, see [`Self::resting`]).
    fn rest_cluster(
        &mut self,
        c: usize,
        first: Option<Touching<T, D>>,
        load: Option<&Load<T, D>>,
    ) -> Vec<Held<T, D>> {
        const SWEEPS: usize = 64;
        // With a load the sweeps converge by a factor that tends to one as the ball
        // outweighs the cluster (what is left is held as on an immovable support).
        const LOADED_SWEEPS: usize = 256;
        let contacts = self.touching(c, first, true);
        let loads: &[(usize, Vector<T, D>, T)] = load.map_or(&[], |l| &l.under);
        if contacts.is_empty() && loads.is_empty() {
            return Vec::new();
        }
        let rest = self.h - self.clusters.list[c].seg_t;
        let rigid = self.clusters.list[c].start;
        let b = &*self.balls;
        let mut delta = Delta::new(&rigid);
        // Surface contacts at the member's surface towards the surface, loads at the
        // member's surface towards the ball: (centre arm, contact arm).
        let arm = |m: usize, towards: Vector<T, D>| {
            let centre_arm = b.seg_x[m] - rigid.center();
            (centre_arm, centre_arm + towards * b.radius[m])
        };
        let arms: Vec<_> = contacts.iter().map(|&(m, n, _, _)| arm(m, n)).collect();
        let load_arms: Vec<_> = loads.iter().map(|&(m, n, _)| arm(m, -n)).collect();
        let (ball, ball_inverse_mass) = load.map_or((usize::MAX, T::zero()), |l| {
            (l.ball, b.inverse_mass[l.ball])
        });
        let ball_chord = load.map_or(Vector::zeros(), |l| b.chord[l.ball]);
        let mut dq = Vector::<T, D>::zeros();
        let mut normal = vec![T::zero(); contacts.len()];
        let mut tangential = vec![Vector::<T, D>::zeros(); contacts.len()];
        let mut carried = vec![T::zero(); loads.len()];
        let scale = contacts
            .iter()
            .map(|&(m, _, v, _)| (b.chord[m] - v).norm())
            .chain(
                loads
                    .iter()
                    .map(|&(m, _, _)| (b.chord[m] - ball_chord).norm()),
            )
            .fold(T::zero(), T::max);
        let sweeps = if loads.is_empty() {
            SWEEPS
        } else {
            LOADED_SWEEPS
        };
        for _ in 0..sweeps {
            let mut largest = T::zero();
            for (k, &(m, n, v, gap)) in contacts.iter().enumerate() {
                let (centre_arm, a) = arms[k];
                // Normal: `u·n > 0` closes on the surface, by at most the gap within the
                // rest of the step (a speculative contact); push back along −n.
                let approach = (b.chord[m] + delta.at(&centre_arm) - v).dot(&n) - gap / rest;
                let total = (normal[k] + approach / delta.stiffness(&a, &n)).max(T::zero());
                let step = total - normal[k];
                normal[k] = total;
                delta.push(&(n * -step), &a);
                largest = largest.max(step.abs() * delta.stiffness(&a, &n));
                if self.rules.friction > T::zero() {
                    let u = b.chord[m] + delta.at(&centre_arm) - v;
                    let bound = self.rules.friction * normal[k];
                    let change = delta.friction(&mut tangential[k], &u, &n, &a, bound);
                    largest = largest.max(change);
                }
            }
            // The ball's load on the members: two bodies, normal impulses only.
            for (k, &(m, n, gap)) in loads.iter().enumerate() {
                let (centre_arm, a) = load_arms[k];
                let member = b.chord[m] + delta.at(&centre_arm);
                let approach = (ball_chord + dq - member).dot(&n) - gap / rest;
                let mass = ball_inverse_mass + delta.stiffness(&a, &n);
                let total = (carried[k] + approach / mass).max(T::zero());
                let step = total - carried[k];
                carried[k] = total;
                dq -= n * (step * ball_inverse_mass);
                delta.push(&(n * step), &a);
                largest = largest.max(step.abs() * mass);
            }
            if largest <= T::lit(1e-12) * scale {
                break;
            }
        }
        // The contacts that hold the cluster: pushing, or left closing at most at the
        // resting floor (a held cluster that needed no new impulse).
        let held: Vec<Held<T, D>> = contacts
            .iter()
            .zip(&arms)
            .zip(&normal)
            .filter(|&((&(m, n, v, gap), (centre_arm, _)), &pushed)| {
                let u = b.chord[m] + delta.at(centre_arm) - v;
                pushed > T::zero() || u.dot(&n) - gap / rest >= -self.rules.floor
            })
            .map(|((&(m, n, v, _), _), _)| (m, n, v))
            .collect();
        let on_surfaces = (contacts
            .iter()
            .zip(&arms)
            .zip(tangential.iter().zip(&normal)))
        .map(|((&(_, n, _, _), arm), (t, &p))| (t - n * p, arm.1));
        let of_loads = (loads.iter().zip(&load_arms).zip(&carried))
            .map(|((&(_, n, _), arm), &p)| (n * p, arm.1));
        let rigid = (on_surfaces.chain(of_loads))
            .filter(|(p, _)| *p != Vector::<T, D>::zeros())
            .fold(rigid, |r, (p, a)| r.with_impulse(&p, &a));
        self.conclude_rest(c, rigid, held, ball, &dq)
    }

    /// Ends [`Self::rest_cluster`]: cluster `c` continues from `rigid` (the impulses
    /// applied), its chord held on the surfaces `held` ([`Self::hold_end_velocity`], its
    /// members held), and the ball it carried, if any, moves by `dq` (chord and velocity
    /// alike: the impulses the cluster took are its whole change).
    fn conclude_rest(
        &mut self,
        c: usize,
        rigid: RigidCluster<T, D>,
        held: Vec<Held<T, D>>,
        ball: usize,
        dq: &Vector<T, D>,
    ) -> Vec<Held<T, D>> {
        if ball != usize::MAX && *dq != Vector::<T, D>::zeros() {
            let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
            self.balls.nudge(ball, self.h, dq, &zero_spin);
        }
        self.finish_cluster(c, rigid);
        if !held.is_empty() {
            self.hold_end_velocity(c, &held);
            for &m in &self.clusters.list[c].members {
                self.balls.supported[m as usize] = true;
            }
        }
        held
    }

    /// Cluster `c`, held on the surfaces `held`, ends its step moving along their normals
    /// as its centre's chord does, as a held ball does (`BallArrays::shift_chord`): with
    /// Verlet, RK4 or the exact integrator the end velocity would otherwise keep half a
    /// step of gravity into the surfaces (`v_end − chord = g τ/2`), and a cluster lying on
    /// the floor would report `±g h/2` on alternate steps (with semi-implicit Euler the
    /// two agree and nothing changes). The part of `v_end − chord` in the span of the
    /// normals is removed; the tangential motion and the rotation are kept.
    fn hold_end_velocity(&mut self, c: usize, held: &[Held<T, D>]) {
        let h = self.h;
        let cluster = &mut self.clusters.list[c];
        let span_time = h - cluster.seg_t;
        if span_time <= T::zero() {
            return;
        }
        let chord = (cluster.end.center() - cluster.start.center()) / span_time;
        let excess = cluster.end.velocity() - chord;
        let along = span(held.iter().map(|t| t.1))
            .iter()
            .fold(Vector::<T, D>::zeros(), |sum, e| sum + e * e.dot(&excess));
        let end = cluster.end;
        cluster.end = end.with_motion(end.velocity() - along, end.angular_momentum());
        cluster.set_member_ends(self.balls, h);
    }

    /// The rigid body of `side` at its segment start `s`, moved by `shift`.
    fn rigid_of(&self, side: Side, shift: &Vector<T, D>) -> Result<RigidCluster<T, D>, String> {
        let rigid = match side {
            Side::Ball(i) => {
                let b = &*self.balls;
                RigidCluster::ball(b.mass[i], b.radius[i], b.seg_x[i], b.seg_v[i], b.seg_w[i])
                    .map_err(|e| format!("ball {i} as a rigid body: {e}"))?
            }
            Side::Cluster(c) => self.clusters.list[c].start,
        };
        Ok(rigid.with_pose(rigid.center() + shift, rigid.orientation()))
    }

    /// Fuses sides `a` and `b` (b's members shifted by `shift`) at `s` into one cluster.
    fn fuse(&mut self, a: Side, b: Side, shift: &Vector<T, D>, s: T) -> Result<(), String> {
        let fusion = self
            .rigid_of(a, &Vector::zeros())?
            .fuse(&self.rigid_of(b, shift)?)
            .map_err(|e| format!("fusing a stuck cluster: {e}"))?;
        // Members and their new body-frame offsets: a's, then b's.
        let mut members = Vec::new();
        let mut offsets = Vec::new();
        for (side, map) in [(a, fusion.members_a), (b, fusion.members_b)] {
            match side {
                Side::Ball(i) => {
                    members.push(i as u32);
                    offsets.push(map.apply(&Vector::zeros()));
                }
                Side::Cluster(c) => {
                    let cluster = &self.clusters.list[c];
                    members.extend_from_slice(&cluster.members);
                    offsets.extend(cluster.offsets.iter().map(|o| map.apply(o)));
                }
            }
        }
        let reach = members
            .iter()
            .zip(&offsets)
            .map(|(&m, o)| o.norm() + self.balls.radius[m as usize])
            .fold(T::zero(), T::max);
        self.clusters.check_span(members.len(), reach + reach)?;
        if *shift != Vector::<T, D>::zeros() {
            let moved = match b {
                Side::Ball(j) => vec![j as u32],
                Side::Cluster(c) => self.clusters.list[c].members.clone(),
            };
            for m in moved {
                self.balls.seg_x[m as usize] += shift;
            }
        }
        let cluster = StuckCluster {
            start: fusion.cluster,
            seg_t: s,
            end: fusion.cluster,
            kick: Vector::zeros(),
            members,
            offsets,
        };
        let list = &mut self.clusters.list;
        let id = match (a, b) {
            (Side::Cluster(c), Side::Cluster(d)) => {
                let (keep, gone) = (c.min(d), c.max(d));
                list[keep] = cluster;
                list.swap_remove(gone);
                if let Some(moved) = list.get(gone) {
                    for &m in &moved.members {
                        self.balls.cluster[m as usize] = gone as u32;
                    }
                }
                keep
            }
            (Side::Cluster(c), Side::Ball(_)) | (Side::Ball(_), Side::Cluster(c)) => {
                list[c] = cluster;
                c
            }
            (Side::Ball(_), Side::Ball(_)) => {
                list.push(cluster);
                list.len() - 1
            }
        };
        for &m in &self.clusters.list[id].members {
            debug_assert!(id as u32 != FREE);
            self.balls.cluster[m as usize] = id as u32;
        }
        let rigid = fusion.cluster;
        self.finish_cluster(id, rigid);
        Ok(())
    }
}
