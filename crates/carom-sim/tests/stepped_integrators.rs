//! The stepped engine's free flight against closed forms, for every integrator: a
//! projectile under gravity and a ball under linear drag, forward and backward.
//!
//! Expected errors (carom-integrate's docs/integrators.md): under constant gravity
//! explicit Euler ends `−g h t/2` off (above the true parabola for `g` pointing down) and
//! semi-implicit Euler `+g h t/2` (below it); Verlet, RK4 and the exact integrator are
//! exact to rounding. Under linear drag the orders are 1, 1, 2, 4 and the exact
//! integrator is exact; both Euler schemes lose speed too fast, explicit Euler overshoots
//! in position and semi-implicit Euler falls short.

use crate::common;

use carom_integrate::Integrator;
use carom_sim::Simulation;
use carom_sim::plan::BroadChoice;
use carom_sim::scene::{BallSpec, Scene, World};
use carom_toi::Direction;
use common::{states, stepped, stepped_with};
use nalgebra::{Vector2, Vector3};

fn projectile() -> Scene<f64, 2> {
    Scene {
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector2::new(1e3, -2.0),
            Vector2::new(3.0, 4.0),
            0.1,
            0.5,
        )],
        ..Scene::default()
    }
}

#[test]
fn projectile_errors_have_the_documented_sign_and_size_for_every_integrator() {
    let s = projectile();
    let (h, t) = (0.01, 1.0);
    let g = s.world.gravity;
    let (x0, v0) = (s.balls[0].pos, s.balls[0].vel);
    let exact = x0 + v0 * t + g * (0.5 * t * t);
    for integrator in Integrator::ALL {
        let mut sim = stepped(&s, integrator, h);
        sim.advance_to(t, &mut ()).unwrap();
        let st = states(&sim);
        let expected_error = match integrator {
            Integrator::ExplicitEuler => -g * (h * t / 2.0),
            Integrator::SemiImplicitEuler => g * (h * t / 2.0),
            _ => Vector2::zeros(),
        };
        let error = st.pos[0] - exact;
        assert!(
            (error - expected_error).norm() < 1e-9,
            "{integrator}: error {error:?}, expected {expected_error:?}"
        );
        assert!(
            (st.vel[0] - (v0 + g * t)).norm() < 1e-12,
            "{integrator}: velocity {:?}",
            st.vel[0]
        );
        if integrator == Integrator::ExplicitEuler {
            assert!(error.y > 0.0, "explicit Euler flies above the parabola");
        }
        if integrator == Integrator::SemiImplicitEuler {
            assert!(
                error.y < 0.0,
                "semi-implicit Euler flies below the parabola"
            );
        }
    }
}

/// One ball of mass 2 under linear drag `b = 3` (`k = 1.5`), no gravity.
fn drag_scene() -> Scene<f64, 3> {
    Scene {
        world: World {
            drag: 3.0,
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector3::new(0.5, -1.0, 2.0),
            Vector3::new(4.0, 1.0, -2.0),
            0.1,
            2.0,
        )],
        ..Scene::default()
    }
}

/// The textbook solution `v = v₀ e^{−kt}`, `x = x₀ + v₀ (1 − e^{−kt})/k` (any sign of `t`).
fn drag_closed_form(s: &Scene<f64, 3>, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let k = s.world.drag / s.balls[0].mass;
    let (x0, v0) = (s.balls[0].pos, s.balls[0].vel);
    let decay = (-k * t).exp();
    (x0 + v0 * ((1.0 - decay) / k), v0 * decay)
}

fn drag_error(integrator: Integrator, h: f64, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let s = drag_scene();
    let mut sim = stepped(&s, integrator, h);
    sim.advance_to(t, &mut ()).unwrap();
    let st = states(&sim);
    let (x, v) = drag_closed_form(&s, t);
    (st.pos[0] - x, st.vel[0] - v)
}

#[test]
fn linear_drag_converges_at_each_integrators_order_and_exact_is_exact() {
    let t = 1.0;
    let v0 = drag_scene().balls[0].vel;
    for (integrator, order) in [
        (Integrator::ExplicitEuler, 1.0),
        (Integrator::SemiImplicitEuler, 1.0),
        (Integrator::VelocityVerlet, 2.0),
        (Integrator::Rk4, 4.0),
    ] {
        let (coarse, _) = drag_error(integrator, 0.02, t);
        let (fine, _) = drag_error(integrator, 0.01, t);
        let measured = (coarse.norm() / fine.norm()).log2();
        assert!(
            (measured - order).abs() < 0.15,
            "{integrator}: measured order {measured}"
        );
    }
    let (dx, dv) = drag_error(Integrator::Exact, 0.01, t);
    assert!(dx.norm() < 1e-13 && dv.norm() < 1e-13, "{dx:?} {dv:?}");
    // Both Euler schemes decay the speed too fast, (1 − kh)^n < e^{−kt}; explicit Euler
    // moves with the old (faster) velocities and overshoots, semi-implicit falls short.
    let along = v0.normalize();
    let (dx, dv) = drag_error(Integrator::ExplicitEuler, 0.01, t);
    assert!(dv.dot(&along) < 0.0 && dx.dot(&along) > 0.0);
    let (dx, dv) = drag_error(Integrator::SemiImplicitEuler, 0.01, t);
    assert!(dv.dot(&along) < 0.0 && dx.dot(&along) < 0.0);
}

