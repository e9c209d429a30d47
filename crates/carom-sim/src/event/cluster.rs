//! Stuck clusters: balls fused by perfectly inelastic "stick" collisions (Collision Lab's
//! Inelastic screen), moving as rigid bodies with exact rotation.
//!
//! A cluster keeps a carom-response [`RigidCluster`] (mass, centre of mass, orientation,
//! inertia with each ball's own disk inertia, velocity, angular momentum) at its
//! reference time, its members and their body-frame offsets, and the carom-toi
//! [`Cluster`] shape of those offsets. In 2D without gravity a free rigid body moves at
//! constant velocity and turns at constant angular velocity, so its pose at any time is
//! exact: `c(t) = c + v (t − t₀)`, `R(t) = R(ω (t − t₀)) R₀`. Its contacts with walls,
//! balls and other clusters come from carom-toi's conservative advancement, which never
//! misses a first contact (PhET's bisection can, and lets a spinning cluster through a
//! wall). Clusters occupy the calendar slots after the balls: cluster `c` is slot `N + c`.

use carom_math::{Real, Rotation, Space, Vector};
use carom_response::{Body, Coefficients, Contact, RigidCluster, normal_velocity, resolve};
use carom_toi::{
    AdvanceOptions, Cluster, ConstantSpin, Kinematics, Status, Window, cluster_ball,
    cluster_border, cluster_cluster,
};
use nalgebra::Const;

use super::state::Mode;
use super::{EventEngine, Pending};
use crate::engine::{Collision, Observer, SimError};

/// A rigid cluster of stuck balls.
#[derive(Clone, Debug)]
pub(crate) struct ClusterBody<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The rigid body at `t_ref`.
    pub(crate) rigid: RigidCluster<T, D>,
    pub(crate) t_ref: T,
    pub(crate) members: Vec<u32>,
    /// Member offsets from the centre of mass in the body frame.
    pub(crate) offsets: Vec<Vector<T, D>>,
    pub(crate) shape: Cluster<T, D>,
    pub(crate) count: u32,
    pub(crate) last_collision: T,
    /// `false` once fused into another cluster.
    pub(crate) alive: bool,
}

impl<T: Real, const D: usize> ClusterBody<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The centre of mass and orientation at time `t`.
    pub(crate) fn pose_at(&self, t: T) -> (Vector<T, D>, Rotation<T, D>) {
        let s = t - self.t_ref;
        let turn =
            <Const<D> as Space<T, D>>::rotation_from_angular(&self.rigid.angular_velocity(), s);
        (
            self.rigid.center() + self.rigid.velocity() * s,
            turn * self.rigid.orientation(),
        )
    }

    /// The motion from time `t` on, for carom-toi.
    pub(crate) fn motion_at(&self, t: T) -> ConstantSpin<T, D> {
        let (c, r) = self.pose_at(t);
        ConstantSpin::new_unchecked(
            c,
            r,
            Kinematics::new_unchecked(self.rigid.velocity(), Vector::zeros()),
            self.rigid.angular_velocity(),
        )
    }

    /// Member `k`'s centre and velocity at time `t`.
    pub(crate) fn member_state(&self, k: usize, t: T) -> (Vector<T, D>, Vector<T, D>) {
        let (c, r) = self.pose_at(t);
        let arm = r * self.offsets[k];
        (
            c + arm,
            self.rigid.velocity()
                + <Const<D> as Space<T, D>>::angular_cross(&self.rigid.angular_velocity(), &arm),
        )
    }

    /// Moves the reference time to `t` (the motion is unchanged).
    pub(crate) fn sync(&mut self, t: T) {
        let (c, r) = self.pose_at(t);
        self.rigid = self.rigid.with_pose(c, r);
        self.t_ref = t;
    }
}

