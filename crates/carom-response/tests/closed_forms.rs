//! Frictionless collisions against closed forms: the textbook 1D results, Collision Lab's
//! normal/tangent decomposition, extreme mass ratios, walls and paddles.

use crate::common;

use carom_response::{Body, Coefficients, Contact, Outcome, central_impulse, resolve};
use common::{TestBall, assert_close};
use nalgebra::{SVector, Vector1, Vector2, Vector3};

/// The textbook head-on result (momentum and Newton's restitution law):
/// `v1' = (m1 u1 + m2 u2 + m2 e (u2 − u1)) / (m1 + m2)` and symmetrically.
fn head_on(m1: f64, m2: f64, u1: f64, u2: f64, e: f64) -> (f64, f64) {
    let p = m1 * u1 + m2 * u2;
    (
        (p + m2 * e * (u2 - u1)) / (m1 + m2),
        (p + m1 * e * (u1 - u2)) / (m1 + m2),
    )
}

/// Collision Lab's formulas (CollisionEngine.collideBalls): normal components exchanged
/// by the 1D law, tangential components unchanged.
fn collision_lab(
    m1: f64,
    m2: f64,
    v1: Vector2<f64>,
    v2: Vector2<f64>,
    normal: Vector2<f64>,
    e: f64,
) -> (Vector2<f64>, Vector2<f64>) {
    let tangent = Vector2::new(-normal.y, normal.x);
    let (v1n, v2n) = (v1.dot(&normal), v2.dot(&normal));
    let (v1t, v2t) = (v1.dot(&tangent), v2.dot(&tangent));
    let v1n_after = ((m1 - m2 * e) * v1n + m2 * (1.0 + e) * v2n) / (m1 + m2);
    let v2n_after = ((m2 - m1 * e) * v2n + m1 * (1.0 + e) * v1n) / (m1 + m2);
    (
        normal * v1n_after + tangent * v1t,
        normal * v2n_after + tangent * v2t,
    )
}

fn head_on_along<const D: usize>(axis: SVector<f64, D>)
where
    nalgebra::Const<D>: carom_response::Space<f64, D>,
{
    let axis = axis.normalize();
    for (m1, m2) in [(1.0, 1.0), (0.5, 1.5), (3.0, 0.25), (1e-3, 7.0)] {
        for (u1, u2) in [(1.0, 0.0), (1.0, -0.5), (2.5, 1.0), (-0.5, -3.0)] {
            for e in [0.0, 0.3, 0.75, 1.0] {
                let a = TestBall::<D>::new(m1, 0.2, SVector::zeros(), axis * u1);
                let b = TestBall::<D>::new(m2, 0.3, axis * 0.5, axis * u2);
                let r = resolve(
                    &a.body(),
                    &b.body(),
                    &a.contact(&b),
                    &Coefficients::frictionless(e).unwrap(),
                );
                let (w1, w2) = head_on(m1, m2, u1, u2, e);
                let tol = 1e-14 * (u1.abs() + u2.abs());
                assert_close(r.velocity[0].as_slice(), (axis * w1).as_slice(), tol, "v1");
                assert_close(r.velocity[1].as_slice(), (axis * w2).as_slice(), tol, "v2");
                assert_eq!(r.outcome, Outcome::Applied(carom_response::Friction::None));
                let [c1, c2] =
                    central_impulse((1.0 / m1, &(axis * u1)), (1.0 / m2, &(axis * u2)), &axis, e)
                        .expect("closing head on");
                assert_close(c1.as_slice(), (axis * w1).as_slice(), tol, "central v1");
                assert_close(c2.as_slice(), (axis * w2).as_slice(), tol, "central v2");
            }
        }
    }
}

#[test]
fn head_on_collisions_match_the_textbook_in_2d_and_3d() {
    head_on_along(Vector2::new(1.0, 0.0));
    head_on_along(Vector2::new(3.0, -4.0));
    head_on_along(Vector3::new(1.0, 2.0, -2.0));
}

