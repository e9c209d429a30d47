//! Helpers shared by the engines' tests: building a stepped engine from a scene with given
//! options, reading a 2D scene file, running a scene step by step with every integrator,
//! running an engine to a time and collecting its collisions, keeping what `carom run`'s
//! driver hands its sink, reading states, measuring how far balls stray out of the
//! border or into each other, checking that a resting scene stays put.

use carom_integrate::Integrator;
use carom_math::{Real, Space, Vector};
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::run::RunSink;
use carom_sim::scene::{LoadedScene, Scene, parse_scene};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Collision, Observer, Simulation, observe};
use carom_toi::Direction;
use nalgebra::Const;

/// The stepped engine for `scene` with `integrator`, step `dt` and broad phase `broad`.
pub(crate) fn stepped<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    integrator: Integrator,
    dt: f64,
) -> SteppedEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    stepped_with(scene, integrator, dt, BroadChoice::Auto, Direction::Forward)
}

/// As [`stepped`], with the broad phase and the direction.
pub(crate) fn stepped_with<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    integrator: Integrator,
    dt: f64,
    broad: BroadChoice,
    direction: Direction,
) -> SteppedEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(integrator),
        dt: Some(dt),
        broad,
    };
    let p = plan(scene, &options).expect("a valid plan");
    SteppedEngine::new(scene, &p, direction).expect("a valid scene")
}

/// `scene` with a static 1 cm box added at the origin, out of every ball's way: a scene
/// far from the origin is then no longer on one side of it, so the engine computes in
/// the scene's own coordinates ([`Scene::recentred`] moves nothing) and meets the
/// rounding of positions that far out, which recentring otherwise spares it.
pub(crate) fn spanning_the_origin<T: Real, const D: usize>(scene: &Scene<T, D>) -> Scene<T, D>
where
    Const<D>: Space<T, D>,
{
    let mut s = scene.clone();
    let shape = carom_geometry::Obb::from_aabb(&carom_geometry::Aabb::new_unchecked(
        Vector::repeat(T::lit(-0.005)),
        Vector::repeat(T::lit(0.005)),
    ));
    s.boxes.push(carom_sim::scene::BoxSpec {
        shape,
        vel: Vector::zeros(),
        restitution: T::one(),
    });
    assert_eq!(
        s.middle(),
        Vector::<T, D>::zeros(),
        "the box keeps the origin"
    );
    s
}

/// The 2D scene of the scene-file text `text`.
pub(crate) fn scene_2d(text: &str) -> Scene<f64, 2> {
    match parse_scene(text).expect("a valid scene") {
        LoadedScene::D2(s) => s,
        LoadedScene::D3(_) => panic!("a 2D scene"),
    }
}

/// Runs `scene` with every integrator for `steps` steps of `dt`, calling `check` after
/// each with the integrator, the step's number (from 1) and the engine. A step that
/// fails panics, naming both.
pub(crate) fn each_step<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    dt: f64,
    steps: u32,
    mut check: impl FnMut(Integrator, u32, &SteppedEngine<T, D>),
) where
    Const<D>: Space<T, D>,
{
    for integrator in Integrator::ALL {
        let mut sim = stepped(scene, integrator, dt);
        for k in 1..=steps {
            sim.advance_to(T::lit(dt * f64::from(k)), &mut ())
                .unwrap_or_else(|e| panic!("{integrator}, step {k}: {e}"));
            check(integrator, k, &sim);
        }
    }
}

/// How far (m) the farthest ball's surface lies beyond the scene's border (negative
/// when every ball is inside).
pub(crate) fn outside_border<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    states: &BallStates<T, D>,
) -> f64
where
    Const<D>: Space<T, D>,
{
    let border = scene.world.border.as_ref().expect("a border").border;
    let mut outside = f64::NEG_INFINITY;
    for (ball, x) in scene.balls.iter().zip(&states.pos) {
        for a in 0..D {
            let below = border.min()[a] - (x[a] - ball.radius);
            let above = x[a] + ball.radius - border.max()[a];
            outside = outside.max(below.max(above).to_f64());
        }
    }
    outside
}

/// The state of every ball now.
pub(crate) fn states<T: Real, const D: usize>(sim: &dyn Simulation<T, D>) -> BallStates<T, D>
where
    Const<D>: Space<T, D>,
{
    let mut s = BallStates::default();
    sim.states(&mut s);
    s
}

/// Records every collision and progress call.
#[derive(Default)]
pub(crate) struct Recorder<T: Real> {
    pub(crate) collisions: Vec<Collision<T>>,
    pub(crate) progress: Vec<T>,
}

