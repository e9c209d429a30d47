//! A ball dropped on the floor under gravity: bounce heights `h e^(2k)` for every
//! integrator, convergence at the integrator's order, and the end of Zeno bouncing.
//!
//! The apex after each bounce is measured from the first sample after it by energy,
//! `y − r + v_y²/(2g)`, which is the exact apex of ballistic flight (no sampling error).
//! Verlet, RK4 and the exact integrator fly ballistic arcs exactly; their bounce heights
//! are off only by the chord the step sweeps instead of the parabola (a contact time off
//! by `g h²/8 / v`): below 1e-4 relative at `h = 1/600` for the first bounces, and smaller
//! at `h/2`. Both Euler schemes carry their first-order energy error (explicit Euler
//! gains, semi-implicit Euler loses): the bounce heights converge at order 1.

use crate::common;

use carom_integrate::Integrator;
use carom_sim::scenes::classic;
use carom_sim::{Collision, Simulation, observe};
use common::{Recorder, states, stepped};

const G: f64 = 9.81;
const R: f64 = 0.1;

/// The apex heights (of the ball's bottom) after each bounce within `t` seconds, and the
/// engine after the run.
fn apexes<const D: usize>(integrator: Integrator, e: f64, dt: f64, t: f64) -> Vec<f64>
where
    nalgebra::Const<D>: carom_math::Space<f64, D>,
{
    let s = classic::ball_drop::<D>(1.0, e);
    let mut sim = stepped(&s, integrator, dt);
    let mut rec = Recorder::default();
    let mut apex = Vec::new();
    let steps = (t / dt).round() as u64;
    for k in 1..=steps {
        let before = rec.collisions.len();
        sim.advance_to(k as f64 * dt, &mut rec).unwrap();
        if rec.collisions.len() > before {
            let st = states(&sim);
            apex.push(st.pos[0][D - 1] - R + st.vel[0][D - 1].powi(2) / (2.0 * G));
        }
    }
    apex
}

#[test]
fn bounce_heights_are_h_e_to_the_2k_for_the_exact_verlet_and_rk4() {
    for e in [0.5, 0.8, 1.0] {
        for integrator in [
            Integrator::VelocityVerlet,
            Integrator::Rk4,
            Integrator::Exact,
        ] {
            let coarse = apexes::<2>(integrator, e, 1.0 / 600.0, 4.0);
            let fine = apexes::<2>(integrator, e, 1.0 / 1200.0, 4.0);
            for k in 0..4 {
                let expected = e.powi(2 * k as i32 + 2);
                let (a, b) = (coarse[k] / expected - 1.0, fine[k] / expected - 1.0);
                assert!(a.abs() < 1e-4, "{integrator} e={e} bounce {k}: {a:e}");
                assert!(
                    b.abs() <= a.abs(),
                    "{integrator} e={e} bounce {k}: {b:e} vs {a:e}"
                );
            }
        }
    }
}

#[test]
fn euler_bounce_heights_converge_at_order_one_with_the_documented_signs() {
    for e in [0.5, 1.0] {
        for integrator in [Integrator::ExplicitEuler, Integrator::SemiImplicitEuler] {
            let coarse = apexes::<2>(integrator, e, 1.0 / 600.0, 4.0);
            let fine = apexes::<2>(integrator, e, 1.0 / 1200.0, 4.0);
            for k in 0..4 {
                let expected = e.powi(2 * k as i32 + 2);
                let (a, b) = (coarse[k] / expected - 1.0, fine[k] / expected - 1.0);
                let ratio = a / b;
                assert!(
                    (1.8..2.2).contains(&ratio),
                    "{integrator} e={e} bounce {k}: errors {a:e}, {b:e}"
                );
                // Explicit Euler gains energy (its ball flies above the parabola),
                // semi-implicit Euler loses it.
                assert_eq!(a > 0.0, integrator == Integrator::ExplicitEuler);
            }
        }
    }
}

#[test]
fn a_3d_drop_bounces_like_the_2d_one() {
    let a2 = apexes::<2>(Integrator::Exact, 0.7, 1.0 / 600.0, 2.0);
    let a3 = apexes::<3>(Integrator::Exact, 0.7, 1.0 / 600.0, 2.0);
    assert_eq!(a2.len(), a3.len());
    for (x, y) in a2.iter().zip(&a3) {
        assert!((x - y).abs() < 1e-12, "{x} vs {y}");
    }
}

#[test]
fn zeno_bouncing_ends_in_rest_after_the_guards_count_of_bounces() {
    // The resting guard (minimum flight 2h) ends the bounces whose rebound e·v is below
    // g h; collisions approaching slower than 2 g h are support, not reported. The
    // rebound speeds are e^k v₀ with v₀ = √(2 g h₀); reported are those with
    // e^k v₀ > 2 g h (k = 0, 1, ...).
    let (e, dt) = (0.5, 1.0 / 600.0);
    let s = classic::ball_drop::<2>(1.0, e);
    let mut sim = stepped(&s, Integrator::Exact, dt);
    let mut rec = Recorder::default();
    let v0 = (2.0 * G * 1.0_f64).sqrt();
    let reported = (0..64)
        .take_while(|&k| e.powi(k) * v0 > 2.0 * G * dt)
        .count();
    let mut energy = observe::energy(&s, &states(&sim));
    for k in 1..=3000 {
        sim.advance_to(f64::from(k) * dt, &mut rec).unwrap();
        let now = observe::energy(&s, &states(&sim));
        assert!(
            now <= energy + 1e-12,
            "energy grew at step {k}: {now} > {energy}"
        );
        energy = now;
    }
    assert_eq!(rec.collisions.len(), reported, "{:?}", sim.stats());
    assert!(
        rec.collisions
            .iter()
            .all(|c| matches!(c, Collision::BallBorder { i: 0, .. }))
    );
    // At rest on the floor, and it stays there: no sinking, no jitter, no more reports.
    let resting = states(&sim);
    assert!((resting.pos[0].y - R).abs() < 1e-12, "{:?}", resting.pos[0]);
    sim.advance_to(60.0, &mut rec).unwrap();
    let later = states(&sim);
    assert_eq!(rec.collisions.len(), reported);
    assert!((later.pos[0].y - R).abs() < 1e-12, "{:?}", later.pos[0]);
    assert!(later.vel[0].norm() < 1e-12);
    assert!((observe::energy(&s, &later) - energy).abs() < 1e-12);
}
