//! Continuous collision detection: nothing passes through anything at any speed.
//!
//! Every scene here would tunnel without CCD: balls at up to 1e6 m/s cross thousands of
//! times their size in one step. The references are closed forms: elastic head-on
//! collisions (velocities exchanged, times of impact `gap / closing speed`), a ball
//! bouncing between two parallel surfaces (a triangle wave), a paddle hitting a ball at
//! rest (`(1 + e) u`), and a brute-force overlap check of every pair after every step.

use crate::common;

use carom_geometry::{Border, Obb};
use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::scene::{BallSpec, BorderSpec, BoxSpec, Scene, World};
use carom_sim::scenes::classic;
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::{Collision, Simulation};
use common::{Recorder, each_step, outside_border, scene_2d, states, stepped};
use nalgebra::{Const, Vector2, Vector3};

const DT: f64 = 1.0 / 600.0;

/// Two balls of radius 0.1 at `x = ∓1` approaching at `±v`, masses `m0` and `m1`, no border.
fn head_on<const D: usize>(v: f64, m0: f64, m1: f64) -> Scene<f64, D> {
    let at = |x: f64| {
        let mut p = nalgebra::SVector::<f64, D>::zeros();
        p[0] = x;
        p
    };
    Scene {
        balls: vec![
            BallSpec::new(at(-1.0), at(v), 0.1, m0),
            BallSpec::new(at(1.0), at(-v), 0.1, m1),
        ],
        ..Scene::default()
    }
}

fn check_head_on<T: Real, const D: usize>(v: f64, tolerance: f64)
where
    Const<D>: Space<T, D>,
{
    let s: Scene<T, D> = head_on::<D>(v, 1.0, 1.0).cast().unwrap();
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
    let mut rec = Recorder::default();
    // They meet at t = 1.8 / 2v and swap velocities; run to the end of the next step.
    let t_hit = 1.8 / (2.0 * v);
    let end = ((t_hit / DT).floor() + 1.0) * DT;
    sim.advance_to(T::lit(end), &mut rec).unwrap();
    assert_eq!(rec.collisions.len(), 1);
    let Collision::BallBall { time, i: 0, j: 1 } = rec.collisions[0] else {
        panic!("{:?}", rec.collisions[0]);
    };
    assert!((time.to_f64() - t_hit).abs() <= tolerance * t_hit);
    let st = states(&sim);
    let x0 = -0.1 - v * (end - t_hit);
    assert!((st.pos[0][0].to_f64() - x0).abs() <= tolerance * x0.abs());
    assert!((st.pos[1][0].to_f64() + x0).abs() <= tolerance * x0.abs());
    assert!((st.vel[0][0].to_f64() + v).abs() <= tolerance * v);
    assert!((st.vel[1][0].to_f64() - v).abs() <= tolerance * v);
}

#[test]
fn balls_meeting_head_on_at_a_million_metres_per_second_bounce() {
    for v in [1.0, 1e3, 1e6] {
        check_head_on::<f64, 2>(v, 1e-12);
        check_head_on::<f64, 3>(v, 1e-12);
        check_head_on::<f32, 2>(v, 1e-5);
        check_head_on::<f32, 3>(v, 1e-5);
    }
}

#[test]
fn a_light_fast_ball_bounces_off_a_heavy_one_at_mass_ratio_1e6() {
    let s = head_on::<2>(1e6, 1.0, 1e6);
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
    sim.advance_to(DT, &mut ()).unwrap();
    let st = states(&sim);
    // v0' = ((m0 − m1) v + 2 m1 (−v)) / (m0 + m1), v1' = (2 m0 v + (m1 − m0)(−v)) / (m0 + m1).
    let (m0, m1, v) = (1.0, 1e6, 1e6);
    let v0 = ((m0 - m1) * v - 2.0 * m1 * v) / (m0 + m1);
    let v1 = (2.0 * m0 * v - (m1 - m0) * v) / (m0 + m1);
    assert!((st.vel[0].x - v0).abs() < 1e-9 * v);
    assert!((st.vel[1].x - v1).abs() < 1e-9 * v);
    assert!(st.pos[1].x - st.pos[0].x > 0.2);
}

