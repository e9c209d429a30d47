//! The numerically hard scales: tiny scenes (1e-9) against parry on the magnified scene,
//! scenes far from the origin (1e6) against the same scene at the origin, carom's `f32`
//! build against its `f64` build, and extreme finite inputs that must not panic.

use std::marker::PhantomData;

use carom_geometry::query::{PointQuery, Ray, RayCast};
use carom_geometry::{Ball, Space, Vector};
use nalgebra::Const;
use proptest::prelude::*;

use crate::parry::{Oracle, OracleContact, Parry2, Parry3};
use crate::queries::{F32_TOLERANCE, check_contact, check_pair, check_point, check_ray};
use crate::scene::{self, Shape};

/// The size of a "tiny" scene: every length is the random scene's times this.
const TINY: f64 = 1e-9;

/// An oracle for tiny scenes: parry answers for the scene magnified by `1/TINY` (where
/// its absolute epsilons of 1e-7 make sense) and the answer is scaled back. Comparing
/// carom on the tiny scene with it checks carom's accuracy and its scale invariance.
struct Magnified<O>(PhantomData<O>);

impl<const D: usize, O: Oracle<D>> Oracle<D> for Magnified<O>
where
    Const<D>: Space<f64, D>,
{
    fn contact(ball: &Ball<f64, D>, shape: &Shape<D>, prediction: f64) -> Option<OracleContact<D>> {
        let big = Ball::new(ball.center() / TINY, ball.radius() / TINY).unwrap();
        O::contact(&big, &shape.scaled(1.0 / TINY), prediction / TINY).map(|c| OracleContact {
            normal: c.normal,
            depth: c.depth * TINY,
            point_on_ball: c.point_on_ball * TINY,
            point_on_shape: c.point_on_shape * TINY,
        })
    }

    fn intersects(a: &Shape<D>, b: &Shape<D>) -> bool {
        O::intersects(&a.scaled(1.0 / TINY), &b.scaled(1.0 / TINY))
    }

    fn distance(a: &Shape<D>, b: &Shape<D>) -> f64 {
        O::distance(&a.scaled(1.0 / TINY), &b.scaled(1.0 / TINY)) * TINY
    }

    fn contact_distance(a: &Shape<D>, b: &Shape<D>) -> f64 {
        O::contact_distance(&a.scaled(1.0 / TINY), &b.scaled(1.0 / TINY)) * TINY
    }

    fn project(shape: &Shape<D>, p: &Vector<f64, D>) -> (Vector<f64, D>, bool) {
        let (q, inside) = O::project(&shape.scaled(1.0 / TINY), &(p / TINY));
        (q * TINY, inside)
    }

    fn cast_ray(
        shape: &Shape<D>,
        ray: &Ray<f64, D>,
        max_toi: f64,
    ) -> Option<(f64, Vector<f64, D>)> {
        let big = Ray::new(ray.origin() / TINY, ray.direction() / TINY).unwrap();
        O::cast_ray(&shape.scaled(1.0 / TINY), &big, max_toi)
    }
}

/// The offset that puts a scene far from the origin.
fn far<const D: usize>() -> Vector<f64, D> {
    Vector::from_fn(|i, _| if i % 2 == 0 { 1e6 } else { -1e6 })
}

/// carom's results on a pair moved by 1e6 equal those at the origin to the rounding of
/// the moved coordinates (a few ulp of 1e6, ~1e-10), far below parry's `f32` tolerance.
fn check_translation_invariance<const D: usize>(
    a: &Shape<D>,
    b: &Shape<D>,
    ball: &Ball<f64, D>,
    ray: &Ray<f64, D>,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let t = far::<D>();
    let tol = 1e-8 * scene::scale(&[a, b]).max(1.0);
    let (fa, fb, fball) = (a.translated(&t), b.translated(&t), ball.translated(&t));
    if let (Some(near), Some(moved)) = (a.signed_distance(b), fa.signed_distance(&fb)) {
        prop_assert!((near - moved).abs() <= tol, "{near} moved {moved}");
        if near.abs() > tol {
            prop_assert_eq!(a.overlaps(b), fa.overlaps(&fb));
        }
    }
    match (b.contact(ball), fb.contact(&fball)) {
        (Some(c), Some(m)) => {
            prop_assert!((c.depth - m.depth).abs() <= tol, "{c:?} moved {m:?}");
            prop_assert!((c.point_on_shape + t - m.point_on_shape).norm() <= tol);
            // A ball centre within rounding of the shape's surface has an ill-defined
            // normal; elsewhere the normal moves with the scene.
            let centre_gap = (ball.center() - c.point_on_shape).norm();
            if centre_gap > 1e-6 {
                prop_assert!((c.normal - m.normal).norm() <= 1e-6, "{c:?} moved {m:?}");
            }
        }
        (Some(c), None) | (None, Some(c)) => prop_assert!(c.depth <= tol),
        (None, None) => {}
    }
    let moved_ray = Ray::new(ray.origin() + t, ray.direction()).unwrap();
    let speed = ray.direction().norm().max(1e-300);
    match (a.cast_ray(ray, 20.0), fa.cast_ray(&moved_ray, 20.0)) {
        (Some(h), Some(m)) => prop_assert!(
            (h.toi - m.toi).abs() * speed <= tol * 1e3 || h.toi.min(m.toi) == 0.0,
            "{h:?} moved {m:?}"
        ),
        (Some(h), None) | (None, Some(h)) => {
            // A graze at the rounding of the moved coordinates.
            let at = ray.point_at(h.toi);
            prop_assert!(
                a.offset(-tol * 1e3).cast_ray(ray, 20.0).is_none(),
                "{h:?} at {at}"
            );
        }
        (None, None) => {}
    }
    Ok(())
}

