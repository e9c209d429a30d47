//! The steppers as engines use them: chunked stepping, the coupled path without springs,
//! balls of infinite mass, and the velocity- and time-dependent fields (Magnus, quadratic
//! drag, spin damping, a time-dependent user field) against closed forms and measured
//! orders.

use crate::common;

use carom_integrate::{
    Acceleration, BallState, Bodies, CoupledStepper, Field, ForceField, Gravity, Integrator,
    LinearDrag, Magnus, QuadraticDrag, Scratch, SpinDamping, SpringNetwork, Stepper, TimeStep,
};
use common::{OneBall, fitted_order, run_bodies};
use nalgebra::{Vector1, Vector2, Vector3};

/// Gravity, quadratic drag, Magnus and spin damping, roughly a table-tennis ball's.
fn air() -> Vec<Field<f64, 3>> {
    vec![
        Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap().into(),
        QuadraticDrag::new(3.8e-4).unwrap().into(),
        Magnus::new(4e-6).unwrap().into(),
        SpinDamping::new(0.5).unwrap().into(),
    ]
}

/// Positions, velocities, spins and inverse masses.
type Arrays = (
    Vec<Vector3<f64>>,
    Vec<Vector3<f64>>,
    Vec<Vector3<f64>>,
    Vec<f64>,
);

/// `n` balls with varied states: masses 2.7 g to 27 g and one of infinite mass.
fn balls(n: usize) -> Arrays {
    let f = |i: usize, a: f64| ((i as f64 + 1.0) * a).sin();
    let x = (0..n)
        .map(|i| Vector3::new(f(i, 0.3), f(i, 0.7), 1.0 + f(i, 1.1)))
        .collect();
    let v = (0..n)
        .map(|i| Vector3::new(10.0 * f(i, 1.3), 5.0 * f(i, 1.7), 3.0 * f(i, 1.9)))
        .collect();
    let w = (0..n)
        .map(|i| Vector3::new(50.0 * f(i, 2.3), 100.0 * f(i, 2.9), 20.0 * f(i, 3.1)))
        .collect();
    let m = (0..n)
        .map(|i| {
            if i == 3 {
                0.0
            } else {
                1.0 / (0.0027 * (1.0 + (i % 10) as f64))
            }
        })
        .collect();
    (x, v, w, m)
}

#[test]
fn stepping_in_chunks_gives_the_same_bits_as_stepping_all_at_once() {
    let dt = TimeStep::new(1.0 / 240.0).unwrap();
    for integrator in Integrator::ALL {
        let field: Vec<Field<f64, 3>> = if integrator == Integrator::Exact {
            vec![
                Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap().into(),
                LinearDrag::new(0.01).unwrap().into(),
                SpinDamping::new(0.5).unwrap().into(),
            ]
        } else {
            air()
        };
        let stepper = Stepper::new(integrator, field).unwrap();
        let (mut x1, mut v1, mut w1, m) = balls(103);
        let (mut x2, mut v2, mut w2) = (x1.clone(), v1.clone(), w1.clone());
        for n in 0..50 {
            let t = f64::from(n) * dt.get();
            let mut all = Bodies::new(&mut x1, &mut v1, &m)
                .unwrap()
                .with_spins(&mut w1)
                .unwrap();
            stepper.step(&mut all, t, dt);
            let parts = Bodies::new(&mut x2, &mut v2, &m)
                .unwrap()
                .with_spins(&mut w2)
                .unwrap();
            // Uneven chunks, stepped last to first.
            let mut chunks: Vec<_> = parts.chunks(7 + n as usize % 5).collect();
            for chunk in chunks.iter_mut().rev() {
                stepper.step(chunk, t, dt);
            }
        }
        assert_eq!((&x1, &v1, &w1), (&x2, &v2, &w2), "{integrator}");
    }
}

#[test]
fn the_coupled_stepper_without_springs_is_the_stepper_to_the_bit() {
    let dt = TimeStep::new(1.0 / 120.0).unwrap();
    let mut scratch = Scratch::new();
    for integrator in [
        Integrator::ExplicitEuler,
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ] {
        let stepper = Stepper::new(integrator, air()).unwrap();
        let coupled =
            CoupledStepper::new(stepper.clone(), SpringNetwork::new(Vec::new()).unwrap()).unwrap();
        let (mut x1, mut v1, mut w1, m) = balls(20);
        let (mut x2, mut v2, mut w2) = (x1.clone(), v1.clone(), w1.clone());
        for n in 0..30 {
            let t = f64::from(n) * dt.get();
            let mut a = Bodies::new(&mut x1, &mut v1, &m)
                .unwrap()
                .with_spins(&mut w1)
                .unwrap();
            stepper.step(&mut a, t, dt);
            let mut b = Bodies::new(&mut x2, &mut v2, &m)
                .unwrap()
                .with_spins(&mut w2)
                .unwrap();
            coupled.step(&mut b, t, dt, &mut scratch).unwrap();
        }
        assert_eq!((&x1, &v1, &w1), (&x2, &v2, &w2), "{integrator}");
    }
}

