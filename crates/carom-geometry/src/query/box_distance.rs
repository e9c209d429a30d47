//! The exact distance between two disjoint boxes, from their closest features.
//!
//! The closest points of two disjoint convex polytopes lie on a pair of features, and some
//! closest pair always involves a vertex of one box and the solid other box, or (in 3D
//! only) an edge of each. So the distance is the smallest of
//!
//! * every corner of A against the solid box B (a clamp in B's frame), and vice versa;
//! * in 3D, every edge of A against every edge of B (segment–segment, Ericson §5.1.9).
//!
//! In 2D two disjoint convex polygons always have a closest pair with a vertex in it, so
//! the edge pairs add nothing and are skipped. At most that is 8 point–box tests in 2D,
//! 16 point–box and 144 segment–segment tests in 3D; the separating axis from the SAT
//! prunes every feature pair that cannot beat the best distance found so far, which
//! leaves the few features facing each other. No allocation. Every candidate is a true
//! pair of points of the two boxes, so rounding can only make a candidate slightly long,
//! never report less than the distance by more than rounding.

use carom_math::{Real, Vector};

use crate::query::sat::RelativeBoxes;

/// The corner `k` of the box `[−h, h]`: `+h[i]` where bit `i` of `k` is set.
#[inline]
fn corner<T: Real, const D: usize>(h: &Vector<T, D>, k: usize) -> Vector<T, D> {
    Vector::<T, D>::from_fn(|i, _| if k >> i & 1 == 1 { h[i] } else { -h[i] })
}

/// The distance from `p` to the solid box `[−h, h]`.
#[inline]
fn point_box_distance_squared<T: Real, const D: usize>(p: &Vector<T, D>, h: &Vector<T, D>) -> T {
    (p - p.sup(&-h).inf(h)).norm_squared()
}

/// The squared distance between the segments `[p1, q1]` and `[p2, q2]` (Ericson,
/// *Real-Time Collision Detection* §5.1.9), with zero-length segments as points.
///
/// Minimises `|p1 + s d1 − p2 − t d2|²` over `s, t ∈ [0, 1]`: the unclamped `s` solves the
/// 2×2 normal equations, `t` follows from `s`, and each is re-clamped once. Parallel
/// segments (`a e − b² = 0`) take `s = 0`, which is one of the minimisers.
fn segment_segment_distance_squared<T: Real, const D: usize>(
    p1: &Vector<T, D>,
    q1: &Vector<T, D>,
    p2: &Vector<T, D>,
    q2: &Vector<T, D>,
) -> T {
    let (zero, one) = (T::zero(), T::one());
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t) = if a == zero && e == zero {
        (zero, zero)
    } else if a == zero {
        (zero, (f / e).clamp(zero, one))
    } else {
        let c = d1.dot(&r);
        if e == zero {
            ((-c / a).clamp(zero, one), zero)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s = if denom > zero {
                ((b * f - c * e) / denom).clamp(zero, one)
            } else {
                zero
            };
            let t = (b * s + f) / e;
            if t < zero {
                ((-c / a).clamp(zero, one), zero)
            } else if t > one {
                (((b - c) / a).clamp(zero, one), one)
            } else {
                (s, t)
            }
        }
    };
    (r + d1 * s - d2 * t).norm_squared()
}

