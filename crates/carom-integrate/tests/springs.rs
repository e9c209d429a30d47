//! Springs between balls (the coupled stepper): two-body oscillations against the closed
//! form (mass ratios up to 1e6), the stiff stability limits on the two-body mode,
//! damping, energy behaviour of a chain, momentum, determinism and errors.

use crate::common;

use carom_integrate::{
    AnchorSpring, Attachment, Bodies, CoupledStepper, Gravity, Integrator, LinearDrag, Link,
    Scratch, Spring, SpringNetwork, Stepper, TimeStep,
};
use nalgebra::{Vector2, Vector3};

/// A coupled stepper with no field and the given links.
fn coupled(integrator: Integrator, links: Vec<Link<f64, 3>>) -> CoupledStepper<f64, 3, ()> {
    CoupledStepper::new(
        Stepper::new(integrator, ()).unwrap(),
        SpringNetwork::new(links).unwrap(),
    )
    .unwrap()
}

fn pair(spring: Spring<f64>) -> Vec<Link<f64, 3>> {
    vec![Link {
        ball: 0,
        other: Attachment::Ball(1),
        spring,
    }]
}

/// Runs `steps` coupled steps, calling `observe` with the positions and velocities after
/// each.
fn run(
    stepper: &CoupledStepper<f64, 3, ()>,
    x: &mut [Vector3<f64>],
    v: &mut [Vector3<f64>],
    inverse_masses: &[f64],
    dt: f64,
    steps: usize,
    mut observe: impl FnMut(&[Vector3<f64>], &[Vector3<f64>]),
) {
    let mut scratch = Scratch::new();
    let dt = TimeStep::new(dt).unwrap();
    for n in 0..steps {
        let mut bodies = Bodies::new(x, v, inverse_masses).unwrap();
        stepper
            .step(&mut bodies, n as f64 * dt.get(), dt, &mut scratch)
            .unwrap();
        observe(x, v);
    }
}

#[test]
fn two_balls_oscillate_at_the_reduced_mass_frequency_for_any_mass_ratio() {
    // Separation r(t) = L + A cos(ωt), ω = sqrt(k/μ), μ = m₁m₂/(m₁+m₂); the centre of mass
    // stays at rest, so ball i sits at c ∓ (m_other/M) r n.
    let axis = Vector3::new(1.0, 2.0, -2.0) / 3.0;
    let (k, rest, stretch) = (50.0, 1.0, 0.2);
    for (m1, m2) in [(1.0, 1.0), (3.0, 0.5), (1e6, 1.0), (1.0, 1e6)] {
        let mu: f64 = m1 * m2 / (m1 + m2);
        let omega = (k / mu).sqrt();
        let total = m1 + m2;
        let r0 = rest + stretch;
        let centre = Vector3::new(5.0, -3.0, 1e3);
        let mut x = [
            centre - axis * (r0 * m2 / total),
            centre + axis * (r0 * m1 / total),
        ];
        let mut v = [Vector3::zeros(); 2];
        let stepper = coupled(Integrator::Rk4, pair(Spring::new(k, 0.0, rest).unwrap()));
        let period = 2.0 * std::f64::consts::PI / omega;
        let steps = 4_000;
        let mut momentum_drift: f64 = 0.0;
        run(
            &stepper,
            &mut x,
            &mut v,
            &[1.0 / m1, 1.0 / m2],
            1.3 * period / steps as f64,
            steps,
            |_, v| {
                momentum_drift =
                    momentum_drift.max((v[0] * m1 + v[1] * m2).norm() / (mu * omega * stretch));
            },
        );
        let r = rest + stretch * (omega * 1.3 * period).cos();
        let expected = [
            centre - axis * (r * m2 / total),
            centre + axis * (r * m1 / total),
        ];
        for i in 0..2 {
            assert!(
                (x[i] - expected[i]).norm() < 1e-9,
                "m = ({m1}, {m2}), ball {i}: {:?} vs {:?}",
                x[i],
                expected[i]
            );
        }
        assert!(
            momentum_drift < 1e-9,
            "m = ({m1}, {m2}): momentum drift {momentum_drift:e}"
        );
    }
}

/// The largest separation over `steps` steps of the two-body mode at `s = ω h`.
fn max_separation(integrator: Integrator, s: f64, m1: f64, m2: f64, steps: usize) -> f64 {
    let k = 1e4; // a stiff spring
    let omega = (k * (1.0 / m1 + 1.0 / m2)).sqrt();
    let stepper = coupled(integrator, pair(Spring::new(k, 0.0, 0.0).unwrap()));
    let mut x = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.01, 0.0, 0.0)];
    let mut v = [Vector3::new(0.0, 0.1, 0.0), Vector3::zeros()];
    let mut max: f64 = 0.0;
    run(
        &stepper,
        &mut x,
        &mut v,
        &[1.0 / m1, 1.0 / m2],
        s / omega,
        steps,
        |x, _| {
            max = max.max((x[0] - x[1]).norm());
        },
    );
    max
}