/// A ball of radius `r` moving along x at `v` from `x0` between a wall at `left` and a
/// face at `right`: the centre bounces on `[left + r, right − r]` as a triangle wave.
fn triangle_wave(x0: f64, v: f64, lo: f64, hi: f64, t: f64) -> f64 {
    let span = hi - lo;
    let u = (x0 - lo + v * t).rem_euclid(2.0 * span);
    lo + if u <= span { u } else { 2.0 * span - u }
}

#[test]
fn a_ball_trapped_between_a_box_and_a_wall_bounces_every_time_within_a_step() {
    // Border x ∈ [−1, 1]; a box whose left face is at x = 0.4; the ball (r = 0.1) runs
    // between x = −0.9 and x = 0.3 at 1e5 m/s: about 69 bounces per step of 1/600 s.
    let v = 1e5;
    let mut s = classic::elastic_box(vec![BallSpec::new(
        Vector2::new(0.0, 0.0),
        Vector2::new(v, 0.0),
        0.1,
        1.0,
    )]);
    s.boxes.push(BoxSpec {
        shape: Obb::from_angle(Vector2::new(0.45, 0.0), Vector2::new(0.05, 0.5), 0.0).unwrap(),
        vel: Vector2::zeros(),
        restitution: 1.0,
    });
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
    let mut rec = Recorder::default();
    for k in 1..=10 {
        let t = f64::from(k) * DT;
        sim.advance_to(t, &mut rec).unwrap();
        let st = states(&sim);
        let expected = triangle_wave(0.0, v, -0.9, 0.3, t);
        // Each bounce rounds the position once (1e-16 of 1 m): 700 bounces stay far
        // below 1e-9.
        assert!(
            (st.pos[0].x - expected).abs() < 1e-9,
            "t = {t}: {:?} vs {expected}",
            st.pos[0]
        );
        assert_eq!(st.pos[0].y, 0.0);
        assert!((st.vel[0].x.abs() - v).abs() < 1e-6);
    }
    // Bounces: one each time the path reaches an end, 1.2 m apart.
    let travelled = v * 10.0 * DT;
    let expected = ((travelled - 0.3) / 1.2).floor() as usize + 1;
    let walls = rec
        .collisions
        .iter()
        .filter(|c| matches!(c, Collision::BallBorder { .. }))
        .count();
    let box_hits = rec.collisions.len() - walls;
    assert_eq!(walls + box_hits, expected);
    assert!(walls.abs_diff(box_hits) <= 1);
    assert!(sim.stats().max_contacts_in_step >= 60);
}

/// A ball sliding along a wall, within rounding of it and pressed into it by less than
/// the engine counts as approaching, must still meet the next wall: the narrow phase
/// reported the wall it slides on as hit once rounding closed the gap, took that for no
/// contact, and lost the floor behind it (found by random scenes: a 1 kg ball squeezed
/// down a wall at 3.1e4 m/s by a 1e6 kg ball left the box through the floor).
/// - Without gravity, 2.8e-16 m off the left wall, pressed in at 1.7e-10 m/s (below the
///   rounding of its speed) and moving down at 3.1e4 m/s: it bounces between floor and
///   ceiling as the triangle wave of its vertical motion (about 80 bounces in the step;
///   before, it ended the step 312 m below the floor).
/// - Under gravity, 1e-12 m off the wall, pressed in at 1e-8 m/s (below the resting floor)
///   and falling at 3 m/s from 1 cm above the floor: it bounces (before, it ended the
///   step 2.1 cm through the floor).
#[test]
fn a_ball_sliding_along_a_wall_meets_the_next_wall() {
    let (r, vy) = (0.05, -31269.83974109964);
    let border = BorderSpec {
        border: Border::new(Vector2::repeat(-2.0), Vector2::repeat(2.0)).unwrap(),
        restitution: 1.0,
        periodic: false,
    };
    let ball = |x: f64, y: f64, vx: f64, vy: f64| {
        BallSpec::new(Vector2::new(x, y), Vector2::new(vx, vy), r, 1.0)
    };
    let fast = Scene {
        world: World {
            border: Some(border),
            ..World::default()
        },
        balls: vec![ball(
            -1.9499999999999997,
            -1.7153294028672454,
            -1.6689227777533233e-10,
            vy,
        )],
        ..Scene::default()
    };
    let falling = Scene {
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            border: Some(border),
            ..World::default()
        },
        balls: vec![ball(-1.949999999999, -1.94, -1e-8, -3.0)],
        ..Scene::default()
    };
    for integrator in Integrator::ALL {
        let mut sim = stepped(&fast, integrator, 0.01);
        sim.advance_to(0.01, &mut ()).unwrap();
        let st = states(&sim);
        let want = triangle_wave(-1.7153294028672454, vy, -1.95, 1.95, 0.01);
        assert!(
            (st.pos[0].y - want).abs() < 1e-6,
            "{integrator}: {:?}, want y = {want}",
            st.pos[0]
        );
        assert!(st.pos[0].x >= -1.95 - 1e-9, "{integrator}: {:?}", st.pos[0]);
        let mut sim = stepped(&falling, integrator, 0.01);
        sim.advance_to(0.01, &mut ()).unwrap();
        let st = states(&sim);
        assert!(st.pos[0].y >= -1.95 - 1e-9, "{integrator}: {:?}", st.pos[0]);
        assert!(st.vel[0].y > 0.0, "{integrator}: {:?}", st.vel[0]);
        assert!(st.pos[0].x >= -1.95 - 1e-9, "{integrator}: {:?}", st.pos[0]);
    }
}