#[test]
fn balls_of_infinite_mass_move_at_constant_velocity_and_spin_under_every_scheme() {
    for integrator in Integrator::ALL {
        let field: Vec<Field<f64, 3>> = if integrator == Integrator::Exact {
            vec![
                Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap().into(),
                LinearDrag::new(0.5).unwrap().into(),
            ]
        } else {
            air()
        };
        let stepper = Stepper::new(integrator, field).unwrap();
        let mut x = vec![Vector3::new(1.0, 2.0, 3.0)];
        let mut v = vec![Vector3::new(-1.0, 0.5, 2.0)];
        let mut w = vec![Vector3::new(10.0, 0.0, 5.0)];
        let mut bodies = Bodies::new(&mut x, &mut v, &[0.0])
            .unwrap()
            .with_spins(&mut w)
            .unwrap();
        run_bodies(&stepper, &mut bodies, 0.125, 8);
        // 8 steps of 1/8 with dyadic data: exactly one second of uniform motion.
        assert_eq!(x[0], Vector3::new(0.0, 2.5, 5.0), "{integrator}");
        assert_eq!(
            (v[0], w[0]),
            (Vector3::new(-1.0, 0.5, 2.0), Vector3::new(10.0, 0.0, 5.0))
        );
    }
}

/// A ball under the Magnus force alone turns at `Ω = S|ω|/m` about its spin axis: the
/// part of `v` along `ω̂` stays, the rest rotates, and the position follows
/// `x(t) = x₀ + v∥ t + (sin(Ωt) v⊥ + (1 − cos Ωt) ω̂ × v⊥) / Ω`.
fn magnus_closed_form(
    x0: Vector3<f64>,
    v0: Vector3<f64>,
    w: Vector3<f64>,
    s_over_m: f64,
    t: f64,
) -> Vector3<f64> {
    let axis = w.normalize();
    let omega = s_over_m * w.norm();
    let along = axis * axis.dot(&v0);
    let across = v0 - along;
    x0 + along * t
        + (across * (omega * t).sin() + axis.cross(&across) * (1.0 - (omega * t).cos())) / omega
}

#[test]
fn magnus_alone_gives_the_closed_form_helix_in_3d_and_circle_in_2d() {
    let (s, m): (f64, f64) = (4e-6, 0.0027);
    let w = Vector3::new(30.0, -80.0, 120.0);
    let (x0, v0) = (Vector3::new(0.0, 0.0, 1.0), Vector3::new(8.0, 3.0, -2.0));
    let stepper = Stepper::new(Integrator::Rk4, Magnus::new(s).unwrap()).unwrap();
    let mut ball = OneBall {
        x: x0,
        v: v0,
        spin: w,
        inverse_mass: 1.0 / m,
    };
    ball.run(&stepper, 1e-3, 2_000, |_, b: &OneBall<f64, 3>| {
        // Magnus does no work: the speed stays (RK4 to its truncation error).
        assert!((b.v.norm() - v0.norm()).abs() < 1e-9);
    });
    let expected = magnus_closed_form(x0, v0, w, s / m, 2.0);
    assert!(
        (ball.x - expected).norm() < 1e-9,
        "{:?} vs {expected:?}",
        ball.x
    );

    // 2D: the spin is the z component; the path is the circle of the 3D formula.
    let stepper2 = Stepper::new(Integrator::Rk4, Magnus::new(s).unwrap()).unwrap();
    let mut flat = OneBall {
        x: Vector2::new(0.0, 1.0),
        v: Vector2::new(8.0, 3.0),
        spin: Vector1::new(120.0),
        inverse_mass: 1.0 / m,
    };
    flat.run(&stepper2, 1e-3, 2_000, |_, _| {});
    let expected = magnus_closed_form(
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(8.0, 3.0, 0.0),
        Vector3::new(0.0, 0.0, 120.0),
        s / m,
        2.0,
    );
    assert!((flat.x - expected.xy()).norm() < 1e-9);
}

#[test]
fn quadratic_drag_along_a_line_follows_its_closed_form() {
    // Along the direction of v₀: v(t) = v₀ / (1 + c' v₀ t), s(t) = ln(1 + c' v₀ t) / c',
    // with c' = c/m.
    let (c, m): (f64, f64) = (3.8e-4, 0.0027);
    let dir = Vector3::new(2.0, -1.0, 2.0) / 3.0;
    let speed = 30.0;
    let stepper = Stepper::new(Integrator::Rk4, QuadraticDrag::new(c).unwrap()).unwrap();
    let mut ball = OneBall::new(Vector3::zeros(), dir * speed);
    ball.inverse_mass = 1.0 / m;
    ball.run(&stepper, 1e-4, 10_000, |_, _| {});
    let cm = c / m;
    let s = (1.0 + cm * speed * 1.0).ln() / cm;
    let v = speed / (1.0 + cm * speed * 1.0);
    assert!((ball.x - dir * s).norm() < 1e-10 * s);
    assert!((ball.v - dir * v).norm() < 1e-10 * v);
}

