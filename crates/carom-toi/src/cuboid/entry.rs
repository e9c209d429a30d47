//! The early exits of a linear ball–box query, before the region walk: the slab test
//! against the box grown by the radius, and Ericson's direct face test at the entry.
//!
//! **Slab test.** The rounded box (the points within `r` of the box) lies inside the box
//! grown by `r`, `[−(h + r), h + r]`. On each axis the centre `x₀ᵢ + wᵢ t` is inside the
//! grown slab during one interval of time (all time, or never, when `wᵢ = 0`); if the
//! intervals of the axes do not meet within `[0, horizon]`, the ball never comes within
//! `r` of the box: no contact, with no square root. Otherwise the first contact is at or
//! after the entry `T_in = maxᵢ` (entry time on axis `i`) and, the path being a straight
//! line and the grown box convex, at or before the exit `T_out = minᵢ` (exit times): the
//! walk only needs `[T_in, T_out]`, and the gap is positive before `T_in`.
//!
//! The interval ends are bounded outwards, so that rounding never turns a contact into an
//! exit: the grown half size is `H = fl(fl(h + r)(1 + 4u))`, at least the exact `h + r`
//! (`(1 − u)² (1 + 4u) >= 1`); an entry `(|x₀| − H) / |w|` is computed with two roundings
//! (each within `u`) and multiplied by `1 − 4u`, an exit `(H ± x₀) / |w|` by `1 + 4u`.
//! An axis with `|x₀ᵢ| <= H` counts as inside from time 0.
//!
//! **Face test** (Ericson, *Real-Time Collision Detection*, §5.5.7). If the centre enters
//! the grown box through the face `σ eₖ` (it starts outside on axis `k` and `k` is the
//! axis of the last entry) at a time `t` when every other coordinate is strictly within
//! the box's own slab, `|xⱼ(t)| < hⱼ`, then the first contact is that face at `t`: before
//! it the distance to the box is at least the distance to the face's plane, which is
//! still more than `r`, and at `t` the closest point is on the face, the ball moving
//! into it. `t` is computed as the region walk computes the face root,
//! `((σ x₀ₖ − hₖ) − r) / |wₖ|` (within `2u (|x₀ₖ| + hₖ + r) / |wₖ| + u t` of exact), and
//! the other coordinates are checked with a margin that covers that error and their own
//! rounding, `|wⱼ| E_t + 4u (|x₀ⱼ| + |wⱼ| t)`. Entries near an edge or a corner (the
//! rounded parts) go to the region walk.

use carom_math::{Real, Vector};

use crate::roots::Quadratic;

/// What the slab test proves about a linear motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Entry<T> {
    /// The centre never enters the grown box within the horizon: no contact.
    Never,
    /// The centre starts inside the grown box on every axis: nothing to skip.
    Inside,
    /// The centre is outside the grown box before `from` and after `to` (`to` capped at
    /// the horizon); `axis` is the axis of the last entry.
    Between {
        /// A lower bound on the entry time (`> 0`).
        from: T,
        /// An upper bound on the exit time, or the horizon if smaller.
        to: T,
        /// The axis the centre enters last through.
        axis: usize,
    },
}

/// The unit roundoff `u = ε/2`.
#[inline]
fn unit<T: Real>() -> T {
    T::EPSILON * T::lit(0.5)
}

/// The slab test (module docs) for the centre `x₀ + w t` and the box `[−h, h]` grown by
/// `r`, up to `horizon`.
pub(super) fn slab_entry<T: Real, const D: usize>(
    x0: &Vector<T, D>,
    w: &Vector<T, D>,
    h: &Vector<T, D>,
    r: T,
    horizon: T,
) -> Entry<T> {
    let four_u = T::lit(4.0) * unit::<T>();
    let (down, up) = (T::one() - four_u, T::one() + four_u);
    let (mut from, mut to) = (T::zero(), horizon);
    let mut axis = None;
    for i in 0..D {
        let grown = (h[i] + r) * up;
        let (x, v) = (x0[i], w[i]);
        if x.abs() <= grown {
            // Inside the grown slab from time 0 until it leaves through the far side.
            if v != T::zero() {
                to = to.min((grown - x * v.copysign_one()) / v.abs() * up);
            }
        } else if x * v < T::zero() {
            // Outside, moving towards the slab.
            let entry = (x.abs() - grown) / v.abs() * down;
            if entry > from || axis.is_none() {
                from = from.max(entry);
                axis = Some(i);
            }
            to = to.min((x.abs() + grown) / v.abs() * up);
        } else {
            return Entry::Never; // outside and not approaching
        }
    }
    match axis {
        None => Entry::Inside,
        Some(_) if from > to => Entry::Never,
        Some(axis) => Entry::Between { from, to, axis },
    }
}