impl<T: Real, const D: usize> RelativeBoxes<T, D> {
    /// The distance between the boxes, for boxes separated along `axis` (unit, in A's
    /// frame, from B towards A, as [`RelativeBoxes::separation`] returns it with a
    /// positive gap). For overlapping boxes the result is not meaningful.
    ///
    /// The separating axis prunes the search. Along `u = −axis` every point of A lies at
    /// or below `max_A = Σ hA_i |u_i|` and every point of B at or above
    /// `min_B = t·u − Σ hB_j |(Rᵀu)_j|`, so a feature pair whose projections are `g` apart
    /// on `u` is at least `g` apart in space. Features are tried after the two support
    /// corners (A's highest and B's lowest on `u`, which give a first bound), and any
    /// whose projected gap already exceeds the best distance found is skipped: only the
    /// features facing each other are measured.
    pub(crate) fn disjoint_distance(&self, axis: &Vector<T, D>) -> T {
        let corners = 1usize << D;
        let u = -axis;
        let u_in_b = self.r.tr_mul(&u);
        let t_u = self.t.dot(&u);
        let a_top = self.ha.dot(&u.abs());
        let b_bottom = t_u - self.hb.dot(&u_in_b.abs());
        // Every corner of A and of B (in A's frame) and its height on u (at most 8 each).
        let mut a_corner = [Vector::<T, D>::zeros(); 8];
        let mut b_corner = [Vector::<T, D>::zeros(); 8];
        let mut a_height = [T::zero(); 8];
        let mut b_height = [T::zero(); 8];
        for k in 0..corners {
            a_corner[k] = corner(&self.ha, k);
            let b_local = corner(&self.hb, k);
            b_corner[k] = self.t + self.r * b_local;
            a_height[k] = a_corner[k].dot(&u);
            b_height[k] = t_u + b_local.dot(&u_in_b);
        }
        let a_corner_to_b = |k: usize| {
            let a_in_b = self.r.tr_mul(&(a_corner[k] - self.t));
            point_box_distance_squared(&a_in_b, &self.hb)
        };
        let b_corner_to_a = |m: usize| point_box_distance_squared(&b_corner[m], &self.ha);
        let highest = (0..corners).fold(0, |best, k| {
            if a_height[k] > a_height[best] {
                k
            } else {
                best
            }
        });
        let lowest = (0..corners).fold(0, |best, m| {
            if b_height[m] < b_height[best] {
                m
            } else {
                best
            }
        });
        let mut best = a_corner_to_b(highest).min(b_corner_to_a(lowest));
        // A squared bound against the squared best: `g > 0` for every feature here.
        let beaten = |gap: T, best: T| gap > T::zero() && gap * gap >= best;
        for k in 0..corners {
            if !beaten(b_bottom - a_height[k], best) {
                best = best.min(a_corner_to_b(k));
            }
            if !beaten(b_height[k] - a_top, best) {
                best = best.min(b_corner_to_a(k));
            }
        }
        if D >= 3 {
            // Edges: corner k to corner k + 2^i for each k with bit i clear.
            for i in 0..D {
                for k in (0..corners).filter(|k| k >> i & 1 == 0) {
                    let k2 = k | 1 << i;
                    let a_high = a_height[k].max(a_height[k2]);
                    if beaten(b_bottom - a_high, best) {
                        continue;
                    }
                    for j in 0..D {
                        for m in (0..corners).filter(|m| m >> j & 1 == 0) {
                            let m2 = m | 1 << j;
                            if beaten(b_height[m].min(b_height[m2]) - a_high, best) {
                                continue;
                            }
                            best = best.min(segment_segment_distance_squared(
                                &a_corner[k],
                                &a_corner[k2],
                                &b_corner[m],
                                &b_corner[m2],
                            ));
                        }
                    }
                }
            }
        }
        best.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Obb;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn segment_distances_cover_the_clamped_cases() {
        let v = |x, y, z| Vector3::new(x, y, z);
        // Crossing skew segments 1 apart.
        let d = segment_segment_distance_squared(
            &v(-1.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(0.0, -1.0, 1.0),
            &v(0.0, 1.0, 1.0),
        );
        assert_eq!(d, 1.0);
        // Parallel, overlapping in projection.
        let d = segment_segment_distance_squared(
            &v(0.0, 0.0, 0.0),
            &v(2.0, 0.0, 0.0),
            &v(1.0, 3.0, 0.0),
            &v(5.0, 3.0, 0.0),
        );
        assert_eq!(d, 9.0);
        // End to end along a line.
        let d = segment_segment_distance_squared(
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(3.0, 0.0, 0.0),
            &v(4.0, 0.0, 0.0),
        );
        assert_eq!(d, 4.0);
        // Degenerate segments are points.
        let p = v(1.0, 1.0, 1.0);
        assert_eq!(segment_segment_distance_squared(&p, &p, &p, &p), 0.0);
        assert_eq!(
            segment_segment_distance_squared(&p, &p, &v(0.0, 0.0, 0.0), &v(2.0, 0.0, 0.0)),
            2.0
        );
        assert_eq!(
            segment_segment_distance_squared(&v(0.0, 0.0, 0.0), &v(2.0, 0.0, 0.0), &p, &p),
            2.0
        );
    }

    /// Every corner–box and edge–edge pair, without pruning.
    fn brute_force(rel: &RelativeBoxes<f64, 3>) -> f64 {
        let b_world = |local: Vector3<f64>| rel.t + rel.r * local;
        let mut best = f64::INFINITY;
        for k in 0..8 {
            let a_in_b = rel.r.tr_mul(&(corner(&rel.ha, k) - rel.t));
            best = best.min(point_box_distance_squared(&a_in_b, &rel.hb));
            best = best.min(point_box_distance_squared(
                &b_world(corner(&rel.hb, k)),
                &rel.ha,
            ));
        }
        for i in 0..3 {
            for k in (0..8).filter(|k| k >> i & 1 == 0) {
                for j in 0..3 {
                    for m in (0..8).filter(|m| m >> j & 1 == 0) {
                        best = best.min(segment_segment_distance_squared(
                            &corner(&rel.ha, k),
                            &corner(&rel.ha, k | 1 << i),
                            &b_world(corner(&rel.hb, m)),
                            &b_world(corner(&rel.hb, m | 1 << j)),
                        ));
                    }
                }
            }
        }
        best.sqrt()
    }

    proptest::proptest! {
        #[test]
        fn pruning_by_the_separating_axis_loses_no_feature(
            c in proptest::array::uniform3(-3.0..3.0f64),
            ha in proptest::array::uniform3(0.0..1.5f64),
            hb in proptest::array::uniform3(0.0..1.5f64),
            wa in proptest::array::uniform3(-3.0..3.0f64),
            wb in proptest::array::uniform3(-3.0..3.0f64),
        ) {
            let a = Obb::from_axis_angle(Vector3::zeros(), ha.into(), wa.into()).unwrap();
            let b = Obb::from_axis_angle(c.into(), hb.into(), wb.into()).unwrap();
            let rel = RelativeBoxes::of_obbs(&a, &b);
            let (axis, gap) = rel.separation();
            if gap > 0.0 {
                let pruned = rel.disjoint_distance(&axis);
                let all = brute_force(&rel);
                proptest::prop_assert!((pruned - all).abs() <= 1e-12 * (1.0 + all), "{pruned} vs {all}");
                proptest::prop_assert!(pruned >= gap * (1.0 - 1e-12), "SAT gaps are lower bounds");
            }
        }
    }

    #[test]
    fn crossed_edges_of_turned_cubes() {
        // The edge–edge case in 3D: no corner is closest.
        let q = core::f64::consts::FRAC_PI_4;
        let a = Obb::from_axis_angle(
            Vector3::zeros(),
            Vector3::repeat(1.0),
            Vector3::new(0.0, 0.0, q),
        )
        .unwrap();
        let b = Obb::from_axis_angle(
            Vector3::new(2.0 * 2f64.sqrt() + 0.5, 0.0, 0.0),
            Vector3::repeat(1.0),
            Vector3::new(0.0, q, 0.0),
        )
        .unwrap();
        let rel = RelativeBoxes::of_obbs(&a, &b);
        assert_relative_eq!(
            rel.disjoint_distance(&rel.separation().0),
            0.5,
            epsilon = 1e-12
        );
    }

    #[test]
    fn corner_to_face_in_2d() {
        let a = Obb::<f64, 2>::from_angle(Vector2::zeros(), Vector2::new(1.0, 1.0), 0.0).unwrap();
        let b = Obb::<f64, 2>::from_angle(
            Vector2::new(3.0 + 2f64.sqrt(), 0.0),
            Vector2::new(1.0, 1.0),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        let rel = RelativeBoxes::of_obbs(&a, &b);
        assert_relative_eq!(
            rel.disjoint_distance(&rel.separation().0),
            2.0,
            epsilon = 1e-12
        );
    }
}
