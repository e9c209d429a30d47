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

use carom_integrate::ForceField;
use carom_math::{Real, Space, Vector};
use carom_response::{Body, Contact, Response, RigidCluster};
use nalgebra::Const;

use super::clusters::{Clusters, FREE, StuckCluster};
use super::response::{Contacts, Effect, Surface};
use crate::engine::Angular;

/// A member near a surface: `(member, unit normal into the surface, surface velocity,
/// gap)`.
type Touching<T, const D: usize> = (usize, Vector<T, D>, Vector<T, D>, T);

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
        let rigid = cluster.at(s, self.stepper, drag, self.t0);
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
        let effect = Effect {
            collided: r.applied() && approach > self.rules.support_speed,
        };
        if r.applied() {
            self.apply(a, 0, &body_a, &r, &contact, s);
            self.apply(b, 1, &body_b, &r, &contact, s);
        }
        let balls = &*self.balls;
        if (balls.chord[j] - balls.chord[i]).dot(&n) < T::zero() && s < self.h {
            // Still closing along the chords: a perfectly inelastic correction.
            let (ca, cb) = (self.chord_body(a, i), self.chord_body(b, j));
            let r = self.stop_closing(&ca, &cb, &contact);
            if r.applied() {
                self.apply(a, 0, &ca, &r, &contact, s);
                self.apply(b, 1, &cb, &r, &contact, s);
            }
        }
        Ok(effect)
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
            self.rest_cluster(c, i, n, surface_velocity);
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
        for (m, normal, v, gap) in self.touching(c, (usize::MAX, *n, surface_velocity, T::zero())) {
            let tolerance = T::lit(1e-9) * b.radius.get(m).copied().unwrap_or(T::zero());
            if m == usize::MAX
                || gap > tolerance
                || v != surface_velocity
                || (normal - n).norm() > T::lit(1e-9)
            {
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
    /// after `first`.
    fn touching(&self, c: usize, first: Touching<T, D>) -> Vec<Touching<T, D>> {
        let b = &*self.balls;
        let cluster = &self.clusters.list[c];
        let s = cluster.seg_t;
        let mut out = vec![first];
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
    /// cluster on the floor rock: each correction at one member lifts the other.
    fn rest_cluster(
        &mut self,
        c: usize,
        i: usize,
        n: &Vector<T, D>,
        surface_velocity: Vector<T, D>,
    ) {
        const SWEEPS: usize = 64;
        let contacts = self.touching(c, (i, *n, surface_velocity, T::zero()));
        let rest = self.h - self.clusters.list[c].seg_t;
        let rigid = self.clusters.list[c].start;
        let centre = rigid.center();
        let inverse_mass = T::one() / rigid.mass();
        let inverse_inertia = rigid.world_inverse_inertia();
        let b = &*self.balls;
        let arms: Vec<(Vector<T, D>, Vector<T, D>)> = contacts
            .iter()
            .map(|&(m, n, _, _)| {
                let centre_arm = b.seg_x[m] - centre;
                (centre_arm, centre_arm + n * b.radius[m])
            })
            .collect();
        let mut dv = Vector::<T, D>::zeros();
        let mut dw = <Const<D> as Space<T, D>>::angular_zero();
        let mut normal = vec![T::zero(); contacts.len()];
        let mut tangential = vec![Vector::<T, D>::zeros(); contacts.len()];
        // Applies the impulse `p` at contact arm `a` to the chord velocities.
        let push =
            |p: &Vector<T, D>, a: &Vector<T, D>, dv: &mut Vector<T, D>, dw: &mut Angular<T, D>| {
                *dv += p * inverse_mass;
                *dw += <Const<D> as Space<T, D>>::inertia_apply(
                    &inverse_inertia,
                    &<Const<D> as Space<T, D>>::cross(a, p),
                );
            };
        // The inverse effective mass of the rigid body at arm `a` along unit `d`.
        let stiffness = |a: &Vector<T, D>, d: &Vector<T, D>| {
            let ad = <Const<D> as Space<T, D>>::cross(a, d);
            inverse_mass
                + <Const<D> as Space<T, D>>::angular_dot(
                    &ad,
                    &<Const<D> as Space<T, D>>::inertia_apply(&inverse_inertia, &ad),
                )
        };
        let scale = contacts
            .iter()
            .map(|&(m, _, v, _)| (b.chord[m] - v).norm())
            .fold(T::zero(), T::max);
        for _ in 0..SWEEPS {
            let mut largest = T::zero();
            for (k, &(m, n, v, gap)) in contacts.iter().enumerate() {
                let (centre_arm, a) = arms[k];
                let relative = |dv: &Vector<T, D>, dw: &Angular<T, D>| {
                    b.chord[m] + dv + <Const<D> as Space<T, D>>::angular_cross(dw, &centre_arm) - v
                };
                // Normal: `u·n > 0` closes on the surface, by at most the gap within the
                // rest of the step (a speculative contact); push back along −n.
                let approach = relative(&dv, &dw).dot(&n) - gap / rest;
                let total = (normal[k] + approach / stiffness(&a, &n)).max(T::zero());
                let step = total - normal[k];
                normal[k] = total;
                push(&(n * -step), &a, &mut dv, &mut dw);
                largest = largest.max(step.abs() * stiffness(&a, &n));
                // Friction: stop the tangential slip, within the cone |F_t| <= μ F_n.
                if self.rules.friction > T::zero() {
                    let u = relative(&dv, &dw);
                    let slip = u - n * u.dot(&n);
                    let speed = slip.norm();
                    if speed > T::zero() {
                        let t = slip / speed;
                        let wanted = tangential[k] - t * (speed / stiffness(&a, &t));
                        let bound = self.rules.friction * normal[k];
                        let total = if wanted.norm() > bound {
                            wanted * (bound / wanted.norm())
                        } else {
                            wanted
                        };
                        let change = total - tangential[k];
                        tangential[k] = total;
                        push(&change, &a, &mut dv, &mut dw);
                        largest = largest.max(change.norm() * stiffness(&a, &t));
                    }
                }
            }
            if largest <= T::lit(1e-12) * scale {
                break;
            }
        }
        let mut rigid = rigid;
        for (k, &(_, n, _, _)) in contacts.iter().enumerate() {
            let p = tangential[k] - n * normal[k];
            if p != Vector::<T, D>::zeros() {
                rigid = rigid.with_impulse(&p, &arms[k].1);
            }
        }
        self.finish_cluster(c, rigid);
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
