//! A ball against a box ([`Aabb`] or [`Obb`]), static or translating, with linear or
//! accelerated relative motion: the exact first contact with the faces, edges (3D) and
//! corners of the rounded box.
//!
//! Method. In the box's frame the ball's centre moves on `x(t) = x₀ + w t + A t²`
//! (`A` = half the relative acceleration; the box does not rotate). The ball touches the
//! box when the distance from `x(t)` to the box `[−h, h]` equals `r`. That distance is
//! `|x − clamp(x, −h, h)|`, and which axes the clamp acts on — the region of the centre
//! (face, edge or corner Voronoi region) — changes only when some `xᵢ(t) = ±hᵢ`, at the
//! roots of `2·D` quadratics (closed form). Between consecutive such times the region
//! is fixed, and the gap is
//!
//! * a **face** (outside on one axis `i`, side `σ`): `σ xᵢ(t) − hᵢ − r`, a quadratic;
//! * an **edge** (3D) or **corner**: `|u(t)| − r` with `u` the offset from the edge line
//!   or the corner (the other components zero): the `SphereGap` of two balls, a
//!   quadratic for linear motion (cancellation-free root) and a quartic under gravity
//!   (bracketed roots);
//! * inside the box itself: negative.
//!
//! The distance to a convex set is continuous, so the gaps of adjacent regions agree at
//! the breakpoints, and the first descent of the whole gap is the first descent found
//! walking the intervals in order, carrying whether the gap has been positive. This
//! handles every case with one loop: linear or ballistic, 2D or 3D, starting apart,
//! touching, or overlapping and leaving (a ballistic ball can leave and come back).
//!
//! Linear motion first takes the early exits of `entry`: the slab test against the box
//! grown by `r` (most misses leave there, without a square root), and Ericson's direct
//! face test at the entry into the grown box (most face hits). What remains, entries near
//! an edge or a corner and balls starting within the grown box, is walked, and only over
//! the interval in which the centre is inside the grown box.
//!
//! Guarantees: at most `4·D` breakpoints and `4·D + 1` intervals; each interval's answer
//! is a closed form or a bracketed ITP refinement on a monotone piece (never an
//! unbracketed Newton step), so a contact is never skipped, and a tangency (a graze that
//! touches without entering) is not reported. Contacts are found to machine precision in
//! time; the interval walk adds no approximation.

mod entry;

use carom_geometry::{Aabb, Ball, Obb};
use carom_math::{Real, Rotation, Vector};

use crate::roots::{Descent, Quadratic, SphereGap, closing};
use crate::{BoxFeature, Kinematics, Status, Toi, Window};
use entry::Entry;

/// The first contact of a ball with an axis-aligned box. `box_motion` is the box's own
/// (non-rotating) motion; only the relative motion matters.
///
/// The normal points from the ball into the box; the point is the closest point of the
/// box at the time of contact (on its surface). The feature is the face, edge or corner
/// touched ([`BoxFeature::Inside`] when the centre starts inside the box).
pub fn ball_aabb<T: Real, const D: usize>(
    ball: &Ball<T, D>,
    ball_motion: &Kinematics<T, D>,
    aabb: &Aabb<T, D>,
    box_motion: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D, BoxFeature> {
    let half = T::lit(0.5);
    let center = (aabb.min() + aabb.max()) * half;
    let frame = BoxFrame {
        center,
        half_extents: aabb.max() - center,
        rotation: None,
    };
    frame.first_contact(ball, ball_motion, box_motion, window)
}

/// The first contact of a ball with an oriented box moving without rotation; as
/// [`ball_aabb`], in the box's frame.
pub fn ball_obb<T: Real, const D: usize>(
    ball: &Ball<T, D>,
    ball_motion: &Kinematics<T, D>,
    obb: &Obb<T, D>,
    box_motion: &Kinematics<T, D>,
    window: &Window<T>,
) -> Toi<T, D, BoxFeature> {
    let frame = BoxFrame {
        center: obb.center(),
        half_extents: obb.half_extents(),
        rotation: Some(obb.rotation()),
    };
    frame.first_contact(ball, ball_motion, box_motion, window)
}

/// A box as its centre, half extents and (unless axis-aligned) rotation.
struct BoxFrame<'a, T: Real, const D: usize> {
    center: Vector<T, D>,
    half_extents: Vector<T, D>,
    rotation: Option<&'a Rotation<T, D>>,
}

