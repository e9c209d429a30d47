//! The five work-precision problems: their scenes, references and error measures, run
//! by every method that can express them.

use carom_integrate::{AnchorSpring, Integrator, Spring, Stepper, TimeStep};
use carom_sim::BallStates;
use carom_sim::scene::{BallSpec, Scene, World};
use carom_sim::scenes::classic;
use carom_sim::scenes::gas::{GasParams, gas};
use nalgebra::{Vector1, Vector2};

use super::{Sizes, measure, timed};
use crate::engines::{self, Method};
use crate::model::WorkPrecisionRow;
use crate::reference::{self, FreeBall};

/// How a run of a scene is scored: the error of the final states (carom's) or of the
/// final positions and velocities (rapier2d's).
trait Score {
    /// The error of `pos`, `vel` at the final time (kinetic energy for the gas).
    fn error(&self, pos: &[Vector2<f64>], vel: &[Vector2<f64>]) -> f64;
}

/// Largest distance of the final positions to the expected ones.
struct Positions(Vec<Vector2<f64>>);

impl Score for Positions {
    fn error(&self, pos: &[Vector2<f64>], _: &[Vector2<f64>]) -> f64 {
        pos.iter()
            .zip(&self.0)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    }
}

/// Relative change of the kinetic energy of balls of these masses.
struct Energy {
    masses: Vec<f64>,
    initial: f64,
}

impl Energy {
    fn kinetic(&self, vel: &[Vector2<f64>]) -> f64 {
        vel.iter()
            .zip(&self.masses)
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum()
    }
}

impl Score for Energy {
    fn error(&self, _: &[Vector2<f64>], vel: &[Vector2<f64>]) -> f64 {
        (self.kinetic(vel) - self.initial).abs() / self.initial
    }
}

/// The rows of `problem`.
pub(super) fn run(problem: &str, sizes: &Sizes) -> Vec<WorkPrecisionRow> {
    match problem {
        "projectile-drag" => {
            let (scene, t) = projectile();
            let b = &scene.balls[0];
            let k = scene.world.drag / b.mass;
            let m = reference::projectile_linear_drag(b.pos, b.vel, scene.world.gravity, k, t);
            engine_rows(problem, &scene, t, &Positions(vec![m.pos]), sizes)
        }
        "bouncing-ball" => {
            let (h, e, t) = (1.0, 0.8, 2.0);
            let scene = classic::ball_drop::<2>(h, e);
            let r = scene.balls[0].radius;
            let (y, _) = reference::bouncing_ball(h, e, -scene.world.gravity.y, t);
            engine_rows(
                problem,
                &scene,
                t,
                &Positions(vec![Vector2::new(0.0, y + r)]),
                sizes,
            )
        }
        "stiff-spring" => spring_rows(problem, sizes),
        "two-ball" => {
            let mut scene = classic::head_on(1.0, 3.0, 2.0, -0.5, 0.9);
            scene.balls[0].pos.y = 0.08;
            let t = 2.0;
            let free = |b: &BallSpec<f64, 2>| FreeBall {
                pos: b.pos,
                vel: b.vel,
                radius: b.radius,
                mass: b.mass,
            };
            let [a, b] =
                reference::free_pair(&free(&scene.balls[0]), &free(&scene.balls[1]), 0.9, t);
            engine_rows(problem, &scene, t, &Positions(vec![a.pos, b.pos]), sizes)
        }
        "elastic-gas" => {
            let scene = gas::<2>(&GasParams {
                n: sizes.gas_balls,
                fraction: 0.3,
                ..GasParams::default()
            })
            .expect("a valid gas");
            let masses: Vec<f64> = scene.balls.iter().map(|b| b.mass).collect();
            let vel: Vec<Vector2<f64>> = scene.balls.iter().map(|b| b.vel).collect();
            let mut energy = Energy {
                masses,
                initial: 0.0,
            };
            energy.initial = energy.kinetic(&vel);
            engine_rows(problem, &scene, sizes.gas_seconds, &energy, sizes)
        }
        _ => Vec::new(),
    }
}

/// A ball thrown at 45° at 14 m/s under gravity and linear drag `b = 0.5 kg/s`: 2 s.
fn projectile() -> (Scene<f64, 2>, f64) {
    let scene = Scene {
        name: Some("projectile-drag".to_owned()),
        world: World {
            gravity: Vector2::new(0.0, -9.81),
            drag: 0.5,
            ..World::default()
        },
        balls: vec![BallSpec::new(
            Vector2::zeros(),
            Vector2::new(10.0, 10.0),
            0.1,
            1.0,
        )],
        boxes: Vec::new(),
    };
    (scene, 2.0)
}

