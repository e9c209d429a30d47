//! Rotating rigid clusters: closed forms for spinning dumbbells, PhET's failure cases (a
//! purely spinning cluster next to a wall; a contact hidden between the samples of a
//! 100-step bisection), agreement with the closed-form ball queries when nothing spins,
//! and random cases against dense sampling.

use crate::common;

use approx::assert_relative_eq;
use carom_geometry::{Ball, Border, HalfSpace};
use carom_toi::{
    AdvanceOptions, Cluster, ConstantSpin, Kinematics, RigidMotion, Side, Status, Wall, Window,
    ball_ball, cluster_ball, cluster_border, cluster_cluster, cluster_plane,
};
use nalgebra::{Rotation2, Rotation3, Vector1, Vector2, Vector3};
use proptest::prelude::*;

/// Two balls of radius `r` at `±(L, 0)` from the centre of mass.
fn dumbbell(l: f64, r: f64) -> Cluster<f64, 2> {
    Cluster::new(&[(Vector2::new(l, 0.0), r), (Vector2::new(-l, 0.0), r)]).unwrap()
}

fn spin2(angle: f64, v: Vector2<f64>, omega: f64) -> ConstantSpin<f64, 2> {
    ConstantSpin::new(
        Vector2::zeros(),
        Rotation2::new(angle),
        Kinematics::linear(v).unwrap(),
        Vector1::new(omega),
    )
    .unwrap()
}

/// The wall `x >= x_wall` (solid side to the right).
fn right_wall(x_wall: f64) -> HalfSpace<f64, 2> {
    HalfSpace::new(Vector2::new(-1.0, 0.0), Vector2::new(x_wall, 0.0)).unwrap()
}

fn options(cluster: &Cluster<f64, 2>) -> AdvanceOptions<f64> {
    AdvanceOptions::relative_to(cluster.bounding_radius()).unwrap()
}

#[test]
fn a_purely_spinning_dumbbell_hits_the_wall_at_the_closed_form_time() {
    // Vertical at t = 0, turning clockwise at 1 rad/s, centre of mass at rest: ball 0
    // reaches x = L cos θ = X − r when θ = acos((X − r)/L). PhET's engine, which looks
    // at the centre's velocity, lets this cluster pass through the wall.
    let (l, r, x_wall) = (1.0, 0.2, 1.1);
    let c = dumbbell(l, r);
    let m = spin2(core::f64::consts::FRAC_PI_2, Vector2::zeros(), -1.0);
    let toi = cluster_plane(
        &c,
        &m,
        &right_wall(x_wall),
        &Window::forward(10.0).unwrap(),
        &options(&c),
    );
    let expected = core::f64::consts::FRAC_PI_2 - ((x_wall - r) / l).acos();
    assert_eq!((toi.status, toi.feature), (Status::Hit, 0));
    assert!(
        (toi.time - expected).abs() < 1e-11,
        "{} vs {expected}",
        toi.time
    );
    assert_eq!(toi.normal, Vector2::new(1.0, 0.0));
    assert_relative_eq!(toi.point.x, x_wall, max_relative = 1e-15);
    // The reported time is on the safe side: the ball is not yet in the wall.
    let centre = m.state_at(toi.time).point(&Vector2::new(l, 0.0));
    assert!(centre.x + r <= x_wall + 1e-12);
    // Backward, spinning the other way: the same contact at −t.
    let back = spin2(core::f64::consts::FRAC_PI_2, Vector2::zeros(), 1.0);
    let b = cluster_plane(
        &c,
        &back,
        &right_wall(x_wall),
        &Window::backward(10.0).unwrap(),
        &options(&c),
    );
    assert_eq!(b.status, Status::Hit);
    assert!((b.time + expected).abs() < 1e-11, "{}", b.time);
}

