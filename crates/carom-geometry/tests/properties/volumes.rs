//! Properties of bounding volumes: merges contain both inputs, an OBB's AABB contains
//! its corners, a ball's AABB and bounding sphere contain the ball, loosening grows,
//! overlap is symmetric; in 2D and 3D, `f64` and `f32`.

use carom_geometry::query::Overlap;
use carom_geometry::{Aabb, BoundingSphere, BoundingVolume, Space, Vector};
use nalgebra::Const;
use proptest::prelude::*;

use crate::scene;

fn sphere<const D: usize>() -> impl Strategy<Value = BoundingSphere<f64, D>> {
    (
        scene::vector::<D>(-5.0, 5.0),
        prop_oneof![Just(0.0), 0.0..3.0],
    )
        .prop_map(|(c, r)| BoundingSphere::new(c, r).unwrap())
}

fn check_volumes<const D: usize>(
    a: &Aabb<f64, D>,
    b: &Aabb<f64, D>,
    s: &BoundingSphere<f64, D>,
    t: &BoundingSphere<f64, D>,
    o: &carom_geometry::Obb<f64, D>,
    ball: &carom_geometry::Ball<f64, D>,
    margin: f64,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let m = a.merged(b);
    prop_assert!(m.contains(a) && m.contains(b));
    let ms = s.merged(t);
    prop_assert!(ms.contains(s) && ms.contains(t), "{ms:?} from {s:?} {t:?}");
    // The merge is minimal: its radius is that of the larger one or (d + r₁ + r₂)/2.
    let d = (s.center() - t.center()).norm();
    let minimal = s
        .radius()
        .max(t.radius())
        .max((d + s.radius() + t.radius()) / 2.0);
    prop_assert!((ms.radius() - minimal).abs() <= 1e-12 * (1.0 + minimal));
    prop_assert_eq!(a.intersects(b), b.intersects(a));
    prop_assert_eq!(s.intersects(t), t.intersects(s));
    prop_assert_eq!(
        a.intersects(b),
        a.overlaps(b),
        "the BV test is the shape test"
    );
    let box_of_obb = o.aabb();
    for c in o.corners() {
        prop_assert!(
            box_of_obb.contains_point(&c),
            "{c:?} outside {box_of_obb:?}"
        );
    }
    // Tight: every face of the AABB touches a corner (to rounding).
    for i in 0..D {
        let lo = o.corners().map(|c| c[i]).fold(f64::INFINITY, f64::min);
        prop_assert!((lo - box_of_obb.min()[i]).abs() <= 1e-12 * (1.0 + lo.abs()));
    }
    let ball_box = ball.aabb();
    for i in 0..D {
        let e = Vector::<f64, D>::from_fn(|k, _| if k == i { ball.radius() } else { 0.0 });
        prop_assert!(ball_box.contains_point(&(ball.center() + e)));
        prop_assert!(ball_box.contains_point(&(ball.center() - e)));
    }
    prop_assert!(
        ball.bounding_sphere()
            .contains(&BoundingSphere::new(ball.center(), ball.radius()).unwrap())
    );
    let loose = a.loosened(margin);
    prop_assert!(loose.contains(a));
    prop_assert!(s.loosened(margin).contains(s));
    prop_assert!(a.volume() <= loose.volume());
    prop_assert!((a.center() - (a.min() + a.max()) / 2.0).norm() == 0.0);
    Ok(())
}

proptest! {
    #[test]
    fn bounding_volume_properties_2d(
        a in scene::aabb::<2>(), b in scene::aabb::<2>(), s in sphere::<2>(), t in sphere::<2>(),
        o in scene::obb::<2>(), ball in scene::ball::<2>(), margin in 0.0..2.0,
    ) {
        check_volumes(&a, &b, &s, &t, &o, &ball, margin)?;
    }

    #[test]
    fn bounding_volume_properties_3d(
        a in scene::aabb::<3>(), b in scene::aabb::<3>(), s in sphere::<3>(), t in sphere::<3>(),
        o in scene::obb::<3>(), ball in scene::ball::<3>(), margin in 0.0..2.0,
    ) {
        check_volumes(&a, &b, &s, &t, &o, &ball, margin)?;
    }

    #[test]
    fn an_f32_obbs_aabb_contains_its_corners_far_from_the_origin(
        o in scene::obb::<3>(), offset in scene::vector::<3>(-1e6, 1e6),
    ) {
        let o = carom_geometry::Obb::<f32, 3>::new(
            (o.center() + offset).map(|x| x as f32),
            o.half_extents().map(|x| x as f32),
            carom_geometry::Rotation::from_matrix_unchecked(o.rotation().matrix().map(|x| x as f32)),
        ).unwrap();
        let b = o.aabb();
        for c in o.corners() {
            prop_assert!(b.contains_point(&c), "{c:?} outside {b:?}");
        }
    }
}