impl<T: Real, const D: usize> EventEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    fn cluster_slot(&self, c: usize) -> usize {
        self.balls.len() + c
    }

    /// The carom-toi search options: contacts located to 1e-12 of the scene's size.
    fn advance_options(&self) -> AdvanceOptions<T> {
        AdvanceOptions::relative_to(self.length_scale)
            .unwrap_or_else(|_| AdvanceOptions::relative_to(T::one()).expect("1 is a valid scale"))
    }

    /// A free ball's earliest contact with any cluster, to fold into its prediction.
    pub(crate) fn predict_ball_vs_clusters(&self, i: usize, best_t: &mut T, best: &mut Pending) {
        let now = self.now;
        let ball = self.ball_at(i, now);
        let kin = Kinematics::new_unchecked(self.balls.velocity_at(i, now), self.balls.accel(i));
        let options = self.advance_options();
        for (c, body) in self.clusters.iter().enumerate().filter(|(_, b)| b.alive) {
            let window = Window::forward(*best_t - now)
                .unwrap_or_else(|_| Window::forward(T::zero()).expect("valid"));
            let toi = cluster_ball(
                &body.shape,
                &body.motion_at(now),
                &ball,
                &kin,
                &window,
                &options,
            );
            // A hit, or (not converged) the time up to which no contact is proven:
            // look again then.
            if toi.status == Status::NoHit {
                continue;
            }
            let t = now + toi.time;
            if t < *best_t {
                *best_t = t;
                *best = if toi.status == Status::NotConverged {
                    Pending::Recheck
                } else {
                    Pending::Cluster {
                        c: c as u32,
                        count: body.count,
                    }
                };
            }
        }
    }

    /// Predicts and schedules cluster `c`'s next event: walls, free balls, other clusters.
    pub(crate) fn predict_cluster(&mut self, c: usize) {
        let slot = self.cluster_slot(c);
        if !self.clusters[c].alive {
            self.pending[slot] = Pending::None;
            self.calendar.cancel(slot);
            return;
        }
        let now = self.now;
        let options = self.advance_options();
        let body = &self.clusters[c];
        let motion = body.motion_at(now);
        let mut best_t = T::INFINITY;
        let mut best = Pending::None;
        let window = |best_t: T| {
            Window::forward(best_t - now)
                .unwrap_or_else(|_| Window::forward(T::zero()).expect("valid"))
        };
        let consider =
            |status: Status, time: T, pending: Pending, best_t: &mut T, best: &mut Pending| {
                if status == Status::NoHit || now + time >= *best_t {
                    return;
                }
                *best_t = now + time;
                *best = if status == Status::NotConverged {
                    Pending::Recheck
                } else {
                    pending
                };
            };
        if let (Some(border), false) = (&self.border, self.periodic) {
            let toi = cluster_border(&body.shape, &motion, border, &window(best_t), &options);
            let (_, wall) = toi.feature;
            consider(
                toi.status,
                toi.time,
                Pending::Wall {
                    axis: wall.axis as u8,
                    upper: wall.side == carom_toi::Side::Upper,
                },
                &mut best_t,
                &mut best,
            );
        }
        for j in 0..self.balls.len() {
            if matches!(self.balls.mode[j], Mode::Stuck(_)) {
                continue;
            }
            let ball = self.ball_at(j, now);
            let kin =
                Kinematics::new_unchecked(self.balls.velocity_at(j, now), self.balls.accel(j));
            let toi = cluster_ball(&body.shape, &motion, &ball, &kin, &window(best_t), &options);
            consider(
                toi.status,
                toi.time,
                Pending::Ball {
                    j: j as u32,
                    count: self.balls.count[j],
                },
                &mut best_t,
                &mut best,
            );
        }
        for (d, other) in self.clusters.iter().enumerate() {
            if d == c || !other.alive {
                continue;
            }
            let toi = cluster_cluster(
                &body.shape,
                &motion,
                &other.shape,
                &other.motion_at(now),
                &window(best_t),
                &options,
            );
            consider(
                toi.status,
                toi.time,
                Pending::Cluster {
                    c: d as u32,
                    count: other.count,
                },
                &mut best_t,
                &mut best,
            );
        }
        self.pending[slot] = best;
        self.calendar.schedule(slot, best_t);
    }

    /// Processes cluster `c`'s pending event.
    pub(crate) fn handle_cluster(
        &mut self,
        c: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        let slot = self.cluster_slot(c);
        match self.pending[slot] {
            Pending::Ball { j, count } => {
                let j = j as usize;
                if self.balls.count[j] == count && !matches!(self.balls.mode[j], Mode::Stuck(_)) {
                    self.cluster_meets_ball(c, j, observer)?;
                    self.predict(j);
                }
            }
            Pending::Cluster { c: d, count } => {
                let d = d as usize;
                if self.clusters[d].alive && self.clusters[d].count == count {
                    self.cluster_meets_cluster(c, d, observer)?;
                }
            }
            Pending::Wall { axis, upper } => {
                self.cluster_meets_wall(c, axis as usize, upper, observer);
            }
            _ => {}
        }
        self.predict_cluster(c);
        Ok(())
    }

    /// Ball `i`'s pending contact with cluster `c` came due.
    pub(crate) fn ball_meets_cluster(
        &mut self,
        i: usize,
        c: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        self.cluster_meets_ball(c, i, observer)?;
        if !matches!(self.balls.mode[i], Mode::Stuck(_)) {
            self.predict(i);
        }
        if self.clusters[c].alive {
            self.predict_cluster(c);
        }
        Ok(())
    }

    /// The member of cluster `c` nearest to the point `p` at the current time, with its
    /// centre, velocity and the unit normal from the member towards `p`.
    fn nearest_member(
        &self,
        c: usize,
        p: &Vector<T, D>,
        radius: T,
    ) -> (usize, Vector<T, D>, Vector<T, D>) {
        let body = &self.clusters[c];
        let mut best = (0, T::INFINITY);
        for k in 0..body.members.len() {
            let (centre, _) = body.member_state(k, self.now);
            let gap =
                (p - centre).norm() - radius - self.balls.motion[body.members[k] as usize].radius;
            if gap < best.1 {
                best = (k, gap);
            }
        }
        let (centre, _) = body.member_state(best.0, self.now);
        let d = p - centre;
        let n = d / d.norm();
        (best.0, centre, n)
    }

    fn cluster_meets_ball(
        &mut self,
        c: usize,
        j: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        let now = self.now;
        self.sync_ball(j);
        self.clusters[c].sync(now);
        let pj = self.balls.motion[j].pos;
        let rj = self.balls.motion[j].radius;
        let (k, member_centre, n) = self.nearest_member(c, &pj, rj);
        let member = self.clusters[c].members[k] as usize;
        let rk = self.balls.motion[member].radius;
        let e = self.ball_restitution(member).min(self.ball_restitution(j));
        let com = self.clusters[c].rigid.center();
        if e == T::zero() && self.stick {
            let ball = self.ball_as_cluster(j);
            self.fuse(c, None, Some((j, ball)))?;
        } else {
            // Cluster is body a, the ball body b; the normal points from a to b.
            let contact = Contact::new_unchecked(n, member_centre + n * rk - com, -n * rj);
            let a = self.clusters[c].rigid.body();
            let b = self.ball_body(j);
            let approach = -normal_velocity(&a, &b, &contact);
            let since = [
                now - self.clusters[c].last_collision,
                now - self.balls.props[j].last_collision,
            ];
            let e = self.collapse.restitution(e, approach, since);
            let r = resolve(
                &a,
                &b,
                &contact,
                &Coefficients::new_unchecked(e, self.friction),
            );
            if !r.applied() {
                return Ok(());
            }
            let body = &mut self.clusters[c];
            body.rigid = body.rigid.with_impulse(&-r.impulse, &contact.offset_a());
            body.count = body.count.wrapping_add(1);
            body.last_collision = now;
            self.balls.motion[j].vel = r.velocity[1];
            if self.friction > T::zero() {
                self.balls.props[j].spin = r.angular_velocity[1];
            }
            self.balls.count[j] = self.balls.count[j].wrapping_add(1);
            self.balls.props[j].last_collision = now;
        }
        self.counters.ball_ball += 1;
        observer.collision(&Collision::BallBall {
            time: now * self.sign,
            i: member.min(j),
            j: member.max(j),
        });
        Ok(())
    }

    fn cluster_meets_cluster(
        &mut self,
        c: usize,
        d: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        let now = self.now;
        self.clusters[c].sync(now);
        self.clusters[d].sync(now);
        // The closest pair of members.
        let mut best = (0, 0, T::INFINITY);
        for a in 0..self.clusters[c].members.len() {
            for b in 0..self.clusters[d].members.len() {
                let (pa, _) = self.clusters[c].member_state(a, now);
                let (pb, _) = self.clusters[d].member_state(b, now);
                let ra = self.balls.motion[self.clusters[c].members[a] as usize].radius;
                let rb = self.balls.motion[self.clusters[d].members[b] as usize].radius;
                let gap = (pb - pa).norm() - ra - rb;
                if gap < best.2 {
                    best = (a, b, gap);
                }
            }
        }
        let (ma, mb) = (
            self.clusters[c].members[best.0] as usize,
            self.clusters[d].members[best.1] as usize,
        );
        let e = self.ball_restitution(ma).min(self.ball_restitution(mb));
        if e == T::zero() && self.stick {
            self.fuse(c, Some(d), None)?;
        } else {
            let (pa, _) = self.clusters[c].member_state(best.0, now);
            let (pb, _) = self.clusters[d].member_state(best.1, now);
            let n = (pb - pa) / (pb - pa).norm();
            let (ra, rb) = (self.balls.motion[ma].radius, self.balls.motion[mb].radius);
            let contact = Contact::new_unchecked(
                n,
                pa + n * ra - self.clusters[c].rigid.center(),
                pb - n * rb - self.clusters[d].rigid.center(),
            );
            let (a, b) = (self.clusters[c].rigid.body(), self.clusters[d].rigid.body());
            let approach = -normal_velocity(&a, &b, &contact);
            let since = [
                now - self.clusters[c].last_collision,
                now - self.clusters[d].last_collision,
            ];
            let e = self.collapse.restitution(e, approach, since);
            let r = resolve(
                &a,
                &b,
                &contact,
                &Coefficients::new_unchecked(e, self.friction),
            );
            if !r.applied() {
                return Ok(());
            }
            for (k, impulse, offset) in [
                (c, -r.impulse, contact.offset_a()),
                (d, r.impulse, contact.offset_b()),
            ] {
                let body = &mut self.clusters[k];
                body.rigid = body.rigid.with_impulse(&impulse, &offset);
                body.count = body.count.wrapping_add(1);
                body.last_collision = now;
            }
            self.predict_cluster(d);
        }
        self.counters.ball_ball += 1;
        observer.collision(&Collision::BallBall {
            time: now * self.sign,
            i: ma.min(mb),
            j: ma.max(mb),
        });
        Ok(())
    }

    fn cluster_meets_wall(
        &mut self,
        c: usize,
        axis: usize,
        upper: bool,
        observer: &mut dyn Observer<T>,
    ) {
        let now = self.now;
        let Some(border) = self.border else { return };
        self.clusters[c].sync(now);
        // The members touching that wall. Several can touch at once (a cluster landing
        // flat); one impulse at a time would alternate between them forever. The wall
        // reacts at one point of the hull of the contact points: the point nearest the
        // projection of the centre of mass, which bounces a flat cluster without spin.
        // (Per tangent axis this is a clamp: exact for the 2D clusters the engine runs.)
        let body = &self.clusters[c];
        let gap_of = |k: usize| {
            let (p, _) = body.member_state(k, now);
            let r = self.balls.motion[body.members[k] as usize].radius;
            if upper {
                border.max()[axis] - p[axis] - r
            } else {
                p[axis] - r - border.min()[axis]
            }
        };
        let deepest = (0..body.members.len())
            .map(gap_of)
            .fold(T::INFINITY, T::min);
        let touching = deepest + T::lit(1e-9) * self.length_scale;
        let mut n = Vector::<T, D>::zeros();
        n[axis] = if upper { T::one() } else { -T::one() };
        let (mut lo, mut hi) = (
            Vector::<T, D>::repeat(T::INFINITY),
            Vector::<T, D>::repeat(-T::INFINITY),
        );
        let mut member = body.members[0] as usize;
        for k in (0..body.members.len()).filter(|&k| gap_of(k) <= touching) {
            let (p, _) = body.member_state(k, now);
            let q = p + n * self.balls.motion[body.members[k] as usize].radius;
            lo = lo.inf(&q);
            hi = hi.sup(&q);
            member = body.members[k] as usize;
        }
        let com = body.rigid.center();
        let mut point = Vector::<T, D>::from_fn(|m, _| com[m].max(lo[m]).min(hi[m]));
        point[axis] = if upper {
            border.max()[axis]
        } else {
            border.min()[axis]
        };
        // The cluster is body a, the wall body b; the normal points into the wall.
        let contact = Contact::new_unchecked(n, point - com, Vector::zeros());
        let e = self.surface_restitution(member, self.border_restitution);
        let response = resolve(
            &body.rigid.body(),
            &Body::fixed(),
            &contact,
            &Coefficients::new_unchecked(e, self.friction),
        );
        if !response.applied() {
            return;
        }
        let body = &mut self.clusters[c];
        body.rigid = body
            .rigid
            .with_impulse(&-response.impulse, &contact.offset_a());
        body.count = body.count.wrapping_add(1);
        body.last_collision = now;
        self.counters.ball_border += 1;
        observer.collision(&Collision::BallBorder {
            time: now * self.sign,
            i: member,
        });
    }

    /// Ball `j` (synchronised) as a rigid cluster of one.
    fn ball_as_cluster(&self, j: usize) -> RigidCluster<T, D> {
        RigidCluster::ball(
            self.balls.props[j].mass,
            self.balls.motion[j].radius,
            self.balls.motion[j].pos,
            self.balls.motion[j].vel,
            self.balls.props[j].spin,
        )
        .expect("a validated ball is a valid rigid body")
    }

    /// Two balls stick: they become a new cluster.
    pub(crate) fn stick_balls(&mut self, i: usize, j: usize) -> Result<usize, SimError> {
        let a = self.ball_as_cluster(i);
        let id = self.clusters.len();
        self.clusters.push(ClusterBody {
            rigid: a,
            t_ref: self.now,
            members: vec![i as u32],
            offsets: vec![Vector::zeros()],
            shape: Cluster::new(&[(Vector::zeros(), self.balls.motion[i].radius)])
                .expect("one valid ball"),
            count: 0,
            last_collision: self.now,
            alive: true,
        });
        self.balls.mode[i] = Mode::Stuck(id);
        let b = self.ball_as_cluster(j);
        self.fuse(id, None, Some((j, b)))?;
        Ok(id)
    }

    /// Fuses into cluster `c` either cluster `d` or the free ball `ball`.
    fn fuse(
        &mut self,
        c: usize,
        d: Option<usize>,
        ball: Option<(usize, RigidCluster<T, D>)>,
    ) -> Result<(), SimError> {
        let now = self.now;
        let other = match (d, &ball) {
            (Some(d), _) => self.clusters[d].rigid,
            (None, Some((_, b))) => *b,
            (None, None) => return Ok(()),
        };
        let fusion = self.clusters[c].rigid.fuse(&other).map_err(|e| {
            SimError::new(
                (now * self.sign).to_f64(),
                format!("fusing a stuck cluster: {e}"),
            )
        })?;
        let mut members = std::mem::take(&mut self.clusters[c].members);
        let mut offsets: Vec<Vector<T, D>> = self.clusters[c]
            .offsets
            .iter()
            .map(|o| fusion.members_a.apply(o))
            .collect();
        match (d, ball) {
            (Some(d), _) => {
                let other = &mut self.clusters[d];
                offsets.extend(other.offsets.iter().map(|o| fusion.members_b.apply(o)));
                members.append(&mut other.members);
                other.alive = false;
                let slot = self.balls.len() + d;
                self.calendar.cancel(slot);
                self.pending[slot] = Pending::None;
            }
            (None, Some((j, _))) => {
                offsets.push(fusion.members_b.apply(&Vector::zeros()));
                members.push(j as u32);
                self.calendar.cancel(j);
                self.pending[j] = Pending::None;
            }
            (None, None) => {}
        }
        let shape_balls: Vec<(Vector<T, D>, T)> = members
            .iter()
            .zip(&offsets)
            .map(|(&m, o)| (*o, self.balls.motion[m as usize].radius))
            .collect();
        let shape = Cluster::new(&shape_balls).map_err(|e| {
            SimError::new(
                (now * self.sign).to_f64(),
                format!(
                    "a stuck cluster can hold at most {} balls (carom-toi's limit): {e}",
                    Cluster::<T, D>::MAX_BALLS
                ),
            )
        })?;
        for &m in &members {
            self.balls.mode[m as usize] = Mode::Stuck(c);
            self.balls.count[m as usize] = self.balls.count[m as usize].wrapping_add(1);
        }
        let body = &mut self.clusters[c];
        body.rigid = fusion.cluster;
        body.t_ref = now;
        body.members = members;
        body.offsets = offsets;
        body.shape = shape;
        body.count = body.count.wrapping_add(1);
        body.last_collision = now;
        Ok(())
    }
}