impl<T: Real, const D: usize> BoxFrame<'_, T, D> {
    fn to_local(&self, v: &Vector<T, D>) -> Vector<T, D> {
        self.rotation.map_or(*v, |r| r.inverse_transform_vector(v))
    }

    fn to_world(&self, v: &Vector<T, D>) -> Vector<T, D> {
        self.rotation.map_or(*v, |r| r * v)
    }

    fn first_contact(
        &self,
        ball: &Ball<T, D>,
        ball_motion: &Kinematics<T, D>,
        box_motion: &Kinematics<T, D>,
        window: &Window<T>,
    ) -> Toi<T, D, BoxFeature> {
        let motion = LocalMotion {
            x0: self.to_local(&(ball.center() - self.center)),
            w: self.to_local(
                &window
                    .direction()
                    .orient(&(ball_motion.velocity() - box_motion.velocity())),
            ),
            half_acceleration: self.to_local(
                &((ball_motion.acceleration() - box_motion.acceleration()) * T::lit(0.5)),
            ),
            h: self.half_extents,
            r: ball.radius(),
        };
        let contact = |status, s: T, feature| {
            let t = window.signed(s);
            let x = motion.at(s);
            let q = x.inf(&motion.h).sup(&-motion.h);
            let u = x - q;
            let dist = u.norm();
            let outward = if dist > T::zero() {
                u / dist
            } else {
                motion.least_penetration_normal(&x)
            };
            Toi {
                status,
                time: t,
                normal: self.to_world(&-outward),
                point: self.center + box_motion.displacement(t) + self.to_world(&q),
                feature,
            }
        };
        match motion.first_contact(window.horizon()) {
            Event::Immediate(feature) => contact(Status::AlreadyTouching, T::zero(), feature),
            Event::At(s, feature) => contact(Status::Hit, s, feature),
            Event::Clear => Toi::no_hit(window.direction().sign(), BoxFeature::Face),
            Event::Overflow => Toi::not_converged(T::zero(), BoxFeature::Face),
        }
    }
}

/// What the interval walk found.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Event<T> {
    Immediate(BoxFeature),
    At(T, BoxFeature),
    Clear,
    Overflow,
}

/// The ball's centre relative to the box, in the box frame, in search time `s >= 0`.
struct LocalMotion<T: Real, const D: usize> {
    x0: Vector<T, D>,
    w: Vector<T, D>,
    half_acceleration: Vector<T, D>,
    h: Vector<T, D>,
    r: T,
}

/// The gap in one region of the box's exterior.
enum RegionGap<T: Real, const D: usize> {
    /// Outside on one axis: a signed quadratic distance to the face plane.
    Face(Quadratic<T>),
    /// Outside on several axes: distance to an edge line or a corner.
    Round(SphereGap<T, D>),
    /// Inside the box: the gap is negative.
    Inside,
}

impl<T: Real, const D: usize> LocalMotion<T, D> {
    fn at(&self, s: T) -> Vector<T, D> {
        self.x0 + (self.w + self.half_acceleration * s) * s
    }

    /// The outward normal of the face the centre is least deep behind (centre inside).
    fn least_penetration_normal(&self, x: &Vector<T, D>) -> Vector<T, D> {
        let axis = (0..D)
            .min_by(|&i, &j| {
                (self.h[i] - x[i].abs())
                    .partial_cmp(&(self.h[j] - x[j].abs()))
                    .unwrap_or(core::cmp::Ordering::Equal)
            })
            .unwrap_or(0);
        let mut n = Vector::zeros();
        n[axis] = x[axis].copysign_one();
        n
    }

    /// The sign of the region on each axis at time `s` (`±1` outside the slab, 0 inside)
    /// and the number of outside axes.
    fn region(&self, s: T) -> ([T; D], usize) {
        let x = self.at(s);
        let mut signs = [T::zero(); D];
        let mut outside = 0;
        for i in 0..D {
            if x[i] > self.h[i] {
                signs[i] = T::one();
            } else if x[i] < -self.h[i] {
                signs[i] = -T::one();
            } else {
                continue;
            }
            outside += 1;
        }
        (signs, outside)
    }

    fn region_gap(&self, signs: &[T; D], outside: usize) -> RegionGap<T, D> {
        match outside {
            0 => RegionGap::Inside,
            1 => {
                let i = (0..D).find(|&i| signs[i] != T::zero()).unwrap_or(0);
                let sigma = signs[i];
                let half = T::lit(0.5);
                RegionGap::Face(Quadratic::new(
                    sigma * self.half_acceleration[i],
                    sigma * self.w[i] * half,
                    (sigma * self.x0[i] - self.h[i]) - self.r,
                ))
            }
            _ => {
                let mask = |v: &Vector<T, D>| {
                    Vector::<T, D>::from_fn(|i, _| {
                        if signs[i] == T::zero() {
                            T::zero()
                        } else {
                            v[i]
                        }
                    })
                };
                let corner = Vector::<T, D>::from_fn(|i, _| signs[i] * self.h[i]);
                RegionGap::Round(SphereGap::new(
                    mask(&(self.x0 - corner)),
                    mask(&self.w),
                    mask(&self.half_acceleration),
                    self.r,
                ))
            }
        }
    }