/// carom's `f32` build against its `f64` build on the same scene (rounded to `f32`).
fn check_f32_build<const D: usize>(
    a: &Shape<D>,
    b: &Shape<D>,
    ball: &Ball<f64, D>,
    p: &Vector<f64, D>,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D> + Space<f32, D>,
{
    let tol = F32_TOLERANCE * scene::scale(&[a, b, &Shape::Ball(*ball)]).max(p.amax());
    let (a32, b32) = (a.to_f32(), b.to_f32());
    let Shape::Ball(ball32) = Shape::Ball(*ball).to_f32() else {
        unreachable!("a ball stays a ball")
    };
    let p32 = p.map(|x| x as f32);
    if let (Some(s64), Some(s32)) = (a.signed_distance(b), a32.signed_distance(&b32)) {
        prop_assert!((s64 - f64::from(s32)).abs() <= tol, "f64 {s64} f32 {s32}");
        if s64.abs() > tol {
            prop_assert_eq!(a.overlaps(b), a32.overlaps(&b32));
        }
    }
    match (b.contact(ball), b32.contact(&ball32)) {
        (Some(c), Some(c32)) => {
            prop_assert!(
                (c.depth - f64::from(c32.depth)).abs() <= tol,
                "{c:?} vs {c32:?}"
            );
            prop_assert!((c32.normal.norm() - 1.0).abs() <= 1e-6);
        }
        (Some(c), None) => prop_assert!(c.depth <= tol),
        (None, Some(c32)) => prop_assert!(f64::from(c32.depth) <= tol),
        (None, None) => {}
    }
    let bp = a.boundary_point(p);
    let bp32 = a32.boundary_point(&p32);
    prop_assert!((bp.signed_distance - f64::from(bp32.signed_distance)).abs() <= tol);
    Ok(())
}

/// Every query on shapes with extreme finite values: no panic (in debug builds, no
/// failed debug assertion either), and every boolean and contact is well formed.
fn check_no_panic<const D: usize>(
    a: &Shape<D>,
    b: &Shape<D>,
    ball: &Ball<f64, D>,
    ray: &Ray<f64, D>,
) where
    Const<D>: Space<f64, D>,
{
    let _ = a.overlaps(b);
    let _ = a.signed_distance(b);
    if let Some(c) = a.contact(ball) {
        assert!(c.depth >= 0.0, "{c:?}");
    }
    let _ = a.boundary_point(&ball.center());
    let _ = a.closest_point(&ray.origin());
    if let Some(h) = a.cast_ray(ray, f64::INFINITY) {
        assert!(h.toi >= 0.0, "{h:?}");
    }
    let _ = ball.cast_ray(ray, f64::MAX);
    let _ = ball.signed_distance_to_point(&ray.origin());
}

/// A finite number from anywhere in the `f64` range, including zero and subnormals.
fn extreme() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        -1e300..1e300,
        -1.0..1.0,
        (-300i32..300, -1.0..1.0).prop_map(|(e, m)| m * 10f64.powi(e)),
        Just(f64::MIN_POSITIVE / 4.0),
    ]
}

