//! The named hard cases, each with its closed-form answer: touching, nested and
//! coincident shapes, in 2D and 3D. parry is consulted where its semantics match
//! (it treats touching balls as apart: `dist² < (r₁ + r₂)²`; carom's shapes are closed).

use std::f64::consts::FRAC_PI_4;

use carom_geometry::query::{
    PointQuery, Ray, RayCast, contact, distance, overlaps, separation, signed_distance,
};
use carom_geometry::{Aabb, Ball, HalfSpace, Obb, Rotation};
use nalgebra::{Vector2, Vector3};

use crate::parry::{Oracle, Parry2, Parry3};
use crate::scene::Shape;

fn ball2(x: f64, y: f64, r: f64) -> Ball<f64, 2> {
    Ball::new(Vector2::new(x, y), r).unwrap()
}

fn ball3(x: f64, y: f64, z: f64, r: f64) -> Ball<f64, 3> {
    Ball::new(Vector3::new(x, y, z), r).unwrap()
}

#[test]
fn touching_balls_overlap_with_contact_depth_zero() {
    let (a, b) = (ball2(0.0, 0.0, 1.5), ball2(3.0, 4.0, 3.5));
    assert!(overlaps(&a, &b));
    assert_eq!(signed_distance(&a, &b), 0.0);
    let c = contact(&a, &b).unwrap();
    assert_eq!(c.depth, 0.0);
    assert_eq!(c.normal, Vector2::new(-0.6, -0.8));
    assert!((c.point_on_ball - Vector2::new(0.9, 1.2)).norm() < 1e-15);
    // parry calls this apart (strict inequality); carom's balls are closed sets.
    assert!(Parry2::contact(&a, &Shape::Ball(b), 0.0).is_none());
    let apart = b.translated(&Vector2::new(0.0, 1e-12));
    assert!(!overlaps(&a, &apart) && contact(&a, &apart).is_none());
}

#[test]
fn touching_a_box_face_an_edge_and_a_corner() {
    let cube = Aabb::new(Vector3::repeat(-1.0), Vector3::repeat(1.0)).unwrap();
    let face = ball3(3.0, 0.5, -0.5, 2.0);
    let edge = ball3(4.0, 5.0, 0.0, 5.0); // 3-4-5 from the edge x = y = 1
    let corner = ball3(3.0, 3.0, 2.0, 3.0); // (2, 2, 1) from the corner: 3
    for (ball, normal) in [
        (face, Vector3::x()),
        (edge, Vector3::new(0.6, 0.8, 0.0)),
        (corner, Vector3::new(2.0, 2.0, 1.0) / 3.0),
    ] {
        let c = contact(&ball, &cube).unwrap();
        assert_eq!(c.depth, 0.0, "{ball:?}");
        assert!((c.normal - normal).norm() < 1e-15, "{c:?}");
        assert!(overlaps(&ball, &cube) && overlaps(&cube, &ball));
        let obb = Obb::from_aabb(&cube);
        assert_eq!(contact(&ball, &obb).unwrap().depth, 0.0);
        let away = ball.translated(&(normal * 1e-12));
        assert!(!overlaps(&away, &cube) && !overlaps(&away, &obb));
        assert!(contact(&away, &cube).is_none());
        let p = Parry3::contact(&ball, &Shape::Aabb(cube), 0.0).unwrap();
        assert!(p.depth.abs() < 1e-6, "{p:?}");
    }
}

