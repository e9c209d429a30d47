//! Fitted bounding volumes against brute force: every point inside (by each volume's own
//! containment test), Welzl's sphere minimal among all spheres through 2..=D+1 of the
//! points, never larger than Ritter's; the calipers rectangle minimal among the
//! rectangles along every pair of points; the hull convex and containing every point.

use carom_geometry::fit::{convex_hull, min_area_rect, minimal_sphere, pca_obb, ritter_sphere};
use carom_geometry::query::PointQuery;
use carom_geometry::{Aabb, BoundingVolume, Vector};
use nalgebra::{DMatrix, DVector, Vector2, Vector3};
use proptest::prelude::*;

use crate::scene;

/// The circumsphere (within their affine hull) of 1 to 4 points: the point; the midpoint;
/// otherwise the centre `p0 + Σ λ_k (p_k − p0)` equidistant from every point, solved with
/// nalgebra's LU. The brute force is what is independent of carom: every subset is tried,
/// where Welzl's recursion picks one.
fn circumsphere<const D: usize>(pts: &[Vector<f64, D>]) -> Option<(Vector<f64, D>, f64)> {
    let p0 = pts[0];
    match pts.len() {
        1 => Some((p0, 0.0)),
        2 => Some(((p0 + pts[1]) / 2.0, (pts[1] - p0).norm() / 2.0)),
        _ => {
            let m = pts.len() - 1;
            let edges: Vec<_> = pts[1..].iter().map(|p| p - p0).collect();
            let a = DMatrix::from_fn(m, m, |j, k| 2.0 * edges[j].dot(&edges[k]));
            let b = DVector::from_fn(m, |j, _| edges[j].norm_squared());
            let lambda = a.lu().solve(&b)?;
            let offset = edges
                .iter()
                .zip(lambda.iter())
                .fold(Vector::zeros(), |s, (e, l)| s + e * *l);
            let r = offset.norm();
            r.is_finite().then_some((p0 + offset, r))
        }
    }
}

/// The smallest radius among candidate spheres through subsets of up to `D + 1` points
/// that contain every point (to a relative 1e-9).
fn brute_force_minimal_radius<const D: usize>(pts: &[Vector<f64, D>]) -> f64 {
    let n = pts.len();
    let mut best = f64::INFINITY;
    for mask in 1u32..(1 << n) {
        if mask.count_ones() as usize > D + 1 {
            continue;
        }
        let subset: Vec<_> = (0..n)
            .filter(|i| mask >> i & 1 == 1)
            .map(|i| pts[i])
            .collect();
        if let Some((c, r)) = circumsphere(&subset)
            && pts
                .iter()
                .all(|p| (p - c).norm() <= r * (1.0 + 1e-9) + 1e-12)
        {
            best = best.min(r);
        }
    }
    best
}

fn points<const D: usize>(n: std::ops::Range<usize>) -> impl Strategy<Value = Vec<Vector<f64, D>>> {
    proptest::collection::vec(scene::vector::<D>(-5.0, 5.0), n)
}

fn check_spheres<const D: usize>(pts: &[Vector<f64, D>], brute: bool) -> Result<(), TestCaseError> {
    let welzl = minimal_sphere(pts).unwrap();
    let ritter = ritter_sphere(pts).unwrap();
    for p in pts {
        prop_assert!(welzl.contains_point(p) && ritter.contains_point(p));
    }
    prop_assert!(
        welzl.radius() <= ritter.radius() * (1.0 + 1e-12),
        "{welzl:?} {ritter:?}"
    );
    if brute {
        let best = brute_force_minimal_radius(pts);
        prop_assert!(
            (welzl.radius() - best).abs() <= 1e-9 * (1.0 + best),
            "Welzl {} brute force {best}",
            welzl.radius()
        );
    }
    Ok(())
}

