//! The collapse and Zeno guards in small closed-form simulations: a ball bouncing under
//! gravity comes to rest after a finite number of bounces, and three balls on a line that
//! collapse without a guard collide finitely often with either guard.

use carom_response::{
    Body, Bounce, Coefficients, CollapseGuard, Contact, RestingGuard, normal_velocity, resolve,
};
use nalgebra::{Vector1, Vector2};

const G: f64 = 9.81;

/// Drops a ball from height `h0` onto a static floor and bounces it with restitution
/// `e`, flight times in closed form (`2 v / g`), until the guard says rest (or the
/// rebound speed underflows to zero). Returns the number of collisions and the time of
/// the last one.
fn bounce_until_rest(
    h0: f64,
    e: f64,
    guard: Option<RestingGuard<f64>>,
    cap: usize,
) -> (usize, f64) {
    let floor = Contact::ball_surface(0.02, &Vector2::new(0.0, -1.0), &Vector2::zeros()).unwrap();
    let v0 = (2.0 * G * h0).sqrt();
    let mut ball = Body::ball(0.0027, 0.02, Vector2::new(0.0, -v0), Vector1::zeros()).unwrap();
    let mut t = v0 / G;
    for collisions in 1..=cap {
        let approach = -normal_velocity(&ball, &Body::fixed(), &floor);
        let decision = guard.map_or(Bounce::Rebound, |g| g.decide(approach, e, G));
        let restitution = if decision == Bounce::Rest { 0.0 } else { e };
        let r = resolve(
            &ball,
            &Body::fixed(),
            &floor,
            &Coefficients::frictionless(restitution).unwrap(),
        );
        ball = r.body_a(&ball);
        let up = ball.velocity().y;
        if decision == Bounce::Rest || up == 0.0 {
            return (collisions, t);
        }
        // Up and down again: flight 2 v / g, landing at the same speed.
        t += 2.0 * up / G;
        ball = ball.with_velocities(Vector2::new(0.0, -up), Vector1::zeros());
    }
    (cap, t)
}

#[test]
fn a_bouncing_ball_comes_to_rest_after_the_predicted_number_of_bounces() {
    let (h0, e, t_min) = (1.0, 0.5, 1e-3);
    let v0 = (2.0 * G * h0).sqrt();
    let (collisions, t_rest) =
        bounce_until_rest(h0, e, Some(RestingGuard::new(t_min).unwrap()), 10_000);
    // Bounce i approaches at e^(i−1) v0 and would rebound at e^i v0: it rests at the first
    // i with e^i v0 < g t_min / 2.
    let predicted = ((G * t_min / (2.0 * v0)).ln() / e.ln()).floor() as usize + 1;
    assert_eq!(collisions, predicted);
    assert!(collisions < 20);
    // It rests just before the Zeno time t∞ = v0/g + 2 v0 e / (g (1 − e)); the bounces
    // cut off last less than t_min / (1 − e) in all.
    let zeno = v0 / G + 2.0 * v0 * e / (G * (1.0 - e));
    assert!(
        t_rest < zeno && zeno - t_rest < t_min / (1.0 - e),
        "rest at {t_rest}, Zeno time {zeno}"
    );
}

#[test]
fn without_the_guard_the_bounces_pile_up_before_the_zeno_time() {
    let (h0, e) = (1.0, 0.5);
    let v0 = (2.0 * G * h0).sqrt();
    let (collisions, t) = bounce_until_rest(h0, e, None, 100_000);
    // Only the underflow of e^k v0 to zero ends it: over a thousand bounces, all of them
    // before the Zeno time.
    assert!(collisions > 1000, "{collisions}");
    assert!(t < v0 / G + 2.0 * v0 * e / (G * (1.0 - e)));
}

