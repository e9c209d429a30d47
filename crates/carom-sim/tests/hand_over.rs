//! `--engine auto` handing a run over from the event engine to the stepped engine when
//! balls come to rest on each other (sustained contact): the exact run up to that
//! instant, the stepped engine's from there, one clock, one summary.

use crate::common;

use carom_geometry::{Aabb, Border, Obb};
use carom_math::Vector;
use carom_sim::plan::{BroadChoice, Plan, RunOptions, plan};
use carom_sim::run::{Summary, drive, sample_times};
use carom_sim::scene::{BallSpec, BorderSpec, BoxSpec, Scene, World};
use carom_sim::{BallStates, Collision, EngineKind, SimErrorKind, build};
use carom_toi::Direction;
use common::{Keep, outside_border, scene_2d, states};
use nalgebra::Const;

const G: f64 = 9.81;
const R: f64 = 0.1;

/// Two balls of radius `R` dropped from rest one above the other onto the floor of a
/// room (restitution 0.5 everywhere): they bounce, the upper one lands on the lower
/// and they settle into a pile of two, which the event engine cannot resolve.
fn pile<const D: usize>() -> Scene<f64, D> {
    let up = |h: f64| Vector::<f64, D>::from_fn(|k, _| if k == 1 { h } else { 0.0 });
    let mut min = Vector::<f64, D>::repeat(-1.0);
    min[1] = 0.0;
    Scene {
        name: None,
        world: World {
            gravity: up(-G),
            restitution: 0.5,
            border: Some(BorderSpec {
                border: Border::new(min, Vector::repeat(3.0)).unwrap(),
                restitution: 0.5,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![
            BallSpec::new(up(0.5), Vector::zeros(), R, 1.0),
            BallSpec::new(up(1.2), Vector::zeros(), R, 1.0),
        ],
        boxes: Vec::new(),
    }
}

/// `carom run` with `--engine auto` (and `--until until --every every --events`).
fn run_auto<const D: usize>(
    scene: &Scene<f64, D>,
    until: f64,
    every: f64,
) -> (Summary<f64, D>, Keep<D>)
where
    Const<D>: carom_math::Space<f64, D>,
{
    let p = plan(scene, &RunOptions::default()).unwrap();
    assert_eq!((p.engine, p.hand_over), (EngineKind::Event, true));
    let direction = if until < 0.0 {
        Direction::Backward
    } else {
        Direction::Forward
    };
    let mut sim = build(scene, &p, direction).unwrap();
    let times = sample_times(until, &[], Some(every)).unwrap();
    let mut keep = Keep::default();
    let summary = drive(sim.as_mut(), scene, &times, &mut keep, true).unwrap();
    (summary, keep)
}

fn the_pile_settles_after_the_hand_over<const D: usize>()
where
    Const<D>: carom_math::Space<f64, D>,
{
    let scene = pile::<D>();
    let (summary, keep) = run_auto(&scene, 3.0, 0.01);

    // The event engine alone stops with sustained contact; that instant is the hand-over.
    let mut exact = build(&scene, &Plan::event(BroadChoice::Auto), Direction::Forward).unwrap();
    let mut exact_collisions = Keep::<D>::default();
    let err = drive(exact.as_mut(), &scene, &[3.0], &mut exact_collisions, true).unwrap_err();
    assert_eq!(err.kind, SimErrorKind::SustainedContact, "{err}");
    let handed = summary.hand_over.as_ref().expect("the run was handed over");
    assert_eq!(handed.time, err.time);
    assert_eq!(handed.reason, err.message);
    assert!(handed.time > 0.5 && handed.time < 1.5, "{}", handed.time);
    assert_eq!(summary.engine, EngineKind::Stepped);
    for name in ["event-driven", "time-stepped"] {
        assert!(summary.pipeline.iter().any(|p| p == name), "{name}");
    }

    // Before the hand-over, the run is the event engine's, collision for collision and
    // sample for sample.
    let before: Vec<_> = (keep.collisions.iter())
        .filter(|c| c.time() <= handed.time)
        .copied()
        .collect();
    assert_eq!(before, exact_collisions.collisions);
    let mut exact = build(&scene, &Plan::event(BroadChoice::Auto), Direction::Forward).unwrap();
    let mut states = BallStates::default();
    for (t, sampled) in keep.samples.iter().filter(|(t, _)| *t < handed.time) {
        exact.advance_to(*t, &mut ()).unwrap();
        exact.states(&mut states);
        assert_eq!(&states, sampled, "t = {t}");
    }

    // After it, one clock: collisions in time order, counted once.
    assert!(
        keep.collisions
            .windows(2)
            .all(|w| w[0].time() <= w[1].time())
    );
    let ball_ball = keep
        .collisions
        .iter()
        .filter(|c| matches!(c, Collision::BallBall { .. }));
    assert_eq!(ball_ball.count() as u64, summary.counters.ball_ball);
    let borders = keep
        .collisions
        .iter()
        .filter(|c| matches!(c, Collision::BallBorder { .. }));
    assert_eq!(borders.count() as u64, summary.counters.ball_border);

    // The pile stands on the floor: heights R and 3R (the stepped engine's resting
    // floor is 2.7e-9 m over a step, docs/stepped.md), nothing moving, never overlapping,
    // and the energy left is the pile's potential energy.
    for (t, s) in &keep.samples {
        let gap = (s.pos[1] - s.pos[0]).norm() - 2.0 * R;
        assert!(gap >= -1e-8, "t = {t}: the balls overlap by {}", -gap);
        assert!(
            s.pos[0][1] >= R - 1e-8,
            "t = {t}: ball 0 at {}",
            s.pos[0][1]
        );
    }
    let (_, last) = keep.samples.last().unwrap();
    for (i, height) in [R, 3.0 * R].into_iter().enumerate() {
        assert!(
            (last.pos[i][1] - height).abs() < 1e-8,
            "ball {i} at {}",
            last.pos[i]
        );
        assert!(
            last.pos[i]
                .iter()
                .enumerate()
                .all(|(k, x)| k == 1 || *x == 0.0)
        );
        assert!(
            last.vel[i].norm() < 1e-6,
            "ball {i} moves at {}",
            last.vel[i]
        );
    }
    let settled = G * (R + 3.0 * R);
    assert!(
        (summary.energy_final - settled).abs() < 1e-6,
        "{} against {settled}",
        summary.energy_final
    );
}

#[test]
fn a_pile_forming_under_auto_is_handed_over_to_the_stepped_engine_and_settles_2d() {
    the_pile_settles_after_the_hand_over::<2>();
}

#[test]
fn a_pile_forming_under_auto_is_handed_over_to_the_stepped_engine_and_settles_3d() {
    the_pile_settles_after_the_hand_over::<3>();
}

/// Balls dropped from rest fall the same way forward and backward in time (gravity does
/// not change sign): the backward run, handed over at `−t_h`, is the forward run
/// mirrored, bit for bit, velocities negated. This checks the shifted clock and the
/// direction of the stepped engine after a backward hand-over.
#[test]
fn a_backward_run_is_handed_over_at_the_mirrored_instant_and_mirrors_the_forward_run() {
    let scene = pile::<2>();
    let (forward, ahead) = run_auto(&scene, 2.0, 0.05);
    let (backward, behind) = run_auto(&scene, -2.0, 0.05);
    let (f, b) = (forward.hand_over.unwrap(), backward.hand_over.unwrap());
    assert_eq!(b.time, -f.time);
    assert_eq!(ahead.samples.len(), behind.samples.len());
    for ((t, s), (u, m)) in ahead.samples.iter().zip(&behind.samples) {
        assert_eq!(*u, -t);
        assert_eq!(s.pos, m.pos, "t = {t}");
        let negated: Vec<_> = m.vel.iter().map(|v| -v).collect();
        assert_eq!(s.vel, negated, "t = {t}");
    }
    assert_eq!(ahead.collisions.len(), behind.collisions.len());
    for (c, d) in ahead.collisions.iter().zip(&behind.collisions) {
        assert_eq!(c.time(), -d.time());
    }
}

/// A kinematic box crossing the room along the floor reaches the pile long after the
/// hand-over, where its path puts it: the stepped engine starts with the box moved by
/// `vel · t_h`, not at its place at time 0 (which would strike `t_h` later).
#[test]
fn a_moving_box_goes_on_along_its_path_after_the_hand_over() {
    let mut scene = pile::<2>();
    let speed = 0.5;
    let face = -0.96;
    scene.boxes.push(BoxSpec {
        shape: Obb::from_aabb(
            &Aabb::new(
                Vector::<f64, 2>::new(face - 0.04, 0.02),
                Vector::<f64, 2>::new(face, 0.18),
            )
            .unwrap(),
        ),
        vel: Vector::<f64, 2>::new(speed, 0.0),
        restitution: 1.0,
    });
    let (summary, keep) = run_auto(&scene, 2.0, 0.25);
    let handed = summary.hand_over.expect("the pile is handed over").time;
    // The face reaches the lower ball, resting at x = 0, when it has come to x = −R.
    let arrival = (-R - face) / speed;
    assert!(arrival > handed + 0.5, "{arrival} vs {handed}");
    let first = keep
        .collisions
        .iter()
        .find(|c| matches!(c, Collision::BallBox { .. }))
        .expect("the box strikes the pile");
    assert_eq!(
        *first,
        Collision::BallBox {
            time: first.time(),
            i: 0,
            k: 0
        }
    );
    assert!(
        (first.time() - arrival).abs() < 1e-9,
        "struck at {} instead of {arrival}",
        first.time()
    );
}

/// The stepped engine takes the run on from the event engine's state at the instant,
/// spins included (friction spins balls up; a scene file has no spins to start from).
#[test]
fn the_stepped_engine_starts_from_the_event_engines_state_spins_included() {
    let mut scene = pile::<3>();
    scene.world.friction = 0.5;
    // A small ball falling onto the shoulder of a large one by a wall, into the wedge
    // between them.
    scene.balls[0].radius = 3.0 * R;
    scene.balls[0].pos.x = -1.0 + 3.0 * R;
    scene.balls[1].pos.x = -1.0 + 2.5 * R;
    let p = plan(&scene, &RunOptions::default()).unwrap();
    let mut exact = build(&scene, &Plan::event(BroadChoice::Auto), Direction::Forward).unwrap();
    let err = exact.advance_to(3.0, &mut ()).unwrap_err();
    let mut at_error = BallStates::default();
    exact.states(&mut at_error);
    assert!(
        at_error.spin.iter().all(|w| w.norm() > 0.1),
        "{:?}",
        at_error.spin
    );
    let mut sim = build(&scene, &p, Direction::Forward).unwrap();
    sim.advance_to(err.time, &mut ()).unwrap();
    assert_eq!(sim.hand_over().map(|h| h.time), Some(err.time));
    let mut handed = BallStates::default();
    sim.states(&mut handed);
    assert_eq!(handed, at_error);
}

/// A ball set down on a box's corner, its centre beyond the corner, slides around it and
/// leaves it (frictionless, a point pivot) where `cos θ = (2/3) cos θ₀`, at
/// `v² = 2 g r (cos θ₀ − cos θ)` along the tangent. The event engine cannot hold a ball
/// on a corner: it hopped there at the resolution of the position (6.6 million hops for
/// this pivot before it was refused: exact, 8.6 s for 1 s). It now ends with sustained
/// contact after 64 such hops, and `auto` hands the pivot over to the stepped engine.
#[test]
fn a_ball_pivoting_over_a_box_corner_is_handed_over_and_leaves_at_the_closed_form_speed() {
    let mut scene = pile::<2>();
    scene.balls = vec![BallSpec::new(
        Vector::<f64, 2>::new(0.6 * R, 0.8 * R + 0.5),
        Vector::zeros(),
        R,
        1.0,
    )];
    scene.boxes.push(BoxSpec {
        shape: Obb::from_aabb(
            &Aabb::new(
                Vector::<f64, 2>::new(-0.9, 0.25),
                Vector::<f64, 2>::new(0.0, 0.5),
            )
            .unwrap(),
        ),
        vel: Vector::zeros(),
        restitution: 0.0,
    });
    let mut exact = build(&scene, &Plan::event(BroadChoice::Auto), Direction::Forward).unwrap();
    let err = exact.advance_to(0.3, &mut ()).unwrap_err();
    assert_eq!(err.kind, SimErrorKind::SustainedContact, "{err}");
    assert!(err.message.contains("edge or a corner"), "{err}");
    assert!(err.time < 1e-3, "{err}");

    let (summary, keep) = run_auto(&scene, 0.3, 0.01);
    assert_eq!(summary.hand_over.map(|h| h.time), Some(err.time));
    let (cos0, cos1) = (0.8, 0.8 * 2.0 / 3.0);
    let speed = (2.0 * G * R * (cos0 - cos1)).sqrt();
    let leaving = speed * cos1;
    let (_, last) = keep.samples.last().unwrap();
    // The stepped engine's default step (1/600 s) follows the slide to 0.2 %.
    assert!(
        (last.vel[0].x - leaving).abs() < 5e-3 * leaving,
        "leaves at {} instead of {leaving}",
        last.vel[0].x
    );
    // Never in the box [−0.9, 0] × [0.25, 0.5].
    for (t, s) in &keep.samples {
        let (x, y) = (s.pos[0].x, s.pos[0].y);
        let dx = (-0.9 - x).max(x).max(0.0);
        let dy = (0.25 - y).max(y - 0.5).max(0.0);
        assert!(
            dx.hypot(dy) >= R - 1e-8,
            "t = {t}: the ball at ({x}, {y}) enters the box"
        );
    }
}

/// Without gravity too: a fuzzed scene (`tests/scenes/light_ball_pinned_without_gravity.toml`)
/// whose light ball ends up pinned between a ball 4e8 times heavier and the border,
/// run backwards. The event engine ends it with an endless cascade at one instant,
/// sustained contact (before, a failure `auto` did not hand over: the run ended there,
/// as it did after a crawl of more than a minute before the calendar kept one heap
/// entry per ball); under `auto` the stepped engine runs on from that instant to the
/// end, every ball inside the border and the energy never above the hand-over's (the
/// collisions lose energy: restitution 0.19 and 0.5, friction).
#[test]
fn a_light_ball_pinned_without_gravity_is_handed_over_to_the_stepped_engine() {
    let scene = scene_2d(include_str!(
        "scenes/light_ball_pinned_without_gravity.toml"
    ));
    assert_eq!(scene.world.gravity, Vector::<f64, 2>::zeros());
    let mut exact = build(&scene, &Plan::event(BroadChoice::Auto), Direction::Backward).unwrap();
    let err = exact.advance_to(-0.05, &mut ()).unwrap_err();
    assert_eq!(err.kind, SimErrorKind::SustainedContact, "{err}");
    assert!(
        err.message.contains("at one instant") && err.message.contains("without gravity"),
        "{err}"
    );
    assert!((err.time + 6.6037e-4).abs() < 1e-8, "{err}");
    let at_hand_over = states(&*exact);

    let (summary, keep) = run_auto(&scene, -0.05, 0.01);
    let handed = summary.hand_over.as_ref().expect("the run was handed over");
    assert_eq!((handed.time, &handed.reason), (err.time, &err.message));
    assert_eq!(summary.engine, EngineKind::Stepped);
    assert_eq!(keep.samples.last().map(|(t, _)| *t), Some(-0.05));
    let energy = |st: &BallStates<f64, 2>| carom_sim::observe::energy(&scene, st);
    let start = energy(&at_hand_over);
    for (t, st) in &keep.samples {
        if *t < handed.time {
            assert!(energy(st) <= start * (1.0 + 1e-9), "t = {t}: energy rose");
        }
        let outside = outside_border(&scene, st);
        assert!(
            outside <= 1e-9,
            "t = {t}: a ball {outside} m outside the border"
        );
    }
}
