//! Building the engine a [`Plan`] chose.

use carom_math::{Real, Space};
use carom_toi::Direction;
use nalgebra::Const;

use crate::engine::{EngineKind, Simulation};
use crate::event::EventEngine;
use crate::plan::Plan;
use crate::scene::{Scene, SceneError};

/// The engine of `plan` for `scene`, running in `direction`.
///
/// # Errors
/// The scene breaks a rule of the contract or cannot run on the chosen engine.
pub fn build<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    plan: &Plan,
    direction: Direction,
) -> Result<Box<dyn Simulation<T, D>>, SceneError>
where
    Const<D>: Space<T, D>,
{
    match plan.engine {
        EngineKind::Event => Ok(Box::new(EventEngine::new(scene, plan, direction)?)),
        EngineKind::Stepped => Err(SceneError::new(
            "",
            "the time-stepped engine is not part of this build yet",
        )),
    }
}
