//! The exact integrators (ballistic, linear drag, spin decay) against the textbook
//! formulas, a fine RK4, their own group property and the limits they must reach.

use crate::common;

use carom_integrate::exact::{ballistic, linear_drag};
use carom_integrate::{
    Bodies, Gravity, Integrator, LinearDrag, PointState, SpinDamping, Stepper, TimeStep,
};
use common::run_bodies;
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;

/// The textbook form `v = v∞ + (v₀ − v∞) e^{−kt}`, `x = x₀ + v∞ t + (v₀ − v∞)(1 − e^{−kt})/k`;
/// accurate when `kt` is neither tiny nor huge.
fn textbook(
    x0: Vector3<f64>,
    v0: Vector3<f64>,
    g: Vector3<f64>,
    k: f64,
    t: f64,
) -> PointState<f64, 3> {
    let v_inf = g / k;
    let decay = (-k * t).exp();
    PointState {
        position: x0 + v_inf * t + (v0 - v_inf) * ((1.0 - decay) / k),
        velocity: v_inf + (v0 - v_inf) * decay,
    }
}

fn relative(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm().max(1.0)
}

const X0: Vector3<f64> = Vector3::new(1.0, -2.0, 10.0);
const V0: Vector3<f64> = Vector3::new(4.0, 0.5, 7.0);
const G: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

#[test]
fn linear_drag_matches_the_textbook_formula() {
    for k in [0.3, 1.0, 2.5, 7.0] {
        for t in [0.2, 1.0, 3.0] {
            let ours = linear_drag(&X0, &V0, &G, k, t);
            let book = textbook(X0, V0, G, k, t);
            assert!(
                relative(&ours.position, &book.position) < 1e-13,
                "k = {k}, t = {t}"
            );
            assert!(
                relative(&ours.velocity, &book.velocity) < 1e-13,
                "k = {k}, t = {t}"
            );
        }
    }
}

#[test]
fn tiny_drag_matches_the_first_order_expansion_where_the_textbook_form_cancels() {
    // x = ballistic − k (v₀ t²/2 + g t³/6) + O(k²), v = v₀ + g t − k (v₀ t + g t²/2) + O(k²).
    let (k, t) = (1e-9, 2.0);
    let ours = linear_drag(&X0, &V0, &G, k, t);
    let free = ballistic(&X0, &V0, &G, t);
    let x1 = free.position - (V0 * (t * t / 2.0) + G * (t * t * t / 6.0)) * k;
    let v1 = free.velocity - (V0 * t + G * (t * t / 2.0)) * k;
    assert!(relative(&ours.position, &x1) < 1e-15);
    assert!(relative(&ours.velocity, &v1) < 1e-15);
    let book = textbook(X0, V0, G, k, t);
    assert!(
        relative(&book.position, &x1) > 1e-9,
        "the textbook form loses digits here"
    );
}

#[test]
fn the_velocity_reaches_the_terminal_velocity_and_stays_finite() {
    let k = 2.0;
    for t in [20.0, 1e3, 1e300] {
        let s = linear_drag(&X0, &V0, &G, k, t);
        assert!(relative(&s.velocity, &(G / k)) < 1e-15, "t = {t}");
        assert!(s.position.iter().all(|c| c.is_finite()));
    }
}

#[test]
fn going_backward_in_time_returns_to_the_start() {
    for (k, t) in [(0.0, 3.0), (1e-9, 3.0), (0.4, 2.0), (2.0, 1.5), (5.0, 1.0)] {
        let there = linear_drag(&X0, &V0, &G, k, t);
        let back = linear_drag(&there.position, &there.velocity, &G, k, -t);
        // Rounding is amplified by up to e^{kt} on the way back.
        let tolerance = 1e-14 * (k * t).exp();
        assert!(
            relative(&back.position, &X0) < tolerance,
            "k = {k}, t = {t}"
        );
        assert!(
            relative(&back.velocity, &V0) < tolerance,
            "k = {k}, t = {t}"
        );
    }
}

/// The stepper for gravity, linear drag and spin damping.
fn closed_form_field() -> (Gravity<f64, 3>, LinearDrag<f64>, SpinDamping<f64>) {
    (
        Gravity::new(G).unwrap(),
        LinearDrag::new(0.02).unwrap(),
        SpinDamping::new(0.7).unwrap(),
    )
}

#[test]
fn the_exact_stepper_agrees_with_a_fine_rk4_for_every_mass() {
    // Masses from 1 g to 1 t (drag rates k = b/m from 20 down to 2e-5) and one of
    // infinite mass.
    let inverse_masses = [1e3, 10.0, 1.0, 1e-3, 0.0];
    let start_x: Vec<_> = (0..5)
        .map(|i| X0 + Vector3::new(f64::from(i), 0.0, 0.0))
        .collect();
    let start_v = vec![V0; 5];
    let start_w = vec![Vector3::new(3.0, -1.0, 20.0); 5];
    let run = |integrator: Integrator, steps: usize| {
        let (mut x, mut v, mut w) = (start_x.clone(), start_v.clone(), start_w.clone());
        let stepper = Stepper::new(integrator, closed_form_field()).unwrap();
        let mut bodies = Bodies::new(&mut x, &mut v, &inverse_masses)
            .unwrap()
            .with_spins(&mut w)
            .unwrap();
        run_bodies(&stepper, &mut bodies, 2.0 / steps as f64, steps);
        (x, v, w)
    };
    let (xe, ve, we) = run(Integrator::Exact, 1);
    // RK4 resolves the fastest rate (k = 20) with k h = 0.005: error ~ (kh)⁴ / 120.
    let (xr, vr, wr) = run(Integrator::Rk4, 8_000);
    for i in 0..5 {
        assert!(
            relative(&xe[i], &xr[i]) < 1e-12,
            "ball {i}: {:?} vs {:?}",
            xe[i],
            xr[i]
        );
        assert!(relative(&ve[i], &vr[i]) < 1e-12, "ball {i}");
        assert!(relative(&we[i], &wr[i]) < 1e-12, "ball {i}");
    }
    // And against the formulas directly.
    for (i, &w_inv) in inverse_masses.iter().enumerate() {
        let expected = if w_inv > 0.0 {
            linear_drag(&start_x[i], &V0, &G, 0.02 * w_inv, 2.0)
        } else {
            PointState {
                position: start_x[i] + V0 * 2.0,
                velocity: V0,
            }
        };
        assert_eq!(xe[i], expected.position);
        assert_eq!(ve[i], expected.velocity);
        let spin_decay = if w_inv > 0.0 {
            (-0.7_f64 * 2.0).exp()
        } else {
            1.0
        };
        assert!(relative(&we[i], &(start_w[i] * spin_decay)) < 1e-15);
    }
}

