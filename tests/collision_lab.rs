//! The Collision Lab example, run headless through the same `run` function its `main`
//! calls (command-line parsing, the printed report, the pictures), checked against
//! physical facts: momentum conserved across ball–ball collisions (in the recorded states
//! and in the printed table), kinetic energy kept at elasticity 100 % and never gained,
//! no ball outside the play area, a stuck cluster that keeps its shape and spins at the
//! rate its angular momentum and inertia give, and the spinning cluster that bounces off
//! the wall instead of passing through.
//!
//! Cargo gives integration tests the path of the package's binaries but not of its
//! examples, so the example's `main.rs` is compiled into this test as a module and its
//! `run` is called with command-line arguments: everything but the three lines of `main`
//! that pick the exit status runs as it does from the command line.

#[allow(
    dead_code,
    reason = "the example's `main` is not called: the tests call `run`"
)]
#[path = "../examples/collision_lab/main.rs"]
mod example;

use example::{Outcome, run};

use carom::sim::Collision;
use carom::sim::scenes::collision_lab::play_area;

use example::lab::Frame;

fn lab(args: &[&str]) -> (Outcome, String) {
    let mut out = Vec::new();
    let outcome = run(args, &mut out).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    (outcome, String::from_utf8(out).expect("UTF-8 output"))
}

/// Every screen and preset, with both meanings of elasticity 0 %.
const SCREENS: [&[&str]; 9] = [
    &["--screen", "intro"],
    &["--screen", "explore1d"],
    &["--screen", "explore2d"],
    &["--screen", "inelastic", "--preset", "head-on"],
    &["--screen", "inelastic", "--preset", "criss-cross"],
    &["--screen", "inelastic", "--preset", "glancing"],
    &[
        "--screen",
        "inelastic",
        "--preset",
        "head-on",
        "--inelastic",
        "stick",
    ],
    &[
        "--screen",
        "inelastic",
        "--preset",
        "criss-cross",
        "--inelastic",
        "stick",
    ],
    &[
        "--screen",
        "inelastic",
        "--preset",
        "glancing",
        "--inelastic",
        "stick",
    ],
];

fn total_momentum(o: &Outcome, states: &carom::sim::BallStates<f64, 2>) -> nalgebra::Vector2<f64> {
    o.record
        .scene
        .balls
        .iter()
        .zip(&states.vel)
        .fold(nalgebra::Vector2::zeros(), |p, (b, v)| p + v * b.mass)
}

fn kinetic(o: &Outcome, states: &carom::sim::BallStates<f64, 2>) -> f64 {
    let s = &o.record.scene;
    s.balls
        .iter()
        .enumerate()
        .map(|(k, b)| {
            0.5 * b.mass * states.vel[k].norm_squared()
                + 0.5 * (0.5 * b.mass * b.radius * b.radius) * states.spin[k].x.powi(2)
        })
        .sum()
}

#[test]
fn every_screen_conserves_momentum_across_ball_ball_collisions_and_never_gains_energy() {
    for screen in SCREENS {
        let args: Vec<&str> = screen.iter().copied().chain(["--until", "4"]).collect();
        let (o, _) = lab(&args);
        let e = o.record.scene.world.restitution;
        let mut ball_ball = 0;
        for i in &o.record.instants {
            let (p0, p1) = (total_momentum(&o, &i.before), total_momentum(&o, &i.after));
            let (k0, k1) = (kinetic(&o, &i.before), kinetic(&o, &i.after));
            assert!(
                k1 <= k0 * (1.0 + 1e-12),
                "{screen:?} t = {}: energy gained {k0} → {k1}",
                i.t
            );
            if i.has_wall() {
                continue;
            }
            ball_ball += 1;
            assert!(
                (p1 - p0).norm() <= 1e-12,
                "{screen:?} t = {}: Δp = {}",
                i.t,
                (p1 - p0).norm()
            );
            if e == 1.0 {
                assert!(
                    (k1 - k0).abs() <= 1e-12 * k0,
                    "{screen:?} t = {}: {k0} → {k1}",
                    i.t
                );
            } else {
                assert!(
                    k1 < k0,
                    "{screen:?}: an inelastic collision must lose energy"
                );
            }
        }
        assert!(ball_ball > 0, "{screen:?}: no ball–ball collision in 4 s");
        assert_eq!(
            o.record.counters.ball_ball as usize,
            o.record
                .instants
                .iter()
                .flat_map(|i| &i.collisions)
                .filter(|c| matches!(c, Collision::BallBall { .. }))
                .count(),
            "{screen:?}: the table has every collision the engine counted"
        );
    }
}

