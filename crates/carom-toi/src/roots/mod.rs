//! Root finding for gap functions: closed-form quadratics, a bracketed ITP solver, and
//! the first "descent" of a gap through zero.
//!
//! Every query reduces to one question about a continuous gap function `g(t)` on an
//! interval: the first time it goes from positive to negative. [`Descent`] is the answer
//! for one interval, and carries whether the gap has already been positive (`armed`), so
//! that intervals chain: a pair that starts overlapping must separate before it can
//! collide again.

mod descent;
mod exact;
mod itp;
mod linear;
mod quadratic;
mod sphere;

pub(crate) use descent::{Descent, first_descent_monotone};
pub(crate) use itp::itp;
pub(crate) use linear::{Budget, LinearContact, LinearSphere, certainly_clear};
pub(crate) use quadratic::Quadratic;
pub(crate) use sphere::SphereGap;

use carom_math::Real;

/// Whether a gap that is `<= 0` at time 0 is closing, from its value, rate and second
/// derivative: a negative rate, or a zero rate with a negative second derivative (the
/// gap goes negative at once). Touching with zero rate and curvature (resting contact
/// whose pressing the caller has cancelled) or a positive curvature (a graze) is not.
///
/// A ball set down at rest on a floor under gravity is closing: it was once taken for
/// resting contact, the gap's descent at 0 was not armed (never positive), and the
/// ball fell through the floor unseen.
#[inline]
pub(crate) fn closing<T: Real>(gap: T, rate: T, curvature: T) -> bool {
    gap <= T::zero() && (rate < T::zero() || (rate == T::zero() && curvature < T::zero()))
}

/// `true` for NaN (the one value not ordered against itself).
#[inline]
pub(crate) fn is_nan<T: Real>(x: T) -> bool {
    x.partial_cmp(&x).is_none()
}