#[test]
fn many_exact_steps_equal_one_long_step() {
    let stepper = Stepper::new(Integrator::Exact, closed_form_field()).unwrap();
    let mut one = (X0, V0, Vector3::new(0.0, 5.0, 0.0));
    let mut many = one;
    stepper.step_ball(
        &mut one.0,
        &mut one.1,
        &mut one.2,
        0.5,
        0.0,
        TimeStep::new(3.0).unwrap(),
    );
    let h = TimeStep::new(3.0 / 1_000.0).unwrap();
    for n in 0..1_000 {
        stepper.step_ball(
            &mut many.0,
            &mut many.1,
            &mut many.2,
            0.5,
            f64::from(n) * h.get(),
            h,
        );
    }
    assert!(relative(&one.0, &many.0) < 1e-12);
    assert!(relative(&one.1, &many.1) < 1e-12);
    assert!(relative(&one.2, &many.2) < 1e-12);
}

#[test]
fn f32_follows_the_f64_closed_form_to_its_precision() {
    let (x0, v0, g) = (
        Vector2::new(1.0_f32, 10.0),
        Vector2::new(4.0_f32, 7.0),
        Vector2::new(0.0_f32, -9.81),
    );
    for (k, t) in [
        (0.0_f32, 1.5_f32),
        (1e-6, 1.5),
        (0.3, 1.5),
        (3.0, 0.7),
        (0.3, -1.0),
    ] {
        let ours = linear_drag(&x0, &v0, &g, k, t);
        let wide = linear_drag(
            &x0.cast::<f64>(),
            &v0.cast::<f64>(),
            &g.cast::<f64>(),
            f64::from(k),
            f64::from(t),
        );
        let scale = wide.position.norm().max(1.0);
        assert!(
            (ours.position.cast::<f64>() - wide.position).norm() < 4e-7 * scale,
            "k = {k}, t = {t}"
        );
        assert!(
            (ours.velocity.cast::<f64>() - wide.velocity).norm()
                < 4e-7 * wide.velocity.norm().max(1.0)
        );
    }
}

fn vector3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn forward_then_backward_is_the_identity(
        x0 in vector3(1e3), v0 in vector3(1e2), g in vector3(20.0), k in 0.0..5.0, t in -2.0..2.0,
    ) {
        let there = linear_drag(&x0, &v0, &g, k, t);
        let back = linear_drag(&there.position, &there.velocity, &g, k, -t);
        let scale = x0.norm() + v0.norm() + g.norm() + 1.0;
        let tolerance = 1e-13 * scale * (k * t.abs()).exp();
        prop_assert!((back.position - x0).norm() < tolerance);
        prop_assert!((back.velocity - v0).norm() < tolerance);
    }

    #[test]
    fn advancing_in_two_pieces_is_advancing_once(
        x0 in vector3(1e3), v0 in vector3(1e2), g in vector3(20.0), k in 0.0..5.0,
        t1 in -1.0..1.0, t2 in -1.0..1.0,
    ) {
        let a = linear_drag(&x0, &v0, &g, k, t1);
        let ab = linear_drag(&a.position, &a.velocity, &g, k, t2);
        let once = linear_drag(&x0, &v0, &g, k, t1 + t2);
        let scale = x0.norm() + v0.norm() + g.norm() + 1.0;
        let tolerance = 1e-13 * scale * (k * (t1.abs() + t2.abs())).exp();
        prop_assert!((ab.position - once.position).norm() < tolerance);
        prop_assert!((ab.velocity - once.velocity).norm() < tolerance);
    }

    #[test]
    fn the_velocity_is_the_derivative_of_the_position_and_obeys_the_ode(
        x0 in vector3(10.0), v0 in vector3(10.0), g in vector3(20.0), k in 0.0..5.0, t in -1.0..1.0,
    ) {
        // Central differences, step δ: errors O(δ²) in the derivative plus rounding.
        let d = 1e-4;
        let at = |s: f64| linear_drag(&x0, &v0, &g, k, s);
        let (before, now, after) = (at(t - d), at(t), at(t + d));
        let scale = (x0.norm() + v0.norm() + g.norm() + 1.0) * (k * t.abs()).exp();
        let dx = (after.position - before.position) / (2.0 * d);
        prop_assert!((dx - now.velocity).norm() < 1e-6 * scale);
        let dv = (after.velocity - before.velocity) / (2.0 * d);
        prop_assert!((dv - (g - now.velocity * k)).norm() < 1e-6 * scale * (1.0 + k * k));
    }
}