#[test]
fn collision_lab_intro_screen_numbers() {
    // Intro screen: 0.5 kg at 1 m/s meets 1.5 kg at −0.5 m/s head on.
    let a = TestBall::<2>::new(0.5, 0.15, Vector2::new(-0.15, 0.0), Vector2::new(1.0, 0.0));
    let b = TestBall::<2>::new(1.5, 0.15, Vector2::new(0.15, 0.0), Vector2::new(-0.5, 0.0));
    let elastic = resolve(
        &a.body(),
        &b.body(),
        &a.contact(&b),
        &Coefficients::elastic(),
    );
    // By hand: v1' = ((0.5 − 1.5)·1 + 2·1.5·(−0.5)) / 2 = −1.25, v2' = ((1.5 − 0.5)(−0.5) + 2·0.5·1) / 2 = 0.25.
    assert_close(elastic.velocity[0].as_slice(), &[-1.25, 0.0], 1e-15, "v1");
    assert_close(elastic.velocity[1].as_slice(), &[0.25, 0.0], 1e-15, "v2");
    // Elasticity 50%: v1' = ((0.5 − 0.75)·1 + 1.5·1.5·(−0.5)) / 2 = −0.6875, v2' = 0.0625.
    let half = resolve(
        &a.body(),
        &b.body(),
        &a.contact(&b),
        &Coefficients::frictionless(0.5).unwrap(),
    );
    assert_close(half.velocity[0].as_slice(), &[-0.6875, 0.0], 1e-15, "v1");
    assert_close(half.velocity[1].as_slice(), &[0.0625, 0.0], 1e-15, "v2");
    // KE before 0.25 + 0.1875 = 0.4375; after 0.5·0.5·0.6875² + 0.5·1.5·0.0625².
    let lost = 0.5 * 0.5 * 0.6875f64.powi(2) + 0.5 * 1.5 * 0.0625f64.powi(2) - 0.4375;
    assert!((half.kinetic_energy_change - lost).abs() < 1e-15);
}

#[test]
fn collision_lab_explore_2d_default_balls_match_its_normal_tangent_decomposition() {
    // Explore 2D defaults: 0.5 kg at (−1, 0) moving (1, 0.3); 1.5 kg at (0, 0.5) moving
    // (−0.5, −0.5); constant radius 0.15. Advance both to first contact (closed form).
    let (p1, v1, m1) = (Vector2::<f64>::new(-1.0, 0.0), Vector2::new(1.0, 0.3), 0.5);
    let (p2, v2, m2) = (Vector2::new(0.0, 0.5), Vector2::new(-0.5, -0.5), 1.5);
    let (dp, dv) = (p2 - p1, v2 - v1);
    let (qa, qb, qc) = (
        dv.norm_squared(),
        dp.dot(&dv),
        dp.norm_squared() - 0.3f64.powi(2),
    );
    let t = (-qb - (qb * qb - qa * qc).sqrt()) / qa;
    assert!(t > 0.0);
    let a = TestBall::<2>::new(m1, 0.15, p1 + v1 * t, v1);
    let b = TestBall::<2>::new(m2, 0.15, p2 + v2 * t, v2);
    let normal = (b.center - a.center).normalize();
    for e in [1.0, 0.6, 0.0] {
        let r = resolve(
            &a.body(),
            &b.body(),
            &a.contact(&b),
            &Coefficients::frictionless(e).unwrap(),
        );
        let (w1, w2) = collision_lab(m1, m2, v1, v2, normal, e);
        assert_close(r.velocity[0].as_slice(), w1.as_slice(), 1e-14, "v1");
        assert_close(r.velocity[1].as_slice(), w2.as_slice(), 1e-14, "v2");
        assert!(r.angular_velocity[0].x.abs() < 1e-14); // r × n = ρ n × n: rounding only
    }
}

#[test]
fn oblique_collisions_leave_tangential_components_unchanged() {
    let cases_3d = [
        (
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.3, 0.4, 0.1),
            Vector3::new(2.0, 1.0, -0.5),
            Vector3::new(-1.0, 0.2, 0.7),
        ),
        (
            Vector3::new(1e6, -1e6, 1e6),
            Vector3::new(1e6 + 0.1, -1e6 + 0.45, 1e6),
            Vector3::new(1.0, 3.0, 0.0),
            Vector3::new(0.0, -2.0, 0.25),
        ),
    ];
    for (c1, c2, v1, v2) in cases_3d {
        let a = TestBall::<3>::new(2.0, 0.2, c1, v1);
        let b = TestBall::<3>::new(0.7, 0.3, c2, v2);
        let contact = a.contact(&b);
        let n = contact.normal();
        let r = resolve(
            &a.body(),
            &b.body(),
            &contact,
            &Coefficients::frictionless(0.8).unwrap(),
        );
        assert!(r.applied());
        let tangential = |v: Vector3<f64>| v - n * n.dot(&v);
        assert_close(
            tangential(r.velocity[0]).as_slice(),
            tangential(v1).as_slice(),
            1e-14,
            "t1",
        );
        assert_close(
            tangential(r.velocity[1]).as_slice(),
            tangential(v2).as_slice(),
            1e-14,
            "t2",
        );
        // Newton's law on the normal components.
        let after = (r.velocity[1] - r.velocity[0]).dot(&n);
        assert!((after + 0.8 * r.normal_velocity).abs() < 1e-14);
        // No spin from a frictionless ball contact (r × n = ρ n × n vanishes up to rounding).
        assert!(r.angular_velocity[0].amax() < 1e-14 && r.angular_velocity[1].amax() < 1e-14);
    }
}

