//! A ball inside a reflecting [`Border`]: the first wall it hits.
//!
//! Each of the `2·D` walls is a plane: on axis `i` the lower wall's gap is
//! `(cᵢ − minᵢ) − r` and the upper wall's `(maxᵢ − cᵢ) − r`, each a quadratic in time
//! (linear without acceleration). The first contact is the earliest descending root over
//! the walls; under gravity a ball moving up still reaches the floor.
//!
//! A ball that starts partly (or wholly) outside and keeps moving out is
//! [`Status::AlreadyTouching`] that wall: reflecting it brings it back, where PhET's
//! engine lets it escape for good. When several walls are touched and closed on at
//! time 0 (a corner), the deepest is reported; the engine reflects it and asks again.

use carom_geometry::{Ball, Border};
use carom_math::{Real, Vector};

use crate::plane::line_gap;
use crate::roots::{Descent, closing};
use crate::{Kinematics, Side, Status, Toi, Wall, Window};

/// The first wall contact of a ball inside a reflecting border.
///
/// The normal points from the ball into the wall (`−eᵢ` for a lower wall, `+eᵢ` for an
/// upper one); the point is on the wall, level with the centre.
pub fn ball_border<T: Real, const D: usize>(
    ball: &Ball<T, D>,
    motion: &Kinematics<T, D>,
    border: &Border<T, D>,
    window: &Window<T>,
) -> Toi<T, D, Wall> {
    let (c, r) = (ball.center(), ball.radius());
    let v = window.direction().orient(&motion.velocity());
    let a = motion.acceleration();
    let (min, max) = (border.min(), border.max());
    let mut immediate: Option<(T, Wall)> = None;
    let mut first: Option<(T, Wall)> = None;
    for axis in 0..D {
        for side in [Side::Lower, Side::Upper] {
            let (gap0, outward) = match side {
                Side::Lower => ((c[axis] - min[axis]) - r, -T::one()),
                Side::Upper => ((max[axis] - c[axis]) - r, T::one()),
            };
            let (rate, acceleration) = (-outward * v[axis], -outward * a[axis]);
            let wall = Wall { axis, side };
            if closing(gap0, rate, acceleration) {
                if immediate.is_none_or(|(deepest, _)| gap0 < deepest) {
                    immediate = Some((gap0, wall));
                }
                continue;
            }
            let gap = line_gap(gap0, rate, acceleration);
            if !gap.is_finite() {
                return Toi::not_converged(T::zero(), wall);
            }
            let horizon = first.map_or(window.horizon(), |(s, _)| s);
            if let Descent::At(s) = gap.first_descent(T::zero(), horizon, gap0 > T::zero())
                && first.is_none_or(|(best, _)| s < best)
            {
                first = Some((s, wall));
            }
        }
    }
    let contact = |status, s: T, wall: Wall| {
        let t = window.signed(s);
        let mut point = c + motion.displacement(t);
        let mut normal = Vector::<T, D>::zeros();
        let (level, out) = match wall.side {
            Side::Lower => (min[wall.axis], -T::one()),
            Side::Upper => (max[wall.axis], T::one()),
        };
        point[wall.axis] = level;
        normal[wall.axis] = out;
        Toi {
            status,
            time: t,
            normal,
            point,
            feature: wall,
        }
    };
    match (immediate, first) {
        (Some((_, wall)), _) => contact(Status::AlreadyTouching, T::zero(), wall),
        (None, Some((s, wall))) => contact(Status::Hit, s, wall),
        (None, None) => Toi::no_hit(
            window.direction().sign(),
            Wall {
                axis: 0,
                side: Side::Lower,
            },
        ),
    }
}
