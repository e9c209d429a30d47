//! Processing events: what happens when a ball's pending event comes due.
//!
//! A collision synchronises the balls involved to the event time, builds the two
//! carom-response bodies and their contact, applies the impulse, counts it, tells the
//! observer, and re-predicts the balls whose motion changed. A stale event (the partner
//! collided since it was predicted) only re-predicts. Restitution passes through the
//! guards first: the TC model for ball–ball collisions, the resting guard for bounces on
//! a surface that gravity presses the ball onto. Every resolved contact leaves at least
//! at the rounding speed of its velocities, so that rounding cannot bring the same
//! contact due again at once ([`parting_shortfall`]). Sustained contact, which no
//! finite sequence of exact events resolves, ends the run with a
//! [`SustainedContact`](crate::SimErrorKind::SustainedContact) error, which
//! `--engine auto` hands over to the stepped engine: balls resting on each other or
//! sinking into each other under gravity, a ball held between two surfaces or on an
//! edge, a ball wedged in flight between surfaces that it meets in turn ever faster.

use carom_geometry::query::PointQuery;
use carom_math::{Real, Space, Vector};
use carom_response::{
    Body, Bounce, Coefficients, Contact, central_impulse, normal_velocity, resolve,
};
use nalgebra::Const;

use super::state::{Mode, Support};
use super::{EventEngine, Partners, Pending};
use crate::engine::{Collision, Observer, SimError};
use crate::scene::{OVERLAP_TOLERANCE, coordinate_resolution};