/// PhET's cluster–wall search: sample 100 steps over the horizon, bisect the first
/// sample interval whose end overlaps.
fn hundred_step_bisection(gap: impl Fn(f64) -> f64, horizon: f64) -> Option<f64> {
    let mut prev = 0.0;
    for k in 1..=100 {
        let t = horizon * f64::from(k) / 100.0;
        if gap(t) < 0.0 {
            let (mut lo, mut hi) = (prev, t);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if gap(mid) < 0.0 { hi = mid } else { lo = mid }
            }
            return Some(lo);
        }
        prev = t;
    }
    None
}

#[test]
fn a_brief_graze_between_two_bisection_samples_is_caught() {
    // Ball 0 on an arm of length 1 spins at 10 rad/s and pokes into the wall only while
    // its angle is within α = 0.03 of 0: from t_c − α/ω to t_c + α/ω with t_c = 0.555,
    // strictly between the samples 0.55 and 0.56 of a 100-step search over [0, 1]; the
    // next pass is after the horizon. Ball 1, on a short arm, never reaches the wall.
    let (r, omega, t_c, alpha) = (0.2, 10.0, 0.555, 0.03);
    let arms = [Vector2::new(1.0, 0.0), Vector2::new(-0.5, 0.0)];
    let c = Cluster::new(&[(arms[0], r), (arms[1], r)]).unwrap();
    let m = spin2(-omega * t_c, Vector2::zeros(), omega);
    let wall = right_wall(r + f64::cos(alpha));
    let gap = |t: f64| {
        let s = m.state_at(t);
        arms.iter()
            .map(|o| wall.signed_distance(&s.point(o)) - r)
            .fold(f64::INFINITY, f64::min)
    };
    assert_eq!(
        hundred_step_bisection(gap, 1.0),
        None,
        "the sampled search misses it"
    );
    let first = t_c - alpha / omega;
    let toi = cluster_plane(&c, &m, &wall, &Window::forward(1.0).unwrap(), &options(&c));
    assert_eq!((toi.status, toi.feature), (Status::Hit, 0));
    assert!((toi.time - first).abs() < 1e-11, "{} vs {first}", toi.time);
}

#[test]
fn without_spin_the_cluster_queries_match_the_closed_forms() {
    let c = dumbbell(1.0, 0.25);
    let v = Vector2::new(2.0, 0.5);
    let m = spin2(0.3, v, 0.0);
    let other = Ball::new(Vector2::new(6.0, 1.0), 0.5).unwrap();
    let ko = Kinematics::linear(Vector2::new(-1.0, 0.0)).unwrap();
    let w = Window::forward(20.0).unwrap();
    let toi = cluster_ball(&c, &m, &other, &ko, &w, &options(&c));
    // Each cluster ball as a lone ball: the earlier contact wins.
    let exact = (0..2)
        .map(|k| {
            let centre = m.state_at(0.0).point(&c.balls()[k].offset());
            let b = Ball::new(centre, 0.25).unwrap();
            (
                ball_ball(&b, &Kinematics::linear(v).unwrap(), &other, &ko, &w).time,
                k,
            )
        })
        .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
    assert!(exact.0.is_finite());
    assert_eq!(toi.feature, exact.1);
    assert!(
        (toi.time - exact.0).abs() < 1e-11,
        "{} vs {}",
        toi.time,
        exact.0
    );
    let n = ball_ball(
        &Ball::new(m.state_at(0.0).point(&c.balls()[exact.1].offset()), 0.25).unwrap(),
        &Kinematics::linear(v).unwrap(),
        &other,
        &ko,
        &w,
    )
    .normal;
    assert_relative_eq!(toi.normal, n, epsilon = 1e-9);
    // Two one-ball clusters are two balls.
    let a = Cluster::new(&[(Vector2::zeros(), 0.5)]).unwrap();
    let b = Cluster::new(&[(Vector2::zeros(), 0.3)]).unwrap();
    let ma = spin2(0.0, Vector2::new(1.0, 0.0), 3.0);
    let mb = ConstantSpin::new(
        Vector2::new(4.0, 0.4),
        Rotation2::identity(),
        Kinematics::at_rest(),
        Vector1::new(-2.0),
    )
    .unwrap();
    let cc = cluster_cluster(&a, &ma, &b, &mb, &w, &options(&a));
    let bb = ball_ball(
        &Ball::new(Vector2::zeros(), 0.5).unwrap(),
        &Kinematics::linear(Vector2::new(1.0, 0.0)).unwrap(),
        &Ball::new(Vector2::new(4.0, 0.4), 0.3).unwrap(),
        &Kinematics::at_rest(),
        &w,
    );
    assert_eq!(cc.feature, (0, 0));
    assert!((cc.time - bb.time).abs() < 1e-11);
}

