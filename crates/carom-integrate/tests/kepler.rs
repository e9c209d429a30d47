//! Convergence orders on a Kepler orbit, measured: explicit Euler 1, semi-implicit Euler
//! 1, velocity Verlet 2, RK4 4.
//!
//! The orbit: `μ = 1`, semi-major axis `a = 1`, eccentricity `e = 0.5`, starting at
//! perihelion `(a(1 − e), 0)` with speed `sqrt(μ (1 + e) / (a (1 − e)))`; the period is
//! `2π`. The reference is the exact Kepler solution: the eccentric anomaly `E` solves
//! Kepler's equation `E − e sin E = M` (Newton's method to 1e-15), and
//! `x = a (cos E − e)`, `y = a sqrt(1 − e²) sin E`. The error is the distance from the
//! computed to the exact position, and the order is the least-squares slope of
//! `ln error` against `ln h` over four step sizes in the asymptotic range.
//!
//! The error is measured at three quarters of a period, not after a whole one: after a
//! whole period semi-implicit Euler's error is second order. It is conjugate to velocity
//! Verlet by a near-identity change of variables `χ = id + O(h)` (it has *effective*
//! order 2), and the `O(h)` terms of `χ` and `χ⁻¹` cancel whenever the orbit is back
//! where it started. [`semi_implicit_euler_has_effective_order_2_after_whole_periods`]
//! shows it.

use crate::common;

use std::f64::consts::PI;

use carom_integrate::{Acceleration, BallState, ForceField, Integrator, Stepper, Vector};
use common::{OneBall, fitted_order};
use nalgebra::{Rotation3, Vector2, Vector3};

const ECCENTRICITY: f64 = 0.5;

/// The inverse-square attraction `a = −μ x / |x|³` to the origin, `μ = 1`.
struct Kepler;

impl<const D: usize> ForceField<f64, D> for Kepler
where
    nalgebra::Const<D>: carom_integrate::Space<f64, D>,
{
    fn acceleration(&self, ball: &BallState<f64, D>) -> Acceleration<f64, D> {
        let r2 = ball.position.norm_squared();
        Acceleration::linear(ball.position * (-1.0 / (r2 * r2.sqrt())))
    }
}

/// The exact position at time `t` (mean anomaly `M = t` since the period is 2π).
fn kepler_position(t: f64) -> Vector2<f64> {
    let e = ECCENTRICITY;
    let m = t.rem_euclid(2.0 * PI);
    let mut big_e = if e > 0.8 { PI } else { m };
    for _ in 0..50 {
        let step = (big_e - e * big_e.sin() - m) / (1.0 - e * big_e.cos());
        big_e -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    Vector2::new(big_e.cos() - e, (1.0 - e * e).sqrt() * big_e.sin())
}

fn start() -> (Vector2<f64>, Vector2<f64>) {
    let e = ECCENTRICITY;
    (
        Vector2::new(1.0 - e, 0.0),
        Vector2::new(0.0, ((1.0 + e) / (1.0 - e)).sqrt()),
    )
}

/// The position error at time `end` after `steps` steps, with the orbit plane mapped into
/// `D` dimensions by `embed`.
fn error_at<const D: usize>(
    integrator: Integrator,
    end: f64,
    steps: usize,
    embed: impl Fn(Vector2<f64>) -> Vector<f64, D>,
) -> f64
where
    nalgebra::Const<D>: carom_integrate::Space<f64, D>,
{
    let stepper = Stepper::new(integrator, Kepler).unwrap();
    let (x0, v0) = start();
    let mut ball = OneBall::new(embed(x0), embed(v0));
    ball.run(&stepper, end / steps as f64, steps, |_, _| {});
    (ball.x - embed(kepler_position(end))).norm()
}

#[test]
fn the_reference_solution_solves_the_equations_of_motion() {
    // Independent of the integrators: the Kepler solution's finite-difference
    // acceleration matches −x/|x|³ along the orbit.
    let h = 1e-4;
    for &t in &[0.0, 0.7, 2.0, PI, 5.5] {
        let a =
            (kepler_position(t + h) - 2.0 * kepler_position(t) + kepler_position(t - h)) / (h * h);
        let x = kepler_position(t);
        let expected = -x / x.norm().powi(3);
        assert!((a - expected).norm() < 1e-6 * expected.norm(), "t = {t}");
    }
    assert!((kepler_position(2.0 * PI) - start().0).norm() < 1e-15);
}

/// The fitted order and the errors at `end` for the given step counts, in 2D.
fn measured_order(integrator: Integrator, end: f64, steps: &[usize]) -> (f64, Vec<f64>) {
    let errors: Vec<f64> = steps
        .iter()
        .map(|&n| error_at(integrator, end, n, |p| p))
        .collect();
    let hs: Vec<f64> = steps.iter().map(|&n| end / n as f64).collect();
    (fitted_order(&hs, &errors), errors)
}

const THREE_QUARTERS: f64 = 1.5 * PI;

#[test]
fn measured_orders_are_1_1_2_4() {
    let cases = [
        (
            Integrator::ExplicitEuler,
            [30_000, 60_000, 120_000, 240_000],
        ),
        (
            Integrator::SemiImplicitEuler,
            [3_000, 6_000, 12_000, 24_000],
        ),
        (Integrator::VelocityVerlet, [750, 1_500, 3_000, 6_000]),
        (Integrator::Rk4, [400, 800, 1_600, 3_200]),
    ];
    for (integrator, steps) in cases {
        let (order, errors) = measured_order(integrator, THREE_QUARTERS, &steps);
        println!("{integrator}: order {order:.4}, errors {errors:?}");
        let expected = f64::from(integrator.order().unwrap());
        assert!(
            (order - expected).abs() < 0.1,
            "{integrator}: measured order {order}, expected {expected}; errors {errors:?}"
        );
    }
}

#[test]
fn semi_implicit_euler_has_effective_order_2_after_whole_periods() {
    let (order, errors) = measured_order(
        Integrator::SemiImplicitEuler,
        2.0 * PI,
        &[3_000, 6_000, 12_000, 24_000],
    );
    assert!(
        (order - 2.0).abs() < 0.05,
        "order {order}, errors {errors:?}"
    );
}

#[test]
fn orders_are_the_same_for_an_orbit_in_a_tilted_plane_in_3d() {
    // The 3D code path (other vectors, the same arithmetic per component) on the orbit
    // turned out of every coordinate plane; the 2D errors are the reference.
    let tilt = Rotation3::from_euler_angles(0.4, -0.9, 1.3);
    let embed = |p: Vector2<f64>| tilt * Vector3::new(p.x, p.y, 0.0);
    for (integrator, steps) in [(Integrator::VelocityVerlet, 1_500), (Integrator::Rk4, 400)] {
        let e3 = error_at(integrator, THREE_QUARTERS, steps, embed);
        let e2 = error_at(integrator, THREE_QUARTERS, steps, |p| p);
        assert!(
            (e3 - e2).abs() < 1e-6 * e2 + 1e-12,
            "{integrator}: 3D {e3}, 2D {e2}"
        );
    }
}