#[test]
fn spin_damping_decays_the_spin_exponentially_under_every_scheme() {
    let lambda: f64 = 0.8;
    let w0 = Vector3::new(10.0, -20.0, 5.0);
    for (integrator, tolerance) in [
        (Integrator::ExplicitEuler, 1e-3),
        (Integrator::SemiImplicitEuler, 1e-3),
        (Integrator::VelocityVerlet, 1e-6),
        (Integrator::Rk4, 1e-12),
        (Integrator::Exact, 1e-13),
    ] {
        let stepper = Stepper::new(integrator, SpinDamping::new(lambda).unwrap()).unwrap();
        let mut ball = OneBall::new(Vector3::zeros(), Vector3::zeros());
        ball.spin = w0;
        ball.run(&stepper, 1e-3, 1_000, |_, _| {});
        let expected = w0 * (-lambda).exp();
        assert!(
            (ball.spin - expected).norm() < tolerance * w0.norm(),
            "{integrator}: {:?}",
            ball.spin
        );
    }
}

/// `a = cos(t)` along x: exercises the stage times (`x(t) = 1 − cos t` from rest at 0).
struct Forcing;

impl ForceField<f64, 2> for Forcing {
    fn acceleration(&self, ball: &BallState<f64, 2>) -> Acceleration<f64, 2> {
        Acceleration::linear(Vector2::new(ball.time.cos(), 0.0))
    }
}

/// The orders of the four schemes on `problem`, from the errors at `steps` step counts
/// over `[0, end]` against `reference`.
fn orders<F: ForceField<f64, D>, const D: usize>(
    field: &F,
    start: OneBall<f64, D>,
    end: f64,
    steps: [usize; 4],
    reference: nalgebra::SVector<f64, D>,
) -> Vec<(Integrator, f64)>
where
    nalgebra::Const<D>: carom_integrate::Space<f64, D>,
{
    [
        Integrator::ExplicitEuler,
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ]
    .into_iter()
    .map(|integrator| {
        let stepper = Stepper::new(integrator, field).unwrap();
        let scale = 4usize.pow(integrator.order().unwrap() - 1).min(64);
        let counts: Vec<usize> = steps.iter().map(|&n| n * 8 / scale).collect();
        let errors: Vec<f64> = counts
            .iter()
            .map(|&n| {
                let mut ball = start;
                ball.run(&stepper, end / n as f64, n, |_, _| {});
                (ball.x - reference).norm()
            })
            .collect();
        let hs: Vec<f64> = counts.iter().map(|&n| end / n as f64).collect();
        (integrator, fitted_order(&hs, &errors))
    })
    .collect()
}

#[test]
fn stage_times_are_right_measured_orders_on_a_time_dependent_field() {
    let start = OneBall::new(Vector2::zeros(), Vector2::zeros());
    let end = 2.0;
    for (integrator, order) in orders(
        &Forcing,
        start,
        end,
        [1_000, 2_000, 4_000, 8_000],
        Vector2::new(1.0 - end.cos(), 0.0),
    ) {
        let expected = f64::from(integrator.order().unwrap());
        println!("{integrator}: measured order {order:.3}");
        assert!((order - expected).abs() < 0.1, "{integrator}: {order}");
    }
}

#[test]
fn verlet_stays_second_order_with_velocity_dependent_forces() {
    // Gravity, quadratic drag and Magnus on a spinning ball; the reference is RK4 with
    // 100 000 steps (its error, ~1e-16 here, is far below the errors measured).
    let field = (
        Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap(),
        QuadraticDrag::new(3.8e-4).unwrap(),
        Magnus::new(4e-6).unwrap(),
    );
    let start = OneBall {
        x: Vector3::zeros(),
        v: Vector3::new(12.0, 2.0, 4.0),
        spin: Vector3::new(0.0, 150.0, 30.0),
        inverse_mass: 1.0 / 0.0027,
    };
    let end = 1.0;
    let reference_stepper = Stepper::new(Integrator::Rk4, field).unwrap();
    let mut reference = start;
    reference.run(&reference_stepper, end / 100_000.0, 100_000, |_, _| {});
    for (integrator, order) in orders(
        &field,
        start,
        end,
        [1_000, 2_000, 4_000, 8_000],
        reference.x,
    ) {
        let expected = f64::from(integrator.order().unwrap());
        println!("{integrator}: measured order {order:.3}");
        assert!((order - expected).abs() < 0.1, "{integrator}: {order}");
    }
}
