//! Ball against ball: exact time of impact under linear or accelerated motion.
//!
//! With `u(t) = c₂(t) − c₁(t)` the relative position and `R = r₁ + r₂`, the balls touch
//! when `|u(t)| = R`. The relative motion is `u(t) = u₀ + w t + (a₂ − a₁) t²/2`:
//!
//! * linear when both balls move at constant velocity, **or when both feel the same
//!   acceleration** (a common gravity cancels): the closed form of DESIGN.md,
//!   `t = c / (−b/2 + √(b²/4 − a c))`, decided by filtered arithmetic (`LinearSphere`):
//!   a quick test in the input precision sends receding and missing pairs away after a
//!   few dot products; the rest is computed in `f64` (exact products for `f32` input)
//!   with a proven error bound, and in double-double only where the bound cannot prove a
//!   sign or the root's accuracy. No linear fallback: a slow closing is solved by the
//!   same formula, and `Δ <= 0` is a miss, never an invented collision;
//! * a quartic otherwise, solved by bracketing (see `SphereGap`).
//!
//! Cases, for the gap at time 0 and the rate `u₀·w`:
//!
//! | state at time 0                         | result                      |
//! |-----------------------------------------|-----------------------------|
//! | apart, closing and meeting              | `Hit` at the first contact  |
//! | apart, receding or missing              | `NoHit`                     |
//! | touching, rate `< 0`                    | `AlreadyTouching`, time 0   |
//! | touching, rate `>= 0` (receding/resting)| `NoHit` (or a later hit under differing accelerations) |
//! | overlapping, rate `< 0`                 | `AlreadyTouching`, time 0   |
//! | overlapping, rate `>= 0`                | `NoHit` until they separate |
//!
//! Touching means that the centre distance rounds to `R`: for linear motion
//! `|u₀|² − R² <= 2u fl(R²)` exactly (`u` the unit roundoff of `f64`), that is
//! `|u₀| <= R (1 + u)` to first order; a gap of one ulp of `R` or more is a `Hit` at its
//! exact time. The signs of the rate and of the gap are decided exactly (to the
//! double-double resolution, `u²` of the terms).

use carom_geometry::Ball;
use carom_math::{Real, Vector};

use crate::roots::{Budget, Descent, LinearContact, LinearSphere, SphereGap, certainly_clear};
use crate::{Kinematics, Status, Toi, Window};