impl<T: Real> Observer<T> for Recorder<T> {
    fn collision(&mut self, collision: &Collision<T>) {
        self.collisions.push(*collision);
    }
    fn progress(&mut self, t: T) {
        self.progress.push(t);
    }
}

/// Runs `sim` to `t` (backwards for an engine built to run backwards): the final states
/// and the collisions on the way.
pub(crate) fn advance<T: Real, const D: usize>(
    sim: &mut dyn Simulation<T, D>,
    t: T,
) -> (BallStates<T, D>, Vec<Collision<T>>)
where
    Const<D>: Space<T, D>,
{
    let mut rec = Recorder::default();
    sim.advance_to(t, &mut rec).expect("the run completes");
    (states(sim), rec.collisions)
}

/// The smallest surface gap between any two balls (minimum image in a periodic box),
/// by brute force over every pair.
pub(crate) fn min_gap<const D: usize>(scene: &Scene<f64, D>, st: &BallStates<f64, D>) -> f64
where
    Const<D>: Space<f64, D>,
{
    let periodic = scene.world.border.filter(|b| b.periodic).map(|b| b.border);
    let mut gap = f64::INFINITY;
    for i in 0..st.pos.len() {
        for j in i + 1..st.pos.len() {
            let d = st.pos[j] - st.pos[i];
            let d = periodic.map_or(d, |b| b.minimum_image(&d));
            gap = gap.min(d.norm() - scene.balls[i].radius - scene.balls[j].radius);
        }
    }
    gap
}

/// A sink that keeps what [`carom_sim::run::drive`] hands it: every sample and, when
/// asked for, every collision.
#[derive(Default)]
pub(crate) struct Keep<const D: usize>
where
    Const<D>: Space<f64, D>,
{
    pub(crate) samples: Vec<(f64, BallStates<f64, D>)>,
    pub(crate) collisions: Vec<Collision<f64>>,
}

impl<const D: usize> RunSink<f64, D> for Keep<D>
where
    Const<D>: Space<f64, D>,
{
    fn sample(&mut self, t: f64, states: &BallStates<f64, D>) {
        self.samples.push((t, states.clone()));
    }
    fn collision(&mut self, collision: &Collision<f64>) {
        self.collisions.push(*collision);
    }
}

/// Advances `sim` from where it is to `until` in `samples` equal parts and checks at
/// each that every ball is within `tolerance` (m) of `expected` and slower than
/// `tolerance` (m/s), and that the energy is the one it had at the start to `tolerance`
/// (relative): a resting stack does not move, sink, drift or gain energy. `what` names
/// the run in the messages.
#[allow(clippy::too_many_arguments)]
pub(crate) fn assert_stays_put<const D: usize>(
    sim: &mut SteppedEngine<f64, D>,
    scene: &Scene<f64, D>,
    expected: &[Vector<f64, D>],
    until: f64,
    samples: u32,
    tolerance: f64,
    observer: &mut dyn Observer<f64>,
    what: &str,
) where
    Const<D>: Space<f64, D>,
{
    let from = sim.time();
    let e0 = observe::energy(scene, &states(sim));
    for k in 1..=samples {
        let t = from + (until - from) * f64::from(k) / f64::from(samples);
        sim.advance_to(t, observer).unwrap();
        let now = states(sim);
        for (i, (p, q)) in now.pos.iter().zip(expected).enumerate() {
            assert!(
                (p - q).norm() < tolerance,
                "{what}, t = {t}: ball {i} at {p:?}, not {q:?} ({:.1e} m off)",
                (p - q).norm()
            );
            assert!(
                now.vel[i].norm() < tolerance,
                "{what}, t = {t}: ball {i} moves at {:.1e} m/s",
                now.vel[i].norm()
            );
        }
        let e = observe::energy(scene, &now);
        assert!(
            (e - e0).abs() <= tolerance * e0.abs(),
            "{what}, t = {t}: energy {e0} -> {e}"
        );
    }
}

/// How deep (m) the deepest overlap between two balls of `scene` is (negative when all
/// are apart; open space, no minimum images).
pub(crate) fn deepest_overlap<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    states: &BallStates<T, D>,
) -> f64
where
    Const<D>: Space<T, D>,
{
    let mut deepest = f64::NEG_INFINITY;
    for a in 0..scene.balls.len() {
        for b in a + 1..scene.balls.len() {
            let gap = (states.pos[b] - states.pos[a]).norm()
                - scene.balls[a].radius
                - scene.balls[b].radius;
            deepest = deepest.max(-gap.to_f64());
        }
    }
    deepest
}
