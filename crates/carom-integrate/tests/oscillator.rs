//! The stability theory of the schemes on the undamped oscillator `ẍ = −ω² x`, measured.
//!
//! Derivations are in the `integrator` module documentation. In short, with
//! `E = (|v|² + ω²|x|²)/2` and `s = ωh`:
//!
//! * explicit Euler multiplies `E` by exactly `1 + s²` every step;
//! * semi-implicit Euler conserves `Q = |v|² + ω²|x|² − h ω² x·v` and velocity Verlet
//!   `Q = |v|² + ω²(1 − s²/4)|x|²` exactly; both forms are positive definite (so `E` is
//!   bounded) iff `s < 2`; above 2 the step matrix has a real eigenvalue `λ` with
//!   `|λ| > 1` and `E` grows by `λ²` per step;
//! * RK4 is `R(hJ)` for a skew generator `J`, a scaled rotation: `E` is multiplied by
//!   exactly `|R(is)|² = 1 − s⁶/72 + s⁸/576` every step, `≤ 1` iff `s ≤ 2√2`.
//!
//! Every test measures the trajectory the stepper produces and compares it with these
//! formulas, in 2D and 3D, `f64` and `f32`.

use crate::common;

use carom_integrate::{Integrator, Real, Space, Stepper, Vector};
use common::{OneBall, oscillator, oscillator_energy, wide};
use nalgebra::Const;
use proptest::prelude::*;

/// `ω`; the step is `h = s / ω`.
const OMEGA: f64 = 3.0;

/// The states `(x, v)` of `steps` steps at `s = ωh`, the start included.
fn trajectory<T: Real, const D: usize>(
    integrator: Integrator,
    s: f64,
    steps: usize,
) -> Vec<(Vector<T, D>, Vector<T, D>)>
where
    Const<D>: Space<T, D>,
{
    let stepper = Stepper::new(integrator, oscillator::<T, D>(T::lit(OMEGA))).unwrap();
    let x0 = Vector::<T, D>::from_fn(|i, _| T::lit([1.0, 0.3, -0.2][i]));
    let v0 = Vector::<T, D>::from_fn(|i, _| T::lit([0.2, -0.5, 0.1][i]));
    let mut ball = OneBall::new(x0, v0);
    let mut states = vec![(x0, v0)];
    ball.run(&stepper, T::lit(s / OMEGA), steps, |_, b| {
        states.push((b.x, b.v));
    });
    states
}

/// `k = ω²` and `h` as the stepper saw them (rounded to `T`), in `f64`.
fn k_and_h<T: Real>(s: f64) -> (f64, f64) {
    let omega = T::lit(OMEGA);
    ((omega * omega).to_f64(), T::lit(s / OMEGA).to_f64())
}

fn energies<T: Real, const D: usize>(states: &[(Vector<T, D>, Vector<T, D>)]) -> Vec<f64> {
    let k = T::lit(OMEGA) * T::lit(OMEGA);
    states
        .iter()
        .map(|(x, v)| oscillator_energy(k, x, v))
        .collect()
}

/// The largest relative deviation of `E_{n+1}/E_n` from `expected`.
fn worst_step_ratio_error(energies: &[f64], expected: f64) -> f64 {
    energies
        .windows(2)
        .map(|w| (w[1] / w[0] - expected).abs() / expected)
        .fold(0.0, f64::max)
}

fn check_explicit_euler<T: Real, const D: usize>(s: f64, tolerance: f64)
where
    Const<D>: Space<T, D>,
{
    let e = energies(&trajectory::<T, D>(Integrator::ExplicitEuler, s, 60));
    let (k, h) = k_and_h::<T>(s);
    let factor = 1.0 + k * h * h;
    let worst = worst_step_ratio_error(&e, factor);
    assert!(worst < tolerance, "s = {s}: worst relative error {worst:e}");
    assert!(e[60] > e[0] * factor.powi(60) * (1.0 - 60.0 * tolerance));
}

#[test]
fn explicit_euler_gains_exactly_one_plus_omega_h_squared_per_step_at_any_step() {
    for s in [1e-3, 0.1, 0.5, 1.0, 1.98, 2.02, 2.9, 4.0] {
        check_explicit_euler::<f64, 2>(s, 1e-12);
        check_explicit_euler::<f64, 3>(s, 1e-12);
    }
    for s in [0.1, 0.5, 1.0, 2.0] {
        check_explicit_euler::<f32, 2>(s, 2e-6);
        check_explicit_euler::<f32, 3>(s, 2e-6);
    }
}