#[test]
fn spinning_dumbbell_in_a_border_hits_the_right_wall_first() {
    let c = dumbbell(1.0, 0.2);
    let m = spin2(core::f64::consts::FRAC_PI_2, Vector2::zeros(), -1.0);
    let border = Border::new(Vector2::new(-3.0, -1.5), Vector2::new(1.1, 1.5)).unwrap();
    let toi = cluster_border(
        &c,
        &m,
        &border,
        &Window::forward(10.0).unwrap(),
        &options(&c),
    );
    let expected = core::f64::consts::FRAC_PI_2 - 0.9f64.acos();
    assert_eq!(
        toi.feature,
        (
            0,
            Wall {
                axis: 0,
                side: Side::Upper
            }
        )
    );
    assert!((toi.time - expected).abs() < 1e-11);
    assert_eq!(toi.normal, Vector2::new(1.0, 0.0));
}

#[test]
fn starting_in_contact() {
    let c = dumbbell(1.0, 0.2);
    let wall = right_wall(1.2);
    let w = Window::forward(10.0).unwrap();
    // Ball 0 touches the wall; turning into it: immediate; turning away: it must leave
    // before it can come back (half a turn later the other ball arrives).
    let into = spin2(0.0, Vector2::new(0.1, 0.0), 0.0);
    assert_eq!(
        cluster_plane(&c, &into, &wall, &w, &options(&c)).status,
        Status::AlreadyTouching
    );
    let away = spin2(0.0, Vector2::zeros(), 1.0);
    let toi = cluster_plane(&c, &away, &wall, &w, &options(&c));
    assert_eq!((toi.status, toi.feature), (Status::Hit, 1));
    assert!(
        (toi.time - core::f64::consts::PI).abs() < 1e-5,
        "{}",
        toi.time
    );
}

#[test]
fn step_budget_is_reported_not_hidden() {
    let c = dumbbell(1.0, 0.2);
    let m = spin2(core::f64::consts::FRAC_PI_2, Vector2::zeros(), -1.0);
    let tight = AdvanceOptions::new(1e-12, 2).unwrap();
    let toi = cluster_plane(
        &c,
        &m,
        &right_wall(1.1),
        &Window::forward(10.0).unwrap(),
        &tight,
    );
    assert_eq!(toi.status, Status::NotConverged);
    assert!(toi.time > 0.0 && toi.time < 1.12, "{}", toi.time);
}

#[test]
fn f32_spinning_dumbbell() {
    let c = Cluster::new(&[
        (Vector2::new(1.0_f32, 0.0), 0.2),
        (Vector2::new(-1.0, 0.0), 0.2),
    ])
    .unwrap();
    let m = ConstantSpin::new(
        Vector2::zeros(),
        Rotation2::new(core::f32::consts::FRAC_PI_2),
        Kinematics::at_rest(),
        Vector1::new(-1.0_f32),
    )
    .unwrap();
    let wall = HalfSpace::new(Vector2::new(-1.0_f32, 0.0), Vector2::new(1.1, 0.0)).unwrap();
    let o = AdvanceOptions::relative_to(c.bounding_radius()).unwrap();
    let toi = cluster_plane(&c, &m, &wall, &Window::forward(10.0).unwrap(), &o);
    let expected = core::f64::consts::FRAC_PI_2 - 0.9f64.acos();
    assert_eq!(toi.status, Status::Hit);
    assert!(
        (f64::from(toi.time) - expected).abs() < 1e-4,
        "{}",
        toi.time
    );
}

