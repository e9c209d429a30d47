//! Stiff springs at and beyond each integrator's stability limit, in carom-integrate:
//! one ball tied to a fixed point (`ω = √(k/m) = 1000 rad/s`), and two balls of mass
//! ratio 1e6 tied to each other (`ω = √(k (1/m₁ + 1/m₂))`, which the light ball sets; the
//! centre of mass starts at rest, so the energy is that of the relative oscillator).
//!
//! The predictions (derived in `carom_integrate::integrator` and docs/integrators.md):
//!
//! * explicit Euler multiplies the energy by exactly `1 + ω²h²` every step, at any `h`;
//! * semi-implicit Euler conserves `v² + ω²x² − hω² x·v`, so below `ωh = 2` the energy
//!   stays within `(1 + ωh/2)/(1 − ωh/2)` of its start; velocity Verlet conserves
//!   `v² + ω²(1 − ω²h²/4) x²`, so the energy stays within `1/(1 − ω²h²/4)`;
//!   beyond `ωh = 2` both grow by `λ²` per step, `λ` the larger root of
//!   `λ² − (2 − ω²h²) λ + 1 = 0`;
//! * RK4 multiplies the energy by exactly `1 − y⁶/72 + y⁸/576` (`y = ωh`) every step: at
//!   most 1 up to `2√2`, more beyond;
//! * the exact integrator has no closed form for springs and is refused.

use carom_integrate::{
    AnchorSpring, Attachment, Bodies, CoupledStepper, Integrator, Link, Scratch, Spring,
    SpringNetwork, Stepper, TimeStep,
};
use nalgebra::{Vector1, Vector2};

use super::row;
use crate::model::StabilityRow;

/// Stiffness (N/m) of the spring on a 1 kg ball: `ω = 1000 rad/s`.
const STIFFNESS: f64 = 1e6;

/// The spring systems the case runs.
#[derive(Clone, Copy, Debug, PartialEq)]
enum System {
    /// One 1 kg ball tied to the origin.
    Anchored,
    /// A ball of this mass (kg) tied to a 1 kg ball.
    Pair(f64),
}

impl System {
    fn name(self) -> String {
        match self {
            System::Anchored => "stiff spring ω = 1000 rad/s".to_owned(),
            System::Pair(m) => format!("stiff spring between balls of mass ratio {m:.0e}"),
        }
    }

    /// The inverse masses and the oscillator's angular frequency.
    fn oscillator(self) -> (Vec<f64>, f64) {
        match self {
            System::Anchored => (vec![1.0], STIFFNESS.sqrt()),
            System::Pair(m) => (vec![1.0 / m, 1.0], (STIFFNESS * (1.0 / m + 1.0)).sqrt()),
        }
    }
}

/// The energies `E_n / E_0` of `system` after each of `steps` steps of `ωh = omega_h`,
/// stopping early when the energy passes `1e12` (so it never overflows), or the stepper's
/// refusal.
fn energies(
    system: System,
    integrator: Integrator,
    omega_h: f64,
    steps: usize,
) -> Result<Vec<f64>, String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    let spring = Spring::new(STIFFNESS, 0.0, 0.0).map_err(|e| text(&e))?;
    let (inverse_masses, omega) = system.oscillator();
    let dt = TimeStep::new(omega_h / omega).map_err(|e| text(&e))?;
    let energy = |x: &[Vector2<f64>], v: &[Vector2<f64>]| {
        let kinetic: f64 = v
            .iter()
            .zip(&inverse_masses)
            .map(|(v, w)| 0.5 * v.norm_squared() / w)
            .sum();
        let stretch = if x.len() == 2 { x[1] - x[0] } else { x[0] };
        kinetic + 0.5 * STIFFNESS * stretch.norm_squared()
    };
    let mut out = Vec::with_capacity(steps);
    let mut record = |x: &[Vector2<f64>], v: &[Vector2<f64>], e0: f64| {
        let ratio = energy(x, v) / e0;
        out.push(ratio);
        ratio > 1e12
    };
    match system {
        System::Anchored => {
            let field = AnchorSpring::new(Vector2::zeros(), spring).map_err(|e| text(&e))?;
            let stepper = Stepper::new(integrator, field).map_err(|e| text(&e))?;
            let (mut x, mut v, mut spin) =
                (Vector2::new(0.01, 0.0), Vector2::zeros(), Vector1::zeros());
            let e0 = energy(&[x], &[v]);
            for n in 0..steps {
                stepper.step_ball(&mut x, &mut v, &mut spin, 1.0, n as f64 * dt.get(), dt);
                if record(&[x], &[v], e0) {
                    break;
                }
            }
        }
        System::Pair(m) => {
            let link = Link {
                ball: 0,
                other: Attachment::Ball(1),
                spring,
            };
            let network = SpringNetwork::new(vec![link]).map_err(|e| text(&e))?;
            let stepper =
                CoupledStepper::new(Stepper::new(integrator, ()).map_err(|e| text(&e))?, network)
                    .map_err(|e| text(&e))?;
            // Stretched by 0.01 m about a centre of mass at rest at the origin.
            let mut x = [
                Vector2::new(-0.01 / (m + 1.0), 0.0),
                Vector2::new(0.01 * m / (m + 1.0), 0.0),
            ];
            let mut v = [Vector2::zeros(); 2];
            let e0 = energy(&x, &v);
            let mut scratch = Scratch::new();
            for n in 0..steps {
                let mut bodies =
                    Bodies::new(&mut x, &mut v, &inverse_masses).map_err(|e| text(&e))?;
                stepper
                    .step(&mut bodies, n as f64 * dt.get(), dt, &mut scratch)
                    .map_err(|e| text(&e))?;
                if record(&x, &v, e0) {
                    break;
                }
            }
        }
    }
    Ok(out)
}