#[test]
fn a_ball_at_a_million_metres_per_second_stays_in_the_border_and_out_of_thin_boxes() {
    // A thin rotated plate (1 mm thick) across the middle of a 3D box, and a ball shot
    // at it at 1e6 m/s in a slanted direction: it must stay on its own side forever.
    let plate = Obb::from_axis_angle(
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.0005, 2.0, 2.0),
        Vector3::new(0.0, 0.2, 0.3),
    )
    .unwrap();
    let normal = plate.axis(0);
    let s = Scene {
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector3::repeat(-1.0), Vector3::repeat(1.0)).unwrap(),
                restitution: 1.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(
            -normal * 0.5,
            Vector3::new(0.9, 0.3, -0.2).normalize() * 1e6,
            0.05,
            1.0,
        )],
        boxes: vec![BoxSpec {
            shape: plate,
            vel: Vector3::zeros(),
            restitution: 1.0,
        }],
        ..Scene::default()
    };
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
    for k in 1..=20 {
        sim.advance_to(f64::from(k) * DT, &mut ()).unwrap();
        let p = states(&sim).pos[0];
        assert!(
            normal.dot(&p) <= -(0.0005 + 0.05) + 1e-9,
            "step {k}: the ball crossed the plate: {p:?}"
        );
        assert!(
            p.amax() <= 1.0 - 0.05 + 1e-9,
            "step {k}: left the border: {p:?}"
        );
        assert!((states(&sim).vel[0].norm() - 1e6).abs() < 1e-3);
    }
    assert!(sim.counters().ball_box > 100 && sim.counters().ball_border > 100);
}

/// In `f32`, a ball of radius 1 mm at 1.04e7 m/s bouncing in a 2 m box, `--dt 0.01`: in
/// a last place of the step's time near its end (1.2e-9 s) it travels 1.2e-2 m, six
/// diameters, which ends a run whose ball meets another ball or a box so (the engine
/// cannot place such contacts; `a_ball_pumped_past_what_f32_resolves_in_a_step_...` in
/// stepped_wedge.rs). A wall is a half-space that its reflection keeps the ball inside
/// of wherever along its path the rounded time puts the contact, so a ball meeting only
/// walls runs on: inside the border at every step (to the touch tolerance, `16 ε`
/// m here), its speed kept, with every integrator.
#[test]
fn a_ball_faster_than_f32_resolves_for_contacts_with_balls_still_bounces_between_walls() {
    let (r, v) = (1e-3, Vector2::new(1e7, 3e6));
    let s = Scene::<f64, 2> {
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector2::repeat(-1.0), Vector2::repeat(1.0)).unwrap(),
                restitution: 1.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(Vector2::new(0.1, 0.2), v, r, 1.0)],
        ..Scene::default()
    }
    .cast::<f32>()
    .unwrap();
    each_step(&s, 0.01, 5, |integrator, k, sim| {
        let now = states(sim);
        let out = outside_border(&s, &now);
        assert!(out <= 2e-6, "{integrator}, step {k}: {out:e} m outside");
        let speed = f64::from(now.vel[0].norm());
        assert!(
            (speed / v.norm() - 1.0).abs() < 1e-6,
            "{integrator}, step {k}: {speed:e} m/s"
        );
    });
}

