//! The stepped engine in the pipeline: the planner's choices, `build`, the driver of
//! `carom run`, the pipeline names and the errors a bad request gets.

use crate::common;

use carom_geometry::Border;
use carom_integrate::Integrator;
use carom_sim::plan::{BroadChoice, EngineChoice, Plan, RunOptions, plan, stepped_broad_phase};
use carom_sim::run::{drive, sample_times};
use carom_sim::scene::{BallSpec, BorderSpec, Inelastic, Scene, World};
use carom_sim::scenes::classic;
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, EngineKind, Simulation, build};
use carom_toi::Direction;
use nalgebra::{Vector2, Vector3};

#[test]
fn auto_chooses_the_stepped_engine_for_drag_and_builds_it() {
    let mut s = classic::ball_drop::<3>(1.0, 0.8);
    s.world.drag = 0.05;
    let p = plan(&s, &RunOptions::default()).unwrap();
    assert_eq!(p.engine, EngineKind::Stepped);
    assert!(p.reason.contains("drag"), "{}", p.reason);
    let sim = build(&s, &p, Direction::Forward).unwrap();
    assert_eq!(sim.kind(), EngineKind::Stepped);
    let pipeline = sim.pipeline();
    for name in [
        "time-stepped",
        "integrator:semi-implicit-euler",
        "broad:brute-force",
        "narrow:ball-border",
        "field:gravity",
        "field:linear-drag",
        "guard:resting",
    ] {
        assert!(
            pipeline.iter().any(|p| p == name),
            "{name} missing: {pipeline:?}"
        );
    }
    // What the scene does not use is not in the pipeline.
    for absent in [
        "narrow:ball-ball",
        "narrow:ball-box",
        "response:friction",
        "periodic-border",
    ] {
        assert!(
            !pipeline.iter().any(|p| p == absent),
            "{absent} present: {pipeline:?}"
        );
    }
}

/// Three balls set down stacked on the floor: `auto` sends them to the stepped engine
/// (the event engine cannot resolve sustained contact), which keeps the stack standing
/// for a second.
#[test]
fn auto_sends_a_stack_under_gravity_to_the_stepped_engine_which_keeps_it_standing() {
    let r = 0.1;
    let s = Scene {
        name: None,
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            restitution: 0.5,
            border: Some(BorderSpec {
                border: Border::new(Vector2::new(-1.0, 0.0), Vector2::new(1.0, 2.0)).unwrap(),
                restitution: 0.5,
                periodic: false,
            }),
            ..World::default()
        },
        balls: (0..3)
            .map(|k| {
                BallSpec::new(
                    Vector2::new(0.0, r * f64::from(2 * k + 1)),
                    Vector2::zeros(),
                    r,
                    1.0,
                )
            })
            .collect(),
        boxes: Vec::new(),
    };
    let p = plan(&s, &RunOptions::default()).unwrap();
    assert_eq!(p.engine, EngineKind::Stepped);
    assert!(p.reason.contains("pressed together"), "{}", p.reason);
    let mut sim = build(&s, &p, Direction::Forward).unwrap();
    sim.advance_to(1.0, &mut ()).unwrap();
    let mut st = BallStates::default();
    sim.states(&mut st);
    for (k, pos) in st.pos.iter().enumerate() {
        let height = r * f64::from(2 * k as u32 + 1);
        assert!(
            (pos - Vector2::new(0.0, height)).norm() < 1e-3,
            "ball {k} at {pos:?}"
        );
    }
}

#[test]
fn the_broad_phase_is_chosen_from_the_scene_and_refused_where_it_cannot_work() {
    let small = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
    assert_eq!(
        stepped_broad_phase(&small, BroadChoice::Auto),
        Ok(BroadChoice::Brute)
    );
    let mut many = gas::<2>(&GasParams::default()).unwrap();
    assert_eq!(
        stepped_broad_phase(&many, BroadChoice::Auto),
        Ok(BroadChoice::Grid)
    );
    many.balls[0].radius = 0.01;
    assert_eq!(
        stepped_broad_phase(&many, BroadChoice::Auto),
        Ok(BroadChoice::Sap)
    );
    let periodic = gas::<2>(&GasParams {
        periodic: true,
        ..GasParams::default()
    })
    .unwrap();
    assert_eq!(
        stepped_broad_phase(&periodic, BroadChoice::Auto),
        Ok(BroadChoice::Grid)
    );
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        broad: BroadChoice::Kd,
        ..RunOptions::default()
    };
    let e = plan(&periodic, &options).unwrap_err();
    assert!(
        e.0.starts_with("--broad kd: the scene has a periodic border"),
        "{e}"
    );
    // Every broad phase gives the same run.
    let s = gas::<2>(&GasParams {
        n: 200,
        fraction: 0.3,
        ..GasParams::default()
    })
    .unwrap();
    let hashes: Vec<u64> = [
        BroadChoice::Brute,
        BroadChoice::Sap,
        BroadChoice::Kd,
        BroadChoice::Grid,
    ]
    .into_iter()
    .map(|broad| {
        let mut sim = common::stepped_with(
            &s,
            Integrator::VelocityVerlet,
            1.0 / 60.0,
            broad,
            Direction::Forward,
        );
        sim.advance_to(2.0, &mut ()).unwrap();
        assert!(sim.pipeline().iter().any(|p| p.starts_with("broad:")));
        carom_sim::observe::state_hash(&common::states(&sim))
    })
    .collect();
    assert!(hashes.windows(2).all(|w| w[0] == w[1]), "{hashes:x?}");
}