/// `|R(is)|²` for RK4's amplification factor, from the complex polynomial.
fn rk4_gain(s: f64) -> f64 {
    let re = 1.0 - s * s / 2.0 + s.powi(4) / 24.0;
    let im = s - s.powi(3) / 6.0;
    re * re + im * im
}

fn check_rk4<T: Real, const D: usize>(s: f64, tolerance: f64)
where
    Const<D>: Space<T, D>,
{
    let e = energies(&trajectory::<T, D>(Integrator::Rk4, s, 60));
    // The rounded h the stepper used, in the formula.
    let (k, h) = k_and_h::<T>(s);
    let gain = rk4_gain(k.sqrt() * h);
    let worst = worst_step_ratio_error(&e, gain);
    assert!(worst < tolerance, "s = {s}: worst relative error {worst:e}");
}

#[test]
fn rk4_is_bounded_to_2_sqrt_2_and_grows_beyond_by_its_amplification_factor() {
    let limit = Integrator::Rk4.oscillator_stability_limit();
    assert!(rk4_gain(0.99 * limit) < 1.0 && rk4_gain(1.01 * limit) > 1.0);
    for s in [0.3, 1.0, 2.0, 0.99 * limit, 1.01 * limit, 3.5] {
        check_rk4::<f64, 2>(s, 1e-12);
        check_rk4::<f64, 3>(s, 1e-12);
        check_rk4::<f32, 3>(s, 3e-6);
    }
    // Bounded over a long run just below the limit, growing just above.
    let below = energies(&trajectory::<f64, 2>(Integrator::Rk4, 0.99 * limit, 20_000));
    assert!(below.iter().all(|&e| e <= below[0] * (1.0 + 1e-12)));
    let above = energies(&trajectory::<f64, 2>(Integrator::Rk4, 1.01 * limit, 2_000));
    assert!(above[2_000] > 1e30 * above[0]);
}

/// The quadratic form each symplectic scheme conserves, in `f64`.
fn modified_energy<T: Real, const D: usize>(
    integrator: Integrator,
    s: f64,
    (x, v): &(Vector<T, D>, Vector<T, D>),
) -> f64 {
    let (k, h) = k_and_h::<T>(s);
    let (x, v) = (wide(x), wide(v));
    match integrator {
        Integrator::SemiImplicitEuler => {
            v.norm_squared() + k * x.norm_squared() - h * k * x.dot(&v)
        }
        Integrator::VelocityVerlet => {
            v.norm_squared() + k * (1.0 - k * h * h / 4.0) * x.norm_squared()
        }
        _ => unreachable!("only the symplectic schemes have one"),
    }
}

/// The largest energy ratio the conserved form allows: `max E / E₀` over the ellipse
/// `Q = Q₀`, from the extreme eigenvalues of `Q` in the variables `(ωx, v)`.
fn energy_bound(integrator: Integrator, s: f64, q0: f64, e0: f64) -> f64 {
    let smallest_eigenvalue = match integrator {
        Integrator::SemiImplicitEuler => 1.0 - s / 2.0,
        _ => 1.0 - s * s / 4.0,
    };
    q0 / smallest_eigenvalue / (2.0 * e0)
}