/// A table-tennis ball (radius 2 cm, 2.7 g) at rest at the origin and a paddle (a box of
/// half extents 1 cm × 10 cm) centred at `center`, turned by `angle`, moving along `x` at
/// `speed`, with restitution `e`.
fn ball_and_paddle(center: Vector2<f64>, angle: f64, speed: f64, e: f64) -> Scene<f64, 2> {
    Scene {
        balls: vec![BallSpec::new(
            Vector2::zeros(),
            Vector2::zeros(),
            0.02,
            0.0027,
        )],
        boxes: vec![BoxSpec {
            shape: Obb::from_angle(center, Vector2::new(0.01, 0.1), angle).unwrap(),
            vel: Vector2::new(speed, 0.0),
            restitution: e,
        }],
        ..Scene::default()
    }
}

#[test]
fn a_paddle_sends_a_ball_at_rest_off_at_one_plus_e_times_its_speed() {
    for (u, e) in [(3.0_f64, 1.0), (3.0, 0.6), (200.0, 0.85), (-50.0, 0.0)] {
        let s = ball_and_paddle(Vector2::new(-0.5 * u.signum(), 0.0), 0.0, u, e);
        let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
        let mut rec = Recorder::default();
        sim.advance_to(1.0 / u.abs() + 2.0 * DT, &mut rec).unwrap();
        let v = states(&sim).vel[0];
        if e > 0.0 {
            assert_eq!(rec.collisions.len(), 1, "u = {u}, e = {e}");
        }
        assert!(
            (v.x - (1.0 + e) * u).abs() < 1e-9 * u.abs(),
            "u = {u}, e = {e}: {v:?}"
        );
        assert_eq!(v.y, 0.0);
        // The paddle hit at the time its face reached the ball: 0.5 − 0.01 − 0.02 = 0.47 m.
        if let Some(Collision::BallBox { time, i: 0, k: 0 }) = rec.collisions.first() {
            assert!((time - 0.47 / u.abs()).abs() < 1e-12);
        }
    }
}

#[test]
fn a_paddle_driven_from_rust_hits_at_its_scripted_speed() {
    // The paddle waits, then is given 40 m/s for the steps it swings, then stops.
    let s = ball_and_paddle(Vector2::new(-0.2, 0.0), 0.3, 0.0, 0.9);
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, DT);
    let mut rec = Recorder::default();
    sim.advance_to(0.1, &mut rec).unwrap();
    assert_eq!(sim.box_center(0), Some(Vector2::new(-0.2, 0.0)));
    sim.set_box_velocity(0, Vector2::new(40.0, 0.0)).unwrap();
    sim.advance_to(0.1 + 6.0 * DT, &mut rec).unwrap();
    sim.set_box_velocity(0, Vector2::zeros()).unwrap();
    sim.advance_to(0.2, &mut rec).unwrap();
    assert_eq!(rec.collisions.len(), 1);
    // The paddle face is tilted by 0.3 rad: the ball leaves along the face normal with
    // (1 + e) times the paddle's normal speed.
    let normal = Vector2::new(0.3_f64.cos(), 0.3_f64.sin());
    let v = states(&sim).vel[0];
    assert!(
        (v - normal * (1.9 * 40.0 * normal.x)).norm() < 1e-9,
        "{v:?}"
    );
    let moved = sim.box_center(0).unwrap() - Vector2::new(-0.2, 0.0);
    assert!((moved - Vector2::new(40.0 * 6.0 * DT, 0.0)).norm() < 1e-12);
    assert!(sim.pipeline().iter().any(|p| p == "kinematic-boxes"));
    assert_eq!(
        sim.set_box_velocity(3, Vector2::zeros())
            .unwrap_err()
            .to_string(),
        "boxes[3]: no such box: the scene has 1"
    );
    assert_eq!(
        sim.set_box_velocity(0, Vector2::new(f64::NAN, 0.0))
            .unwrap_err()
            .field,
        "boxes[0].vel[0]"
    );
}

