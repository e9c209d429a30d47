//! Helpers shared by the stepped-engine tests: building an engine from a scene with
//! given options, collecting collisions, reading states.

#![allow(dead_code)] // each test file uses a part

use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::scene::Scene;
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Collision, Observer, Simulation};
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