impl<T: Real, const D: usize> EventEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    /// Processes the pending event of calendar slot `i` (a ball, or a cluster after the
    /// balls) at the current time.
    pub(crate) fn handle(
        &mut self,
        i: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        let now = self.now;
        if i >= self.balls.len() {
            return self.handle_cluster(i - self.balls.len(), observer);
        }
        if let Partners::Cells(cells) = &self.partners
            && let Some((axis, upper)) = cells.crossing_due(i)
        {
            self.cross(i, axis, upper);
            return Ok(());
        }
        match self.pending[i] {
            Pending::None => {}
            Pending::Recheck => self.predict(i),
            Pending::Cluster { c, count } => {
                let c = c as usize;
                if self.clusters[c].alive && self.clusters[c].count == count {
                    self.ball_meets_cluster(i, c, observer)?;
                } else {
                    self.predict(i);
                }
            }
            Pending::Rebuild => {
                let periodic = self.periodic_border().copied();
                self.balls.sync(i, now, periodic.as_ref());
                if let Partners::Lists(lists) = &mut self.partners {
                    lists.rebuild(i, self.balls.motion[i].pos);
                }
                self.predict(i);
            }
            Pending::LeaveSupport => {
                self.sync_ball(i);
                self.free(i);
                self.predict(i);
            }
            Pending::Ball { j, count } => {
                let j = j as usize;
                if self.balls.count[j] != count || self.is_stuck(j) {
                    self.predict(i);
                } else if self.sticks(i, j) {
                    self.sync_ball(i);
                    self.sync_ball(j);
                    let c = self.stick_balls(i, j)?;
                    self.counters.ball_ball += 1;
                    observer.collision(&Collision::BallBall {
                        time: self.now * self.sign,
                        i: i.min(j),
                        j: i.max(j),
                    });
                    self.predict_cluster(c);
                } else {
                    // Read before the impulse frees a ball resting on a surface.
                    let pressing = if self.balls.accelerated {
                        let (a, b) = (
                            self.balls.position_at(i, now),
                            self.balls.position_at(j, now),
                        );
                        let offset = self.separation(&a, &b);
                        self.refuse_sunken_pair(
                            i,
                            j,
                            &offset,
                            self.scene_amax(&a).max(self.scene_amax(&b)),
                        )?;
                        self.pair_pressing(i, j, &offset)
                    } else {
                        None
                    };
                    self.collide_balls(i, j, observer);
                    if let Some(pressing) = pressing {
                        self.refuse_resting_pair(i, j, pressing)?;
                    }
                    self.predict(i);
                    self.predict(j);
                }
            }
            Pending::Wall { axis, upper } => {
                self.collide_wall(i, axis as usize, upper, observer)?;
                self.predict(i);
            }
            Pending::Box { k } => {
                self.collide_box(i, k as usize, observer)?;
                self.predict(i);
            }
        }
        Ok(())
    }

    /// `true` if balls `i` and `j` stick: restitution 0 in a "stick" world.
    fn sticks(&self, i: usize, j: usize) -> bool {
        self.stick && self.ball_restitution(i).min(self.ball_restitution(j)) == T::zero()
    }

    pub(crate) fn sync_ball(&mut self, i: usize) {
        let periodic = self.periodic_border().copied();
        self.balls.sync(i, self.now, periodic.as_ref());
    }

    /// Ball `i` as a carom-response body (synchronised).
    pub(crate) fn ball_body(&self, i: usize) -> Body<T, D> {
        let (m, r) = (self.balls.props[i].mass, self.balls.motion[i].radius);
        let inertia = <Const<D> as Space<T, D>>::ball_inertia_factor() * m * r * r;
        Body::new_unchecked(
            T::one() / m,
            <Const<D> as Space<T, D>>::inertia_isotropic(T::one() / inertia),
            self.balls.motion[i].vel,
            self.balls.props[i].spin,
        )
    }

    /// A ball's trajectory changed: count it (invalidating events predicted with it)
    /// and remember when, for the collapse guard.
    fn changed(&mut self, i: usize) {
        self.balls.count[i] = self.balls.count[i].wrapping_add(1);
        self.balls.props[i].last_collision = self.now;
    }

    /// Ball `i` flies freely again under gravity.
    fn free(&mut self, i: usize) {
        if let Mode::Resting(_) = self.balls.mode[i] {
            self.balls.mode[i] = Mode::Free;
            self.balls.accel[i] = self.gravity;
            self.balls.count[i] = self.balls.count[i].wrapping_add(1);
        }
    }

    /// After an impulse on a resting ball: it stays resting only if its velocity along the
    /// support normal still matches the support's; otherwise it flies (and if it now
    /// presses into the support, the next prediction finds that contact at once).
    fn check_support(&mut self, i: usize) {
        let Some(support) = self.support_of(i) else {
            return;
        };
        let (n, support_velocity) = self.support_frame(support);
        if (self.balls.motion[i].vel - support_velocity).dot(&n) != T::zero() {
            self.free(i);
        }
    }

    /// The unit normal into the support and the support's velocity.
    fn support_frame(&self, support: Support) -> (Vector<T, D>, Vector<T, D>) {
        match support {
            Support::Wall { axis, upper } => {
                let mut n = Vector::<T, D>::zeros();
                n[axis] = if upper { T::one() } else { -T::one() };
                (n, Vector::zeros())
            }
            Support::BoxFace { k, axis, upper } => {
                let b = &self.boxes[k];
                let mut local = Vector::<T, D>::zeros();
                // Into the box: against the face's outward normal.
                local[axis] = if upper { -T::one() } else { T::one() };
                (b.shape.vector_to_world(&local), b.vel)
            }
        }
    }

    fn collide_balls(&mut self, i: usize, j: usize, observer: &mut dyn Observer<T>) {
        self.sync_ball(i);
        self.sync_ball(j);
        let ci = self.balls.motion[i].pos;
        let offset = self.separation(&ci, &self.balls.motion[j].pos);
        let nominal = self.ball_restitution(i).min(self.ball_restitution(j));
        let since = [
            self.now - self.balls.props[i].last_collision,
            self.now - self.balls.props[j].last_collision,
        ];
        let (normal, applied) = if self.friction == T::zero() {
            // Smooth balls: the central impulse, no spin (carom-response's
            // `central_impulse`, `resolve` to rounding).
            let distance = offset.norm();
            if !(distance > T::zero() && distance.finite()) {
                // Coincident centres cannot come from a predicted contact of positive radii.
                return;
            }
            let normal = offset / distance;
            let (vi, vj) = (self.balls.motion[i].vel, self.balls.motion[j].vel);
            let approach = -(vj - vi).dot(&normal);
            let e = self.collapse.restitution(nominal, approach, since);
            let masses = (
                T::one() / self.balls.props[i].mass,
                T::one() / self.balls.props[j].mass,
            );
            let response = central_impulse((masses.0, &vi), (masses.1, &vj), &normal, e);
            if let Some([vi, vj]) = response {
                self.balls.motion[i].vel = vi;
                self.balls.motion[j].vel = vj;
            }
            (normal, response.is_some())
        } else {
            let (ri, rj) = (self.balls.motion[i].radius, self.balls.motion[j].radius);
            let Ok(contact) = Contact::between_balls(&ci, ri, &(ci + offset), rj) else {
                // Coincident centres cannot come from a predicted contact of positive radii.
                return;
            };
            let (a, b) = (self.ball_body(i), self.ball_body(j));
            let approach = -normal_velocity(&a, &b, &contact);
            let e = self.collapse.restitution(nominal, approach, since);
            let response = resolve(
                &a,
                &b,
                &contact,
                &Coefficients::new_unchecked(e, self.friction),
            );
            if response.applied() {
                self.balls.motion[i].vel = response.velocity[0];
                self.balls.motion[j].vel = response.velocity[1];
                self.balls.props[i].spin = response.angular_velocity[0];
                self.balls.props[j].spin = response.angular_velocity[1];
            }
            (contact.normal(), response.applied())
        };
        let parted = self.part_by_rounding(i, j, &normal);
        if !(applied || parted) {
            return;
        }
        self.changed(i);
        self.changed(j);
        self.check_support(i);
        self.check_support(j);
        if !applied {
            // Only parted by rounding: not a collision.
            return;
        }
        self.counters.ball_ball += 1;
        observer.collision(&Collision::BallBall {
            time: self.now * self.sign,
            i: i.min(j),
            j: i.max(j),
        });
    }

    /// How hard gravity presses touching balls `i` and `j` (centre `offset` apart, from
    /// `i` to `j`) together, with the unit normal from `i` to `j`: minus the acceleration
    /// of their gap along the line of centres. `None` unless it presses: unless one rests
    /// on a surface, its weight cancelled, and the other does not.
    fn pair_pressing(
        &self,
        i: usize,
        j: usize,
        offset: &Vector<T, D>,
    ) -> Option<(T, Vector<T, D>)> {
        let normal = offset.try_normalize(T::zero())?;
        let pressing = -(self.balls.accel(j) - self.balls.accel(i)).dot(&normal);
        (pressing > T::zero()).then_some((pressing, normal))
    }

    /// An error if balls `i` and `j`, meeting under gravity, overlap by more than a
    /// scene may start with ([`OVERLAP_TOLERANCE`]) and the resolution of their
    /// coordinates: a ball pressed onto another, hopping on it at instants too close for
    /// the positions to tell their gap apart, which ratchets into it. That is sustained
    /// contact, which this engine cannot resolve. (Fuzzed: a ball sliding down the flank
    /// of one pressed into the floor 5e4 m from the origin, both hopping every 6.8e-7 s,
    /// sank 1.6e-8 m into it in 30,000 hops before the resting-pair error; the hops were
    /// too long for the resting guard.)
    ///
    /// `offset` goes from `i`'s centre to `j`'s, whose largest coordinate is `scale`.
    fn refuse_sunken_pair(
        &self,
        i: usize,
        j: usize,
        offset: &Vector<T, D>,
        scale: T,
    ) -> Result<(), SimError> {
        let overlap = self.balls.motion[i].radius + self.balls.motion[j].radius - offset.norm();
        let allowed = T::lit(OVERLAP_TOLERANCE) + coordinate_resolution(scale);
        if overlap <= allowed {
            return Ok(());
        }
        Err(self.sustained(
            &format!(
                "balls {} and {} are pressed into each other under gravity (they overlap by {:.3e} m)",
                i.min(j),
                i.max(j),
                overlap.to_f64()
            ),
            Some("a ball resting on another"),
        ))
    }

    /// An error if balls `i` and `j`, just resolved while gravity pressed them together
    /// along `normal` ([`EventEngine::pair_pressing`]), part too slowly for the resting
    /// guard's shortest flight a second time, later than the first: they rest on each
    /// other. That is sustained contact, which this engine cannot resolve: it has no
    /// resting state on a ball, and the pair hopped forever (fuzzed: a 900 kg ball
    /// rolling over a 993 kg one on the floor, 2.3 million events in 0.53 s and then one
    /// every 2.4 ns, a crawl that never ended). A slow parting within one instant is
    /// not enough: a heavy ball pressing a light one into the floor parts slowly many
    /// times in the cascade that turns it back, and the run goes on.
    fn refuse_resting_pair(
        &mut self,
        i: usize,
        j: usize,
        (pressing, normal): (T, Vector<T, D>),
    ) -> Result<(), SimError> {
        let parting = (self.balls.motion[j].vel - self.balls.motion[i].vel).dot(&normal);
        let pair = (i.min(j), i.max(j));
        let seen = self.resting_pair.filter(|(p, _)| *p == pair);
        if self.resting.decide(parting, T::one(), pressing) == Bounce::Rebound {
            if seen.is_some() {
                self.resting_pair = None;
            }
            return Ok(());
        }
        if !seen.is_some_and(|(_, t)| t < self.now) {
            self.resting_pair = Some((pair, self.now));
            return Ok(());
        }
        Err(self.sustained(
            &format!(
                "balls {} and {} rest on each other under gravity",
                pair.0, pair.1
            ),
            Some("a stack, a pile"),
        ))
    }

    /// Balls `i` and `j`, in contact along `normal` (from `i` to `j`) and just resolved,
    /// made to separate at least at the resolution of their velocities
    /// ([`rounding_speed`]) by an impulse along the normal; `true` if one was needed.
    ///
    /// The prediction finds a contact closing, and the response resolves it, from
    /// differently rounded products of the same state. At a contact the impulse leaves
    /// tangential (restitution 0, a graze) the prediction could find it closing again
    /// at once while the impulse found nothing to do, or changed the velocities by an
    /// ulp at a time, and the same event came due again and again at one instant
    /// (fuzzed s58: a 1 kg ball grazing a 1 mg one, 768 times, then the run ended as an
    /// endless cascade). The opening costs rounding of the velocities and conserves
    /// momentum.
    fn part_by_rounding(&mut self, i: usize, j: usize, normal: &Vector<T, D>) -> bool {
        let (vi, vj) = (self.balls.motion[i].vel, self.balls.motion[j].vel);
        let (wi, wj) = (
            T::one() / self.balls.props[i].mass,
            T::one() / self.balls.props[j].mass,
        );
        let Some(shortfall) = parting_shortfall(&vi, &vj, normal, T::zero()) else {
            return false;
        };
        let impulse = *normal * (shortfall / (wi + wj));
        self.balls.motion[i].vel = vi - impulse * wi;
        self.balls.motion[j].vel = vj + impulse * wj;
        true
    }

    /// The ball's restitution in ball–ball collisions: its own or the world's.
    pub(crate) fn ball_restitution(&self, i: usize) -> T {
        self.balls.props[i]
            .restitution
            .unwrap_or(self.world_restitution)
    }

    /// The restitution of ball `i` against a surface of restitution `surface`: the
    /// minimum of the ball's own value (if it has one) and the surface's.
    pub(crate) fn surface_restitution(&self, i: usize, surface: T) -> T {
        self.balls.props[i]
            .restitution
            .map_or(surface, |e| e.min(surface))
    }

    /// A bounce of ball `i` on an immovable surface moving at `surface_velocity`, along
    /// `normal` (from the ball into the surface), touching at `point`. Returns `true` if
    /// an impulse was applied; `support` is where the ball rests if the guard says so.
    ///
    /// # Errors
    /// The ball would rest where no surface can hold it, again ([`Self::refuse_held`]).
    fn bounce(
        &mut self,
        i: usize,
        normal: Vector<T, D>,
        point: Vector<T, D>,
        surface_velocity: Vector<T, D>,
        surface_restitution: T,
        support: Option<Support>,
    ) -> Result<bool, SimError> {
        let r = self.balls.motion[i].radius;
        let contact = Contact::new_unchecked(
            normal,
            normal * r,
            point - self.balls.motion[i].pos - normal * r,
        );
        let a = self.ball_body(i);
        let b = Body::kinematic(surface_velocity, <Const<D> as Space<T, D>>::angular_zero())
            .unwrap_or_else(|_| Body::fixed());
        let approach = -normal_velocity(&a, &b, &contact);
        let mut e = self.surface_restitution(i, surface_restitution);
        let pressing = self.gravity.dot(&normal);
        // The heights the ball's position can resolve.
        let resolution = coordinate_resolution(self.scene_amax(&self.balls.motion[i].pos));
        let stops = self
            .resting
            .decide_resolved(approach, e, pressing, resolution)
            == Bounce::Rest;
        let rest = stops && support.is_some_and(|s| self.holds(i, s));
        if stops && !rest {
            // An edge or a corner, or a face that ends under the ball: it would rest
            // where nothing holds it, and hops there at the resolution instead.
            self.refuse_held(i, || {
                format!(
                    "ball {i} is held on {}, which cannot hold it at rest (an edge or a corner it pivots over)",
                    describe(support)
                )
            })?;
        }
        if rest {
            e = T::zero();
        }
        let response = resolve(
            &a,
            &b,
            &contact,
            &Coefficients::new_unchecked(e, self.friction),
        );
        // Leaving at least at the resolution of the velocities, as two balls do
        // (`part_by_rounding`; the surface is a body of no inverse mass), and, pressed
        // onto the surface, fast enough to rise above the resolution of the position,
        // unless it rests. A ball rebounding from a box's edge at the resolution of its
        // velocity flew 3.4e-15 s, too short for its position (at x = 431 m) to move: it
        // met the same edge again and again while the clock crept on (a ball sliding
        // off a face at 9 m/s, forever). Rising `resolution` under `g_n` takes
        // `√(2 g_n resolution)`.
        let lift = if pressing > T::zero() {
            (T::lit(2.0) * pressing * resolution).sqrt()
        } else {
            T::zero()
        };
        let shortfall = if rest {
            None
        } else {
            parting_shortfall(&response.velocity[0], &surface_velocity, &normal, lift)
        };
        // A ball that comes to rest changes its motion even when no impulse was needed
        // (set down touching at rest): its pressing is cancelled from now on.
        if !(response.applied() || shortfall.is_some() || rest) {
            return Ok(false);
        }
        let mut v = response.velocity[0];
        if let Some(shortfall) = shortfall {
            v -= normal * shortfall;
        }
        if rest {
            // Rest exactly: no normal velocity relative to the surface.
            v -= normal * (v - surface_velocity).dot(&normal);
        }
        self.balls.motion[i].vel = v;
        if self.friction > T::zero() {
            self.balls.props[i].spin = response.angular_velocity[0];
        }
        self.changed(i);
        if let (true, Some(s)) = (rest, support) {
            // No normal acceleration; gravity's tangential part still drives the ball.
            self.balls.accel[i] = self.gravity - normal * pressing;
            self.balls.mode[i] = Mode::Resting(s);
        } else {
            self.check_support(i);
        }
        // Only parted by rounding, or set down at rest: not a collision.
        Ok(response.applied())
    }

    /// Whether `support` can hold ball `i` at rest: a wall always, a box face unless the
    /// ball leaves it within the resting guard's shortest flight (it reaches the face's
    /// end), where it holds it no more than a corner does. Resting there, the ball was
    /// freed at once and met the box again at the same instant, forever (fuzzed s31: a
    /// ball sliding off a face at 2e5 m/s).
    fn holds(&self, i: usize, support: Support) -> bool {
        match support {
            Support::Wall { .. } => true,
            Support::BoxFace { k, axis, .. } => self
                .face_exit_time(i, k, axis)
                .is_none_or(|s| s > self.resting.min_flight_time()),
        }
    }

    fn collide_wall(
        &mut self,
        i: usize,
        axis: usize,
        upper: bool,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        self.sync_ball(i);
        let Some(border) = self.border else {
            return Ok(());
        };
        let mut normal = Vector::<T, D>::zeros();
        normal[axis] = if upper { T::one() } else { -T::one() };
        let mut point = self.balls.motion[i].pos;
        point[axis] = if upper {
            border.max()[axis]
        } else {
            border.min()[axis]
        };
        let support = Some(Support::Wall { axis, upper });
        self.refuse_cornered(i, support, Surface::Wall { axis, upper })?;
        if self.bounce(
            i,
            normal,
            point,
            Vector::zeros(),
            self.border_restitution,
            support,
        )? {
            self.counters.ball_border += 1;
            observer.collision(&Collision::BallBorder {
                time: self.now * self.sign,
                i,
            });
        }
        Ok(())
    }

    fn collide_box(
        &mut self,
        i: usize,
        k: usize,
        observer: &mut dyn Observer<T>,
    ) -> Result<(), SimError> {
        self.sync_ball(i);
        let b = self.boxes[k];
        let obb = b.at(self.now);
        let centre = self.balls.motion[i].pos;
        let image = obb.center() - self.separation(&centre, &obb.center());
        let boundary = obb.boundary_point(&image);
        // Work in the image's frame, then shift the contact point back to the ball.
        let normal = -boundary.normal;
        let point = boundary.point + (centre - image);
        // The face the ball touches, if it touches a face (not an edge or a corner):
        // only a face can hold a resting ball.
        let local = obb.to_local(&image);
        let h = obb.half_extents();
        let mut outside = (0usize, 0usize);
        for m in (0..D).filter(|&m| local[m].abs() > h[m]) {
            outside = (outside.0 + 1, m);
        }
        let support = (outside.0 == 1).then(|| Support::BoxFace {
            k,
            axis: outside.1,
            upper: local[outside.1] > T::zero(),
        });
        self.refuse_cornered(i, support, Surface::Box(k))?;
        if self.bounce(i, normal, point, b.vel, b.restitution, support)? {
            self.counters.ball_box += 1;
            observer.collision(&Collision::BallBox {
                time: self.now * self.sign,
                i,
                k,
            });
        }
        Ok(())
    }

    /// An error if ball `i`, under gravity, is held between two surfaces: resting on one
    /// and meeting another (`support`, the face it meets, or `None` for an edge or a
    /// corner; `surface` names the wall or box) soon after the last time
    /// ([`Self::refuse_held`]), or, in flight, meeting surfaces that take turns ever
    /// faster ([`Self::refuse_wedged`]). This engine cannot resolve either (it rests a
    /// ball on one surface). Fuzzed (3D, friction 0.3): a spinning ball in the corner of
    /// the floor and a wall, pushed into the wall by the floor's friction and lifted off
    /// the floor by the wall's, met them in turn 14 million times in 0.2 s, each round a
    /// little shorter.
    fn refuse_cornered(
        &mut self,
        i: usize,
        support: Option<Support>,
        surface: Surface,
    ) -> Result<(), SimError> {
        if !self.balls.accelerated {
            return Ok(());
        }
        match self.balls.mode[i] {
            Mode::Resting(resting_on) if support != Some(resting_on) => self.refuse_held(i, || {
                format!(
                    "ball {i} rests on {} and is held against {} (a corner or a wedge)",
                    describe(Some(resting_on)),
                    describe(support),
                )
            }),
            Mode::Free => self.refuse_wedged(i, surface),
            _ => Ok(()),
        }
    }

    /// An error if free ball `i` meets surfaces (border walls, boxes) [`WEDGED_REPEATS`]
    /// times in a row, each a different one from the last and within the resting
    /// guard's shortest flight of it: it is wedged between them (squeezed by a moving
    /// box, or held in a corner it cannot rest in), in flight only at the resolution of
    /// its position. Fuzzed 2D scene run backwards (z40, 5e4 m from the origin): a ball
    /// between the border, a static box and a box moving into them met the three in turn
    /// every 1.2e-12 s, 37 million times in 20 s of computing, the run all but stopped.
    /// Squeezes that resolve take far fewer (a box's corner squeezing a ball out of a
    /// corner: tens of contacts).
    fn refuse_wedged(&mut self, i: usize, surface: Surface) -> Result<(), SimError> {
        let repeats = match self.wedged {
            Some((ball, t, last, n))
                if ball == i
                    && last != surface
                    && self.now - t < self.resting.min_flight_time() =>
            {
                n + 1
            }
            _ => 1,
        };
        self.wedged = Some((i, self.now, surface, repeats));
        if repeats < WEDGED_REPEATS {
            return Ok(());
        }
        Err(self.sustained(
            &format!(
                "ball {i} is wedged: {} contacts with walls and boxes in a row, each with a different one from the last and within {:e} s of it, the last with {}",
                repeats,
                self.resting.min_flight_time().to_f64(),
                surface.describe(),
            ),
            None,
        ))
    }

    /// An error if ball `i` is held where this engine cannot rest it (between two
    /// surfaces, or on an edge) [`HELD_REPEATS`] times in a row, each within the
    /// resting guard's shortest flight of the one before: sustained contact, in which it
    /// would hop at the resolution of its position millions of times (a ball pivoting
    /// over a box's edge in a fuzzed 3D scene: 3.27 million by t = 0.3 s, 1.81 million of
    /// them in its last 0.05 s, 2.8e-8 s apart).
    /// Fewer are a squeeze that resolves (a box's corner pressing a ball resting on the
    /// floor squeezes it out in 20 bounces). `what` names the surfaces.
    fn refuse_held(&mut self, i: usize, what: impl FnOnce() -> String) -> Result<(), SimError> {
        let repeats = match self.held {
            Some((ball, t, n))
                if ball == i && t < self.now && self.now - t < self.resting.min_flight_time() =>
            {
                n + 1
            }
            Some((ball, t, n)) if ball == i && t == self.now => n,
            _ => 1,
        };
        self.held = Some((i, self.now, repeats));
        if repeats < HELD_REPEATS {
            return Ok(());
        }
        Err(self.sustained(
            &format!(
                "{} ({repeats} times in a row, each within {:e} s of the last)",
                what(),
                self.resting.min_flight_time().to_f64()
            ),
            None,
        ))
    }

    /// The error that ends the run at a sustained contact, now: `what` happened, which is
    /// sustained contact (of the kind `example` names, if any), with the remedy. Every
    /// sustained-contact rule of this module words its error so.
    fn sustained(&self, what: &str, example: Option<&str>) -> SimError {
        let example = example.map(|e| format!(" ({e})")).unwrap_or_default();
        SimError::sustained_contact(
            (self.now * self.sign).to_f64(),
            format!(
                "{what}: sustained contact{example}, which the event engine cannot resolve; the stepped engine simulates it (--engine auto hands the run over to it)"
            ),
        )
    }
}

