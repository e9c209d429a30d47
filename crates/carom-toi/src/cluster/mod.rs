//! Rigid clusters of balls (stuck balls moving as one body) against planes, border
//! walls, balls and other clusters.
//!
//! A spinning cluster's ball centres move on trochoids: no closed form gives their first
//! contact. The queries here use conservative advancement with rigorous bounds (see
//! `advance`), so the first contact is never skipped, then refine it with ITP to the
//! tolerance of [`AdvanceOptions`] (`10⁻¹²` of the scene scale by default). The motion
//! is any [`RigidMotion`]; [`ConstantSpin`] is the constant-velocity, constant-spin one.
//!
//! Every component (cluster ball × obstacle) is a contact of its own: the first one to
//! touch is reported, with its ball index in the feature. Components that start in
//! contact and are not closing are ignored until they separate (by more than the
//! tolerance): a receding pair is never reported.

mod advance;
mod motion;

pub use advance::AdvanceOptions;
pub use motion::{ConstantSpin, RigidMotion, RigidState};

use carom_geometry::{Ball, Border, HalfSpace};
use carom_math::{
    InvalidValue, Problem, Real, Space, Vector, ensure_finite_vector, ensure_positive,
};
use nalgebra::Const;

use crate::ball::unit_or;
use crate::{Kinematics, Side, Status, Toi, Wall, Window};
use advance::{Advance, Bounds, Components, Sample, advance};
use motion::Oriented;

/// One ball of a cluster: its offset from the reference point in the body frame and its
/// radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterBall<T: Real, const D: usize> {
    offset: Vector<T, D>,
    radius: T,
    reach: T,
}

impl<T: Real, const D: usize> ClusterBall<T, D> {
    /// The offset from the cluster's reference point (body frame).
    pub fn offset(&self) -> Vector<T, D> {
        self.offset
    }

    /// The radius.
    pub fn radius(&self) -> T {
        self.radius
    }

    /// `|offset|`: how far the centre is from the reference point.
    pub fn reach(&self) -> T {
        self.reach
    }
}

/// A rigid set of 1 to 64 balls.
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster<T: Real, const D: usize> {
    balls: Vec<ClusterBall<T, D>>,
    bounding_radius: T,
}

impl<T: Real, const D: usize> Cluster<T, D> {
    /// The most balls a cluster may have (the advancement tracks components in a fixed
    /// bit set: no allocation per query).
    pub const MAX_BALLS: usize = 64;

    /// A cluster of balls given as `(offset from the reference point, radius)`.
    ///
    /// # Errors
    /// `balls` if empty or longer than [`Cluster::MAX_BALLS`]; `balls[k].offset[i]` if not
    /// finite; `balls[k].radius` if not finite or not `> 0`.
    pub fn new(balls: &[(Vector<T, D>, T)]) -> Result<Self, InvalidValue> {
        if balls.is_empty() {
            return Err(InvalidValue::new("balls", Problem::Empty));
        }
        if balls.len() > Self::MAX_BALLS {
            return Err(InvalidValue::new(
                "balls",
                Problem::OutOfRange {
                    value: balls.len() as f64,
                    min: 1.0,
                    max: Self::MAX_BALLS as f64,
                },
            ));
        }
        let mut out = Vec::with_capacity(balls.len());
        for (k, (offset, radius)) in balls.iter().enumerate() {
            let context = format!("balls[{k}]");
            let offset = ensure_finite_vector("offset", offset).map_err(|e| e.within(&context))?;
            let radius = ensure_positive("radius", *radius).map_err(|e| e.within(&context))?;
            out.push(ClusterBall {
                offset,
                radius,
                reach: offset.norm(),
            });
        }
        let bounding_radius = out.iter().fold(T::zero(), |m, b| m.max(b.reach + b.radius));
        Ok(Self {
            balls: out,
            bounding_radius,
        })
    }

    /// The balls.
    pub fn balls(&self) -> &[ClusterBall<T, D>] {
        &self.balls
    }

    /// The radius of the smallest sphere about the reference point that contains every
    /// ball: a natural scale for [`AdvanceOptions::relative_to`].
    pub fn bounding_radius(&self) -> T {
        self.bounding_radius
    }
}

/// Cluster balls against static planes `n·x = offset` (free side `n·x > offset`).
struct PlaneSet<'a, T: Real, const D: usize, M> {
    balls: &'a [ClusterBall<T, D>],
    motion: M,
    planes: &'a [(Vector<T, D>, T)],
}