/// The deepest overlap of any two balls or of a ball with the border.
fn deepest_overlap(s: &Scene<f64, 2>, pos: &[Vector2<f64>]) -> f64 {
    let b = s.world.border.unwrap().border;
    let mut worst = 0.0_f64;
    for i in 0..pos.len() {
        let r = s.balls[i].radius;
        worst = worst.max((b.min() - pos[i]).add_scalar(r).max());
        worst = worst.max((pos[i] - b.max()).add_scalar(r).max());
        for j in i + 1..pos.len() {
            worst = worst.max(r + s.balls[j].radius - (pos[i] - pos[j]).norm());
        }
    }
    worst
}

#[test]
fn a_fast_dense_gas_never_overlaps() {
    // 300 balls at packing fraction 0.3 with thermal speeds of 1e4 m/s: each ball
    // crosses the box many times per step of 1/60 s and collides thousands of times.
    let s = gas::<2>(&GasParams {
        n: 300,
        fraction: 0.3,
        speed: 1e4,
        seed: 5,
        ..GasParams::default()
    })
    .unwrap();
    let mut sim = stepped(&s, Integrator::SemiImplicitEuler, 1.0 / 60.0);
    let e0 = carom_sim::observe::energy(&s, &states(&sim));
    for k in 1..=5 {
        sim.advance_to(f64::from(k) / 60.0, &mut ()).unwrap();
        let st = states(&sim);
        let overlap = deepest_overlap(&s, &st.pos);
        assert!(overlap < 1e-9, "step {k}: overlap {overlap:e}");
        let e = carom_sim::observe::energy(&s, &st);
        assert!((e - e0).abs() < 1e-9 * e0, "step {k}: energy {e0} -> {e}");
    }
    assert!(sim.stats().max_contacts_in_step > 1000);
    assert_eq!(sim.stats().capped_steps, 0);
}

/// A fuzzed scene, reduced (`--dt 0.01`, gravity, balls to 7e5 m/s, masses 1e-5 kg to
/// 5 t): a 9.7 mg ball is pumped to 700 m/s in the top right corner of the box between
/// a 3.6 g ball and the top wall. Contacts within a millionth of the step (1e-8 s) were
/// one instant, answered bottom-up: the ball met the 3.6 g ball again 7e-9 s after the
/// top wall, lower, so first, and each time ran on past the side wall, which only the
/// top wall's answer would have brought into view. It ended 1.2e-5 m beyond the wall
/// with the exact and Verlet integrators (3.2e-6 m with semi-implicit Euler). An
/// instant is now short enough that no ball moves more than 1e-9 m within it: every
/// ball stays inside the box, to 1e-9 m, at every step, with every integrator.
const LIGHT_BALL_PUMPED_INTO_A_CORNER: &str =
    include_str!("scenes/light_ball_pumped_into_a_corner.toml");

#[test]
fn a_light_ball_pumped_into_a_corner_stays_inside_the_box() {
    let s = scene_2d(LIGHT_BALL_PUMPED_INTO_A_CORNER);
    each_step(&s, 0.01, 75, |integrator, k, sim| {
        let outside = outside_border(&s, &states(sim));
        assert!(
            outside <= 1e-9,
            "{integrator}, step {k}: {outside:e} m outside"
        );
    });
}

