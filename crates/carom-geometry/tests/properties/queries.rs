//! carom's queries against parry on random scenes, written once and run in 2D and 3D.
//!
//! carom computes in `f64`, parry in `f32`; results must agree to [`F32_TOLERANCE`] of
//! the scene's scale. Where the answer is discontinuous (a ray grazing a shape, shapes
//! touching within the tolerance, a ball centre equidistant from two faces) a mismatch
//! is accepted only if carom's own answer is shown valid another way: a graze must stay
//! a graze when the shape is grown or shrunk by the tolerance, and a different contact
//! normal must separate the ball as well as parry's does.

use carom_geometry::query::Ray;
use carom_geometry::{Ball, Space, Vector};
use nalgebra::Const;
use proptest::prelude::*;

use crate::parry::{Oracle, Parry2, Parry3};
use crate::scene::{self, Shape};

/// parry's `f32` results are trusted to this fraction of the scene scale.
pub(crate) const F32_TOLERANCE: f64 = 1e-5;

/// carom's contact of a ball with a shape against parry's `contact` (prediction 0).
pub(crate) fn check_contact<const D: usize, O: Oracle<D>>(
    ball: &Ball<f64, D>,
    shape: &Shape<D>,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let scale = scene::scale(&[&Shape::Ball(*ball), shape]);
    let tol = F32_TOLERANCE * scale;
    match (shape.contact(ball), O::contact(ball, shape, 0.0)) {
        (Some(c), Some(p)) => {
            prop_assert!(
                (c.depth - p.depth).abs() <= tol,
                "depth {c:?} vs parry {p:?}"
            );
            prop_assert!((c.normal.norm() - 1.0).abs() < 1e-12, "{c:?}");
            let consistent = c.point_on_ball + c.normal * c.depth - c.point_on_shape;
            prop_assert!(consistent.norm() <= 1e-12 * scale, "{c:?}");
            // The point on the shape is a nearest boundary point: parry projects it on
            // itself and finds it as far from the centre as its own point.
            let (q, _) = O::project(shape, &c.point_on_shape);
            prop_assert!(
                (q - c.point_on_shape).norm() <= tol,
                "{c:?} is off the surface"
            );
            let ours = (ball.center() - c.point_on_shape).norm();
            let theirs = (ball.center() - p.point_on_shape).norm();
            prop_assert!((ours - theirs).abs() <= tol, "{c:?} vs parry {p:?}");
            if (c.normal - p.normal).norm() <= 1e-3 {
                prop_assert!((c.point_on_ball - p.point_on_ball).norm() <= 1e-3 * scale);
            } else {
                // Equally deep faces (or a centre within rounding of the surface): the
                // normal must still push the ball out by the depth.
                let out = ball.translated(&(c.normal * (c.depth + 4.0 * tol)));
                prop_assert!(
                    !O::intersects(&Shape::Ball(out), shape),
                    "carom's normal {c:?} does not separate; parry {p:?}"
                );
            }
        }
        (Some(c), None) => prop_assert!(c.depth <= tol, "parry misses {c:?}"),
        (None, Some(p)) => prop_assert!(p.depth <= tol, "carom misses parry's {p:?}"),
        (None, None) => {}
    }
    Ok(())
}

/// Overlap, distance and signed distance of a pair against parry's `intersection_test`,
/// `distance` and `contact`; symmetry and sign consistency within carom.
pub(crate) fn check_pair<const D: usize, O: Oracle<D>>(
    a: &Shape<D>,
    b: &Shape<D>,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let (Some(overlap), Some(signed)) = (a.overlaps(b), a.signed_distance(b)) else {
        return Ok(()); // two half-spaces: not a carom pair
    };
    let scale = scene::scale(&[a, b]);
    let tol = F32_TOLERANCE * scale;
    // Swapped arguments compute in the other shape's frame: equal up to rounding.
    let rounding = 1e-12 * scale;
    let swapped = b.signed_distance(a).unwrap_or(f64::NAN);
    prop_assert!(
        (swapped - signed).abs() <= rounding,
        "{signed} swapped {swapped}"
    );
    prop_assert!(
        b.overlaps(a) == Some(overlap) || signed.abs() <= rounding,
        "overlap is symmetric"
    );
    prop_assert!(
        (overlap && signed <= tol) || (!overlap && signed >= -tol),
        "overlap {overlap} but signed distance {signed}"
    );
    if overlap != O::intersects(a, b) {
        prop_assert!(
            signed.abs() <= tol,
            "overlap {overlap} vs parry at distance {signed}"
        );
    }
    let parry_distance = O::distance(a, b);
    prop_assert!(
        (signed.max(0.0) - parry_distance).abs() <= tol,
        "distance {signed} vs parry {parry_distance}"
    );
    if signed < -tol {
        let parry_signed = O::contact_distance(a, b);
        prop_assert!(
            (signed - parry_signed).abs() <= tol,
            "penetration {signed} vs parry {parry_signed}"
        );
    }
    Ok(())
}

