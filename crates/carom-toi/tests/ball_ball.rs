//! Ball–ball time of impact against closed forms and the named hard cases: touching,
//! grazing by 1e-9 either way, gaps of 1e-12, 1e6 m/s, coordinates near 1e6, f32,
//! backward time, common and differing accelerations.

use crate::common;

use approx::assert_relative_eq;
use carom_geometry::Ball;
use carom_toi::{Direction, Kinematics, Status, Window, ball_ball};
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;

fn ball2(x: f64, y: f64, r: f64) -> Ball<f64, 2> {
    Ball::new(Vector2::new(x, y), r).unwrap()
}

fn moving(vx: f64, vy: f64) -> Kinematics<f64, 2> {
    Kinematics::linear(Vector2::new(vx, vy)).unwrap()
}

fn forward() -> Window<f64> {
    Window::unbounded(Direction::Forward)
}

#[test]
fn head_on_closed_form_with_normal_and_point() {
    let toi = ball_ball(
        &ball2(0.0, 0.0, 0.3),
        &moving(2.0, 0.0),
        &ball2(5.0, 0.0, 0.2),
        &moving(-0.5, 0.0),
        &forward(),
    );
    assert_eq!(toi.status, Status::Hit);
    assert_relative_eq!(toi.time, 4.5 / 2.5, max_relative = 1e-15);
    assert_eq!(toi.normal, Vector2::new(1.0, 0.0));
    // Ball 1 at 3.6, its surface at 3.9 = ball 2's centre 4.1 − 0.2.
    assert_relative_eq!(toi.point, Vector2::new(3.9, 0.0), max_relative = 1e-15);
}

#[test]
fn oblique_contact_matches_the_textbook_root() {
    // Ball 2 moves along −x at height b: contact when |u| = R, at t = (x − √(R² − b²))/v.
    let (x, b, v, r) = (7.0, 0.6, 3.0, 1.0);
    let toi = ball_ball(
        &ball2(0.0, 0.0, 0.5),
        &Kinematics::at_rest(),
        &ball2(x, b, 0.5),
        &moving(-v, 0.0),
        &forward(),
    );
    let expected = (x - (r * r - b * b).sqrt()) / v;
    assert_relative_eq!(toi.time, expected, max_relative = 1e-15);
    assert_relative_eq!(toi.normal, Vector2::new(0.8, 0.6), max_relative = 1e-14);
}

#[test]
fn touching_overlapping_receding_and_resting_follow_the_status_table() {
    let a = ball2(0.0, 0.0, 0.5);
    let touching = ball2(1.0, 0.0, 0.5);
    let overlapping = ball2(0.9, 0.0, 0.5);
    let rest = Kinematics::at_rest();
    let case =
        |b: &Ball<f64, 2>, v: (f64, f64)| ball_ball(&a, &rest, b, &moving(v.0, v.1), &forward());
    let t = case(&touching, (-1.0, 0.0));
    assert_eq!((t.status, t.time), (Status::AlreadyTouching, 0.0));
    assert_eq!(t.point, Vector2::new(0.5, 0.0));
    assert_eq!(case(&touching, (1.0, 0.0)).status, Status::NoHit);
    assert_eq!(case(&touching, (0.0, 0.0)).status, Status::NoHit);
    assert_eq!(
        case(&touching, (0.0, 1.0)).status,
        Status::NoHit,
        "tangential"
    );
    let o = case(&overlapping, (-1.0, 0.0));
    assert_eq!((o.status, o.time), (Status::AlreadyTouching, 0.0));
    assert_relative_eq!(o.point, Vector2::new(0.45, 0.0), max_relative = 1e-15);
    assert_eq!(case(&overlapping, (1.0, 0.0)).status, Status::NoHit);
    assert_eq!(case(&overlapping, (0.0, 0.0)).status, Status::NoHit);
    assert!(case(&overlapping, (1.0, 0.0)).time.is_infinite());
}

#[test]
fn grazing_by_one_nanometre_is_decided_correctly_even_far_away() {
    // Ball 2 passes ball 1 at miss distance m; contact iff m < R = 1. Far away, the
    // textbook discriminant b²/4 − a c subtracts two numbers of size 1e12.
    for x in [10.0, 1e3, 1e6] {
        for (m, hits) in [(1.0 + 1e-9, false), (1.0 - 1e-9, true)] {
            let toi = ball_ball(
                &ball2(0.0, 0.0, 0.5),
                &Kinematics::at_rest(),
                &ball2(x, m, 0.5),
                &moving(-1.0, 0.0),
                &forward(),
            );
            assert_eq!(toi.is_hit(), hits, "x = {x}, m = {m}");
            if hits {
                let half_chord = ((1.0 - m) * (1.0 + m)).sqrt();
                assert_relative_eq!(toi.time, x - half_chord, max_relative = 1e-15);
            }
        }
    }
}