/// In `f32` (`64 ε` = 7.6e-6): a ball bouncing between floor and ceiling at 6e4 m/s
/// drifts at 0.04 m/s into a side wall. The narrow phase counted `64 ε` of the ball's
/// whole speed, 0.46 m/s, as rounding of every approach, the side wall's too, and let
/// the ball through it: 0.038 m outside after a second (a fuzzed scene went 0.95 m
/// out). A wall's normal is an axis and its approach a component of the chord, read as
/// it is: the ball now stops at the wall (0.04 m/s is below the support speed, `2 g h`),
/// inside the box at every step, with every integrator.
#[test]
fn a_fast_ball_in_f32_does_not_pass_a_side_wall_it_drifts_into() {
    let r = 0.014;
    let s = Scene::<f64, 2> {
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            border: Some(BorderSpec {
                border: Border::new(Vector2::new(-1.87, -3.73), Vector2::new(1.87, 3.73)).unwrap(),
                restitution: 1.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector2::new(-1.85, 0.0),
            Vector2::new(-0.04, 6e4),
            r,
            0.0036,
        )],
        ..Scene::default()
    }
    .cast::<f32>()
    .unwrap();
    each_step(&s, 0.01, 100, |integrator, k, sim| {
        let x = states(sim).pos[0].x;
        assert!(
            x - r as f32 >= -1.87 - 1e-6,
            "{integrator}, step {k}: {:e} m outside",
            -1.87 - (x - r as f32)
        );
    });
}

/// In `f32`: a ball resting on the floor of a 3D box while another ball flies at 4.2e4
/// m/s. The narrow phase's resting floor held `64 ε` of the scene's fastest speed (0.32
/// m/s), so the resting ball's approach to the floor at `g h` (0.098 m/s) was no
/// contact, and it fell through the floor, 7.2e-2 m by 0.5 s (a fuzzed scene). The
/// narrow phase now counts only gravity's part of that floor, and the rounding of each
/// contact's own speeds: the ball stays on the floor with every integrator.
#[test]
fn a_ball_resting_on_the_floor_beside_a_very_fast_ball_in_f32_stays_on_it() {
    let (r, floor) = (0.056, -0.934);
    let s = Scene::<f64, 3> {
        world: World {
            gravity: Vector3::new(0.0, -9.81, 0.0),
            restitution: 0.0,
            border: Some(BorderSpec {
                border: Border::new(
                    Vector3::new(-2.05, floor, -2.52),
                    Vector3::new(2.05, 0.934, 2.52),
                )
                .unwrap(),
                restitution: 0.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![
            BallSpec::new(
                Vector3::new(0.146, -0.896, 0.887),
                Vector3::new(3740.0, 12998.0, 39970.0),
                0.038,
                6.2,
            ),
            BallSpec::new(
                Vector3::new(0.087, floor + r, -1.35),
                Vector3::new(0.358, 0.0, -1.597),
                r,
                2.02,
            ),
        ],
        ..Scene::default()
    }
    .cast::<f32>()
    .unwrap();
    each_step(&s, 0.01, 50, |integrator, k, sim| {
        let y = states(sim).pos[1].y;
        assert!(
            y - r as f32 >= floor as f32 - 1e-6,
            "{integrator}, step {k}: {:e} m below the floor",
            floor as f32 - (y - r as f32)
        );
    });
}

/// A ball falling along a side wall while drifting into it at 5e-8 m/s, below the
/// resting floor (a millionth of what gravity adds in a step, 9.8e-8 m/s at `dt = 0.01`).
/// The floor held every wall's contact, so the drift was never a contact and the ball
/// left the border by 5e-8 m a second (a fuzzed scene: 1.1e-7 m in 2 s). Gravity presses
/// nothing into a side wall, and the floor now holds a wall's contact only by `|n·ĝ|`: the
/// ball stays inside at every step, with every integrator.
#[test]
fn a_ball_falling_along_a_side_wall_drifting_into_it_slowly_stays_inside() {
    let r = 0.05;
    let s = Scene::<f64, 2> {
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            border: Some(BorderSpec {
                border: Border::new(Vector2::new(-1.0, -10.0), Vector2::new(1.0, 10.0)).unwrap(),
                restitution: 0.5,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector2::new(-1.0 + r, 9.0),
            Vector2::new(-5e-8, 0.0),
            r,
            1.0,
        )],
        ..Scene::default()
    };
    each_step(&s, 0.01, 100, |integrator, k, sim| {
        let outside = outside_border(&s, &states(sim));
        assert!(
            outside <= 1e-12,
            "{integrator}, step {k}: {outside:e} m outside"
        );
    });
}