/// The first contact of two balls moving with constant accelerations (zero for linear
/// motion), looking in the window's direction.
///
/// The normal points from ball 1 to ball 2; the point is the middle of the contact (the
/// touching point at a hit, the middle of the overlap for [`Status::AlreadyTouching`]).
///
/// ```
/// use carom_toi::{ball_ball, Kinematics, Status, Window};
/// use carom_geometry::Ball;
/// use nalgebra::Vector2;
///
/// let a = Ball::new(Vector2::new(0.0, 0.0), 0.5)?;
/// let b = Ball::new(Vector2::new(3.0, 0.0), 0.5)?;
/// let toward = Kinematics::linear(Vector2::new(1.0, 0.0))?;
/// let toi = ball_ball(&a, &toward, &b, &Kinematics::at_rest(), &Window::forward(10.0)?);
/// assert_eq!(toi.status, Status::Hit);
/// assert_eq!(toi.time, 2.0);
/// assert_eq!(toi.normal, Vector2::new(1.0, 0.0));
/// assert_eq!(toi.point, Vector2::new(2.5, 0.0));
/// # Ok::<(), carom_math::InvalidValue>(())
/// ```
pub fn ball_ball<T: Real, const D: usize>(
    ball1: &Ball<T, D>,
    motion1: &Kinematics<T, D>,
    ball2: &Ball<T, D>,
    motion2: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D> {
    let accelerations = motion2.acceleration() - motion1.acceleration();
    if accelerations.iter().fold(T::zero(), |sum, x| sum + x.abs()) != T::zero() {
        return ballistic_ball_ball(ball1, motion1, ball2, motion2, window);
    }
    // Linear relative motion (equal accelerations cancel). Receding and missing pairs,
    // most of all, leave after a few dot products in the input precision, without a
    // square root; the rest continues in f64, out of line.
    if certainly_clear(
        &(ball2.center() - ball1.center()),
        &(motion2.velocity() - motion1.velocity()),
        ball1.radius() + ball2.radius(),
        window.direction().sign(),
        window.horizon(),
    ) {
        return Toi::no_hit(window.direction().sign(), ());
    }
    linear_ball_ball(ball1, motion1, ball2, motion2, window)
}

/// The first contact time of two balls in linear relative motion (constant velocities,
/// or a common acceleration, which cancels), given as the relative position
/// `offset = c₂ − c₁` now, the relative velocity `velocity = v₂ − v₁` and the sum of the
/// radii `radius = r₁ + r₂`, looking in the window's direction: the time [`ball_ball`]
/// returns as [`Toi::hit_time`] for such a pair, to a resolution of positions the caller
/// gives, without the normal and the contact point.
///
/// For an engine that schedules events and computes each contact only when it comes
/// due: it predicts many pairs per event and keeps at most one, so the normal and point
/// (a square root, a division and a dozen products per hit) are wasted on the rest, and
/// it has the relative motion at hand. The same filtered arithmetic decides every pair
/// (receding and missing pairs leave after a few dot products, pairs that meet only after
/// the horizon as well), with one difference: [`ball_ball`] proves every root within
/// `16u` of exact (`u` the unit roundoff), recomputing in double-double when the plain
/// bound cannot, while here a plain root is also accepted when its proven error moves the
/// relative position by at most `reach`. An engine passes the resolution of its
/// coordinates (the event-driven engine: `4 u_T` times the largest coordinate, four
/// roundings of it; `0` asks for `ball_ball`'s accuracy). Near touching the plain bound
/// fails the relative budget for almost every pair (`c = |u|² − R²` cancels), and in a
/// dense gas that recomputation was a twelfth of the engine's work (docs/toi.md).
/// Touching, closing pairs are `Some(0)`, as with [`ball_ball`]. `None` for a pair that
/// recedes, misses, meets beyond the horizon or, as for [`Status::NotConverged`],
/// overflows.
///
/// ```
/// use carom_toi::{relative_contact_time, Window};
/// use nalgebra::Vector2;
///
/// // Ball 2 three units ahead, ball 1 closing at 1 unit per second; radii sum to 1.
/// let (offset, velocity) = (Vector2::new(3.0, 0.0), Vector2::new(-1.0, 0.0));
/// let within = |horizon| Window::forward(horizon);
/// assert_eq!(relative_contact_time(&offset, &velocity, 1.0, &within(10.0)?, 0.0), Some(2.0));
/// assert_eq!(relative_contact_time(&offset, &velocity, 1.0, &within(1.0)?, 0.0), None);
/// # Ok::<(), carom_math::InvalidValue>(())
/// ```
#[inline]
pub fn relative_contact_time<T: Real, const D: usize>(
    offset: &Vector<T, D>,
    velocity: &Vector<T, D>,
    radius: T,
    window: &Window<T>,
    reach: T,
) -> Option<T> {
    if certainly_clear(
        offset,
        velocity,
        radius,
        window.direction().sign(),
        window.horizon(),
    ) {
        return None;
    }
    relative_time(offset, velocity, radius, window, reach)
}

/// [`relative_contact_time`] for a pair not proven to recede or miss, out of line, in
/// `f64` whatever `T` is.
#[inline(never)]
fn relative_time<T: Real, const D: usize>(
    offset: &Vector<T, D>,
    velocity: &Vector<T, D>,
    radius: T,
    window: &Window<T>,
    reach: T,
) -> Option<T> {
    let wide = |v: &Vector<T, D>| v.map(T::to_f64);
    let gap = LinearSphere::new(
        wide(offset),
        window.direction().orient(&wide(velocity)),
        radius.to_f64(),
    );
    let budget = Budget {
        relative: root_budget::<T>(),
        reach: reach.to_f64(),
    };
    match gap.first_contact(window.horizon().to_f64(), budget) {
        LinearContact::At(s) => Some(window.signed(T::lit(s))),
        LinearContact::Immediate => Some(window.signed(T::zero())),
        LinearContact::Clear | LinearContact::Overflow => None,
    }
}

/// The relative error allowed for a plain root: 12 u in f64; for f32 output a sixteenth
/// of its unit roundoff, so that the final rounding to f32 is the only visible error.
fn root_budget<T: Real>() -> f64 {
    (6.0 * f64::EPSILON).max(T::EPSILON.to_f64() / 32.0)
}

/// A linear pair not proven to recede or miss, computed in `f64` whatever `T` is: for
/// `f32` input every difference and product is then exact, for `f64` it is the working
/// precision.
#[inline(never)]
fn linear_ball_ball<T: Real, const D: usize>(
    ball1: &Ball<T, D>,
    motion1: &Kinematics<T, D>,
    ball2: &Ball<T, D>,
    motion2: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D> {
    match linear_gap(
        ball1,
        &motion1.velocity(),
        ball2,
        &motion2.velocity(),
        window,
    ) {
        (LinearContact::Clear, _) => Toi::no_hit(window.direction().sign(), ()),
        (LinearContact::At(s), gap) => linear_contact(Status::Hit, s, &gap, ball1, motion1, window),
        (LinearContact::Immediate, gap) => {
            linear_contact(Status::AlreadyTouching, 0.0, &gap, ball1, motion1, window)
        }
        (LinearContact::Overflow, _) => Toi::not_converged(T::zero(), ()),
    }
}

/// The first contact of a linear pair in search time, and its gap, in `f64`.
#[inline]
fn linear_gap<T: Real, const D: usize>(
    ball1: &Ball<T, D>,
    velocity1: &Vector<T, D>,
    ball2: &Ball<T, D>,
    velocity2: &Vector<T, D>,
    window: &Window<T>,
) -> (LinearContact<f64>, LinearSphere<f64, D>) {
    // Computed in f64 whatever `T` is: for f32 input every difference and product is
    // then exact, for f64 it is the working precision.
    let wide = |v: Vector<T, D>| v.map(T::to_f64);
    let gap = LinearSphere::new(
        wide(ball2.center()) - wide(ball1.center()),
        window
            .direction()
            .orient(&(wide(*velocity2) - wide(*velocity1))),
        ball1.radius().to_f64() + ball2.radius().to_f64(),
    );
    let budget = Budget {
        relative: root_budget::<T>(),
        reach: 0.0,
    };
    (gap.first_contact(window.horizon().to_f64(), budget), gap)
}

/// The contact of a linear pair at search time `s`: two square roots in all (the root
/// and the normal's length).
fn linear_contact<T: Real, const D: usize>(
    status: Status,
    s: f64,
    gap: &LinearSphere<f64, D>,
    ball1: &Ball<T, D>,
    motion1: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D> {
    let t = window.signed(T::lit(s));
    let offset = gap.offset(s);
    let dist = offset.norm();
    let normal = unit_or(&offset, dist, gap.velocity());
    let r1 = ball1.radius().to_f64();
    Toi {
        status,
        time: t,
        normal: normal.map(T::lit),
        point: ball1.center()
            + motion1.displacement(t)
            + (normal * (r1 + (dist - gap.radius()) * 0.5)).map(T::lit),
        feature: (),
    }
}

/// Differing accelerations: the quartic gap of `SphereGap`.
#[inline(never)]
fn ballistic_ball_ball<T: Real, const D: usize>(
    ball1: &Ball<T, D>,
    motion1: &Kinematics<T, D>,
    ball2: &Ball<T, D>,
    motion2: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D> {
    let gap = SphereGap::new(
        ball2.center() - ball1.center(),
        window
            .direction()
            .orient(&(motion2.velocity() - motion1.velocity())),
        (motion2.acceleration() - motion1.acceleration()) * T::lit(0.5),
        ball1.radius() + ball2.radius(),
    );
    let contact = |status, s: T| {
        let t = window.signed(s);
        let u = gap.offset(s);
        let dist = u.norm();
        let normal = unit_or(&u, dist, &(-gap.offset(T::zero()) + gap.offset(T::one())));
        let c1 = ball1.center() + motion1.displacement(t);
        Toi {
            status,
            time: t,
            normal,
            point: c1
                + normal
                    * (ball1.radius() + (dist - ball1.radius() - ball2.radius()) * T::lit(0.5)),
            feature: (),
        }
    };
    if gap.closing_at_start() {
        return contact(Status::AlreadyTouching, T::zero());
    }
    match gap.first_descent(T::zero(), window.horizon(), gap.gap(T::zero()) > T::zero()) {
        Some(Descent::At(s)) => contact(Status::Hit, s),
        Some(Descent::Clear { .. }) => Toi::no_hit(window.direction().sign(), ()),
        None => Toi::not_converged(T::zero(), ()),
    }
}

/// `v / length`, or the normalised `fallback` (or the first axis) when `length` is zero:
/// coincident centres have no direction of their own.
pub(crate) fn unit_or<T: Real, const D: usize>(
    v: &Vector<T, D>,
    length: T,
    fallback: &Vector<T, D>,
) -> Vector<T, D> {
    if length > T::zero() && length.finite() {
        return v / length;
    }
    let f = fallback.norm();
    if f > T::zero() && f.finite() {
        fallback / f
    } else {
        let mut e = Vector::zeros();
        e[0] = T::one();
        e
    }
}