/// How many times in a row, each soon after the last, a ball may be held where the
/// event engine cannot rest it before the run ends ([`EventEngine::refuse_held`]).
const HELD_REPEATS: u32 = 64;

/// How many surface contacts in a row, each soon after the last and with a different
/// surface, a free ball may make before the run ends ([`EventEngine::refuse_wedged`]):
/// far more than a squeeze that resolves takes, and a few milliseconds of computing (the
/// wedged ball of `tests/scenes/corner_crush.toml`, run backwards, ends the whole
/// `carom run` in 0.01 s).
const WEDGED_REPEATS: u32 = 4096;

/// A wall or a box a ball meets (which feature of a box does not matter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Surface {
    /// A border wall.
    Wall { axis: usize, upper: bool },
    /// Box `k`.
    Box(usize),
}

impl Surface {
    fn describe(self) -> String {
        match self {
            Self::Wall { axis, upper } => describe(Some(Support::Wall { axis, upper })),
            Self::Box(k) => format!("boxes[{k}]"),
        }
    }
}

/// A surface a ball meets, named for a message: a face that can hold it, or (`None`) an
/// edge or a corner of a box.
fn describe(support: Option<Support>) -> String {
    match support {
        Some(Support::Wall { axis, upper }) => format!(
            "the border's {} wall on axis {axis}",
            if upper { "upper" } else { "lower" }
        ),
        Some(Support::BoxFace { k, .. }) => format!("a face of boxes[{k}]"),
        None => "an edge or a corner of a box".to_owned(),
    }
}