#[test]
fn touching_boxes_overlap_at_distance_zero() {
    let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
    let side = Aabb::new(Vector2::new(1.0, 0.5), Vector2::new(2.0, 3.0)).unwrap();
    let corner = Aabb::new(Vector2::new(1.0, 1.0), Vector2::new(2.0, 2.0)).unwrap();
    for b in [side, corner] {
        assert!(overlaps(&a, &b));
        assert_eq!(signed_distance(&a, &b), 0.0);
        let (oa, ob) = (Obb::from_aabb(&a), Obb::from_aabb(&b));
        assert!(overlaps(&oa, &ob) && overlaps(&a, &ob));
        assert_eq!(separation(&oa, &ob).distance, 0.0);
        assert_eq!(distance(&oa, &ob), 0.0);
    }
    // A unit cube resting on a cube turned 45° about z: touching along the top edge.
    let q = Obb::from_axis_angle(
        Vector3::zeros(),
        Vector3::repeat(1.0),
        Vector3::new(0.0, 0.0, FRAC_PI_4),
    )
    .unwrap();
    let top = 2f64.sqrt();
    let resting = Obb::new(
        Vector3::new(0.0, top + 1.0, 0.0),
        Vector3::repeat(1.0),
        Rotation::identity(),
    )
    .unwrap();
    assert!(overlaps(&q, &resting));
    assert!(signed_distance(&q, &resting).abs() < 1e-15);
    let lifted = resting.translated(&Vector3::new(0.0, 1e-9, 0.0));
    assert!(!overlaps(&q, &lifted));
    assert!((distance(&q, &lifted) - 1e-9).abs() < 1e-15);
}

#[test]
fn touching_a_half_space_with_every_shape() {
    let floor = HalfSpace::new(Vector3::z(), Vector3::new(0.0, 0.0, -1.0)).unwrap();
    let ball = ball3(5.0, 5.0, 1.0, 2.0);
    let aabb = Aabb::new(Vector3::new(-1.0, -1.0, -1.0), Vector3::new(1.0, 1.0, 3.0)).unwrap();
    // A cube balanced on its corner: the corner is √3 below the centre.
    let tilt =
        Rotation::<f64, 3>::rotation_between(&Vector3::new(1.0, 1.0, 1.0), &Vector3::z()).unwrap();
    let obb = Obb::new(
        Vector3::new(0.0, 0.0, 3f64.sqrt() - 1.0),
        Vector3::repeat(1.0),
        tilt,
    )
    .unwrap();
    assert_eq!(contact(&ball, &floor).unwrap().depth, 0.0);
    assert!(overlaps(&aabb, &floor) && overlaps(&floor, &aabb));
    assert_eq!(signed_distance(&aabb, &floor), 0.0);
    assert!(signed_distance(&obb, &floor).abs() < 1e-15);
    let up = Vector3::new(0.0, 0.0, 1e-9);
    assert!(!overlaps(&ball.translated(&up), &floor));
    assert!(!overlaps(&aabb.translated(&up), &floor));
    assert!(!overlaps(&obb.translated(&up), &floor));
}

#[test]
fn nested_shapes_report_the_shortest_way_out() {
    // A small ball deep inside a big one: depth r₁ + r₂ − d.
    let (big, small) = (ball3(0.0, 0.0, 0.0, 10.0), ball3(1.0, 2.0, 2.0, 1.0));
    let c = contact(&small, &big).unwrap();
    assert_eq!(c.depth, 1.0 + 10.0 - 3.0);
    assert!((c.normal - Vector3::new(1.0, 2.0, 2.0) / 3.0).norm() < 1e-15);
    // A ball inside a box leaves through the nearest face (y, 0.25 away).
    let table = Aabb::new(Vector2::new(-2.0, -1.0), Vector2::new(2.0, 1.0)).unwrap();
    let b = ball2(0.5, 0.75, 0.5);
    let c = contact(&b, &table).unwrap();
    assert_eq!((c.normal, c.depth), (Vector2::y(), 0.75));
    let p = Parry2::contact(&b, &Shape::Aabb(table), 0.0).unwrap();
    assert!((p.depth - 0.75).abs() < 1e-6 && (p.normal - Vector2::y()).norm() < 1e-6);
    // A box inside a box: leaving [0, 10]² takes 8.5 in x ([0.5, 8.5]) but only 5 in y
    // ([3, 5]: 5 down, or the outer box 5 up, along +y from the inner box).
    let outer = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(10.0, 10.0)).unwrap();
    let inner = Aabb::new(Vector2::new(0.5, 3.0), Vector2::new(8.5, 5.0)).unwrap();
    assert_eq!(signed_distance(&outer, &inner), -5.0);
    let s = separation(&Obb::from_aabb(&outer), &Obb::from_aabb(&inner));
    assert_eq!((s.distance, s.axis), (-5.0, Vector2::y()));
    let p = Parry2::contact_distance(&Shape::Aabb(outer), &Shape::Aabb(inner));
    assert!((p + 5.0).abs() < 1e-5, "parry {p}");
    // A ball wholly below a floor.
    let floor = HalfSpace::new(Vector2::y(), Vector2::zeros()).unwrap();
    assert_eq!(contact(&ball2(0.0, -5.0, 1.0), &floor).unwrap().depth, 6.0);
}