#[test]
fn tiny_gaps_are_resolved_to_the_last_bit() {
    for gap in [1e-12, 1e-15, 3e-16] {
        let x = 1.0 + gap;
        let toi = ball_ball(
            &ball2(0.0, 0.0, 0.5),
            &Kinematics::at_rest(),
            &ball2(x, 0.0, 0.5),
            &moving(-1.0, 0.0),
            &forward(),
        );
        assert_eq!(toi.status, Status::Hit);
        // x − 1 is exact (Sterbenz): the true time of the input given.
        assert_relative_eq!(toi.time, x - 1.0, max_relative = 4.0 * f64::EPSILON);
    }
}

#[test]
fn huge_speeds_and_far_coordinates_keep_relative_accuracy() {
    let toi = ball_ball(
        &ball2(0.0, 0.0, 0.5),
        &moving(1e6, 0.0),
        &ball2(3.0, 0.0, 0.5),
        &Kinematics::at_rest(),
        &forward(),
    );
    assert_relative_eq!(toi.time, 2e-6, max_relative = 1e-15);
    // The same scene translated by (1e6, −1e6): differences are exact, so the time is
    // bit-identical, and the contact point is the translated one.
    let base = ball_ball(
        &ball2(0.25, 0.5, 0.5),
        &moving(1.0, 0.3),
        &ball2(3.0, 1.0, 0.5),
        &moving(-0.7, 0.1),
        &forward(),
    );
    let far = ball_ball(
        &ball2(1e6 + 0.25, -1e6 + 0.5, 0.5),
        &moving(1.0, 0.3),
        &ball2(1e6 + 3.0, -1e6 + 1.0, 0.5),
        &moving(-0.7, 0.1),
        &forward(),
    );
    assert_eq!(far.time, base.time);
    assert_eq!(far.normal, base.normal);
    assert_relative_eq!(
        far.point - Vector2::new(1e6, -1e6),
        base.point,
        epsilon = 1e-9
    );
}

#[test]
fn f32_handles_the_same_cases() {
    let b = |x: f32, y: f32| Ball::new(Vector3::new(x, y, 0.0), 0.5_f32).unwrap();
    let v = |x: f32| Kinematics::linear(Vector3::new(x, 0.0, 0.0)).unwrap();
    let w = Window::<f32>::unbounded(Direction::Forward);
    let toi = ball_ball(
        &b(0.0, 0.0),
        &Kinematics::at_rest(),
        &b(3.0, 0.0),
        &v(-2.0),
        &w,
    );
    assert_eq!((toi.status, toi.time), (Status::Hit, 1.0));
    let graze = ball_ball(
        &b(0.0, 0.0),
        &Kinematics::at_rest(),
        &b(100.0, 1.001),
        &v(-1.0),
        &w,
    );
    assert_eq!(graze.status, Status::NoHit);
    let hit = ball_ball(
        &b(0.0, 0.0),
        &Kinematics::at_rest(),
        &b(100.0, 0.999),
        &v(-1.0),
        &w,
    );
    let expected = 100.0 - ((1.0_f64 - f64::from(0.999_f32)) * (1.0 + f64::from(0.999_f32))).sqrt();
    assert_relative_eq!(f64::from(hit.time), expected, max_relative = 1e-6);
    let fast = ball_ball(
        &b(0.0, 0.0),
        &v(1e6),
        &b(1e3, 0.0),
        &Kinematics::at_rest(),
        &w,
    );
    assert_relative_eq!(fast.time, 999.0 / 1e6, max_relative = 1e-7);
}

#[test]
fn backward_finds_the_pair_that_recedes_forward() {
    let a = ball2(0.0, 0.0, 0.5);
    let b = ball2(3.0, 0.0, 0.5);
    let away = moving(1.0, 0.0);
    let rest = Kinematics::at_rest();
    assert_eq!(
        ball_ball(&a, &rest, &b, &away, &forward()).status,
        Status::NoHit
    );
    let back = ball_ball(
        &a,
        &rest,
        &b,
        &away,
        &Window::unbounded(Direction::Backward),
    );
    assert_eq!((back.status, back.time), (Status::Hit, -2.0));
    assert_eq!(back.normal, Vector2::new(1.0, 0.0));
    // At t = −2 ball 2 was at x = 1: the contact point is x = 0.5.
    assert_relative_eq!(back.point, Vector2::new(0.5, 0.0), max_relative = 1e-15);
    // An approaching pair, seen backward, recedes.
    let toward = moving(-1.0, 0.0);
    let w = Window::backward(10.0).unwrap();
    assert_eq!(ball_ball(&a, &rest, &b, &toward, &w).status, Status::NoHit);
    // Overlapping and approaching backward: immediate.
    let o = ball_ball(&a, &rest, &ball2(0.9, 0.0, 0.5), &away, &w);
    assert_eq!((o.status, o.time), (Status::AlreadyTouching, 0.0));
}