/// The rows of a scene problem: the stepped engine with every integrator at every step,
/// the event engine once (if it can run the scene), rapier2d at every step.
fn engine_rows(
    problem: &str,
    scene: &Scene<f64, 2>,
    t: f64,
    score: &dyn Score,
    sizes: &Sizes,
) -> Vec<WorkPrecisionRow> {
    let mut rows = Vec::new();
    let carom_point = |method: Method| {
        let once = || {
            let mut sim = engines::build(scene, method).ok()?;
            let (done, seconds) = timed(|| sim.advance_to(t, &mut ()));
            done.ok()?;
            let st: BallStates<f64, 2> = engines::states(sim.as_ref());
            Some((score.error(&st.pos, &st.vel), seconds))
        };
        measure(problem, &method.name(), method.dt(), sizes.repeats, once)
    };
    for integrator in Integrator::ALL {
        for &dt in &sizes.steps {
            rows.extend(carom_point(Method::Stepped(integrator, dt)));
        }
    }
    rows.extend(carom_point(Method::Event));
    #[cfg(feature = "rapier")]
    for &dt in &sizes.steps {
        rows.extend(rapier_point(problem, scene, t, dt, score, sizes.repeats));
    }
    rows
}

/// rapier2d on `scene` with step `dt`, for whole steps up to `t` (the last step is
/// shortened so the run ends at `t` exactly).
#[cfg(feature = "rapier")]
fn rapier_point(
    problem: &str,
    scene: &Scene<f64, 2>,
    t: f64,
    dt: f64,
    score: &dyn Score,
    repeats: usize,
) -> Option<WorkPrecisionRow> {
    use crate::peer::rapier::RapierScene;
    let steps = (t / dt).round() as usize;
    let once = || {
        let mut peer = RapierScene::new(scene, t / steps as f64).ok()?;
        let ((), seconds) = timed(|| (0..steps).for_each(|_| peer.step()));
        let (pos, vel): (Vec<Vector2<f64>>, Vec<Vector2<f64>>) = (0..scene.balls.len())
            .map(|i| {
                (
                    Vector2::from(peer.position(i)),
                    Vector2::from(peer.velocity(i)),
                )
            })
            .unzip();
        Some((score.error(&pos, &vel), seconds))
    };
    measure(problem, "rapier2d", Some(dt), repeats, once)
}

/// The stiff damped spring: `k = 1e4 N/m`, `c = 4 N·s/m`, `m = 1 kg` (`ω = 100 rad/s`,
/// `ζ = 0.02`), rest length 1 m, released at rest 0.5 m stretched; 1 s (16 periods, the
/// amplitude down to `e^(−2)`: the error is measured while there is motion left).
const SPRING: (f64, f64, f64) = (1e4, 4.0, 1.0);

fn spring_rows(problem: &str, sizes: &Sizes) -> Vec<WorkPrecisionRow> {
    let (k, c, rest) = SPRING;
    let (omega, t, x0) = (k.sqrt(), 1.0, 1.5);
    let zeta = c / (2.0 * omega);
    let (stretch, _) = reference::damped_oscillator(x0 - rest, 0.0, omega, zeta, t);
    let expected = Vector2::new(rest + stretch, 0.0);
    let mut rows = Vec::new();
    for integrator in Integrator::ALL {
        let Ok(spring) = Spring::new(k, c, rest) else {
            continue;
        };
        let Ok(field) = AnchorSpring::new(Vector2::zeros(), spring) else {
            continue;
        };
        // The exact integrator is refused: a spring has no closed form.
        let Ok(stepper) = Stepper::new(integrator, field) else {
            continue;
        };
        for &dt in &sizes.spring_steps {
            let steps = (t / dt).round() as usize;
            let Ok(h) = TimeStep::new(t / steps as f64) else {
                continue;
            };
            let once = || {
                let (mut x, mut v, mut w) =
                    (Vector2::new(x0, 0.0), Vector2::zeros(), Vector1::zeros());
                let ((), seconds) = timed(|| {
                    for n in 0..steps {
                        stepper.step_ball(&mut x, &mut v, &mut w, 1.0, n as f64 * h.get(), h);
                    }
                });
                Some(((x - expected).norm(), seconds))
            };
            rows.extend(measure(
                problem,
                &format!("carom-integrate/{integrator}"),
                Some(dt),
                sizes.repeats,
                once,
            ));
        }
    }
    #[cfg(feature = "rapier")]
    for &dt in &sizes.spring_steps {
        use crate::peer::rapier::RapierScene;
        let steps = (t / dt).round() as usize;
        let once = || {
            let mut peer =
                RapierScene::anchored_spring(1.0, 0.1, SPRING, [x0, 0.0], t / steps as f64);
            let ((), seconds) = timed(|| (0..steps).for_each(|_| peer.step()));
            Some(((Vector2::from(peer.position(0)) - expected).norm(), seconds))
        };
        rows.extend(measure(
            problem,
            "rapier2d (spring joint)",
            Some(dt),
            sizes.repeats,
            once,
        ));
    }
    rows
}