#[test]
fn stiff_springs_are_stable_just_below_the_limit_and_blow_up_just_above() {
    // The relative coordinate of two balls on a zero-length spring is the oscillator with
    // ω² = k (1/m₁ + 1/m₂), so the oscillator limits apply to ω h, including at a mass
    // ratio of 1e6 where the light ball sets ω.
    for integrator in [
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ] {
        let limit = integrator.oscillator_stability_limit();
        for (m1, m2) in [(1.0, 1.0), (1e6, 1.0)] {
            let below = max_separation(integrator, 0.99 * limit, m1, m2, 20_000);
            assert!(
                below < 0.5,
                "{integrator} m = ({m1}, {m2}) at 0.99 × limit: {below}"
            );
            // At least RK4's 1.07 per step: 500 steps grow the 0.01 start by over 1e10.
            let above = max_separation(integrator, 1.01 * limit, m1, m2, 500);
            assert!(
                above > 1e8,
                "{integrator} m = ({m1}, {m2}) at 1.01 × limit: {above}"
            );
        }
    }
}

#[test]
fn damped_anchor_spring_follows_the_underdamped_closed_form() {
    // Motion along a line through the anchor, so the damping −c (v·n) n is −c v:
    // x(t) = e^{−γt} (x₀ cos ω_d t + (v₀ + γ x₀)/ω_d sin ω_d t), γ = c/2m, ω_d² = k/m − γ².
    let (k, c, m): (f64, f64, f64) = (40.0, 0.8, 2.0);
    let gamma = c / (2.0 * m);
    let wd = (k / m - gamma * gamma).sqrt();
    let dir = Vector3::new(0.0, 0.6, 0.8);
    let anchor = Vector3::new(1.0, 1.0, 1.0);
    let (s0, u0) = (0.5, -1.0);
    let spring = Spring::new(k, c, 0.0).unwrap();
    let links = vec![Link {
        ball: 0,
        other: Attachment::Anchor(anchor),
        spring,
    }];
    let stepper = coupled(Integrator::Rk4, links);
    let mut x = [anchor + dir * s0];
    let mut v = [dir * u0];
    let t = 3.0;
    run(
        &stepper,
        &mut x,
        &mut v,
        &[1.0 / m],
        t / 6_000.0,
        6_000,
        |_, _| {},
    );
    let s = (-gamma * t).exp() * (s0 * (wd * t).cos() + (u0 + gamma * s0) / wd * (wd * t).sin());
    assert!((x[0] - (anchor + dir * s)).norm() < 1e-11, "{:?}", x[0]);

    // The same spring as a field (AnchorSpring through Stepper) is the same arithmetic.
    let field_stepper =
        Stepper::new(Integrator::Rk4, AnchorSpring::new(anchor, spring).unwrap()).unwrap();
    let (mut xf, mut vf) = ([anchor + dir * s0], [dir * u0]);
    let inverse_mass = [1.0 / m];
    let mut bodies = Bodies::new(&mut xf, &mut vf, &inverse_mass).unwrap();
    common::run_bodies(&field_stepper, &mut bodies, t / 6_000.0, 6_000);
    assert_eq!((xf, vf), (x, v));
}

/// A chain of `n` balls joined by springs, the first anchored, stretched and released.
fn chain(n: usize) -> (Vec<Link<f64, 3>>, Vec<Vector3<f64>>, Vec<f64>) {
    let spring = Spring::new(500.0, 0.0, 0.1).unwrap();
    let mut links = vec![Link {
        ball: 0,
        other: Attachment::Anchor(Vector3::zeros()),
        spring,
    }];
    links.extend((1..n).map(|i| Link {
        ball: i,
        other: Attachment::Ball(i - 1),
        spring,
    }));
    let x = (0..n)
        .map(|i| Vector3::new(0.12 * (i + 1) as f64, 0.01 * (i as f64).sin(), 0.0))
        .collect();
    let m = (0..n).map(|i| 1.0 / (1.0 + 0.5 * (i % 3) as f64)).collect();
    (links, x, m)
}

fn total_energy(
    net: &SpringNetwork<f64, 3>,
    x: &[Vector3<f64>],
    v: &[Vector3<f64>],
    inverse_masses: &[f64],
) -> f64 {
    let kinetic: f64 = v
        .iter()
        .zip(inverse_masses)
        .map(|(v, w)| 0.5 * v.norm_squared() / w)
        .sum();
    kinetic + net.potential_energy(x).unwrap()
}

