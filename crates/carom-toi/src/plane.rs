//! A ball against a static plane (a [`HalfSpace`]), and the time a centre crosses a
//! plane or a level (the faces of periodic cells).
//!
//! Along the plane's unit normal `n` the motion is one-dimensional: the gap
//! `g(t) = n·c(t) − offset − r = g₀ + v t + a t²/2` with `v = n·velocity`,
//! `a = n·acceleration`. Linear motion gives a line, gravity a parabola, and the first
//! contact is the descending root of that quadratic (see `Quadratic`): under gravity
//! a ball moving away from a floor still hits it once it falls back.

use carom_geometry::{Ball, HalfSpace};
use carom_math::{Real, Vector};

use crate::roots::{Descent, Quadratic, closing};
use crate::{Crossing, Kinematics, Side, Status, Toi, Window};

/// The gap `g₀ + v s + a s²/2` as a quadratic in the search time `s`.
#[inline]
pub(crate) fn line_gap<T: Real>(gap0: T, rate: T, acceleration: T) -> Quadratic<T> {
    let half = T::lit(0.5);
    Quadratic::new(acceleration * half, rate * half, gap0)
}

/// The first contact of a ball with the solid side of a plane.
///
/// A ball on the solid side (overlapping) and moving deeper is [`Status::AlreadyTouching`];
/// one moving out is not reported until it has left and comes back. The normal is the
/// plane's inward normal `−n` (from the ball into the solid); the point is on the plane.
pub fn ball_plane<T: Real, const D: usize>(
    ball: &Ball<T, D>,
    motion: &Kinematics<T, D>,
    plane: &HalfSpace<T, D>,
    window: &Window<T>,
) -> Toi<T, D> {
    let n = plane.normal();
    let gap0 = plane.signed_distance(&ball.center()) - ball.radius();
    let rate = n.dot(&window.direction().orient(&motion.velocity()));
    let acceleration = n.dot(&motion.acceleration());
    let contact = |status, s: T| {
        let t = window.signed(s);
        let center = ball.center() + motion.displacement(t);
        Toi {
            status,
            time: t,
            normal: -n,
            point: plane.project(&center),
            feature: (),
        }
    };
    if closing(gap0, rate, acceleration) {
        return contact(Status::AlreadyTouching, T::zero());
    }
    let gap = line_gap(gap0, rate, acceleration);
    if !gap.is_finite() {
        return Toi::not_converged(T::zero(), ());
    }
    match gap.first_descent(T::zero(), window.horizon(), gap0 > T::zero()) {
        Descent::At(s) => contact(Status::Hit, s),
        Descent::Clear { .. } => Toi::no_hit(window.direction().sign(), ()),
    }
}

/// The first time the centre of a body moving from `center` with `motion` crosses the
/// plane's boundary, to the other side from the one it is on just after now.
///
/// [`Side::Upper`] is the free side (where the normal points), [`Side::Lower`] the solid
/// side. A centre that starts on the plane belongs to the side it moves into; one that
/// stays on the plane never crosses.
pub fn plane_crossing<T: Real, const D: usize>(
    center: &Vector<T, D>,
    motion: &Kinematics<T, D>,
    plane: &HalfSpace<T, D>,
    window: &Window<T>,
) -> Crossing<T> {
    let n = plane.normal();
    level_crossing(
        plane.signed_distance(center),
        n.dot(&motion.velocity()),
        n.dot(&motion.acceleration()),
        T::zero(),
        window,
    )
}

/// The first time a coordinate `x(t) = x + v t + a t²/2` crosses `level`, to the other
/// side from the one it is on just after now (the side of the first non-zero of
/// `x − level`, `v`, `a`). For the axis-aligned faces of periodic cells, pass one
/// component of the position, velocity and acceleration.
///
/// Non-finite input gives [`Status::NotConverged`].
pub fn level_crossing<T: Real>(x: T, v: T, a: T, level: T, window: &Window<T>) -> Crossing<T> {
    let sign = window.direction().sign::<T>();
    let (offset, rate) = (x - level, v * sign);
    let side = [offset, rate, a]
        .into_iter()
        .find(|&q| q != T::zero())
        .map(T::copysign_one);
    let none = |status| Crossing {
        status,
        time: T::INFINITY * sign,
        to: Side::Upper,
    };
    let Some(side) = side else {
        return none(if offset.finite() && rate.finite() {
            Status::NoHit
        } else {
            Status::NotConverged
        });
    };
    // The distance to the level measured towards the side the centre is on.
    let gap = line_gap(offset * side, rate * side, a * side);
    if !gap.is_finite() {
        return none(Status::NotConverged);
    }
    match gap.descending_root() {
        Some(s) if s > T::zero() && s <= window.horizon() => Crossing {
            status: Status::Hit,
            time: window.signed(s),
            to: if side > T::zero() {
                Side::Lower
            } else {
                Side::Upper
            },
        },
        _ => none(Status::NoHit),
    }
}
