//! carom's two engines as the report runs them: one [`Method`] names an engine (and the
//! stepped engine's integrator and step), [`build`] makes it for a scene through the
//! planner, as `carom run` would, and [`states`] reads every ball.

use core::fmt;

use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::plan::{EngineChoice, PlanError, RunOptions, plan};
use carom_sim::scene::{Scene, SceneError};
use carom_sim::{BallStates, Simulation};
use carom_toi::Direction;
use nalgebra::Const;

/// A carom engine configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The exact event-driven engine.
    Event,
    /// The time-stepped engine with this integrator and step (s).
    Stepped(Integrator, f64),
}

impl Method {
    /// The report's name of the method: `carom-event`, or `carom-stepped/<integrator>`.
    pub fn name(self) -> String {
        match self {
            Method::Event => "carom-event".to_owned(),
            Method::Stepped(integrator, _) => format!("carom-stepped/{integrator}"),
        }
    }

    /// The step, for the stepped engine.
    pub fn dt(self) -> Option<f64> {
        match self {
            Method::Event => None,
            Method::Stepped(_, dt) => Some(dt),
        }
    }
}

/// Why an engine could not be built for a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum BuildError {
    /// The planner refused the options for this scene.
    Plan(PlanError),
    /// The engine refused the scene.
    Scene(SceneError),
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::Plan(e) => write!(f, "{e}"),
            BuildError::Scene(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for BuildError {}

/// The engine `method` for `scene`, running forward.
///
/// # Errors
/// [`BuildError::Plan`] when the method cannot run the scene (the event engine on a
/// scene with drag, say), [`BuildError::Scene`] when the scene breaks a rule of the
/// contract (naming the field).
pub fn build<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    method: Method,
) -> Result<Box<dyn Simulation<T, D>>, BuildError>
where
    Const<D>: Space<T, D>,
{
    let options = match method {
        Method::Event => RunOptions {
            engine: EngineChoice::Event,
            ..RunOptions::default()
        },
        Method::Stepped(integrator, dt) => RunOptions {
            engine: EngineChoice::Stepped,
            integrator: Some(integrator),
            dt: Some(dt),
            ..RunOptions::default()
        },
    };
    let plan = plan(scene, &options).map_err(BuildError::Plan)?;
    carom_sim::build(scene, &plan, Direction::Forward).map_err(BuildError::Scene)
}

/// The state of every ball of `sim` now.
pub fn states<T: Real, const D: usize>(sim: &dyn Simulation<T, D>) -> BallStates<T, D>
where
    Const<D>: Space<T, D>,
{
    let mut out = BallStates::default();
    sim.states(&mut out);
    out
}