#[test]
fn spinning_about_a_principal_axis_in_3d() {
    // A 3D dumbbell spinning about z, like the 2D one.
    let c = Cluster::new(&[
        (Vector3::new(1.0, 0.0, 0.0), 0.2),
        (Vector3::new(-1.0, 0.0, 0.0), 0.2),
    ])
    .unwrap();
    let m = ConstantSpin::new(
        Vector3::zeros(),
        Rotation3::from_axis_angle(&Vector3::z_axis(), core::f64::consts::FRAC_PI_2),
        Kinematics::at_rest(),
        Vector3::new(0.0, 0.0, -1.0),
    )
    .unwrap();
    let wall = HalfSpace::new(Vector3::new(-1.0, 0.0, 0.0), Vector3::new(1.1, 0.0, 0.0)).unwrap();
    let o = AdvanceOptions::relative_to(c.bounding_radius()).unwrap();
    let toi = cluster_plane(&c, &m, &wall, &Window::forward(10.0).unwrap(), &o);
    let expected = core::f64::consts::FRAC_PI_2 - 0.9f64.acos();
    assert!((toi.time - expected).abs() < 1e-11, "{}", toi.time);
}

/// The smallest gap of every cluster ball to the plane at time t.
fn plane_gap(
    c: &Cluster<f64, 3>,
    m: &ConstantSpin<f64, 3>,
    plane: &HalfSpace<f64, 3>,
    t: f64,
) -> f64 {
    let s = m.state_at(t);
    c.balls()
        .iter()
        .map(|b| plane.signed_distance(&s.point(&b.offset())) - b.radius())
        .fold(f64::INFINITY, f64::min)
}