    /// The times in `(lo, hi)` where the centre crosses a slab boundary `xᵢ = ±hᵢ`,
    /// sorted.
    fn breakpoints(&self, lo: T, hi: T) -> ([T; 12], usize) {
        let mut out = [T::zero(); 12];
        let mut n = 0;
        let half = T::lit(0.5);
        for i in 0..D {
            for level in [self.h[i], -self.h[i]] {
                let q = Quadratic::new(
                    self.half_acceleration[i],
                    self.w[i] * half,
                    self.x0[i] - level,
                );
                let (roots, m) = q.roots();
                for &t in &roots[..m] {
                    if t > lo && t < hi && n < out.len() {
                        out[n] = t;
                        n += 1;
                    }
                }
            }
        }
        // Insertion sort: at most 12 values.
        for k in 1..n {
            let mut j = k;
            while j > 0 && out[j - 1] > out[j] {
                out.swap(j - 1, j);
                j -= 1;
            }
        }
        (out, n)
    }

    fn first_contact(&self, hi: T) -> Event<T> {
        let finite = |i: usize| {
            self.x0[i].finite() && self.w[i].finite() && self.half_acceleration[i].finite()
        };
        if !(0..D).all(finite) {
            return Event::Overflow;
        }
        if self.half_acceleration.iter().all(|&a| a == T::zero()) {
            // Linear: the slab test and the direct face test first (`entry`).
            match entry::slab_entry(&self.x0, &self.w, &self.h, self.r, hi) {
                Entry::Never => return Event::Clear,
                Entry::Inside => {}
                Entry::Between { from, to, axis } => {
                    let face = entry::face_contact(&self.x0, &self.w, &self.h, self.r, axis, hi);
                    if let Some(t) = face {
                        return Event::At(t, BoxFeature::from_outside_axes(1, D));
                    }
                    // Apart before `from`, never touching after `to`: walk from the last
                    // region boundary before `from` (armed), exactly as the full walk
                    // does from there on, and stop at `to`.
                    let (breaks, n) = self.breakpoints(T::zero(), to);
                    let start = breaks[..n].iter().rposition(|&b| b <= from);
                    let lo = start.map_or(T::zero(), |k| breaks[k]);
                    return self.walk_from(
                        &breaks[start.map_or(0, |k| k + 1)..n],
                        lo,
                        to,
                        T::one(),
                    );
                }
            }
        }
        let q0 = self.x0.inf(&self.h).sup(&-self.h);
        self.walk(T::zero(), hi, (self.x0 - q0).norm() - self.r)
    }

    /// The region walk on `[lo, hi]`: `gap_lo` is the gap at `lo` (any positive value
    /// when only its sign is known); at `lo = 0` a touching or overlapping start is
    /// decided by the rate of the region it moves into.
    fn walk(&self, lo: T, hi: T, gap_lo: T) -> Event<T> {
        let (breaks, n) = self.breakpoints(lo, hi);
        self.walk_from(&breaks[..n], lo, hi, gap_lo)
    }

    /// [`walk`](Self::walk) given the region boundaries in `(lo, hi)`, sorted.
    fn walk_from(&self, breaks: &[T], lo: T, hi: T, gap_lo: T) -> Event<T> {
        let ends = breaks.iter().copied().chain(core::iter::once(hi));
        let mut armed = gap_lo > T::zero();
        let mut lo = lo;
        for (k, end) in ends.enumerate() {
            if end <= lo && k > 0 {
                continue;
            }
            let probe = if end.finite() {
                lo + (end - lo) * T::lit(0.5)
            } else {
                lo + T::one() + lo.abs()
            };
            let (signs, outside) = self.region(probe);
            let feature = BoxFeature::from_outside_axes(outside, D);
            let region = self.region_gap(&signs, outside);
            if k == 0 && gap_lo <= T::zero() && self.closing_at_start(&region, gap_lo) {
                let at_start = BoxFeature::from_outside_axes(self.region(T::zero()).1, D);
                return Event::Immediate(at_start);
            }
            let descent = match &region {
                RegionGap::Face(q) => Some(q.first_descent(lo, end, armed)),
                RegionGap::Round(s) => s.first_descent(lo, end, armed),
                RegionGap::Inside if armed => Some(Descent::At(lo)),
                RegionGap::Inside => Some(Descent::Clear { armed }),
            };
            match descent {
                Some(Descent::At(s)) => return Event::At(s, feature),
                Some(Descent::Clear { armed: now }) => armed = now,
                None => return Event::Overflow,
            }
            lo = end;
        }
        Event::Clear
    }