#[test]
fn mass_ratio_1e6_light_ball_bounces_at_minus_v_plus_2v_heavy() {
    let (big, small) = (1e6, 1.0);
    let (v_heavy, v_light) = (2.0, -3.0);
    let heavy = TestBall::<2>::new(big, 1.0, Vector2::zeros(), Vector2::new(v_heavy, 0.0));
    let light = TestBall::<2>::new(
        small,
        0.1,
        Vector2::new(1.1, 0.0),
        Vector2::new(v_light, 0.0),
    );
    let r = resolve(
        &heavy.body(),
        &light.body(),
        &heavy.contact(&light),
        &Coefficients::elastic(),
    );
    let (w_heavy, w_light) = head_on(big, small, v_heavy, v_light, 1.0);
    assert!((r.velocity[1].x - w_light).abs() < 1e-12);
    assert!((r.velocity[0].x - w_heavy).abs() < 1e-12);
    // The limits: the light ball leaves at −v + 2V, the heavy one changes by 2 (m/M)(v − V).
    assert!((r.velocity[1].x - (-v_light + 2.0 * v_heavy)).abs() < 2e-5);
    assert!((r.velocity[0].x - v_heavy - 2.0 * small / big * (v_light - v_heavy)).abs() < 1e-10);
    let p_before = big * v_heavy + small * v_light;
    let p_after = big * r.velocity[0].x + small * r.velocity[1].x;
    assert!((p_after - p_before).abs() <= 1e-12 * (big * v_heavy.abs()));
}

#[test]
fn restitution_zero_leaves_a_common_normal_velocity_and_one_conserves_energy() {
    let a = TestBall::<3>::new(1.0, 0.5, Vector3::zeros(), Vector3::new(1.0, 0.5, 0.0));
    let b = TestBall::<3>::new(
        3.0,
        0.5,
        Vector3::new(0.6, 0.8, 0.0),
        Vector3::new(-0.5, -0.25, 1.0),
    );
    let contact = a.contact(&b);
    let slide = resolve(&a.body(), &b.body(), &contact, &Coefficients::slide());
    let n = contact.normal();
    assert!((slide.velocity[0].dot(&n) - slide.velocity[1].dot(&n)).abs() < 1e-15);
    assert!(slide.kinetic_energy_change < 0.0);
    let elastic = resolve(&a.body(), &b.body(), &contact, &Coefficients::elastic());
    let ke = |v: [Vector3<f64>; 2]| 0.5 * v[0].norm_squared() + 1.5 * v[1].norm_squared();
    let before = ke([a.velocity, b.velocity]);
    assert!((ke(elastic.velocity) - before).abs() < 1e-15 * before);
    assert!(elastic.kinetic_energy_change.abs() < 1e-15 * before);
}

#[test]
fn ball_on_a_static_wall_reverses_the_normal_component_times_e() {
    for e in [0.0, 0.5, 1.0] {
        let ball =
            Body::<f64, 2>::ball(0.3, 0.1, Vector2::new(2.0, -3.0), Vector1::zeros()).unwrap();
        // The floor below the ball: normal from the ball into the floor is −y.
        let contact =
            Contact::ball_surface(0.1, &Vector2::new(0.0, -1.0), &Vector2::zeros()).unwrap();
        let r = resolve(
            &ball,
            &Body::fixed(),
            &contact,
            &Coefficients::frictionless(e).unwrap(),
        );
        assert_eq!(r.velocity[0], Vector2::new(2.0, 3.0 * e));
        assert_eq!(r.velocity[1], Vector2::zeros());
        assert_eq!(r.normal_impulse, 0.3 * 3.0 * (1.0 + e));
        let lost = 0.5 * 0.3 * (9.0 * e * e - 9.0);
        assert!((r.kinetic_energy_change - lost).abs() < 1e-15);
        assert!((r.contact_energy_change - lost).abs() < 1e-15);
    }
}