/// The area of the tightest rectangle with one side along `u` around every point.
fn rect_area(pts: &[Vector2<f64>], u: Vector2<f64>) -> f64 {
    let v = Vector2::new(-u.y, u.x);
    let span = |d: Vector2<f64>| {
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, -f64::INFINITY), |(lo, hi), p| {
                (lo.min(d.dot(p)), hi.max(d.dot(p)))
            });
        hi - lo
    };
    span(u) * span(v)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn spheres_contain_all_points_and_welzl_is_minimal_2d(pts in points::<2>(1..8)) {
        check_spheres(&pts, true)?;
    }

    #[test]
    fn spheres_contain_all_points_and_welzl_is_minimal_3d(pts in points::<3>(1..8)) {
        check_spheres(&pts, true)?;
    }

    #[test]
    fn spheres_of_large_and_degenerate_sets(
        pts in points::<3>(1..400),
        dup in 0usize..4,
        flatten in any::<bool>(),
    ) {
        // Duplicated points and (optionally) a coplanar set.
        let mut pts: Vec<_> = pts.iter().map(|p| if flatten { Vector3::new(p.x, p.y, 1.0) } else { *p }).collect();
        for k in 0..dup.min(pts.len()) {
            pts.push(pts[k]);
        }
        check_spheres(&pts, false)?;
    }

    #[test]
    fn fits_far_from_the_origin_contain_every_point(pts in points::<3>(1..50), f32_build in any::<bool>()) {
        let far: Vec<_> = pts.iter().map(|p| p + Vector3::new(1e6, -1e6, 1e6)).collect();
        if f32_build {
            let pts32: Vec<_> = far.iter().map(|p| p.map(|x| x as f32)).collect();
            let s = minimal_sphere(&pts32).unwrap();
            let r = ritter_sphere(&pts32).unwrap();
            let o = pca_obb(&pts32).unwrap();
            for p in &pts32 {
                prop_assert!(s.contains_point(p) && r.contains_point(p) && o.contains_point(p));
            }
        } else {
            check_spheres(&far, false)?;
            let o = pca_obb(&far).unwrap();
            prop_assert!(far.iter().all(|p| o.contains_point(p)));
            // Relative precision survives: the sphere about the shifted set is the same size.
            let here = minimal_sphere(&pts).unwrap().radius();
            let there = minimal_sphere(&far).unwrap().radius();
            prop_assert!((here - there).abs() <= 1e-8, "{here} vs {there}");
        }
    }

    #[test]
    fn pca_boxes_contain_every_point_and_are_proper(pts in points::<3>(1..60), pts2 in points::<2>(1..60)) {
        let o = pca_obb(&pts).unwrap();
        prop_assert!(pts.iter().all(|p| o.contains_point(p)));
        prop_assert!(carom_math::determinant(o.rotation().matrix()) > 0.0);
        let o2 = pca_obb(&pts2).unwrap();
        prop_assert!(pts2.iter().all(|p| o2.contains_point(p)));
        // Along each of its axes the box spans exactly the points' spread.
        for i in 0..3 {
            let (lo, hi) = pts.iter().map(|p| o.axis(i).dot(p)).fold((f64::INFINITY, -f64::INFINITY), |(l, h), x| (l.min(x), h.max(x)));
            prop_assert!((2.0 * o.half_extents()[i] - (hi - lo)).abs() <= 1e-9 * (1.0 + hi - lo));
        }
    }

    #[test]
    fn min_area_rect_is_minimal_over_all_point_pairs(pts in points::<2>(1..40)) {
        let r = min_area_rect(&pts).unwrap();
        prop_assert!(pts.iter().all(|p| r.contains_point(p)));
        let area = 4.0 * r.half_extents().x * r.half_extents().y;
        let mut best = rect_area(&pts, Vector2::x());
        for a in &pts {
            for b in &pts {
                if a != b {
                    best = best.min(rect_area(&pts, (b - a).normalize()));
                }
            }
        }
        prop_assert!((area - best).abs() <= 1e-9 * (1.0 + best), "calipers {area} brute force {best}");
        let pca = pca_obb(&pts).unwrap();
        prop_assert!(area <= 4.0 * pca.half_extents().x * pca.half_extents().y * (1.0 + 1e-9) + 1e-12);
        prop_assert!(area <= Aabb::from_points(&pts).unwrap().volume() * (1.0 + 1e-9) + 1e-12);
    }

    #[test]
    fn convex_hull_is_convex_and_contains_every_point(pts in points::<2>(1..60)) {
        let hull = convex_hull(&pts).unwrap();
        prop_assert!(hull.iter().all(|h| pts.contains(h)), "hull vertices are input points");
        let n = hull.len();
        if n >= 3 {
            for i in 0..n {
                let (a, b, c) = (hull[i], hull[(i + 1) % n], hull[(i + 2) % n]);
                let turn = (b - a).perp(&(c - b));
                prop_assert!(turn > 0.0, "strict left turns only");
                for p in &pts {
                    prop_assert!((b - a).perp(&(p - a)) >= -1e-12, "{p:?} right of an edge");
                }
            }
        }
    }
}