/// The nearest boundary point and closest point against parry's `project_point`.
pub(crate) fn check_point<const D: usize, O: Oracle<D>>(
    shape: &Shape<D>,
    p: &Vector<f64, D>,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let scale = scene::scale(&[shape]).max(p.amax());
    let tol = F32_TOLERANCE * scale;
    let ours = shape.boundary_point(p);
    let (q, inside) = O::project(shape, p);
    prop_assert!(
        (ours.point + ours.normal * ours.signed_distance - p).norm() <= 1e-12 * scale,
        "p = point + s n fails: {ours:?}"
    );
    prop_assert!((ours.normal.norm() - 1.0).abs() < 1e-12);
    prop_assert!(
        (ours.signed_distance.abs() - (p - q).norm()).abs() <= tol,
        "{ours:?} vs parry {q:?}"
    );
    if ours.signed_distance.abs() > tol {
        prop_assert_eq!(ours.signed_distance < 0.0, inside, "{:?}", ours);
    }
    let (back, _) = O::project(shape, &ours.point);
    prop_assert!(
        (back - ours.point).norm() <= tol,
        "{ours:?} is off the surface"
    );
    let solid = if inside { *p } else { q };
    prop_assert!((shape.closest_point(p) - solid).norm() <= tol);
    Ok(())
}

/// Ray casts against parry's `cast_ray_and_get_normal` (solid). A mismatch in the time of
/// impact must be a graze: parry's time lies between carom's times for the shape grown
/// and shrunk by the tolerance.
pub(crate) fn check_ray<const D: usize, O: Oracle<D>>(
    shape: &Shape<D>,
    ray: &Ray<f64, D>,
    max_toi: f64,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let tol = F32_TOLERANCE * scene::scale(&[shape]).max(ray.origin().amax());
    let speed = ray.direction().norm();
    let toi_tol = if speed > 0.0 { tol / speed } else { 0.0 };
    let ours = shape.cast_ray(ray, max_toi);
    let theirs = O::cast_ray(shape, ray, max_toi);
    let close = match (ours, theirs) {
        (Some(h), Some((t, _))) => (h.toi - t).abs() <= toi_tol,
        (None, None) => true,
        _ => false,
    };
    if !close {
        let inf = f64::INFINITY;
        let early = shape
            .offset(tol)
            .cast_ray(ray, max_toi + toi_tol)
            .map_or(inf, |h| h.toi);
        let late = shape
            .offset(-tol)
            .cast_ray(ray, (max_toi - toi_tol).max(0.0))
            .map_or(inf, |h| h.toi);
        let parry_toi = theirs.map_or(inf, |h| h.0);
        prop_assert!(
            early <= parry_toi && parry_toi <= late,
            "carom {ours:?} vs parry {theirs:?} outside the graze bracket [{early}, {late}]"
        );
    }
    if let Some(h) = ours {
        prop_assert!(h.toi >= 0.0 && h.toi <= max_toi);
        prop_assert!((h.normal.norm() - 1.0).abs() < 1e-12, "{h:?}");
        let at = ray.point_at(h.toi);
        prop_assert!(
            shape.boundary_point(&at).signed_distance.abs() <= tol || h.toi == 0.0,
            "hit {h:?} is off the surface"
        );
        if let (true, Some((_, n))) = (h.toi > 0.0 && close, theirs) {
            // A corner or edge hit may report either adjacent face: carom's normal must
            // then bound the shape (every corner behind the plane through the hit).
            if (h.normal - n).norm() > 1e-3 {
                for c in shape.corners() {
                    prop_assert!(
                        h.normal.dot(&(c - at)) <= tol,
                        "{h:?} vs parry normal {n:?}"
                    );
                }
                prop_assert!(!shape.corners().is_empty(), "{h:?} vs parry normal {n:?}");
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn ball_contacts_match_parry_2d(ball in scene::ball::<2>(), shape in scene::shape::<2>()) {
        check_contact::<2, Parry2>(&ball, &shape)?;
    }

    #[test]
    fn ball_contacts_match_parry_3d(ball in scene::ball::<3>(), shape in scene::shape::<3>()) {
        check_contact::<3, Parry3>(&ball, &shape)?;
    }

    #[test]
    fn pairs_match_parry_2d(a in scene::shape::<2>(), b in scene::shape::<2>()) {
        check_pair::<2, Parry2>(&a, &b)?;
    }

    #[test]
    fn pairs_match_parry_3d(a in scene::shape::<3>(), b in scene::shape::<3>()) {
        check_pair::<3, Parry3>(&a, &b)?;
    }

    #[test]
    fn point_queries_match_parry_2d(s in scene::shape::<2>(), p in scene::vector::<2>(-8.0, 8.0)) {
        check_point::<2, Parry2>(&s, &p)?;
    }

    #[test]
    fn point_queries_match_parry_3d(s in scene::shape::<3>(), p in scene::vector::<3>(-8.0, 8.0)) {
        check_point::<3, Parry3>(&s, &p)?;
    }

    #[test]
    fn ray_casts_match_parry_2d(s in scene::shape::<2>(), r in scene::ray::<2>(), max in 0.0..20.0) {
        check_ray::<2, Parry2>(&s, &r, max)?;
    }

    #[test]
    fn ray_casts_match_parry_3d(s in scene::shape::<3>(), r in scene::ray::<3>(), max in 0.0..20.0) {
        check_ray::<3, Parry3>(&s, &r, max)?;
    }
}
