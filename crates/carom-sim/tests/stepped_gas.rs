//! Many balls: energy conservation of an elastic gas, periodic boxes, determinism on 1, 2
//! and 3 threads and across runs, and the step grid. (The gas's drift against rapier2d's on
//! the same scene is tested in carom-report, which holds the rapier2d peer.)

use crate::common;

use carom_geometry::Obb;
use carom_integrate::Integrator;
use carom_sim::plan::BroadChoice;
use carom_sim::scene::{BoxSpec, Scene};
use carom_sim::scenes::collision_lab::{self, Screen};
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{Simulation, observe};
use carom_toi::Direction;
use common::{Recorder, states, stepped, stepped_with};
use nalgebra::{Vector2, Vector3};

#[test]
fn an_elastic_gas_keeps_its_energy_to_rounding() {
    // Kinetic energy changes only by the rounding of each impulse (a few ulps of the
    // pair's energy) and of the positions; 10 s at dt = 1/60 with thousands of
    // collisions stays within 1e-12 of the start.
    let s = gas::<2>(&GasParams {
        n: 2000,
        fraction: 0.3,
        ..GasParams::default()
    })
    .unwrap();
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, 1.0 / 60.0);
    let e0 = observe::energy(&s, &states(&sim));
    sim.advance_to(10.0, &mut ()).unwrap();
    let e1 = observe::energy(&s, &states(&sim));
    assert!((e1 - e0).abs() < 1e-12 * e0, "{e0} -> {e1}");
    assert!(sim.counters().ball_ball > 10_000, "{:?}", sim.counters());
    let s3 = gas::<3>(&GasParams {
        n: 1000,
        fraction: 0.2,
        ..GasParams::default()
    })
    .unwrap();
    let mut sim = stepped(&s3, Integrator::Rk4, 1.0 / 60.0);
    let e0 = observe::energy(&s3, &states(&sim));
    sim.advance_to(5.0, &mut ()).unwrap();
    let e1 = observe::energy(&s3, &states(&sim));
    assert!((e1 - e0).abs() < 1e-12 * e0, "3D: {e0} -> {e1}");
}

/// The deepest overlap of two balls in a periodic box (minimum image).
fn deepest_periodic_overlap(s: &Scene<f64, 3>, pos: &[Vector3<f64>]) -> f64 {
    let border = s.world.border.unwrap().border;
    let mut worst = 0.0_f64;
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            let d = border.minimum_image(&(pos[j] - pos[i])).norm();
            worst = worst.max(s.balls[i].radius + s.balls[j].radius - d);
        }
    }
    worst
}

#[test]
fn a_periodic_gas_keeps_energy_and_momentum_and_never_overlaps() {
    let s = gas::<3>(&GasParams {
        n: 400,
        fraction: 0.3,
        periodic: true,
        speed: 3.0,
        ..GasParams::default()
    })
    .unwrap();
    let border = s.world.border.unwrap().border;
    for broad in [BroadChoice::Grid, BroadChoice::Brute] {
        let mut sim = stepped_with(
            &s,
            Integrator::SemiImplicitEuler,
            1.0 / 60.0,
            broad,
            Direction::Forward,
        );
        let st = states(&sim);
        let (e0, p0) = (observe::energy(&s, &st), observe::momentum(&s, &st));
        for k in 1..=6 {
            sim.advance_to(f64::from(k) / 6.0, &mut ()).unwrap();
            let st = states(&sim);
            assert!(deepest_periodic_overlap(&s, &st.pos) < 1e-9);
            assert!(
                st.pos
                    .iter()
                    .all(|p| (0..3).all(|a| { border.min()[a] <= p[a] && p[a] < border.max()[a] }))
            );
            let (e, p) = (observe::energy(&s, &st), observe::momentum(&s, &st));
            assert!((e - e0).abs() < 1e-12 * e0);
            assert!((p - p0).norm() < 1e-10);
        }
        assert!(sim.pipeline().iter().any(|p| p == "periodic-border"));
    }
}

#[test]
fn a_ball_crossing_a_periodic_cell_many_times_per_step_still_meets_the_others() {
    // One ball at 1e4 m/s in a periodic box 4 m wide (about 4 crossings per step of
    // 1/600 s): the engine cuts each step into windows short enough for the minimum
    // image. It must collide with the resting balls on its line, never pass through.
    let mut s = gas::<2>(&GasParams {
        n: 25,
        fraction: 0.2,
        periodic: true,
        speed: 0.0,
        radius: 0.2,
        ..GasParams::default()
    })
    .unwrap();
    s.balls[12].vel = Vector2::new(1e4, 3e3);
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, 1.0 / 600.0);
    let e0 = observe::energy(&s, &states(&sim));
    let border = s.world.border.unwrap().border;
    for k in 1..=20 {
        sim.advance_to(f64::from(k) / 600.0, &mut ()).unwrap();
        let st = states(&sim);
        for i in 0..st.pos.len() {
            for j in i + 1..st.pos.len() {
                let d = border.minimum_image(&(st.pos[j] - st.pos[i])).norm();
                assert!(d > 0.4 - 1e-9, "step {k}: balls {i} and {j} overlap");
            }
        }
    }
    assert!((observe::energy(&s, &states(&sim)) - e0).abs() < 1e-9 * e0);
    assert!(sim.counters().ball_ball > 10);
    assert!(sim.stats().broad_builds > 20, "{:?}", sim.stats());
}