#[test]
fn paddle_moving_at_u_sends_a_ball_at_rest_off_at_one_plus_e_times_u() {
    let u = Vector3::new(0.0, 0.0, 4.0);
    for e in [0.0, 0.8, 1.0] {
        let paddle = Body::<f64, 3>::kinematic(u, Vector3::zeros()).unwrap();
        let ball = Body::ball(0.0027, 0.02, Vector3::zeros(), Vector3::zeros()).unwrap();
        // The paddle (a) is below the ball (b): normal from paddle to ball is +z.
        let contact = Contact::new(
            Vector3::z(),
            Vector3::new(0.05, 0.0, 0.0),
            Vector3::new(0.0, 0.0, -0.02),
        )
        .unwrap();
        let r = resolve(
            &paddle,
            &ball,
            &contact,
            &Coefficients::frictionless(e).unwrap(),
        );
        assert_close(
            r.velocity[1].as_slice(),
            (u * (1.0 + e)).as_slice(),
            1e-15,
            "ball",
        );
        assert_eq!(r.velocity[0], u);
        // The paddle does work on the ball; the contact itself never creates energy.
        let gained = 0.5 * 0.0027 * ((1.0 + e) * 4.0f64).powi(2);
        assert!((r.kinetic_energy_change - gained).abs() < 1e-15);
        assert!(r.contact_energy_change <= 1e-18);
    }
    // A spinning paddle passes on the velocity of its contact point, v + ω × r.
    let paddle = Body::<f64, 2>::kinematic(Vector2::zeros(), Vector1::new(2.0)).unwrap();
    let ball = Body::ball(1.0, 0.1, Vector2::zeros(), Vector1::zeros()).unwrap();
    // Contact point 0.5 along +x from the paddle's pivot, ball above it: ω × r = (0, 1).
    let contact = Contact::new(
        Vector2::y(),
        Vector2::new(0.5, 0.0),
        Vector2::new(0.0, -0.1),
    )
    .unwrap();
    let r = resolve(&paddle, &ball, &contact, &Coefficients::elastic());
    assert_close(r.velocity[1].as_slice(), &[0.0, 2.0], 1e-15, "ball");
}

#[test]
fn receding_touching_and_immovable_pairs_get_no_impulse() {
    let a = TestBall::<2>::new(1.0, 0.5, Vector2::zeros(), Vector2::new(-1.0, 0.0));
    let b = TestBall::<2>::new(1.0, 0.5, Vector2::new(1.0, 0.0), Vector2::new(1.0, 5.0));
    let r = resolve(
        &a.body(),
        &b.body(),
        &a.contact(&b),
        &Coefficients::new(0.5, 1.0).unwrap(),
    );
    assert_eq!(r.outcome, Outcome::Receding);
    assert_eq!(
        (r.velocity, r.impulse, r.kinetic_energy_change),
        ([a.velocity, b.velocity], Vector2::zeros(), 0.0)
    );
    // Sliding past each other: zero normal velocity, tangential motion only.
    let c = TestBall::<2>::new(1.0, 0.5, Vector2::new(1.0, 0.0), Vector2::new(0.0, 3.0));
    let a0 = TestBall::<2>::new(1.0, 0.5, Vector2::zeros(), Vector2::zeros());
    let r = resolve(
        &a0.body(),
        &c.body(),
        &a0.contact(&c),
        &Coefficients::new(0.5, 1.0).unwrap(),
    );
    assert_eq!(r.outcome, Outcome::Touching);
    assert_eq!(r.velocity[1], c.velocity);
    // Two immovable bodies: nothing can happen, and nothing is NaN.
    let paddle = Body::<f64, 2>::kinematic(Vector2::new(0.0, 1.0), Vector1::zeros()).unwrap();
    let contact = Contact::new(Vector2::y(), Vector2::zeros(), Vector2::zeros()).unwrap();
    let r = resolve(
        &Body::fixed(),
        &paddle,
        &Contact::new(-Vector2::y(), Vector2::zeros(), Vector2::zeros()).unwrap(),
        &Coefficients::elastic(),
    );
    assert_eq!(r.outcome, Outcome::Immovable);
    assert_eq!(r.velocity[1], Vector2::new(0.0, 1.0));
    let r = resolve(
        &Body::<f64, 2>::fixed(),
        &Body::fixed(),
        &contact,
        &Coefficients::elastic(),
    );
    assert_eq!(r.outcome, Outcome::Touching);
}