#[test]
fn no_ball_is_ever_outside_the_play_area() {
    for screen in SCREENS {
        let args: Vec<&str> = screen.iter().copied().chain(["--until", "6"]).collect();
        let (o, _) = lab(&args);
        let area = play_area(example::lab::screen_of(o.record.case));
        for f in &o.record.frames {
            for (k, b) in o.record.scene.balls.iter().enumerate() {
                let p = f.states.pos[k];
                for axis in 0..2 {
                    assert!(
                        p[axis] - b.radius >= area.min()[axis] - 1e-9
                            && p[axis] + b.radius <= area.max()[axis] + 1e-9,
                        "{screen:?}: ball {k} at {p:?} (r = {}) outside at t = {}",
                        b.radius,
                        f.t
                    );
                }
            }
        }
    }
}

/// The two vectors of a printed `(+0.1234, -0.5678)`.
fn vectors(line: &str) -> Vec<[f64; 2]> {
    line.split('(')
        .skip(1)
        .filter_map(|s| {
            let inner = s.split(')').next()?;
            let mut it = inner.split(',').map(|x| x.trim().parse::<f64>());
            match (it.next(), it.next()) {
                (Some(Ok(x)), Some(Ok(y))) => Some([x, y]),
                _ => None,
            }
        })
        .collect()
}

#[test]
fn the_printed_table_shows_the_total_momentum_kept_in_each_ball_ball_collision() {
    let (o, text) = lab(&["--screen", "explore2d", "--until", "5"]);
    let totals: Vec<&str> = text
        .lines()
        .filter(|l| l.trim_start().starts_with("total") && l.contains("conserved"))
        .collect();
    let ball_ball = o.record.instants.iter().filter(|i| !i.has_wall()).count();
    assert_eq!(totals.len(), ball_ball, "{text}");
    assert!(ball_ball >= 3, "{text}");
    for line in totals {
        let v = vectors(line);
        assert_eq!(v.len(), 2, "{line}");
        assert_eq!(
            v[0], v[1],
            "printed to 4 decimals, before and after agree: {line}"
        );
    }
    // Walls: the printed impulse is the change of the total.
    for line in text.lines().filter(|l| l.contains("the wall's impulse")) {
        let v = vectors(line);
        assert_eq!(v.len(), 3, "{line}");
        let [before, after, impulse] = [v[0], v[1], v[2]];
        for ((b, a), j) in before.iter().zip(after).zip(impulse) {
            assert!((a - b - j).abs() < 2e-4, "{line}");
        }
    }
    assert!(
        text.contains("kinetic energy:    conserved (elasticity 100 %)"),
        "{text}"
    );
}

#[test]
fn a_stuck_cluster_keeps_its_shape_and_spins_at_angular_momentum_over_inertia() {
    let (o, text) = lab(&[
        "--screen",
        "inelastic",
        "--preset",
        "glancing",
        "--inelastic",
        "stick",
        "--until",
        "5",
    ]);
    let scene = &o.record.scene;
    let stick = o
        .record
        .instants
        .iter()
        .find(|i| i.body_after[1] == i.body_after[0])
        .expect("the balls stick");
    let (b0, b1) = (&scene.balls[0], &scene.balls[1]);
    let (m, r) = ([b0.mass, b1.mass], [b0.radius, b1.radius]);
    let mut spins = Vec::new();
    for f in o.record.frames.iter().filter(|f| f.t >= stick.t) {
        let (p0, p1) = (f.states.pos[0], f.states.pos[1]);
        // Touching, for good.
        assert!(
            ((p1 - p0).norm() - (r[0] + r[1])).abs() < 1e-9,
            "t = {}: gap {}",
            f.t,
            (p1 - p0).norm() - r[0] - r[1]
        );
        // Angular momentum about the centre of mass over the moment of inertia of two disks
        // (parallel-axis theorem), computed here from the states alone.
        let com = (p0 * m[0] + p1 * m[1]) / (m[0] + m[1]);
        let vcom = (f.states.vel[0] * m[0] + f.states.vel[1] * m[1]) / (m[0] + m[1]);
        let cross = |a: nalgebra::Vector2<f64>, b: nalgebra::Vector2<f64>| a.x * b.y - a.y * b.x;
        let orbital: f64 = (0..2)
            .map(|k| m[k] * cross(f.states.pos[k] - com, f.states.vel[k] - vcom))
            .sum();
        let inertia: f64 = (0..2)
            .map(|k| m[k] * (f.states.pos[k] - com).norm_squared() + 0.5 * m[k] * r[k] * r[k])
            .sum();
        let own: f64 = (0..2).map(|k| 0.5 * m[k] * r[k] * r[k]).sum();
        let w = f.states.spin[0].x;
        assert_eq!(
            w, f.states.spin[1].x,
            "one angular velocity for the cluster"
        );
        // L = Σ m r × v_rel + Σ I_own ω = I ω.
        assert!(
            (orbital + own * w - inertia * w).abs() < 1e-12,
            "t = {}",
            f.t
        );
        // Rigid rotation: the members' relative velocity is ω × (p1 − p0).
        let rel = f.states.vel[1] - f.states.vel[0];
        let d = p1 - p0;
        assert!(
            (rel - nalgebra::Vector2::new(-w * d.y, w * d.x)).norm() < 1e-12,
            "t = {}",
            f.t
        );
        spins.push(w);
    }
    assert!(spins.len() > 100 && spins.iter().all(|&w| w == spins[0] && w != 0.0));
    assert!(
        text.contains("stuck cluster {1,2}: spins rigidly"),
        "{text}"
    );
}