/// The per-step growth of the unstable symplectic schemes beyond `ωh = 2`: `λ²`.
fn symplectic_growth(omega_h: f64) -> f64 {
    let trace = 2.0 - omega_h * omega_h;
    let lambda = f64::midpoint(trace.abs(), (trace * trace - 4.0).sqrt());
    lambda * lambda
}

/// RK4's per-step energy factor `|R(iy)|²`.
fn rk4_factor(y: f64) -> f64 {
    1.0 - y.powi(6) / 72.0 + y.powi(8) / 576.0
}

/// The measured per-step growth over the last 10 steps.
fn late_growth(e: &[f64]) -> f64 {
    let n = e.len();
    (e[n - 1] / e[n - 11]).powf(0.1)
}

/// The rows of the stiff-spring case.
pub(super) fn rows() -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    rows.push(explicit_euler());
    for system in [System::Anchored, System::Pair(1e6)] {
        for integrator in [
            Integrator::SemiImplicitEuler,
            Integrator::VelocityVerlet,
            Integrator::Rk4,
        ] {
            rows.push(below_limit(system, integrator));
            rows.push(beyond_limit(system, integrator));
        }
    }
    let case = "stiff spring, exact integrator: refused (springs have no closed form)";
    rows.push(
        match energies(System::Anchored, Integrator::Exact, 1.0, 1) {
            Err(why) => row(case, true, format!("refused: {why}")),
            Ok(_) => row(case, false, "accepted a field without a closed form"),
        },
    );
    rows
}

fn explicit_euler() -> StabilityRow {
    let (omega_h, steps) = (0.1, 1000);
    let case = format!(
        "stiff spring ω = 1000 rad/s, explicit Euler at ωh = {omega_h}: energy × (1 + ω²h²) every step (unstable at any step)"
    );
    match energies(System::Anchored, Integrator::ExplicitEuler, omega_h, steps) {
        Ok(e) => {
            let predicted = (1.0 + omega_h * omega_h).powi(e.len() as i32);
            let measured = e[e.len() - 1];
            let off = (measured / predicted - 1.0).abs();
            row(
                case,
                off < 1e-9,
                format!(
                    "E/E₀ after {} steps {measured:.6e}, predicted {predicted:.6e} (relative difference {off:.1e}, bound 1e-9)",
                    e.len()
                ),
            )
        }
        Err(why) => row(case, false, why),
    }
}

fn below_limit(system: System, integrator: Integrator) -> StabilityRow {
    let limit = integrator.oscillator_stability_limit();
    let omega_h = 0.9 * limit;
    let steps = 10_000;
    let bound = match integrator {
        Integrator::SemiImplicitEuler => (1.0 + omega_h / 2.0) / (1.0 - omega_h / 2.0),
        Integrator::VelocityVerlet => 1.0 / (1.0 - omega_h * omega_h / 4.0),
        _ => 1.0,
    } * (1.0 + 1e-9);
    let case = format!(
        "{}, {integrator} at ωh = 0.9 × {limit:.3}: bounded",
        system.name()
    );
    match energies(system, integrator, omega_h, steps) {
        Ok(e) => {
            let max = e.iter().copied().fold(0.0, f64::max);
            row(
                case,
                e.len() == steps && max <= bound,
                format!(
                    "max E/E₀ over {} steps {max:.4} (bound {bound:.4} from the conserved form)",
                    e.len()
                ),
            )
        }
        Err(why) => row(case, false, why),
    }
}

fn beyond_limit(system: System, integrator: Integrator) -> StabilityRow {
    let limit = integrator.oscillator_stability_limit();
    let omega_h = 1.1 * limit;
    let predicted = match integrator {
        Integrator::Rk4 => rk4_factor(omega_h),
        _ => symplectic_growth(omega_h),
    };
    let case = format!(
        "{}, {integrator} at ωh = 1.1 × {limit:.3}: grows as predicted (the prediction passes)",
        system.name()
    );
    match energies(system, integrator, omega_h, 1000) {
        Ok(e) if e.len() > 11 => {
            let growth = late_growth(&e);
            let off = (growth / predicted - 1.0).abs();
            row(
                case,
                off < 1e-3 && e[e.len() - 1] > 1e12,
                format!(
                    "E/E₀ passed 1e12 after {} steps, growing × {growth:.4}/step (predicted × {predicted:.4})",
                    e.len()
                ),
            )
        }
        Ok(e) => row(case, false, format!("only {} steps", e.len())),
        Err(why) => row(case, false, why),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spring_prediction_holds() {
        let rows = rows();
        assert_eq!(rows.len(), 14);
        for r in &rows {
            assert!(r.pass, "{}: {}", r.case, r.figure);
        }
    }

    #[test]
    fn the_growth_factors_match_the_integrator_docs() {
        // At ωh = 2 the symplectic schemes are at the limit (λ = −1); at 2√2 RK4 is.
        assert!((symplectic_growth(2.0) - 1.0).abs() < 1e-12);
        assert!((rk4_factor(2.0 * std::f64::consts::SQRT_2) - 1.0).abs() < 1e-12);
        assert!(rk4_factor(1.0) < 1.0 && rk4_factor(3.0) > 1.0);
    }
}