/// Equal balls on a line, exact event-driven dynamics: next contact of neighbours in
/// closed form, collisions resolved by `resolve` with the guard's restitution. Returns
/// the number of collisions before `t_end` (stopping at `cap`) and the time reached.
fn line_of_balls(
    positions: &[f64],
    velocities: &[f64],
    e: f64,
    guard: CollapseGuard<f64>,
    t_end: f64,
    cap: usize,
) -> (usize, f64) {
    const RADIUS: f64 = 0.01;
    let mut x = positions.to_vec();
    let mut v = velocities.to_vec();
    let mut last = vec![f64::NEG_INFINITY; x.len()];
    let mut t = 0.0;
    for count in 0..cap {
        let next = (0..x.len() - 1)
            .filter(|&i| v[i] > v[i + 1])
            .map(|i| {
                (
                    ((x[i + 1] - x[i] - 2.0 * RADIUS) / (v[i] - v[i + 1])).max(0.0),
                    i,
                )
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((dt, i)) = next.filter(|(dt, _)| t + dt <= t_end) else {
            return (count, t_end);
        };
        t += dt;
        for (xi, vi) in x.iter_mut().zip(&v) {
            *xi += vi * dt;
        }
        let body =
            |k: usize| Body::ball(1.0, RADIUS, Vector2::new(v[k], 0.0), Vector1::zeros()).unwrap();
        let contact = Contact::new(
            Vector2::x(),
            Vector2::new(RADIUS, 0.0),
            Vector2::new(-RADIUS, 0.0),
        )
        .unwrap();
        let (a, b) = (body(i), body(i + 1));
        let approach = -normal_velocity(&a, &b, &contact);
        let restitution = guard.restitution(e, approach, [t - last[i], t - last[i + 1]]);
        let r = resolve(
            &a,
            &b,
            &contact,
            &Coefficients::frictionless(restitution).unwrap(),
        );
        v[i] = r.velocity[0].x;
        v[i + 1] = r.velocity[1].x;
        last[i] = t;
        last[i + 1] = t;
    }
    (cap, t)
}

/// McNamara and Young's setup: `n` equal balls at unit spacing on a line, random
/// velocities in [−1, 1] (a fixed linear congruential sequence), no walls.
fn column(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut state = 12345u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (
        (0..n).map(|i| i as f64).collect(),
        (0..n).map(|_| 2.0 * uniform() - 1.0).collect(),
    )
}

/// Columns that collapse without a guard with this sequence (found by running it; the
/// same columns with e = 0.7 do not collapse).
const COLLAPSING: [(usize, f64); 2] = [(20, 0.5), (30, 0.3)];

#[test]
fn columns_collapse_without_a_guard() {
    for (n, e) in COLLAPSING {
        let (x, v) = column(n);
        let (count, t) = line_of_balls(&x, &v, e, CollapseGuard::Off, 1000.0, 100_000);
        assert_eq!(
            count, 100_000,
            "{n} balls, e = {e}: the collision count must explode"
        );
        // The collisions pile up at (near) a finite time: in floating point the collapse
        // ends in runs of collisions that advance time by next to nothing.
        assert!(t < 200.0, "{n} balls: stuck at t = {t}");
        let (_, t_half) = line_of_balls(&x, &v, e, CollapseGuard::Off, 1000.0, 50_000);
        assert!(t - t_half < 0.01, "{n} balls: t = {t}, t_half = {t_half}");
    }
}

/// Runs every collapsing column with `guard`: it must reach the end time with fewer than
/// `max_collisions` collisions.
fn assert_finite_with(guard: CollapseGuard<f64>, max_collisions: usize) {
    for (n, e) in COLLAPSING {
        let (x, v) = column(n);
        let (count, t) = line_of_balls(&x, &v, e, guard, 1000.0, 100_000);
        assert!(
            count < max_collisions,
            "{n} balls, {guard:?}: {count} collisions"
        );
        assert_eq!(t, 1000.0);
    }
}

#[test]
fn the_tc_model_keeps_the_collision_count_finite() {
    assert_finite_with(CollapseGuard::tc_model(1e-4).unwrap(), 10_000);
}

#[test]
fn the_elastic_threshold_keeps_the_collision_count_finite() {
    assert_finite_with(CollapseGuard::elastic_below(1e-4).unwrap(), 100_000);
}

#[test]
fn columns_that_do_not_collapse_are_unaffected_by_the_guards() {
    for (n, e) in [(10, 0.5), (10, 0.7), (20, 0.7)] {
        let (x, v) = column(n);
        let run = |guard| line_of_balls(&x, &v, e, guard, 1000.0, 100_000);
        let off = run(CollapseGuard::Off);
        assert!(off.0 < 1000 && off.1 == 1000.0, "{n} balls: {off:?}");
        assert_eq!(off, run(CollapseGuard::tc_model(1e-4).unwrap()));
        assert_eq!(off, run(CollapseGuard::elastic_below(1e-6).unwrap()));
    }
}