fn extreme_shape<const D: usize>() -> impl Strategy<Value = Shape<D>>
where
    Const<D>: Space<f64, D>,
{
    let v = || proptest::array::uniform::<_, D>(extreme()).prop_map(Vector::from);
    (v(), v(), scene::rotation::<D>(), extreme(), 0u8..4).prop_filter_map(
        "valid shapes",
        |(c, h, r, radius, kind)| {
            let h = h.abs();
            match kind {
                0 => Ball::new(c, radius.abs()).ok().map(Shape::Ball),
                1 => carom_geometry::Aabb::from_center_half_extents(c, h)
                    .ok()
                    .filter(|a| a.min().iter().chain(a.max().iter()).all(|x| x.is_finite()))
                    .map(Shape::Aabb),
                2 => carom_geometry::Obb::new(c, h, r).ok().map(Shape::Obb),
                _ => carom_geometry::HalfSpace::new(h, c)
                    .ok()
                    .map(Shape::HalfSpace),
            }
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn tiny_scenes_match_parry_magnified_2d(
        ball in scene::ball::<2>(), a in scene::shape::<2>(), b in scene::shape::<2>(),
        p in scene::vector::<2>(-8.0, 8.0), r in scene::ray::<2>(),
    ) {
        let tiny_ball = Ball::new(ball.center() * TINY, ball.radius() * TINY).unwrap();
        let (a, b) = (a.scaled(TINY), b.scaled(TINY));
        check_contact::<2, Magnified<Parry2>>(&tiny_ball, &a)?;
        check_pair::<2, Magnified<Parry2>>(&a, &b)?;
        check_point::<2, Magnified<Parry2>>(&a, &(p * TINY))?;
        let tiny_ray = Ray::new(r.origin() * TINY, r.direction() * TINY).unwrap();
        check_ray::<2, Magnified<Parry2>>(&a, &tiny_ray, 20.0)?;
    }

    #[test]
    fn tiny_scenes_match_parry_magnified_3d(
        ball in scene::ball::<3>(), a in scene::shape::<3>(), b in scene::shape::<3>(),
        p in scene::vector::<3>(-8.0, 8.0), r in scene::ray::<3>(),
    ) {
        let tiny_ball = Ball::new(ball.center() * TINY, ball.radius() * TINY).unwrap();
        let (a, b) = (a.scaled(TINY), b.scaled(TINY));
        check_contact::<3, Magnified<Parry3>>(&tiny_ball, &a)?;
        check_pair::<3, Magnified<Parry3>>(&a, &b)?;
        check_point::<3, Magnified<Parry3>>(&a, &(p * TINY))?;
        let tiny_ray = Ray::new(r.origin() * TINY, r.direction() * TINY).unwrap();
        check_ray::<3, Magnified<Parry3>>(&a, &tiny_ray, 20.0)?;
    }

    #[test]
    fn far_from_the_origin_equals_at_the_origin_2d(
        a in scene::shape::<2>(), b in scene::shape::<2>(), ball in scene::ball::<2>(),
        r in scene::ray::<2>(),
    ) {
        check_translation_invariance(&a, &b, &ball, &r)?;
    }

    #[test]
    fn far_from_the_origin_equals_at_the_origin_3d(
        a in scene::shape::<3>(), b in scene::shape::<3>(), ball in scene::ball::<3>(),
        r in scene::ray::<3>(),
    ) {
        check_translation_invariance(&a, &b, &ball, &r)?;
    }

    #[test]
    fn the_f32_build_matches_the_f64_build_2d(
        a in scene::shape::<2>(), b in scene::shape::<2>(), ball in scene::ball::<2>(),
        p in scene::vector::<2>(-8.0, 8.0),
    ) {
        check_f32_build(&a, &b, &ball, &p)?;
    }

    #[test]
    fn the_f32_build_matches_the_f64_build_3d(
        a in scene::shape::<3>(), b in scene::shape::<3>(), ball in scene::ball::<3>(),
        p in scene::vector::<3>(-8.0, 8.0),
    ) {
        check_f32_build(&a, &b, &ball, &p)?;
    }

    #[test]
    fn no_query_panics_on_extreme_finite_input_2d(
        a in extreme_shape::<2>(), b in extreme_shape::<2>(),
        c in proptest::array::uniform::<_, 2>(extreme()), radius in extreme(),
        o in proptest::array::uniform::<_, 2>(extreme()), d in proptest::array::uniform::<_, 2>(extreme()),
    ) {
        if let (Ok(ball), Ok(ray)) = (Ball::new(c.into(), radius.abs()), Ray::new(o.into(), d.into())) {
            check_no_panic(&a, &b, &ball, &ray);
        }
    }

    #[test]
    fn no_query_panics_on_extreme_finite_input_3d(
        a in extreme_shape::<3>(), b in extreme_shape::<3>(),
        c in proptest::array::uniform::<_, 3>(extreme()), radius in extreme(),
        o in proptest::array::uniform::<_, 3>(extreme()), d in proptest::array::uniform::<_, 3>(extreme()),
    ) {
        if let (Ok(ball), Ok(ray)) = (Ball::new(c.into(), radius.abs()), Ray::new(o.into(), d.into())) {
            check_no_panic(&a, &b, &ball, &ray);
        }
    }
}