#[test]
fn a_purely_spinning_stuck_cluster_bounces_off_the_wall_instead_of_passing_through() {
    let (o, text) = lab(&["--case", "spinning-cluster-wall", "--until", "2"]);
    let free = o
        .without_wall
        .as_ref()
        .expect("the case also runs without the wall");
    let stick = &o.record.instants[0];
    assert_eq!(stick.body_after, vec![0, 0], "the first collision sticks");
    assert!(
        total_momentum(&o, &stick.after).norm() < 1e-15,
        "the cluster only spins"
    );
    let wall = o
        .record
        .instants
        .iter()
        .find(|i| i.has_wall())
        .expect("the cluster meets the wall");
    // The wall pushes the cluster away: momentum towards −x.
    assert!(total_momentum(&o, &wall.after).x < -0.1, "{text}");
    let reach = |outcome_frames: &[Frame], scene: &carom::sim::scene::Scene<f64, 2>| {
        outcome_frames
            .iter()
            .flat_map(|f| {
                scene
                    .balls
                    .iter()
                    .enumerate()
                    .map(move |(k, b)| f.states.pos[k].x + b.radius - 2.0)
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert!(reach(&o.record.frames, &o.record.scene) <= 1e-9, "{text}");
    assert!(
        reach(&free.frames, &free.scene) > 0.05,
        "without the wall it would pass 5 cm through"
    );
    assert!(text.contains("no ball ever enters a wall"), "{text}");
}

#[test]
fn reverse_runs_the_screen_backwards_in_time() {
    let (back, text) = lab(&["--screen", "intro", "--reverse", "--until", "3"]);
    assert_eq!(back.record.until, -3.0);
    assert!(text.contains("(backwards)"), "{text}");
    // Going back, ball 1 (x = −1, v = +1) moves left: x(−t) = −1 − t until it meets the wall.
    let f = back.record.frames.iter().find(|f| f.t <= -0.5).unwrap();
    assert!(
        (f.states.pos[0].x - (-1.0 + f.t)).abs() < 1e-12,
        "{}",
        f.states.pos[0].x
    );
    assert!(back.record.frames.iter().all(|f| f.t <= 0.0));
    // A negative --until means the same.
    let (fwd, _) = lab(&["--screen", "intro", "--until", "-3"]);
    assert_eq!(
        fwd.record.frames.len(),
        back.record.frames.len(),
        "a negative --until is --reverse"
    );
}

#[test]
fn pictures_and_the_animation_are_written() {
    let dir = std::env::temp_dir().join(format!("carom-collision-lab-test-{}", std::process::id()));
    let dir_arg = dir.to_str().unwrap();
    let (o, text) = lab(&[
        "--screen", "intro", "--until", "1", "--out", dir_arg, "--frames", "3",
    ]);
    assert_eq!(o.pictures.len(), 3, "{text}");
    for p in &o.pictures {
        let bytes = std::fs::read(p).unwrap();
        let name = p.file_name().unwrap().to_str().unwrap();
        let extension = p.extension().unwrap().to_str().unwrap();
        if extension == "png" {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
            let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
            assert_eq!(
                width,
                if name.contains("quantities") {
                    1200
                } else {
                    1500
                }
            );
        } else {
            assert!(extension == "gif" && bytes.starts_with(b"GIF89a"), "{name}");
        }
        assert!(text.contains(name), "{text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_options_are_refused_naming_the_flag() {
    let mut out = Vec::new();
    let e = run(&["--elasticity", "150"], &mut out).err().unwrap();
    assert!(e.to_string().starts_with("--elasticity"), "{e}");
    let e = run(&["--screen", "pinball"], &mut out).err().unwrap();
    assert!(e.to_string().contains("pinball"), "{e}");
    let e = run(&["--frames", "10"], &mut out).err().unwrap();
    assert!(e.to_string().contains("--out"), "{e}");
}