/// A scene using everything at once, above the engine's parallel threshold: a gas
/// under gravity with friction, inelastic collisions and a tilted table.
fn busy_scene() -> Scene<f64, 2> {
    let mut s = gas::<2>(&GasParams {
        n: 3000,
        fraction: 0.25,
        restitution: 0.9,
        speed: 5.0,
        seed: 11,
        ..GasParams::default()
    })
    .unwrap();
    s.world.gravity = Vector2::new(0.0, -9.81);
    s.world.friction = 0.2;
    s.boxes.push(BoxSpec {
        shape: Obb::from_angle(Vector2::new(0.0, -20.0), Vector2::new(15.0, 0.3), 0.2).unwrap(),
        vel: Vector2::zeros(),
        restitution: 0.7,
    });
    // Clear the balls the table overlaps.
    let table = s.boxes[0].shape;
    s.balls.retain(|b| {
        let local = table.to_local(&b.pos);
        let q = local.inf(&table.half_extents()).sup(&-table.half_extents());
        (local - q).norm() > b.radius
    });
    s
}

fn hash_on(threads: usize, s: &Scene<f64, 2>, until: f64) -> (u64, SteppedEngine<f64, 2>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut sim = stepped(s, Integrator::SemiImplicitEuler, 1.0 / 120.0);
        sim.advance_to(until, &mut ()).unwrap();
        (observe::state_hash(&states(&sim)), sim)
    })
}

#[test]
fn the_state_is_bit_identical_on_1_2_and_3_threads_and_across_runs() {
    let s = busy_scene();
    assert!(s.balls.len() > 2048, "the parallel paths must be exercised");
    let (reference, sim) = hash_on(1, &s, 0.5);
    assert!(sim.counters().ball_ball > 100 && sim.counters().ball_box > 0);
    for threads in [2, 3, 2] {
        assert_eq!(hash_on(threads, &s, 0.5).0, reference, "{threads} threads");
    }
    let periodic = gas::<3>(&GasParams {
        n: 3000,
        fraction: 0.3,
        periodic: true,
        ..GasParams::default()
    })
    .unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut sim = stepped(&periodic, Integrator::Rk4, 1.0 / 30.0);
            sim.advance_to(1.0, &mut ()).unwrap();
            observe::state_hash(&states(&sim))
        })
    };
    let reference = run(1);
    assert_eq!(run(2), reference);
    assert_eq!(run(3), reference);
}

#[test]
fn how_a_run_is_cut_into_samples_on_the_grid_does_not_change_it() {
    let s = busy_scene();
    let dt = 1.0 / 120.0;
    let (whole, _) = hash_on(2, &s, 0.25);
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, dt);
    let mut rec = Recorder::default();
    for k in [1, 2, 3, 7, 8, 20, 29, 30] {
        sim.advance_to(f64::from(k) * dt, &mut rec).unwrap();
    }
    assert_eq!(observe::state_hash(&states(&sim)), whole);
    // Collisions come in time order.
    assert!(
        rec.collisions
            .windows(2)
            .all(|w| w[0].time() <= w[1].time())
    );
}

#[test]
fn an_off_grid_target_is_reached_by_one_shortened_step() {
    // Free flight: landing on 0.35 dt and continuing is exact.
    let s = collision_lab::scene(Screen::Explore2d, &collision_lab::Options::default());
    let dt = 0.01;
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, dt);
    sim.advance_to(0.0035, &mut ()).unwrap();
    assert_eq!(sim.time(), 0.0035);
    let st = states(&sim);
    assert!((st.pos[0] - (s.balls[0].pos + s.balls[0].vel * 0.0035)).norm() < 1e-15);
    assert_eq!(sim.stats().steps, 1);
    sim.advance_to(0.02, &mut ()).unwrap();
    assert_eq!(sim.time(), 0.02);
    assert_eq!(sim.stats().steps, 3, "0.0035 → 0.01 → 0.02");
    // A target within rounding of the grid is the grid point: no sliver of a step.
    sim.advance_to(0.03 + 1e-13, &mut ()).unwrap();
    assert_eq!(sim.stats().steps, 4);
    // Going back is refused, naming the direction.
    let e = sim.advance_to(0.01, &mut ()).unwrap_err();
    assert!(e.message.contains("goes forward"), "{e}");
}

#[test]
fn an_elastic_run_backward_from_its_end_returns_to_its_start() {
    let mut s = collision_lab::scene(Screen::Explore2d, &collision_lab::Options::default());
    let t = 5.0;
    let mut forward = stepped(&s, Integrator::SemiImplicitEuler, 1.0 / 600.0);
    forward.advance_to(t, &mut ()).unwrap();
    let end = states(&forward);
    assert!(forward.counters().ball_ball > 0 && forward.counters().ball_border > 0);
    let start = s.clone();
    for (b, (p, v)) in s.balls.iter_mut().zip(end.pos.iter().zip(&end.vel)) {
        b.pos = *p;
        b.vel = *v;
    }
    let mut backward = stepped_with(
        &s,
        Integrator::SemiImplicitEuler,
        1.0 / 600.0,
        BroadChoice::Auto,
        Direction::Backward,
    );
    let mut rec = Recorder::default();
    backward.advance_to(-t, &mut rec).unwrap();
    assert_eq!(backward.time(), -t);
    let back = states(&backward);
    for (i, b) in start.balls.iter().enumerate() {
        assert!(
            (back.pos[i] - b.pos).norm() < 1e-9,
            "ball {i}: {:?} vs {:?}",
            back.pos[i],
            b.pos
        );
        assert!((back.vel[i] - b.vel).norm() < 1e-9);
    }
    // Backward collisions have negative, decreasing times.
    assert!(rec.collisions.iter().all(|c| c.time() <= 0.0));
    assert!(
        rec.collisions
            .windows(2)
            .all(|w| w[0].time() >= w[1].time())
    );
    assert_eq!(
        rec.collisions.len() as u64,
        forward.counters().ball_ball + forward.counters().ball_border
    );
}