#[test]
fn bad_scenes_and_options_are_errors_naming_the_field() {
    let p = plan(
        &classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0),
        &RunOptions {
            engine: EngineChoice::Stepped,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let mut bad = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
    bad.balls[1].radius = -0.1;
    let e = SteppedEngine::new(&bad, &p, Direction::Forward)
        .err()
        .unwrap();
    assert_eq!(e.to_string(), "balls[1].radius: must be > 0, got -0.1");
    let mut tiny = p;
    tiny.dt = Some(1e-60);
    let f32_scene: Scene<f32, 2> = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0).cast().unwrap();
    let e = SteppedEngine::new(&f32_scene, &tiny, Direction::Forward)
        .err()
        .unwrap();
    assert_eq!(e.field, "--dt");
    // A periodic box must hold two diameters in half a period.
    let crowded = Scene {
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap(),
                restitution: 1.0,
                periodic: true,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector2::new(0.5, 0.5),
            Vector2::zeros(),
            0.3,
            1.0,
        )],
        ..Scene::default()
    };
    let e = SteppedEngine::new(&crowded, &p, Direction::Forward)
        .err()
        .unwrap();
    assert_eq!(e.field, "world.border");
}

#[test]
fn stick_scenes_run_on_the_stepped_engine_and_auto_picks_it_where_the_event_engine_cannot() {
    let stepped = RunOptions {
        engine: EngineChoice::Stepped,
        ..RunOptions::default()
    };
    let has_stick = |p: &Plan, s: &Scene<f64, 2>| {
        let sim = build(s, p, Direction::Forward).unwrap();
        sim.pipeline().iter().any(|n| n == "response:stick")
    };
    // 2D without gravity: auto keeps the exact engine; forced, the stepped engine runs it.
    let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 0.0);
    s.world.inelastic = Inelastic::Stick;
    assert_eq!(
        plan(&s, &RunOptions::default()).unwrap().engine,
        EngineKind::Event
    );
    let p = plan(&s, &stepped).unwrap();
    assert_eq!(p.engine, EngineKind::Stepped);
    assert!(has_stick(&p, &s));
    // Under gravity the event engine cannot: auto says why and picks the stepped engine.
    let mut falling = s.clone();
    falling.world.gravity = Vector2::new(0.0, -9.81);
    let p = plan(&falling, &RunOptions::default()).unwrap();
    assert_eq!(p.engine, EngineKind::Stepped);
    assert!(p.reason.contains("gravity"), "{}", p.reason);
    let e = plan(
        &falling,
        &RunOptions {
            engine: EngineChoice::Event,
            ..RunOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.0.contains("--engine stepped"), "{e}");
    // 3D on auto: the stepped engine, because clusters tumble.
    let mut s3 = classic::ball_drop::<3>(1.0, 0.0);
    s3.world.inelastic = Inelastic::Stick;
    s3.balls.push(BallSpec::new(
        Vector3::new(0.5, 0.0, 0.5),
        Vector3::zeros(),
        0.1,
        1.0,
    ));
    let p = plan(&s3, &RunOptions::default()).unwrap();
    assert_eq!(p.engine, EngineKind::Stepped);
    assert!(p.reason.contains("3D"), "{}", p.reason);
    assert!(build(&s3, &p, Direction::Forward).is_ok());
    // A per-ball restitution of 0 sticks too; restitution above 0 everywhere does not.
    let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 0.0);
    s.world.inelastic = Inelastic::Stick;
    s.world.restitution = 0.5;
    let p = plan(&s, &stepped).unwrap();
    assert!(!has_stick(&p, &s));
    s.balls[0].restitution = Some(0.0);
    assert!(has_stick(&p, &s));
}

#[test]
fn carom_run_drives_the_stepped_engine_through_its_samples() {
    // What `carom run scene.toml --engine stepped --until 2 --every 0.5 --events` does.
    let s = classic::ball_drop::<3>(1.0, 0.9);
    let p = plan(
        &s,
        &RunOptions {
            engine: EngineChoice::Stepped,
            integrator: Some(Integrator::Exact),
            ..RunOptions::default()
        },
    )
    .unwrap();
    let mut sim = build(&s, &p, Direction::Forward).unwrap();
    let times = sample_times(2.0, &[], Some(0.5)).unwrap();
    let mut sink = common::Keep::<3>::default();
    let summary = drive(sim.as_mut(), &s, &times, &mut sink, true).unwrap();
    assert_eq!(
        sink.samples.iter().map(|(t, _)| *t).collect::<Vec<_>>(),
        [0.0, 0.5, 1.0, 1.5, 2.0]
    );
    assert_eq!(summary.engine, EngineKind::Stepped);
    assert!(summary.pipeline.iter().any(|p| p == "integrator:exact"));
    // Bounces at t₁ = √(2h/g), then after flights of 2 eᵏ v₀/g: three by t = 2.
    let (g, v0) = (9.81, (2.0_f64 * 9.81).sqrt());
    let t1 = v0 / g;
    let expected = [t1, t1 + 1.8 * v0 / g, t1 + (1.8 + 1.62) * v0 / g];
    assert_eq!(sink.collisions.len(), 3);
    assert_eq!(summary.counters.ball_border, 3);
    for (c, t) in sink.collisions.iter().zip(expected) {
        assert!((c.time() - t).abs() < 1e-5, "{} vs {t}", c.time());
    }
    assert!(summary.energy_final <= summary.energy_initial);
    // The ball falls along z only.
    let last = &sink.samples[4].1;
    assert_eq!((last.pos[0].x, last.pos[0].y), (0.0, 0.0));
    assert_eq!(last.vel[0].x, 0.0);
}