#[test]
fn coincident_centres_have_the_documented_finite_normals() {
    let (a, b) = (ball3(1.0, 1.0, 1.0, 1.0), ball3(1.0, 1.0, 1.0, 2.0));
    let c = contact(&a, &b).unwrap();
    assert_eq!((c.normal, c.depth), (Vector3::x(), 3.0));
    assert_eq!(c.point_on_shape, Vector3::new(3.0, 1.0, 1.0));
    assert_eq!(signed_distance(&a, &b), -3.0);
    // A ball at the centre of a cube: the +x face (ties go to the lowest axis, upper face).
    let cube = Aabb::new(Vector3::zeros(), Vector3::repeat(2.0)).unwrap();
    let c = contact(&a, &cube).unwrap();
    assert_eq!((c.normal, c.depth), (Vector3::x(), 2.0));
    let turned = Obb::from_axis_angle(
        Vector3::repeat(1.0),
        Vector3::repeat(1.0),
        Vector3::new(0.3, 0.2, 0.1),
    )
    .unwrap();
    let c = contact(&a, &turned).unwrap();
    assert!((c.normal - turned.axis(0)).norm() < 1e-15 && (c.depth - 2.0).abs() < 1e-15);
    // A point at a ball's centre, a ray from it, concentric boxes.
    assert_eq!(b.boundary_point(&b.center()).normal, Vector3::x());
    let hit = b
        .cast_ray(&Ray::new(b.center(), Vector3::y()).unwrap(), 1.0)
        .unwrap();
    assert_eq!((hit.toi, hit.normal), (0.0, Vector3::x()));
    let o = Obb::from_aabb(&cube);
    assert_eq!(separation(&o, &o).axis, Vector3::x());
    assert!(
        c.normal
            .iter()
            .chain(hit.normal.iter())
            .all(|x| x.is_finite())
    );
}

#[test]
fn zero_size_boxes_work_as_points_and_segments() {
    let point = Aabb::new(Vector2::new(1.0, 1.0), Vector2::new(1.0, 1.0)).unwrap();
    let segment = Aabb::new(Vector2::new(0.0, 3.0), Vector2::new(4.0, 3.0)).unwrap();
    assert_eq!(distance(&point, &segment), 2.0);
    let b = ball2(1.0, 2.0, 1.0);
    assert!(overlaps(&b, &point) && overlaps(&b, &segment));
    assert_eq!(contact(&b, &segment).unwrap().normal, -Vector2::y());
    let flat =
        Obb::<f64, 2>::from_angle(Vector2::zeros(), Vector2::new(2.0, 0.0), FRAC_PI_4).unwrap();
    let ray = Ray::new(Vector2::new(-1.0, 1.0), Vector2::new(1.0, 0.0)).unwrap();
    let hit = flat.cast_ray(&ray, 10.0).unwrap();
    assert!((hit.toi - 2.0).abs() < 1e-15);
    assert!(Parry2::cast_ray(&Shape::Obb(flat), &ray, 10.0).is_some());
    let p = Obb::<f64, 3>::new(Vector3::zeros(), Vector3::zeros(), Rotation::identity()).unwrap();
    let q = Obb::<f64, 3>::new(
        Vector3::new(0.0, 3.0, 4.0),
        Vector3::zeros(),
        Rotation::identity(),
    )
    .unwrap();
    assert_eq!(distance(&p, &q), 5.0);
}