/// How much slower than [`rounding_speed`] (or `least`, if faster) `b` leaves `a` along
/// `normal` (from `a` to `b`), if it does: the normal relative velocity a parting must
/// add. `None` when they already separate at least that fast.
fn parting_shortfall<T: Real, const D: usize>(
    a: &Vector<T, D>,
    b: &Vector<T, D>,
    normal: &Vector<T, D>,
    least: T,
) -> Option<T> {
    let shortfall = rounding_speed(a, b).max(least) - (b - a).dot(normal);
    (shortfall > T::zero()).then_some(shortfall)
}

/// The resolution of a contact's normal relative velocity: `8 ε (|v_a| + |v_b|)` (`ε`
/// the machine epsilon, two unit roundoffs), sixteen roundings of the largest terms the relative velocity and
/// its normal component are computed from, in whatever frame (the prediction computes
/// a box contact's in the box's). A pair separating at least this fast is separating
/// however its normal velocity is computed, and a velocity change this large along a
/// unit normal (whose largest component is at least `1/√D`) changes a component of
/// the velocity by several roundings. (Its two roots cost 0.3-0.4 % of the instructions of
/// the 3D gas, callgrind; the sum of the components' magnitudes instead cost 1.4 %.)
fn rounding_speed<T: Real, const D: usize>(a: &Vector<T, D>, b: &Vector<T, D>) -> T {
    T::lit(8.0) * T::EPSILON * (a.norm() + b.norm())
}
