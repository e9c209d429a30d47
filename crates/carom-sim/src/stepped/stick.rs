//! Contacts that involve stuck clusters: fusion, rigid-body impulses at a member's contact
//! point, and the hold of the stack the cluster belongs to.
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
//!    integrated again; its members' chords follow. A slow contact onto a body held
//!    below it gets no impulse (the collapse guard's elastic one juggled a ball on a
//!    resting cluster, gaining energy): the hold below stops it.
//! 4. **Hold.** If the member's chord still closes on the other side (gravity pulls a
//!    cluster back into the floor within the rest of the step, a ball rests on it, it
//!    rests on another cluster), the stack around the contact is held at once: every
//!    cluster and ball in contact with it, and the walls, boxes and held balls under
//!    them (see `stack`).
//!
//! [`resolve`]: carom_response::resolve

use carom_integrate::ForceField;
use carom_math::{Real, Space, Vector};
use carom_response::{Body, Contact, Response, RigidCluster};
use nalgebra::Const;

use super::clusters::{Clusters, FREE, Motion, StuckCluster, member_motion};
use super::response::{Contacts, Effect, Surface};
use super::stack::{Approach, Seed, SeedOther};

/// One side of a contact: a free ball or a cluster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Side {
    Ball(usize),
    Cluster(usize),
}