/// The largest relative energy error of a chain over 2 s with step `dt`.
fn chain_energy_error(integrator: Integrator, dt: f64) -> f64 {
    let (links, mut x, m) = chain(8);
    let stepper = coupled(integrator, links);
    let mut v = vec![Vector3::zeros(); 8];
    let e0 = total_energy(stepper.network(), &x, &v, &m);
    let mut worst: f64 = 0.0;
    let steps = (2.0 / dt).round() as usize;
    run(&stepper, &mut x, &mut v, &m, dt, steps, |x, v| {
        worst = worst.max((total_energy(stepper.network(), x, v, &m) / e0 - 1.0).abs());
    });
    worst
}

#[test]
fn verlet_keeps_a_chain_energy_error_bounded_and_second_order() {
    let coarse = chain_energy_error(Integrator::VelocityVerlet, 2e-3);
    let fine = chain_energy_error(Integrator::VelocityVerlet, 1e-3);
    assert!(coarse < 1e-2, "{coarse}");
    let ratio = coarse / fine;
    assert!(
        (3.5..4.5).contains(&ratio),
        "halving h divides the energy error by {ratio}"
    );
    // Explicit Euler on the same chain gains energy without bound.
    assert!(chain_energy_error(Integrator::ExplicitEuler, 1e-3) > 10.0 * coarse);
}

#[test]
fn coupled_stepping_is_deterministic_and_independent_of_scratch_history() {
    let (links, x0, m) = chain(12);
    let stepper = CoupledStepper::new(
        Stepper::new(
            Integrator::Rk4,
            (
                Gravity::new(Vector3::new(0.0, -9.81, 0.0)).unwrap(),
                LinearDrag::new(0.1).unwrap(),
            ),
        )
        .unwrap(),
        SpringNetwork::new(links).unwrap(),
    )
    .unwrap();
    let dt = TimeStep::new(1e-3).unwrap();
    let simulate = |scratch: &mut Scratch<f64, 3>| {
        let (mut x, mut v) = (x0.clone(), vec![Vector3::zeros(); 12]);
        for n in 0..200 {
            let mut bodies = Bodies::new(&mut x, &mut v, &m).unwrap();
            stepper
                .step(&mut bodies, f64::from(n) * dt.get(), dt, scratch)
                .unwrap();
        }
        (x, v)
    };
    let fresh = simulate(&mut Scratch::new());
    // A scratch that has served a larger system, with garbage left in it.
    let mut used = Scratch::with_capacity(100);
    let mut big_x = vec![Vector3::new(7.0, 7.0, 7.0); 100];
    let mut big_v = vec![Vector3::new(-3.0, 1.0, 2.0); 100];
    let big_m = vec![1.0; 100];
    let mut bodies = Bodies::new(&mut big_x, &mut big_v, &big_m).unwrap();
    stepper.step(&mut bodies, 0.0, dt, &mut used).unwrap();
    assert_eq!(simulate(&mut used), fresh);
    assert_eq!(simulate(&mut Scratch::new()), fresh);
}

#[test]
fn too_few_balls_and_exact_with_springs_are_errors() {
    let spring = Spring::new(1.0, 0.0, 0.0).unwrap();
    let stepper = coupled(Integrator::Rk4, pair(spring));
    let mut x = [Vector3::new(1.0, 2.0, 3.0)];
    let mut v = [Vector3::zeros()];
    let mut bodies = Bodies::new(&mut x, &mut v, &[1.0]).unwrap();
    let e = stepper
        .step(
            &mut bodies,
            0.0,
            TimeStep::new(0.1).unwrap(),
            &mut Scratch::new(),
        )
        .unwrap_err();
    assert_eq!(e.to_string(), "bodies.len: must be in [2, inf], got 1");
    assert_eq!(x[0], Vector3::new(1.0, 2.0, 3.0));

    let exact = Stepper::new(Integrator::Exact, ()).unwrap();
    let e = CoupledStepper::new(exact, SpringNetwork::new(pair(spring)).unwrap()).unwrap_err();
    assert_eq!(e.integrator, Integrator::Exact);
    assert!(
        e.to_string()
            .contains("springs between balls have no closed-form solution")
    );
    // Without springs the exact integrator is fine (here in 2D, free flight).
    let free = CoupledStepper::new(
        Stepper::new(Integrator::Exact, ()).unwrap(),
        SpringNetwork::new(Vec::new()).unwrap(),
    )
    .unwrap();
    let (mut x, mut v) = ([Vector2::new(1.0, 2.0)], [Vector2::new(0.5, -1.0)]);
    let mut bodies = Bodies::new(&mut x, &mut v, &[1.0]).unwrap();
    free.step(
        &mut bodies,
        0.0,
        TimeStep::new(2.0).unwrap(),
        &mut Scratch::new(),
    )
    .unwrap();
    assert_eq!(x[0], Vector2::new(2.0, 0.0));
}