impl<T: Real, const D: usize, M: RigidMotion<T, D>> Components<T, D> for PlaneSet<'_, T, D, M> {
    type State = RigidState<T, D>;

    fn count(&self) -> usize {
        self.balls.len() * self.planes.len()
    }

    fn state(&self, s: T) -> RigidState<T, D> {
        self.motion.state_at(s)
    }

    fn sample(&self, state: &RigidState<T, D>, k: usize) -> Sample<T> {
        let (ball, (n, offset)) = (
            &self.balls[k / self.planes.len()],
            &self.planes[k % self.planes.len()],
        );
        Sample {
            gap: n.dot(&state.point(&ball.offset)) - *offset - ball.radius,
            rate: n.dot(&state.point_velocity(&ball.offset)),
        }
    }

    fn bounds(&self, k: usize, s0: T, s1: T) -> Bounds<T> {
        let reach = self.balls[k / self.planes.len()].reach;
        let curvature = self.motion.acceleration_bound(reach, s0, s1);
        Bounds {
            speed: self.motion.speed_bound(reach, s0, s1),
            curvature_apart: curvature,
            curvature_any: curvature,
        }
    }

    fn separating_for_good(&self, state: &RigidState<T, D>, k: usize, s: T) -> bool {
        let (ball, (n, offset)) = (
            &self.balls[k / self.planes.len()],
            &self.planes[k % self.planes.len()],
        );
        self.motion.acceleration_bound(T::zero(), s, T::MAX) == T::zero()
            && n.dot(&state.velocity) >= T::zero()
            && n.dot(&state.position) - *offset - ball.reach - ball.radius > T::zero()
    }

    fn contact(&self, state: &RigidState<T, D>, k: usize) -> (Vector<T, D>, Vector<T, D>) {
        let (ball, (n, offset)) = (
            &self.balls[k / self.planes.len()],
            &self.planes[k % self.planes.len()],
        );
        let c = state.point(&ball.offset);
        (-n, c - n * (n.dot(&c) - *offset))
    }
}

/// Balls of one rigid body against balls of another.
struct PairSet<'a, T: Real, const D: usize, M1, M2> {
    first: &'a [ClusterBall<T, D>],
    motion1: M1,
    second: &'a [ClusterBall<T, D>],
    motion2: M2,
}

impl<T: Real, const D: usize, M1: RigidMotion<T, D>, M2: RigidMotion<T, D>>
    PairSet<'_, T, D, M1, M2>
{
    fn pair(&self, k: usize) -> (&ClusterBall<T, D>, &ClusterBall<T, D>) {
        (
            &self.first[k / self.second.len()],
            &self.second[k % self.second.len()],
        )
    }
}

impl<T: Real, const D: usize, M1: RigidMotion<T, D>, M2: RigidMotion<T, D>> Components<T, D>
    for PairSet<'_, T, D, M1, M2>
{
    type State = (RigidState<T, D>, RigidState<T, D>);

    fn count(&self) -> usize {
        self.first.len() * self.second.len()
    }

    fn state(&self, s: T) -> Self::State {
        (self.motion1.state_at(s), self.motion2.state_at(s))
    }

    fn sample(&self, (s1, s2): &Self::State, k: usize) -> Sample<T> {
        let (a, b) = self.pair(k);
        let d = s2.point(&b.offset) - s1.point(&a.offset);
        let dist = d.norm();
        let dv = s2.point_velocity(&b.offset) - s1.point_velocity(&a.offset);
        Sample {
            gap: dist - (a.radius + b.radius),
            rate: if dist > T::zero() {
                d.dot(&dv) / dist
            } else {
                T::zero()
            },
        }
    }

    fn bounds(&self, k: usize, s0: T, s1: T) -> Bounds<T> {
        let (a, b) = self.pair(k);
        let speed =
            self.motion1.speed_bound(a.reach, s0, s1) + self.motion2.speed_bound(b.reach, s0, s1);
        let acceleration = self.motion1.acceleration_bound(a.reach, s0, s1)
            + self.motion2.acceleration_bound(b.reach, s0, s1);
        // d²|d|/dt² = u·d̈ + |ḋ_⊥|²/|d| <= |d̈| + |ḋ|²/|d|, and |d| >= r_a + r_b while apart.
        Bounds {
            speed,
            curvature_apart: acceleration + speed * speed / (a.radius + b.radius),
            curvature_any: T::INFINITY,
        }
    }

    fn separating_for_good(&self, (s1, s2): &Self::State, k: usize, s: T) -> bool {
        let (a, b) = self.pair(k);
        let d = s2.position - s1.position;
        self.motion1.acceleration_bound(T::zero(), s, T::MAX) == T::zero()
            && self.motion2.acceleration_bound(T::zero(), s, T::MAX) == T::zero()
            && d.dot(&(s2.velocity - s1.velocity)) >= T::zero()
            && d.norm() - (a.reach + b.reach + a.radius + b.radius) > T::zero()
    }

    fn contact(&self, (s1, s2): &Self::State, k: usize) -> (Vector<T, D>, Vector<T, D>) {
        let (a, b) = self.pair(k);
        let (pa, pb) = (s1.point(&a.offset), s2.point(&b.offset));
        let d = pb - pa;
        let dist = d.norm();
        let n = unit_or(
            &d,
            dist,
            &(s2.point_velocity(&b.offset) - s1.point_velocity(&a.offset)),
        );
        (
            n,
            pa + n * (a.radius + (dist - a.radius - b.radius) * T::lit(0.5)),
        )
    }
}