impl<T: Real, const D: usize, F: ForceField<T, D>> Contacts<'_, T, D, F>
where
    Const<D>: Space<T, D>,
{
    pub(super) fn side(&self, i: usize) -> Side {
        Clusters::of(self.balls, i).map_or(Side::Ball(i), Side::Cluster)
    }

    /// Restarts cluster `c`'s segment at `s` (members on their chords, the motion and the
    /// end of the step unchanged) and returns its rigid state there.
    pub(super) fn begin_cluster(&mut self, c: usize, s: T) -> RigidCluster<T, D> {
        let flight = self.flight();
        self.clusters.list[c].restart_at(self.balls, s, &flight)
    }

    /// Cluster `c` continues from `rigid` at its segment start: the rest of the step is
    /// integrated again and the members' chords follow.
    pub(super) fn finish_cluster(&mut self, c: usize, rigid: RigidCluster<T, D>) {
        let flight = self.flight();
        let cluster = &mut self.clusters.list[c];
        let s = cluster.seg_t;
        cluster.restart_from(self.balls, rigid, s, &flight);
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
    /// of them in a cluster or held with others in this step (see `stack`), or the pair
    /// sticking.
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
        // Held with other bodies in this step: held again after the collision (see
        // `stack::Groups`).
        let grouped = self.groups.grouped(i) || self.groups.grouped(j);
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
        let nominal = balls.pair_restitution(i, j);
        if self.rules.stick && nominal == T::zero() {
            // Where the pair touches on the chords, relative to where the bodies' rigid
            // poses put the two balls: a free ball's pose moves by the difference, else
            // b's (see `fuse`).
            let align = (xj - xi) - (self.rigid_place(j) + shift - self.rigid_place(i));
            let align = match (a, b) {
                (Side::Ball(_), Side::Cluster(_)) => [-align, Vector::zeros()],
                _ => [Vector::zeros(), align],
            };
            self.fuse(a, b, shift, &align, s)?;
            if grouped && s < self.h {
                let seed = Seed {
                    ball: i,
                    other: SeedOther::Ball(j),
                };
                self.hold_stack(seed, s, Approach::Slow);
            }
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
        // A slow contact onto a held body below is resting: no impulse (the collapse
        // guard's elastic one would juggle a ball on a resting cluster, gaining energy);
        // the hold stops it.
        let onto_support = slow && self.onto_held([i, j], [&xi, &xj], &n);
        let effect = Effect {
            collided: r.applied() && !slow,
        };
        if r.applied() && !onto_support {
            self.apply(a, 0, &body_a, &r, &contact, s);
            self.apply(b, 1, &body_b, &r, &contact, s);
        }
        let balls = &*self.balls;
        let closing = (balls.chord[j] - balls.chord[i]).dot(&n) < T::zero();
        if (closing || grouped) && s < self.h {
            let seed = Seed {
                ball: i,
                other: SeedOther::Ball(j),
            };
            self.hold_stack(seed, s, self.rehold(i, Some(j)));
        }
        Ok(effect)
    }

    /// Which contacts a hold after a contact of ball `i` with `j` (or a surface, `None`)
    /// takes in: one that touches a pile held at the step's start (see `piles`) takes in
    /// every free ball near the stack ([`Approach::Resting`]), so that the pile is held
    /// again at once, not grown by one ball a hold; any other only the slow contacts
    /// ([`Approach::Slow`]).
    fn rehold(&self, i: usize, j: Option<usize>) -> Approach {
        let piled = |k: usize| self.balls.cluster[k] == FREE && self.groups.piled(k);
        let free_j = j.is_none_or(|j| self.balls.cluster[j] == FREE);
        if self.balls.cluster[i] == FREE && free_j && (piled(i) || j.is_some_and(piled)) {
            Approach::Resting
        } else {
            Approach::Slow
        }
    }

    /// Whether, of balls `i` at `xi` and `j` at `xj` (along `n` from `i` to `j`), the lower
    /// one along gravity (not side by side, see
    /// [`Rules::lies_below`](super::response::Rules::lies_below)) is held in this step
    /// (see `stack`) and, if it is a free ball, does not move up into the other: the upper
    /// one then lands on a support.
    fn onto_held(
        &self,
        [i, j]: [usize; 2],
        [xi, xj]: [&Vector<T, D>; 2],
        n: &Vector<T, D>,
    ) -> bool {
        let balls = &*self.balls;
        let (ball_i, ball_j) = ((xi, balls.radius[i]), (xj, balls.radius[j]));
        let (low, normal) = if self.rules.lies_below(ball_i, ball_j) {
            (j, *n)
        } else if self.rules.lies_below(ball_j, ball_i) {
            (i, -n)
        } else {
            return false;
        };
        balls.supported[low]
            && (balls.cluster[low] != FREE || balls.chord[low].dot(&normal) >= -self.rules.floor)
    }

    /// Ball `i` (a member of a cluster, or a free ball held with others in this step, see
    /// `stack`) touching a wall or a box along `n` (from the ball into the surface) at
    /// `s`.
    pub(crate) fn stuck_surface(
        &mut self,
        i: usize,
        surface: Surface<T, D>,
        n: &Vector<T, D>,
        s: T,
    ) -> Effect {
        let grouped = self.groups.grouped(i);
        let side = self.side(i);
        let (body, centre) = self.begin(side, s);
        let (surface_velocity, nominal) = match surface {
            Surface::Wall => (Vector::zeros(), self.rules.border_restitution),
            Surface::Box(k, v) => (v, self.boxes.restitution[k]),
        };
        let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
        let other = Body::kinematic(surface_velocity, zero_spin).unwrap_or_else(|_| Body::fixed());
        let point = self.balls.seg_x[i] + n * self.balls.radius[i];
        let point = match side {
            Side::Cluster(c) => self.reaction_point(c, &point, n, surface_velocity, s),
            Side::Ball(_) => point,
        };
        let Ok(contact) = Contact::new(*n, point - centre, Vector::zeros()) else {
            return Effect::default();
        };
        let mut effect = Effect::default();
        if let Some(r) = self.surface_collision(&body, &other, &contact, nominal) {
            effect.collided = true;
            self.apply(side, 0, &body, &r, &contact, s);
        }
        let closing = (surface_velocity - self.balls.chord[i]).dot(n) < T::zero();
        if (closing || grouped) && s < self.h {
            let seed = Seed {
                ball: i,
                other: SeedOther::Surface(*n),
            };
            self.hold_stack(seed, s, self.rehold(i, None));
        }
        effect
    }

    /// Where a surface with normal `n` (into it) reacts on cluster `c` whose member touches
    /// it at `point` at `s`: several members can touch the same surface at once (a cluster
    /// landing flat), and one impulse at a time would alternate between them; as in the
    /// event engine, the surface reacts at the point of the contact points' bounding box
    /// nearest the centre of mass, projected on the contact plane (a flat cluster bounces
    /// without spin).
    fn reaction_point(
        &self,
        c: usize,
        point: &Vector<T, D>,
        n: &Vector<T, D>,
        surface_velocity: Vector<T, D>,
        s: T,
    ) -> Vector<T, D> {
        let b = &*self.balls;
        let (mut lo, mut hi) = (*point, *point);
        let mut several = false;
        for &m in &self.clusters.list[c].members {
            let m = m as usize;
            let tolerance = T::lit(1e-9) * b.radius[m];
            self.for_each_surface(m, s, |_, normal, v, gap| {
                if gap > tolerance || v != surface_velocity || (normal - n).norm() > T::lit(1e-9) {
                    return;
                }
                let q = b.seg_x[m] + n * b.radius[m];
                lo = lo.inf(&q);
                hi = hi.sup(&q);
                several = true;
            });
        }
        if !several {
            return *point;
        }
        let com = self.clusters.list[c].start.center();
        let nearest = com.sup(&lo).inf(&hi);
        nearest - n * (nearest - point).dot(n)
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

    /// Where ball `i` is on its body's rigid pose at the body's segment start: its
    /// cluster's centre plus its arm, or the ball itself.
    fn rigid_place(&self, i: usize) -> Vector<T, D> {
        match self.side(i) {
            Side::Ball(_) => self.balls.seg_x[i],
            Side::Cluster(c) => {
                let cluster = &self.clusters.list[c];
                let k = (cluster.members.iter())
                    .position(|&m| m as usize == i)
                    .expect("a member of its cluster");
                let (arm, _, _) = member_motion(&cluster.start, &cluster.offsets[k]);
                cluster.start.center() + arm
            }
        }
    }

    /// Fuses sides `a` and `b` (b's members shifted by `shift`) at `s` into one cluster,
    /// their rigid poses moved by `align` as well (a's, b's).
    ///
    /// A member moves on its chord within a step while its cluster's pose turns it on an
    /// arc (see `clusters`), the two apart by up to the sagitta. Its place on the chord
    /// is where a contact finds it, its place on the arc where the fused cluster would
    /// keep it: fused that way, a ball meeting a turning cluster stayed overlapping its
    /// member by the sagitta for good (up to 1.1e-3 m in fuzzed scenes). `align` moves
    /// one side's pose so that the touching pair keeps, in the fused cluster, the offset
    /// it has on the chords: exactly touching. It moves a free ball rather than a
    /// cluster: moving a cluster that rested on a floor by its member's offset (up to
    /// 3.1e-5 m in a fuzzed scene) left that scene's step running for over a minute in
    /// its holds (not traced further), moving the ball did not. The
    /// members' places at `s` stay on their chords (no jump); their segments end at the
    /// fused cluster's rigid places.
    fn fuse(
        &mut self,
        a: Side,
        b: Side,
        shift: &Vector<T, D>,
        [align_a, align_b]: &[Vector<T, D>; 2],
        s: T,
    ) -> Result<(), String> {
        let fusion = self
            .rigid_of(a, align_a)?
            .fuse(&self.rigid_of(b, &(shift + align_b))?)
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
            push: Motion::zero(),
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