#[test]
fn horizon_cuts_far_events_and_keeps_the_one_at_the_horizon() {
    let args = (ball2(0.0, 0.0, 0.5), moving(1.0, 0.0), ball2(3.0, 0.0, 0.5));
    let at = |h: f64| {
        ball_ball(
            &args.0,
            &args.1,
            &args.2,
            &Kinematics::at_rest(),
            &Window::forward(h).unwrap(),
        )
    };
    assert_eq!(at(1.999).status, Status::NoHit);
    assert_eq!(at(2.0).status, Status::Hit);
    let back = ball_ball(
        &args.0,
        &args.1,
        &args.2,
        &Kinematics::at_rest(),
        &Window::backward(5.0).unwrap(),
    );
    assert_eq!(back.status, Status::NoHit);
}

#[test]
fn a_common_gravity_leaves_the_time_linear_and_the_contact_on_the_parabola() {
    let g = Vector2::new(0.0, -9.81);
    let k1 = Kinematics::new(Vector2::new(2.0, 5.0), g).unwrap();
    let k2 = Kinematics::new(Vector2::new(-0.5, 5.0), g).unwrap();
    let (b1, b2) = (ball2(0.0, 0.0, 0.3), ball2(5.0, 0.0, 0.2));
    let toi = ball_ball(&b1, &k1, &b2, &k2, &forward());
    assert_relative_eq!(toi.time, 1.8, max_relative = 1e-15);
    let c1 = b1.center() + k1.displacement(1.8);
    assert_relative_eq!(toi.point, c1 + Vector2::new(0.3, 0.0), max_relative = 1e-14);
}

#[test]
fn differing_accelerations_give_the_quartic_root() {
    // Ball 2 falls from rest at height 3 onto ball 1 (sum of radii 1): 3 − 5t² = 1.
    let toi = ball_ball(
        &ball2(0.0, 0.0, 0.5),
        &Kinematics::at_rest(),
        &ball2(0.0, 3.0, 0.5),
        &Kinematics::new(Vector2::zeros(), Vector2::new(0.0, -10.0)).unwrap(),
        &forward(),
    );
    assert_eq!(toi.status, Status::Hit);
    assert_relative_eq!(toi.time, 0.4f64.sqrt(), max_relative = 1e-15);
    assert_relative_eq!(toi.normal, Vector2::new(0.0, 1.0), epsilon = 1e-15);
    // Thrown up past it: the lob rises away (receding) and only falls back later.
    let lob = ball_ball(
        &ball2(0.0, 0.0, 0.5),
        &Kinematics::at_rest(),
        &ball2(0.0, 1.5, 0.5),
        &Kinematics::new(Vector2::new(0.0, 4.0), Vector2::new(0.0, -10.0)).unwrap(),
        &forward(),
    );
    // 1.5 + 4t − 5t² = 1 at t = (4 + √26)/10.
    assert_relative_eq!(lob.time, (4.0 + 26f64.sqrt()) / 10.0, max_relative = 1e-14);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Differing constant accelerations in 3D against dense sampling and bisection of the
    /// exact gap: the query never misses a contact the sampling finds, and what it
    /// reports is a real contact no later than the sampled one.
    #[test]
    fn ballistic_pairs_agree_with_brute_force(
        p in prop::array::uniform3(-3.0..3.0f64),
        v in prop::array::uniform3(-4.0..4.0f64),
        a in prop::array::uniform3(-6.0..6.0f64),
        r in 0.1..1.0f64,
    ) {
        let (p, v, a) = (Vector3::from(p), Vector3::from(v), Vector3::from(a));
        let b1 = Ball::new(Vector3::zeros(), 0.5).unwrap();
        let b2 = Ball::new(p, r).unwrap();
        let k2 = Kinematics::new(v, a).unwrap();
        let horizon = 3.0;
        let gap = |t: f64| (p + k2.displacement(t)).norm() - (0.5 + r);
        let toi = ball_ball(&b1, &Kinematics::at_rest(), &b2, &k2, &Window::forward(horizon).unwrap());
        let brute = common::brute_first_contact(gap, horizon, 20_000);
        if toi.status == Status::AlreadyTouching {
            prop_assert!(gap(0.0) <= 0.0);
        } else if let Some((tb, turn)) = brute {
            prop_assert_eq!(toi.status, Status::Hit);
            // A turn is a flat maximum: its time is known to about √u.
            let tol = if turn { 1e-6 } else { 1e-9 };
            prop_assert!(toi.time <= tb + tol, "query {} after sampled {}", toi.time, tb);
        }
        if toi.status == Status::Hit && gap(toi.time) < -1e-9 {
            // Overlapping since the start: it turned back there.
            prop_assert!(common::is_turn(gap, toi.time), "no turn at {}", toi.time);
        } else if toi.status == Status::Hit {
            prop_assert!(gap(toi.time).abs() < 1e-9, "gap {} at {}", gap(toi.time), toi.time);
            prop_assert!(common::min_gap(gap, toi.time, (toi.time + 1e-4).min(horizon), 100) <= 1e-9);
            if gap(0.0) > 0.0 {
                // Nothing penetrates before the reported time.
                prop_assert!(common::min_gap(gap, 0.0, toi.time, 2000) >= -1e-9);
            }
        }
    }
}