    /// Whether a ball touching or overlapping the rounded box at time 0 closes on it:
    /// the rate of the gap of the region it moves into, or, with its centre inside the
    /// box, its motion along the normal of the nearest face.
    fn closing_at_start(&self, region: &RegionGap<T, D>, gap0: T) -> bool {
        match region {
            RegionGap::Face(q) => closing(
                gap0,
                q.rate(T::zero()),
                q.rate(T::one()) - q.rate(T::zero()),
            ),
            RegionGap::Round(s) => s.closing_at_start(),
            RegionGap::Inside => {
                let inside = (0..D).all(|i| self.x0[i].abs() < self.h[i]);
                if !inside {
                    return true; // on the box surface, moving into it
                }
                let n = self.least_penetration_normal(&self.x0);
                closing(gap0, n.dot(&self.w), n.dot(&self.half_acceleration))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The full walk from time 0, without the early exits.
    fn walked<const D: usize>(m: &LocalMotion<f64, D>, hi: f64) -> Event<f64> {
        let q0 = m.x0.inf(&m.h).sup(&-m.h);
        m.walk(0.0, hi, (m.x0 - q0).norm() - m.r)
    }

    fn motion<const D: usize>(
        x0: [f64; D],
        w: [f64; D],
        h: [f64; D],
        r: f64,
    ) -> LocalMotion<f64, D> {
        LocalMotion {
            x0: Vector::from(x0),
            w: Vector::from(w),
            half_acceleration: Vector::zeros(),
            h: Vector::from(h),
            r,
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// The slab test and the direct face test change nothing: the same event, time
        /// and feature as walking every region from time 0 (3D).
        #[test]
        fn early_exits_agree_with_the_full_walk_3d(
            x0 in prop::array::uniform3(-6.0..6.0f64), w in prop::array::uniform3(-3.0..3.0f64),
            h in prop::array::uniform3(0.1..1.5f64), r in 0.05..1.0f64, hi in 0.5..20.0f64,
        ) {
            let m = motion(x0, w, h, r);
            prop_assert_eq!(m.first_contact(hi), walked(&m, hi));
        }

        /// The same in 2D, with velocities along an axis (parallel to a face), entries
        /// aimed at the corner of the grown box, and entries at the end of a face, where
        /// the face test must leave the decision to the walk.
        #[test]
        fn early_exits_agree_with_the_full_walk_2d(
            x0 in prop::array::uniform2(-6.0..6.0f64), w in prop::array::uniform2(-3.0..3.0f64),
            h in prop::array::uniform2(0.1..1.5f64), r in 0.05..1.0f64, aim in 0..4,
        ) {
            let (mut x0, mut w) = (x0, w);
            match aim {
                // Parallel to the x faces.
                0 => w[1] = 0.0,
                // At the corner of the grown box: y = ±(h + r) on entry.
                1 => x0[1] = (h[1] + r).copysign(x0[1]),
                // At the end of the x face: y = ±h when x enters the grown slab.
                2 => {
                    let t = (x0[0].abs() - h[0] - r) / w[0].abs();
                    x0[1] = h[1].copysign(x0[1]) - w[1] * t;
                }
                _ => {}
            }
            let m = motion(x0, w, h, r);
            prop_assert_eq!(m.first_contact(f64::INFINITY), walked(&m, f64::INFINITY));
        }
    }

    #[test]
    fn a_face_hit_leaves_at_the_face_test_and_a_miss_at_the_slab_test() {
        let m = motion([-4.0, 0.3], [2.0, 0.0], [1.0, 1.0], 0.5);
        assert_eq!(m.first_contact(10.0), Event::At(1.25, BoxFeature::Face));
        let miss = motion([-4.0, 1.6], [2.0, 0.0], [1.0, 1.0], 0.5);
        assert_eq!(miss.first_contact(10.0), Event::Clear);
        let corner = motion([-4.0, 1.3, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0], 0.5);
        assert!(matches!(
            corner.first_contact(10.0),
            Event::At(_, BoxFeature::Edge)
        ));
    }
}