fn check_bounded<T: Real, const D: usize>(
    integrator: Integrator,
    s: f64,
    steps: usize,
    tolerance: f64,
) where
    Const<D>: Space<T, D>,
{
    let states = trajectory::<T, D>(integrator, s, steps);
    let q0 = modified_energy(integrator, s, &states[0]);
    let drift = states
        .iter()
        .map(|y| (modified_energy(integrator, s, y) / q0 - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        drift < tolerance,
        "{integrator} s = {s}: modified energy drifts {drift:e}"
    );
    let e = energies(&states);
    let bound = energy_bound(integrator, s, q0, e[0]);
    let max = e.iter().copied().fold(0.0, f64::max) / e[0];
    assert!(
        max <= bound * (1.0 + tolerance),
        "{integrator} s = {s}: E/E0 reaches {max}, bound {bound}"
    );
}

#[test]
fn semi_implicit_euler_and_verlet_conserve_a_modified_energy_and_stay_bounded_below_2() {
    for integrator in [Integrator::SemiImplicitEuler, Integrator::VelocityVerlet] {
        let limit = integrator.oscillator_stability_limit();
        assert_eq!(limit, 2.0);
        for s in [0.01, 0.5, 1.5, 0.99 * limit] {
            check_bounded::<f64, 2>(integrator, s, 100_000, 1e-10);
            check_bounded::<f64, 3>(integrator, s, 10_000, 1e-11);
            check_bounded::<f32, 3>(integrator, s, 10_000, 2e-3);
        }
    }
}

/// The eigenvalue of largest modulus of `M` for `s > 2`: `tr M = 2 − s²`, `det M = 1`.
fn dominant_eigenvalue(s: f64) -> f64 {
    let trace = 2.0 - s * s;
    (trace - (trace * trace - 4.0).sqrt()) / 2.0
}

/// Checks the growth rate after the energy has grown by `10^decades` in theory (enough
/// for the other eigenvector's share to vanish, not enough to overflow `T`).
fn check_growth<T: Real, const D: usize>(
    integrator: Integrator,
    s: f64,
    decades: f64,
    tolerance: f64,
) where
    Const<D>: Space<T, D>,
{
    let (k, h) = k_and_h::<T>(s);
    let lambda = dominant_eigenvalue(k.sqrt() * h);
    let expected = lambda * lambda;
    let steps = (decades / expected.log10()).ceil() as usize;
    let e = energies(&trajectory::<T, D>(integrator, s, steps));
    let measured = e[steps] / e[steps - 1];
    assert!(
        (measured / expected - 1.0).abs() < tolerance,
        "{integrator} s = {s}: E grows by {measured} per step, theory {expected}"
    );
}

#[test]
fn semi_implicit_euler_and_verlet_grow_by_the_dominant_eigenvalue_above_2() {
    for integrator in [Integrator::SemiImplicitEuler, Integrator::VelocityVerlet] {
        let limit = integrator.oscillator_stability_limit();
        for s in [1.01 * limit, 2.5, 3.5] {
            check_growth::<f64, 2>(integrator, s, 100.0, 1e-9);
            check_growth::<f64, 3>(integrator, s, 100.0, 1e-9);
            check_growth::<f32, 2>(integrator, s, 25.0, 1e-4);
        }
    }
}

#[test]
fn every_scheme_is_bounded_just_below_its_limit_and_grows_just_above() {
    for integrator in [
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ] {
        let limit = integrator.oscillator_stability_limit();
        let below = energies(&trajectory::<f64, 3>(integrator, 0.99 * limit, 50_000));
        let max = below.iter().copied().fold(0.0, f64::max) / below[0];
        assert!(
            max < 200.0,
            "{integrator} at 0.99 × limit: E/E0 reaches {max}"
        );
        // Growth by at least 1.15 per step (RK4's |R|² at 1.01 × 2√2; the symplectic
        // schemes' λ² is 1.76): 500 steps multiply E by more than 1e30.
        let above = energies(&trajectory::<f64, 3>(integrator, 1.01 * limit, 500));
        assert!(above[500] > 1e30 * above[0], "{integrator} at 1.01 × limit");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn explicit_euler_factor_holds_for_any_step(s in 1e-3_f64..5.0) {
        let e = energies(&trajectory::<f64, 2>(Integrator::ExplicitEuler, s, 10));
        let (k, h) = k_and_h::<f64>(s);
        prop_assert!(worst_step_ratio_error(&e, 1.0 + k * h * h) < 1e-12);
    }

    #[test]
    fn symplectic_schemes_conserve_their_modified_energy_below_2(s in 1e-3_f64..1.999) {
        for integrator in [Integrator::SemiImplicitEuler, Integrator::VelocityVerlet] {
            let states = trajectory::<f64, 2>(integrator, s, 2_000);
            let q0 = modified_energy(integrator, s, &states[0]);
            for y in &states {
                prop_assert!((modified_energy(integrator, s, y) / q0 - 1.0).abs() < 1e-11);
            }
        }
    }

    #[test]
    fn rk4_gain_holds_for_any_step(s in 1e-2_f64..3.5) {
        let e = energies(&trajectory::<f64, 3>(Integrator::Rk4, s, 10));
        let (k, h) = k_and_h::<f64>(s);
        prop_assert!(worst_step_ratio_error(&e, rk4_gain(k.sqrt() * h)) < 1e-12);
    }
}
