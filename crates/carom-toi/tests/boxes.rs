//! Ball against boxes: faces, edges and corners of the rounded box in closed form,
//! linear and under gravity, rotated and moving boxes, starting inside; brute force for
//! random ballistic cases.

use crate::common;

use approx::assert_relative_eq;
use carom_geometry::{Aabb, Ball, Obb};
use carom_toi::{BoxFeature, Direction, Kinematics, Status, Window, ball_aabb, ball_obb};
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;

fn forward() -> Window<f64> {
    Window::unbounded(Direction::Forward)
}

fn unit_square() -> Aabb<f64, 2> {
    Aabb::new(Vector2::new(-1.0, -1.0), Vector2::new(1.0, 1.0)).unwrap()
}

fn linear2(vx: f64, vy: f64) -> Kinematics<f64, 2> {
    Kinematics::linear(Vector2::new(vx, vy)).unwrap()
}

#[test]
fn face_contact_in_2d() {
    let ball = Ball::new(Vector2::new(-4.0, 0.3), 0.5).unwrap();
    let toi = ball_aabb(
        &ball,
        &linear2(2.0, 0.0),
        &unit_square(),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!((toi.status, toi.feature), (Status::Hit, BoxFeature::Face));
    assert_relative_eq!(toi.time, 1.25, max_relative = 1e-15);
    assert_eq!(toi.normal, Vector2::new(1.0, 0.0));
    assert_relative_eq!(toi.point, Vector2::new(-1.0, 0.3), max_relative = 1e-15);
}

#[test]
fn corner_contact_in_2d_is_the_rounded_corner_not_the_square() {
    // Moving along x at height 1.3: the expanded square (half size 1.5) would be hit at
    // x = −1.5, the rounded corner only at x = −1 − √(0.25 − 0.09) = −1.4.
    let ball = Ball::new(Vector2::new(-4.0, 1.3), 0.5).unwrap();
    let toi = ball_aabb(
        &ball,
        &linear2(1.0, 0.0),
        &unit_square(),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!((toi.status, toi.feature), (Status::Hit, BoxFeature::Corner));
    assert_relative_eq!(toi.time, 2.6, max_relative = 1e-14);
    assert_relative_eq!(toi.normal, Vector2::new(0.8, -0.6), max_relative = 1e-14);
    assert_relative_eq!(toi.point, Vector2::new(-1.0, 1.0), max_relative = 1e-15);
    // Passing at height 1.5 + 1e-9 misses; at 1.5 − 1e-9 grazes the corner.
    let miss = Ball::new(Vector2::new(-4.0, 1.5 + 1e-9), 0.5).unwrap();
    assert_eq!(
        ball_aabb(
            &miss,
            &linear2(1.0, 0.0),
            &unit_square(),
            &Kinematics::at_rest(),
            &forward()
        )
        .status,
        Status::NoHit
    );
    let graze = Ball::new(Vector2::new(-4.0, 1.5 - 1e-9), 0.5).unwrap();
    let g = ball_aabb(
        &graze,
        &linear2(1.0, 0.0),
        &unit_square(),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!((g.status, g.feature), (Status::Hit, BoxFeature::Corner));
    let half_chord = ((0.5 - (0.5 - 1e-9)) * (0.5 + 0.5 - 1e-9_f64)).sqrt();
    assert_relative_eq!(g.time, 3.0 - half_chord, max_relative = 1e-12);
}

#[test]
fn edge_and_corner_contacts_in_3d() {
    let cube = Aabb::new(Vector3::new(-1.0, -1.0, -1.0), Vector3::new(1.0, 1.0, 1.0)).unwrap();
    let rest = Kinematics::at_rest();
    // Along x at (y, z) = (1.3, 0): the edge parallel to z at (−1, 1).
    let edge = Ball::new(Vector3::new(-4.0, 1.3, 0.0), 0.5).unwrap();
    let k = Kinematics::linear(Vector3::new(1.0, 0.0, 0.0)).unwrap();
    let toi = ball_aabb(&edge, &k, &cube, &rest, &forward());
    assert_eq!(toi.feature, BoxFeature::Edge);
    assert_relative_eq!(toi.time, 2.6, max_relative = 1e-14);
    assert_relative_eq!(
        toi.point,
        Vector3::new(-1.0, 1.0, 0.0),
        max_relative = 1e-15
    );
    // Along the diagonal towards the corner (1, 1, 1): contact at distance r from it.
    let d = Vector3::new(1.0, 1.0, 1.0) / 3f64.sqrt();
    let corner = Ball::new(Vector3::new(1.0, 1.0, 1.0) + d * 5.0, 0.5).unwrap();
    let k = Kinematics::linear(-d * 2.0).unwrap();
    let toi = ball_aabb(&corner, &k, &cube, &rest, &forward());
    assert_eq!(toi.feature, BoxFeature::Corner);
    assert_relative_eq!(toi.time, 2.25, max_relative = 1e-14);
    assert_relative_eq!(toi.normal, -d, max_relative = 1e-14);
}

#[test]
fn ballistic_face_edge_and_corner() {
    let g = Vector2::new(0.0, -10.0);
    // Dropped from height 4 above the top face: 4 − 5t² = 1.5.
    let drop = Ball::new(Vector2::new(0.2, 4.0), 0.5).unwrap();
    let toi = ball_aabb(
        &drop,
        &Kinematics::new(Vector2::zeros(), g).unwrap(),
        &unit_square(),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!(toi.feature, BoxFeature::Face);
    assert_relative_eq!(toi.time, 0.5_f64.sqrt(), max_relative = 1e-15);
    // Dropped just beside the corner: x = 1.3, falls onto the corner at y − 1 = 0.4.
    let beside = Ball::new(Vector2::new(1.3, 4.0), 0.5).unwrap();
    let toi = ball_aabb(
        &beside,
        &Kinematics::new(Vector2::zeros(), g).unwrap(),
        &unit_square(),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!(toi.feature, BoxFeature::Corner);
    // 4 − 5t² = 1.4.
    assert_relative_eq!(toi.time, 0.52_f64.sqrt(), max_relative = 1e-14);
    assert_relative_eq!(toi.normal, Vector2::new(-0.6, -0.8), max_relative = 1e-13);
    // 3D: dropped beside an edge of a cube.
    let cube = Aabb::new(Vector3::new(-1.0, -1.0, -1.0), Vector3::new(1.0, 1.0, 1.0)).unwrap();
    let ball = Ball::new(Vector3::new(1.3, 4.0, 0.0), 0.5).unwrap();
    let k = Kinematics::new(Vector3::zeros(), Vector3::new(0.0, -10.0, 0.0)).unwrap();
    let toi = ball_aabb(&ball, &k, &cube, &Kinematics::at_rest(), &forward());
    assert_eq!(toi.feature, BoxFeature::Edge);
    assert_relative_eq!(toi.time, 0.52_f64.sqrt(), max_relative = 1e-14);
}

#[test]
fn a_lob_rises_past_the_corner_and_lands_on_top() {
    // From (−3, 0) at (2, 8) under g = 10: it rises past the top-left corner (at x = −1.2
    // it is at height 3.15) and comes down on the top face: 8t − 5t² = 1.2, x ∈ [−1, 1].
    let lob = Ball::new(Vector2::new(-3.0, 0.0), 0.2).unwrap();
    let k = Kinematics::new(Vector2::new(2.0, 8.0), Vector2::new(0.0, -10.0)).unwrap();
    let toi = ball_aabb(&lob, &k, &unit_square(), &Kinematics::at_rest(), &forward());
    assert_eq!((toi.status, toi.feature), (Status::Hit, BoxFeature::Face));
    assert_relative_eq!(toi.time, (8.0 + 40f64.sqrt()) / 10.0, max_relative = 1e-15);
    assert_eq!(toi.normal, Vector2::new(0.0, -1.0));
    // With a horizon before the landing: nothing, though it passes within 2 of the box.
    let early = ball_aabb(
        &lob,
        &k,
        &unit_square(),
        &Kinematics::at_rest(),
        &Window::forward(1.4).unwrap(),
    );
    assert_eq!(early.status, Status::NoHit);
}

#[test]
fn rotated_and_moving_boxes() {
    // A square rotated by 45°: its corner points along +x at distance √2.
    let obb = Obb::from_angle(
        Vector2::zeros(),
        Vector2::new(1.0, 1.0),
        core::f64::consts::FRAC_PI_4,
    )
    .unwrap();
    let ball = Ball::new(Vector2::new(5.0, 0.0), 0.5).unwrap();
    let toi = ball_obb(
        &ball,
        &linear2(-1.0, 0.0),
        &obb,
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_eq!(toi.feature, BoxFeature::Corner);
    assert_relative_eq!(toi.time, 5.0 - 0.5 - 2f64.sqrt(), max_relative = 1e-14);
    assert_relative_eq!(
        toi.point,
        Vector2::new(2f64.sqrt(), 0.0),
        max_relative = 1e-14
    );
    // The same box moving towards a ball at rest: relative motion is what counts, and the
    // point is on the box where it is at the time of contact.
    let still = Ball::new(Vector2::new(5.0, 0.0), 0.5).unwrap();
    let toi2 = ball_obb(
        &still,
        &Kinematics::at_rest(),
        &obb,
        &linear2(1.0, 0.0),
        &forward(),
    );
    assert_relative_eq!(toi2.time, toi.time, max_relative = 1e-15);
    assert_relative_eq!(
        toi2.point,
        Vector2::new(2f64.sqrt() + toi.time, 0.0),
        max_relative = 1e-14
    );
}

#[test]
fn starting_states() {
    let rest = Kinematics::at_rest();
    // Touching the face and approaching: immediate. Touching and leaving: none.
    let touching = Ball::new(Vector2::new(-1.5, 0.0), 0.5).unwrap();
    let t = ball_aabb(
        &touching,
        &linear2(1.0, 0.0),
        &unit_square(),
        &rest,
        &forward(),
    );
    assert_eq!(
        (t.status, t.time, t.feature),
        (Status::AlreadyTouching, 0.0, BoxFeature::Face)
    );
    assert_eq!(t.normal, Vector2::new(1.0, 0.0));
    assert_eq!(
        ball_aabb(
            &touching,
            &linear2(-1.0, 0.0),
            &unit_square(),
            &rest,
            &forward()
        )
        .status,
        Status::NoHit
    );
    assert_eq!(
        ball_aabb(
            &touching,
            &linear2(0.0, 1.0),
            &unit_square(),
            &rest,
            &forward()
        )
        .status,
        Status::NoHit
    );
    // Centre inside the box: the nearest face decides.
    let inside = Ball::new(Vector2::new(0.8, 0.1), 0.5).unwrap();
    let i = ball_aabb(
        &inside,
        &linear2(-1.0, 0.0),
        &unit_square(),
        &rest,
        &forward(),
    );
    assert_eq!(
        (i.status, i.feature),
        (Status::AlreadyTouching, BoxFeature::Inside)
    );
    assert_eq!(i.normal, Vector2::new(-1.0, 0.0));
    assert_eq!(
        ball_aabb(
            &inside,
            &linear2(1.0, 0.0),
            &unit_square(),
            &rest,
            &forward()
        )
        .status,
        Status::NoHit
    );
    // Overlapping the top and leaving upward under gravity: it separates (up to 1.75),
    // then falls back onto the face: −0.2 + 3t − 5t² = 0, the descending root.
    let leaving = Ball::new(Vector2::new(0.0, 1.3), 0.5).unwrap();
    let k = Kinematics::new(Vector2::new(0.0, 3.0), Vector2::new(0.0, -10.0)).unwrap();
    let back = ball_aabb(&leaving, &k, &unit_square(), &rest, &forward());
    assert_eq!((back.status, back.feature), (Status::Hit, BoxFeature::Face));
    assert_relative_eq!(back.time, (3.0 + 5f64.sqrt()) / 10.0, max_relative = 1e-15);
    // Thrown so that it only just reaches the surface (apex exactly at gap 0): it never
    // separates, and turns back into the box at the apex, t = 0.25: that is its
    // contact (without it the ball sank through the box unseen).
    // Exactly representable: gap −0.25 + 2t − 4t² peaks at 0.
    let sunk = Ball::new(Vector2::new(0.0, 1.25), 0.5).unwrap();
    let tangent = Kinematics::new(Vector2::new(0.0, 2.0), Vector2::new(0.0, -8.0)).unwrap();
    let turn = ball_aabb(&sunk, &tangent, &unit_square(), &rest, &forward());
    assert_eq!((turn.status, turn.time), (Status::Hit, 0.25));
    // Turning back while still overlapping (apex at gap −0.25 + 1 − 1 = −0.25 at
    // t = 0.25): the contact is the turn.
    let deep = Kinematics::new(Vector2::new(0.0, 2.0), Vector2::new(0.0, -8.0)).unwrap();
    let deeper = Ball::new(Vector2::new(0.0, 1.0), 0.5).unwrap();
    let turn = ball_aabb(&deeper, &deep, &unit_square(), &rest, &forward());
    assert_eq!((turn.status, turn.time), (Status::Hit, 0.25));
}

#[test]
fn backward_and_f32() {
    let ball = Ball::new(Vector2::new(-4.0_f32, 0.3), 0.5).unwrap();
    let away = Kinematics::linear(Vector2::new(-2.0_f32, 0.0)).unwrap();
    let sq = Aabb::new(Vector2::new(-1.0_f32, -1.0), Vector2::new(1.0, 1.0)).unwrap();
    let b = ball_aabb(
        &ball,
        &away,
        &sq,
        &Kinematics::at_rest(),
        &Window::backward(10.0).unwrap(),
    );
    assert_eq!((b.status, b.time), (Status::Hit, -1.25));
    assert_eq!(b.normal, Vector2::new(1.0, 0.0));
}

/// `ball_obb` against dense sampling of the exact gap (distance to the moving box minus
/// the radius) up to `horizon`: the same status and time as the first sampled contact
/// (a descent, or a turn of an overlap that never opened),
/// a real contact for a dip shorter than the sampling step, the contact point on the
/// box and the normal from the centre to it.
fn agrees_with_brute_force(
    ball: &Ball<f64, 3>,
    k: &Kinematics<f64, 3>,
    obb: &Obb<f64, 3>,
    kb: &Kinematics<f64, 3>,
    horizon: f64,
) -> Result<(), TestCaseError> {
    let r = ball.radius();
    let gap = |t: f64| {
        let moved = obb.translated(&kb.displacement(t));
        let x = moved.to_local(&(ball.center() + k.displacement(t)));
        let he = moved.half_extents();
        (x - x.inf(&he).sup(&-he)).norm() - r
    };
    let toi = ball_obb(ball, k, obb, kb, &Window::forward(horizon).unwrap());
    let brute = common::brute_first_contact(gap, horizon, 20_000);
    if toi.status == Status::AlreadyTouching {
        prop_assert!(gap(0.0) <= 1e-12);
    } else if let Some((tb, turn)) = brute {
        prop_assert_eq!(toi.status, Status::Hit);
        // A turn is a flat maximum: its time is known to about √u.
        let tol = if turn { 1e-6 } else { 1e-8 };
        prop_assert!((toi.time - tb).abs() < tol, "{} vs {}", toi.time, tb);
    }
    if toi.status == Status::Hit && gap(toi.time) < -1e-9 {
        // Overlapping since the start: it turned back there.
        prop_assert!(common::is_turn(gap, toi.time), "no turn at {}", toi.time);
    } else if toi.status == Status::Hit {
        // Also for a dip shorter than the sampling step: a real contact.
        prop_assert!(gap(toi.time).abs() < 1e-9);
        let touch = obb.translated(&kb.displacement(toi.time));
        let p = ball.center() + k.displacement(toi.time);
        // Point on the box surface, unit normal from the centre towards it.
        prop_assert!((toi.normal.norm() - 1.0).abs() < 1e-12);
        prop_assert!((p + toi.normal * r - toi.point).norm() < 1e-7);
        let h = obb.half_extents();
        prop_assert!(
            touch
                .to_local(&toi.point)
                .abs()
                .iter()
                .zip(h.iter())
                .all(|(x, h)| *x <= h + 1e-9)
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Ballistic balls against a rotated, moving 3D box.
    #[test]
    fn ballistic_obb_agrees_with_brute_force(
        c in prop::array::uniform3(-4.0..4.0f64),
        v in prop::array::uniform3(-4.0..4.0f64),
        g in prop::array::uniform3(-8.0..8.0f64),
        h in prop::array::uniform3(0.0..1.5f64),
        axis in prop::array::uniform3(-2.0..2.0f64),
        vb in prop::array::uniform3(-1.0..1.0f64),
        r in 0.05..1.0f64,
    ) {
        let obb = Obb::from_axis_angle(Vector3::new(0.5, -0.2, 0.1), Vector3::from(h), Vector3::from(axis)).unwrap();
        let ball = Ball::new(Vector3::from(c), r).unwrap();
        let k = Kinematics::new(Vector3::from(v), Vector3::from(g)).unwrap();
        let kb = Kinematics::linear(Vector3::from(vb)).unwrap();
        agrees_with_brute_force(&ball, &k, &obb, &kb, 2.0)?;
    }

    /// Linear motion (the slab test and the direct face test, then the walk) against a
    /// rotated, moving 3D box; a third of the cases aim at an edge of the grown box,
    /// where the face test must not decide.
    #[test]
    fn linear_obb_agrees_with_brute_force(
        c in prop::array::uniform3(-4.0..4.0f64),
        v in prop::array::uniform3(-4.0..4.0f64),
        h in prop::array::uniform3(0.0..1.5f64),
        axis in prop::array::uniform3(-2.0..2.0f64),
        vb in prop::array::uniform3(-1.0..1.0f64),
        r in 0.05..1.0f64,
        aim_at_edge in 0..3,
    ) {
        let obb = Obb::from_axis_angle(Vector3::new(0.5, -0.2, 0.1), Vector3::from(h), Vector3::from(axis)).unwrap();
        let kb = Kinematics::linear(Vector3::from(vb)).unwrap();
        let k = Kinematics::linear(Vector3::from(v)).unwrap();
        let mut c = Vector3::from(c);
        if aim_at_edge == 0 {
            // Start where the relative motion passes through the box's (1, 1, ·) edge
            // line grown by r, at time 1.
            let edge = obb.center() + obb.rotation() * Vector3::new(h[0] + r, h[1] + r, 0.0);
            c = edge - (k.velocity() - kb.velocity());
        }
        agrees_with_brute_force(&Ball::new(c, r).unwrap(), &k, &obb, &kb, 3.0)?;
    }
}