#[test]
fn a_backward_run_under_drag_follows_the_reversed_closed_form() {
    // Backward in time a ball under drag was faster: v(−T) = v₀ e^{kT}.
    let s = drag_scene();
    let t = -1.0;
    let (x, v) = drag_closed_form(&s, t);
    let mut sim = stepped_with(
        &s,
        Integrator::Exact,
        0.01,
        BroadChoice::Auto,
        Direction::Backward,
    );
    sim.advance_to(t, &mut ()).unwrap();
    assert_eq!(sim.time(), t);
    let st = states(&sim);
    assert!((st.pos[0] - x).norm() < 1e-12 * x.norm());
    assert!((st.vel[0] - v).norm() < 1e-12 * v.norm());
    assert!(
        v.norm() > 4.0 * s.balls[0].vel.norm(),
        "the ball sped up going back"
    );
    // RK4 follows it too, to its own accuracy.
    let mut sim = stepped_with(
        &s,
        Integrator::Rk4,
        0.01,
        BroadChoice::Auto,
        Direction::Backward,
    );
    sim.advance_to(t, &mut ()).unwrap();
    assert!((states(&sim).vel[0] - v).norm() < 1e-8 * v.norm());
}

#[test]
fn f32_flight_matches_the_closed_form_to_single_precision() {
    let s64 = projectile();
    let s: Scene<f32, 2> = s64.cast().unwrap();
    let mut sim = stepped(&s, Integrator::Exact, 0.01);
    sim.advance_to(1.0, &mut ()).unwrap();
    let st = states(&sim);
    let exact = s64.balls[0].pos + s64.balls[0].vel + s64.world.gravity * 0.5;
    let got = Vector2::new(f64::from(st.pos[0].x), f64::from(st.pos[0].y));
    // 100 steps, each rounding a position of size 1e3 to f32 (half an ulp, 3e-5).
    let rounding = 100.0 * f64::from(f32::EPSILON) * exact.norm();
    assert!((got - exact).norm() < rounding, "{got:?} vs {exact:?}");
}

/// A run reaches the time it is asked for, to the precision's resolution of that time,
/// however long it is. The step loop once stopped as soon as it was within 64 ε of the
/// target, which in `f32` is many steps late in a long run: a free ball at 1 m/s, asked
/// for 2e4 s in steps of 0.01 s, was reported at x = 19999.85 (0.15 s of motion missing,
/// 15 steps); at 5e3 s at 4999.97. Checked against the closed form `x = v t`, at sample
/// times on and off the step grid, and backward.
#[test]
fn a_long_f32_run_reaches_its_target_time_not_steps_short_of_it() {
    let s64 = Scene {
        balls: vec![BallSpec::new(
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            0.1,
            1.0,
        )],
        ..Scene::default()
    };
    let s: Scene<f32, 2> = s64.cast().unwrap();
    for direction in [Direction::Forward, Direction::Backward] {
        let sign = direction.sign::<f64>();
        let mut sim = stepped_with(
            &s,
            Integrator::SemiImplicitEuler,
            0.01,
            BroadChoice::Auto,
            direction,
        );
        for t in [5000.0, 12_345.678, 20_000.0] {
            let target = sign * t;
            sim.advance_to(target as f32, &mut ()).unwrap();
            let x = f64::from(states(&sim).pos[0].x);
            // The time is resolved to a few units in its last place (2e4 s in f32: 2e-3
            // s a unit), and so is the place of a ball moving 1 m/s; every step also
            // rounds the place to one half unit.
            let resolution = 4.0 * f64::from(f32::EPSILON) * t;
            assert!(
                (x - target).abs() <= 2.0 * resolution,
                "{direction:?}: at t = {target} the ball is at {x}, {} m from v t",
                x - target
            );
        }
    }
}

/// A step so small that reaching the target needs more than 2⁵³ steps (where the step
/// grid's count stops being exact, and which no machine would finish) is an error naming
/// the count, not a run that never ends; a step just fine for the same target runs.
#[test]
fn a_run_needing_more_than_2_pow_53_steps_is_refused_at_once() {
    let s = projectile();
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, 1e-300);
    let e = sim.advance_to(0.1, &mut ()).unwrap_err();
    assert!(e.to_string().contains("more than 2^53"), "{e}");
    assert_eq!(sim.time(), 0.0, "nothing was simulated");
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, 1e-3);
    sim.advance_to(0.1, &mut ()).unwrap();
    assert!((sim.time() - 0.1).abs() < 1e-15);
}