/// The face contact of the direct test (module docs) through the face on `axis` that
/// the centre starts in front of, if every other coordinate is certainly inside the
/// box's slab at that time and the time is within `horizon`.
pub(super) fn face_contact<T: Real, const D: usize>(
    x0: &Vector<T, D>,
    w: &Vector<T, D>,
    h: &Vector<T, D>,
    r: T,
    axis: usize,
    horizon: T,
) -> Option<T> {
    let four_u = T::lit(4.0) * unit::<T>();
    let sigma = x0[axis].copysign_one();
    // The face's quadratic exactly as the region walk builds it.
    let face = Quadratic::new(
        T::zero(),
        sigma * w[axis] * T::lit(0.5),
        (sigma * x0[axis] - h[axis]) - r,
    );
    let t = face.descending_root()?;
    if !(t > T::zero() && t <= horizon) {
        return None;
    }
    let t_err = four_u * ((x0[axis].abs() + h[axis] + r) / w[axis].abs() + t);
    (0..D)
        .filter(|&j| j != axis)
        .all(|j| {
            let x = x0[j] + w[j] * t;
            let margin =
                w[j].abs() * t_err + four_u * (x0[j].abs() + w[j].abs() * t) + T::MIN_POSITIVE;
            x.abs() + margin < h[j]
        })
        .then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn slabs_that_do_not_meet_are_a_miss() {
        let h = Vector2::new(1.0, 1.0);
        // Passing above the grown square (half size 1.5) at height 1.6: never within.
        let e = slab_entry(
            &Vector2::new(-4.0, 1.6),
            &Vector2::new(1.0, 0.0),
            &h,
            0.5,
            100.0,
        );
        assert_eq!(e, Entry::Never);
        // Moving away.
        let e = slab_entry(
            &Vector2::new(-4.0, 0.0),
            &Vector2::new(-1.0, 0.0),
            &h,
            0.5,
            100.0,
        );
        assert_eq!(e, Entry::Never);
        // Diagonal pass outside the grown square's corner: x enters at 1, y leaves at 0.9.
        let e = slab_entry(
            &Vector2::new(-2.5, 0.6),
            &Vector2::new(1.0, 1.0),
            &h,
            0.5,
            100.0,
        );
        assert_eq!(e, Entry::Never);
    }

    #[test]
    fn entry_and_exit_bound_the_exact_times() {
        let h = Vector2::new(1.0, 1.0);
        let Entry::Between { from, to, axis } = slab_entry(
            &Vector2::new(-4.0, 0.3),
            &Vector2::new(2.0, 0.0),
            &h,
            0.5,
            100.0,
        ) else {
            panic!("enters")
        };
        assert_eq!(axis, 0);
        assert!(from <= 1.25 && from > 1.25 * (1.0 - 1e-15), "{from}");
        assert!((2.75..2.75 * (1.0 + 1e-15)).contains(&to), "{to}");
        assert_eq!(
            slab_entry(
                &Vector2::new(-4.0, 0.3),
                &Vector2::new(2.0, 0.0),
                &h,
                0.5,
                1.0
            ),
            Entry::Never,
            "beyond the horizon"
        );
        assert_eq!(
            slab_entry(
                &Vector2::new(0.2, 0.3),
                &Vector2::new(2.0, 0.0),
                &h,
                0.5,
                1.0
            ),
            Entry::Inside
        );
    }

    #[test]
    fn face_test_accepts_faces_and_leaves_corners_to_the_walk() {
        let h = Vector2::new(1.0, 1.0);
        let x0 = Vector2::new(-4.0, 0.3);
        assert_eq!(
            face_contact(&x0, &Vector2::new(2.0, 0.0), &h, 0.5, 0, 100.0),
            Some(1.25)
        );
        // At height 1.3 the entry point is beside the face: a corner, not decided here.
        let x0 = Vector2::new(-4.0, 1.3);
        assert_eq!(
            face_contact(&x0, &Vector2::new(1.0, 0.0), &h, 0.5, 0, 100.0),
            None
        );
        // Exactly at the edge of the face (height 1): not strictly inside, left to the walk.
        let x0 = Vector2::new(-4.0, 1.0);
        assert_eq!(
            face_contact(&x0, &Vector2::new(1.0, 0.0), &h, 0.5, 0, 100.0),
            None
        );
    }
}
