//! The ping-pong example, run headless through the `run` function its `main` calls
//! (see tests/collision_lab.rs for why), checked against physical facts: the paddle's hit
//! reverses the served ball along the table, no ball is ever inside the table, the
//! symmetric pair collides above the net with its momentum kept (up to what gravity and
//! drag change during one step), and the accurate integrators agree with the reference.

#[allow(
    dead_code,
    reason = "the example's `main` is not called: the tests call `run`"
)]
#[path = "../examples/ping_pong/main.rs"]
mod example;

use carom::integrate::Integrator;
use carom::sim::Collision;
use example::rally::{BALL_MASS, BALL_RADIUS, DRAG, Part, along_table, part};
use example::run;

fn rally(args: &[&str]) -> (example::Outcome, String) {
    let mut out = Vec::new();
    let o = run(args, &mut out).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    (o, String::from_utf8(out).unwrap())
}

#[test]
fn the_paddle_returns_the_served_ball_and_no_ball_enters_the_table() {
    let (o, text) = rally(&["--until", "1.2", "--integrator", "semi-implicit-euler,rk4"]);
    for r in std::iter::once(&o.reference).chain(&o.rallies) {
        let hit = r
            .events
            .iter()
            .find(|c| matches!(c, Collision::BallBox { i: 0, k, .. } if part(*k) == Part::Paddle))
            .unwrap_or_else(|| panic!("{}: the paddle misses\n{text}", r.integrator));
        let step = (hit.time() / r.dt).ceil() as usize;
        let (before, after) = (
            along_table(&o.frame, r, step - 1, 0),
            along_table(&o.frame, r, step, 0),
        );
        assert!(
            before > 2.0 && after < -5.0,
            "{}: {before} → {after}",
            r.integrator
        );
        // The table top is box 0: every ball stays outside it (touching allowed).
        let table = r.scene.boxes[0].shape;
        for (t, s) in &r.frames {
            for p in &s.pos {
                // Signed distance from the box, computed in its frame.
                let q = table.to_local(p).abs() - table.half_extents();
                let outside = q.map(|x| x.max(0.0)).norm();
                let d = if outside > 0.0 { outside } else { q.max() };
                assert!(
                    d >= BALL_RADIUS - 1e-6,
                    "{}: a ball {d} from the table at t = {t}",
                    r.integrator
                );
            }
        }
    }
    assert!(text.contains("ball 1 – paddle"), "{text}");
}

#[test]
fn the_symmetric_pair_collides_above_the_net_keeping_momentum() {
    let (o, _) = rally(&["--until", "0.5", "--integrator", "exact"]);
    let r = &o.reference;
    let c = r
        .events
        .iter()
        .find(|c| matches!(c, Collision::BallBall { i: 1, j: 2, .. }))
        .expect("balls 2 and 3 meet");
    let step = (c.time() / r.dt).ceil() as usize;
    let p = |f: usize| (r.frames[f].1.vel[1] + r.frames[f].1.vel[2]) * BALL_MASS;
    // Over one step, gravity and drag change the pair's momentum by about
    // 2 m g dt + b (v₂ + v₃) dt; the collision itself changes nothing.
    let (p0, p1) = (p(step - 1), p(step));
    let expected = nalgebra::Vector3::new(0.0, 0.0, -2.0 * BALL_MASS * 9.81 * r.dt)
        - p0 * (DRAG / BALL_MASS) * r.dt;
    assert!(
        (p1 - p0 - expected).norm() < 1e-7,
        "{:?}",
        p1 - p0 - expected
    );
    // By symmetry they meet on the net's plane, well above the net.
    let local = o.frame.local(&r.frames[step].1.pos[1]);
    assert!(local.x.abs() < 0.05 && local.z > 0.3, "{local:?}");
    // Head-on: each ball's velocity along the table reverses.
    assert!(
        along_table(&o.frame, r, step - 1, 1) > 2.0 && along_table(&o.frame, r, step, 1) < -2.0
    );
}

#[test]
fn accurate_integrators_follow_the_reference_and_the_table_prints_each_drift() {
    let (o, text) = rally(&["--until", "0.8"]);
    assert_eq!(o.rallies.len(), Integrator::ALL.len());
    let reference_end = o.reference.frames.last().unwrap().1.pos[0];
    for r in &o.rallies {
        assert!(
            text.contains(&format!("  {:<22}", r.integrator.to_string())),
            "{text}"
        );
        if matches!(
            r.integrator,
            Integrator::Rk4 | Integrator::Exact | Integrator::VelocityVerlet
        ) {
            let end = r.frames.last().unwrap().1.pos[0];
            assert!(
                (end - reference_end).norm() < 0.05,
                "{}: {}",
                r.integrator,
                (end - reference_end).norm()
            );
        }
    }
    let e = run(&["--integrator", "leapfrog"], &mut Vec::new())
        .err()
        .unwrap();
    assert!(e.to_string().starts_with("--integrator"), "{e}");
}
