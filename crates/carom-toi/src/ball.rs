//! Ball against ball: exact time of impact under linear or accelerated motion.
//!
//! With `u(t) = c₂(t) − c₁(t)` the relative position and `R = r₁ + r₂`, the balls touch
//! when `|u(t)| = R`. The relative motion is `u(t) = u₀ + w t + (a₂ − a₁) t²/2`:
//!
//! * linear when both balls move at constant velocity, **or when both feel the same
//!   acceleration** (a common gravity cancels): the closed form of DESIGN.md,
//!   `t = c / (−b/2 + √(b²/4 − a c))`, with the accurate `c` and discriminant described
//!   in the `SphereGap` docs (no linear fallback: a slow closing is solved by the same
//!   formula, and `Δ <= 0` is a miss, never an invented collision);
//! * a quartic otherwise, solved by bracketing (see `SphereGap`).
//!
//! Cases, for `gap₀ = |u₀| − R` and the rate `u₀·w`:
//!
//! | state at time 0                         | result                      |
//! |-----------------------------------------|-----------------------------|
//! | apart, closing and meeting              | `Hit` at the first contact  |
//! | apart, receding or missing              | `NoHit`                     |
//! | touching (`gap₀ = 0`), rate `< 0`       | `AlreadyTouching`, time 0   |
//! | touching, rate `>= 0` (receding/resting)| `NoHit` (or a later hit under differing accelerations) |
//! | overlapping, rate `< 0`                 | `AlreadyTouching`, time 0   |
//! | overlapping, rate `>= 0`                | `NoHit` until they separate |

use carom_geometry::Ball;
use carom_math::{Real, Vector};

use crate::roots::{Descent, SphereGap};
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
    let direction = window.direction();
    let gap = SphereGap::new(
        ball2.center() - ball1.center(),
        direction.orient(&(motion2.velocity() - motion1.velocity())),
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
    let descent = if gap.is_linear() {
        // Receding pairs leave before any square root; a closing pair in contact has a
        // descending root <= 0 and is immediate.
        match gap.linear_first_contact(window.horizon()) {
            Some(Descent::At(s)) if s == T::zero() || gap.gap(T::zero()) <= T::zero() => {
                return contact(Status::AlreadyTouching, T::zero());
            }
            other => other,
        }
    } else {
        if gap.closing_at_start() {
            return contact(Status::AlreadyTouching, T::zero());
        }
        gap.first_descent(T::zero(), window.horizon(), gap.gap(T::zero()) > T::zero())
    };
    match descent {
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