#[test]
fn f32_head_on_matches_the_textbook_to_single_precision() {
    let a = Body::<f32, 3>::ball(0.5, 0.1, Vector3::new(1.0, 0.0, 0.0), Vector3::zeros()).unwrap();
    let b = Body::<f32, 3>::ball(1.5, 0.1, Vector3::new(-0.5, 0.0, 0.0), Vector3::zeros()).unwrap();
    let contact =
        Contact::between_balls(&Vector3::zeros(), 0.1f32, &Vector3::new(0.2, 0.0, 0.0), 0.1)
            .unwrap();
    let r = resolve(
        &a,
        &b,
        &contact,
        &Coefficients::frictionless(0.5f32).unwrap(),
    );
    let (w1, w2) = head_on(0.5, 1.5, 1.0, -0.5, 0.5);
    assert!((f64::from(r.velocity[0].x) - w1).abs() < 1e-6);
    assert!((f64::from(r.velocity[1].x) - w2).abs() < 1e-6);
}

#[test]
fn speeds_of_1e6_far_from_the_origin_keep_relative_accuracy() {
    let a = TestBall::<2>::new(1.0, 1.0, Vector2::new(1e6, 1e6), Vector2::new(1e6, 0.0));
    let b = TestBall::<2>::new(
        2.0,
        1.0,
        Vector2::new(1e6 + 2.0, 1e6),
        Vector2::new(-1e6, 0.0),
    );
    let r = resolve(
        &a.body(),
        &b.body(),
        &a.contact(&b),
        &Coefficients::frictionless(0.9).unwrap(),
    );
    let (w1, w2) = head_on(1.0, 2.0, 1e6, -1e6, 0.9);
    assert!((r.velocity[0].x - w1).abs() < 1e-15 * 1e6 * 4.0);
    assert!((r.velocity[1].x - w2).abs() < 1e-15 * 1e6 * 4.0);
}

#[test]
fn grazing_contact_gets_a_tiny_impulse_and_stays_finite() {
    // Normal almost orthogonal to the relative velocity: v_n = −1e-12.
    let a = TestBall::<3>::new(1.0, 0.5, Vector3::zeros(), Vector3::new(0.0, 1.0, -1e-12));
    let b = TestBall::<3>::new(1.0, 0.5, Vector3::new(0.0, 0.0, -1.0), Vector3::zeros());
    let r = resolve(
        &a.body(),
        &b.body(),
        &a.contact(&b),
        &Coefficients::new(1.0, 0.5).unwrap(),
    );
    assert!(r.applied());
    assert!((r.normal_impulse - 1e-12).abs() < 1e-24);
    // Sliding with μ j_n ≪ |v_t|: the friction impulse is capped at μ j_n.
    assert_eq!(
        r.outcome,
        Outcome::Applied(carom_response::Friction::Sliding)
    );
    assert!((r.tangential_impulse.norm() - 0.5e-12).abs() < 1e-24);
    assert!(r.velocity.iter().all(|v| v.iter().all(|x| x.is_finite())));
}

#[test]
fn a_smooth_ball_on_an_immovable_ball_reverses_its_normal_velocity_times_e() {
    // Ball a (1 kg) hits an immovable ball b obliquely along n = (0.6, 0.8): the normal
    // component −e v_n comes back, the tangential one stays; b does not move.
    let n = Vector2::new(0.6, 0.8);
    let v = Vector2::new(2.0, 1.0);
    let v_n = v.dot(&n);
    for e in [0.0, 0.5, 1.0] {
        let [a, b] = central_impulse((1.0, &v), (0.0, &Vector2::zeros()), &n, e)
            .expect("closing on the immovable ball");
        assert_close(
            a.as_slice(),
            (v - n * ((1.0 + e) * v_n)).as_slice(),
            1e-15,
            "a",
        );
        assert_eq!(b, Vector2::zeros());
    }
    // No impulse: receding, touching at zero normal speed, or both immovable.
    let z = Vector2::zeros();
    assert!(central_impulse((1.0, &-v), (0.0, &z), &n, 1.0).is_none());
    let tangential = Vector2::new(-0.8, 0.6);
    assert!(central_impulse((1.0, &tangential), (1.0, &z), &n, 1.0).is_none());
    assert!(central_impulse((0.0, &v), (0.0, &z), &n, 1.0).is_none());
}