/// Runs the advancement and turns its outcome into a [`Toi`] with `feature(k)`.
fn finish<T: Real, const D: usize, C: Components<T, D>, F>(
    set: &C,
    window: &Window<T>,
    options: &AdvanceOptions<T>,
    feature: impl Fn(usize) -> F,
) -> Toi<T, D, F> {
    let contact = |status, s: T, k: usize| {
        let (normal, point) = set.contact(&set.state(s), k);
        Toi {
            status,
            time: window.signed(s),
            normal,
            point,
            feature: feature(k),
        }
    };
    match advance(set, window.horizon(), options) {
        Advance::Immediate(k) => contact(Status::AlreadyTouching, T::zero(), k),
        Advance::At(s, k) => contact(Status::Hit, s, k),
        Advance::Clear => Toi::no_hit(window.direction().sign(), feature(0)),
        Advance::NotConverged(s) => Toi::not_converged(window.signed(s), feature(0)),
    }
}

/// The first contact of a moving cluster with the solid side of a static plane.
///
/// The normal is the plane's inward normal (from the cluster into the solid); the point
/// is on the plane; the feature is the index of the cluster ball that touches.
pub fn cluster_plane<T: Real, const D: usize, M: RigidMotion<T, D>>(
    cluster: &Cluster<T, D>,
    motion: &M,
    plane: &HalfSpace<T, D>,
    window: &Window<T>,
    options: &AdvanceOptions<T>,
) -> Toi<T, D, usize> {
    let planes = [(plane.normal(), plane.offset())];
    let set = PlaneSet {
        balls: cluster.balls(),
        motion: Oriented {
            motion,
            sign: window.direction().sign(),
        },
        planes: &planes,
    };
    finish(&set, window, options, |k| k)
}

/// The first wall contact of a moving cluster inside a reflecting border. The feature is
/// the cluster ball's index and the wall; the normal points into the wall.
pub fn cluster_border<T: Real, const D: usize, M: RigidMotion<T, D>>(
    cluster: &Cluster<T, D>,
    motion: &M,
    border: &Border<T, D>,
    window: &Window<T>,
    options: &AdvanceOptions<T>,
) -> Toi<T, D, (usize, Wall)> {
    // Wall 2i is the lower wall of axis i (free side x_i > min_i), 2i + 1 the upper.
    let walls: [(Vector<T, D>, T); 6] = core::array::from_fn(|j| {
        let (axis, upper) = (j / 2 % D, j % 2 == 1);
        let mut n = Vector::<T, D>::zeros();
        n[axis] = if upper { -T::one() } else { T::one() };
        let offset = if upper {
            -border.max()[axis]
        } else {
            border.min()[axis]
        };
        (n, offset)
    });
    let set = PlaneSet {
        balls: cluster.balls(),
        motion: Oriented {
            motion,
            sign: window.direction().sign(),
        },
        planes: &walls[..2 * D],
    };
    finish(&set, window, options, |k| {
        let j = k % (2 * D);
        let side = if j % 2 == 1 { Side::Upper } else { Side::Lower };
        (k / (2 * D), Wall { axis: j / 2, side })
    })
}

/// The first contact of a moving cluster with a ball moving with constant acceleration.
/// The normal points from the cluster ball to the ball; the feature is the cluster
/// ball's index.
pub fn cluster_ball<T: Real, const D: usize, M: RigidMotion<T, D>>(
    cluster: &Cluster<T, D>,
    motion: &M,
    ball: &Ball<T, D>,
    ball_motion: &Kinematics<T, D>,
    window: &Window<T>,
    options: &AdvanceOptions<T>,
) -> Toi<T, D, usize>
where
    Const<D>: Space<T, D>,
{
    let single = [ClusterBall {
        offset: Vector::zeros(),
        radius: ball.radius(),
        reach: T::zero(),
    }];
    let translating = ConstantSpin::translating(ball.center(), *ball_motion);
    let sign = window.direction().sign();
    let set = PairSet {
        first: cluster.balls(),
        motion1: Oriented { motion, sign },
        second: &single,
        motion2: Oriented {
            motion: &translating,
            sign,
        },
    };
    finish(&set, window, options, |k| k)
}

/// The first contact of two moving clusters. The normal points from the first cluster's
/// ball to the second's; the feature is `(ball of the first, ball of the second)`.
pub fn cluster_cluster<T: Real, const D: usize, M1: RigidMotion<T, D>, M2: RigidMotion<T, D>>(
    first: &Cluster<T, D>,
    motion1: &M1,
    second: &Cluster<T, D>,
    motion2: &M2,
    window: &Window<T>,
    options: &AdvanceOptions<T>,
) -> Toi<T, D, (usize, usize)> {
    let sign = window.direction().sign();
    let set = PairSet {
        first: first.balls(),
        motion1: Oriented {
            motion: motion1,
            sign,
        },
        second: second.balls(),
        motion2: Oriented {
            motion: motion2,
            sign,
        },
    };
    let m = second.balls().len();
    finish(&set, window, options, |k| (k / m, k % m))
}