fn random_cluster() -> impl Strategy<Value = Cluster<f64, 3>> {
    prop::collection::vec((prop::array::uniform3(-1.0..1.0f64), 0.05..0.5f64), 1..5).prop_map(|v| {
        Cluster::new(
            &v.into_iter()
                .map(|(o, r)| (Vector3::from(o), r))
                .collect::<Vec<_>>(),
        )
        .unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random 3D clusters (translating, accelerating, spinning) against a floor, against
    /// dense sampling and bisection of the exact gap.
    #[test]
    fn cluster_plane_agrees_with_brute_force(
        c in random_cluster(),
        v in prop::array::uniform3(-2.0..2.0f64),
        g in prop::array::uniform3(-5.0..5.0f64),
        w in prop::array::uniform3(-8.0..8.0f64),
        axis in prop::array::uniform3(-2.0..2.0f64),
        height in 0.5..4.0f64,
    ) {
        let m = ConstantSpin::new(Vector3::new(0.0, height, 0.0), Rotation3::new(Vector3::from(axis)),
            Kinematics::new(Vector3::from(v), Vector3::from(g)).unwrap(), Vector3::from(w)).unwrap();
        let floor = HalfSpace::new(Vector3::new(0.0, 1.0, 0.0), Vector3::zeros()).unwrap();
        let gap = |t| plane_gap(&c, &m, &floor, t);
        prop_assume!(gap(0.0) > 1e-2);
        let horizon = 2.0;
        let o = AdvanceOptions::relative_to(c.bounding_radius()).unwrap();
        let toi = cluster_plane(&c, &m, &floor, &Window::forward(horizon).unwrap(), &o);
        prop_assert_ne!(toi.status, Status::NotConverged);
        let brute = common::brute_first_descent(gap, horizon, 20_000);
        if let Some(tb) = brute {
            prop_assert_eq!(toi.status, Status::Hit);
            prop_assert!(toi.time <= tb + 1e-9, "query {} after sampled {}", toi.time, tb);
        }
        if toi.status == Status::Hit {
            prop_assert!(gap(toi.time).abs() < 1e-9, "gap {}", gap(toi.time));
            prop_assert!(common::min_gap(gap, 0.0, toi.time, 4000) >= -1e-12);
            prop_assert!(toi.time >= brute.unwrap_or(0.0) - 1e-9 || common::min_gap(gap, toi.time, toi.time + 1e-3, 1000) < 1e-9);
        }
    }

    /// Random spinning clusters against a moving ball and against each other.
    #[test]
    fn cluster_pairs_agree_with_brute_force(
        c in random_cluster(),
        d in random_cluster(),
        p in prop::array::uniform3(-4.0..4.0f64),
        v in prop::array::uniform3(-3.0..3.0f64),
        w1 in prop::array::uniform3(-6.0..6.0f64),
        w2 in prop::array::uniform3(-6.0..6.0f64),
    ) {
        let m1 = ConstantSpin::new(Vector3::zeros(), Rotation3::identity(), Kinematics::at_rest(), Vector3::from(w1)).unwrap();
        let m2 = ConstantSpin::new(Vector3::from(p), Rotation3::identity(), Kinematics::linear(Vector3::from(v)).unwrap(), Vector3::from(w2)).unwrap();
        let gap = |t: f64| {
            let (s1, s2) = (m1.state_at(t), m2.state_at(t));
            let mut g = f64::INFINITY;
            for a in c.balls() {
                for b in d.balls() {
                    g = g.min((s2.point(&b.offset()) - s1.point(&a.offset())).norm() - a.radius() - b.radius());
                }
            }
            g
        };
        prop_assume!(gap(0.0) > 1e-2);
        let horizon = 2.0;
        let o = AdvanceOptions::relative_to(c.bounding_radius().max(d.bounding_radius())).unwrap();
        let toi = cluster_cluster(&c, &m1, &d, &m2, &Window::forward(horizon).unwrap(), &o);
        prop_assert_ne!(toi.status, Status::NotConverged);
        let brute = common::brute_first_descent(gap, horizon, 20_000);
        if let Some(tb) = brute {
            prop_assert_eq!(toi.status, Status::Hit);
            prop_assert!(toi.time <= tb + 1e-9, "query {} after sampled {}", toi.time, tb);
        }
        if toi.status == Status::Hit {
            prop_assert!(gap(toi.time).abs() < 1e-9, "gap {}", gap(toi.time));
            prop_assert!(common::min_gap(gap, 0.0, toi.time, 4000) >= -1e-12);
        }
        // The single-ball form against the first ball of `d` translating with m2.
        let ball = Ball::new(m2.state_at(0.0).point(&d.balls()[0].offset()), d.balls()[0].radius()).unwrap();
        let single = cluster_ball(&c, &m1, &ball, &Kinematics::linear(Vector3::from(v)).unwrap(), &Window::forward(horizon).unwrap(), &o);
        let gap1 = |t: f64| {
            let s1 = m1.state_at(t);
            let q = ball.center() + Vector3::from(v) * t;
            c.balls().iter().map(|a| (q - s1.point(&a.offset())).norm() - a.radius() - ball.radius()).fold(f64::INFINITY, f64::min)
        };
        if gap1(0.0) > 1e-2 {
            if let Some(tb) = common::brute_first_descent(gap1, horizon, 20_000) {
                prop_assert_eq!(single.status, Status::Hit);
                prop_assert!(single.time <= tb + 1e-9);
            }
            if single.status == Status::Hit {
                prop_assert!(gap1(single.time).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn a_spinning_cluster_moving_away_is_no_hit_even_without_a_horizon() {
    let c = dumbbell(1.0, 0.2);
    let m = spin2(0.0, Vector2::new(-1.0, 0.3), 7.0);
    let toi = cluster_plane(
        &c,
        &m,
        &right_wall(1.5),
        &Window::unbounded(carom_toi::Direction::Forward),
        &options(&c),
    );
    assert_eq!(toi.status, Status::NoHit);
    let other = Ball::new(Vector2::new(3.0, 0.0), 0.5).unwrap();
    let away = cluster_ball(
        &c,
        &m,
        &other,
        &Kinematics::linear(Vector2::new(1.0, 0.0)).unwrap(),
        &Window::unbounded(carom_toi::Direction::Forward),
        &options(&c),
    );
    assert_eq!(away.status, Status::NoHit);
}
