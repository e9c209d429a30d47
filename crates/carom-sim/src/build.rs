//! Building the engine a [`Plan`] chose: the one entry point `carom run` calls.

use carom_math::{Real, Space};
use carom_toi::Direction;
use nalgebra::Const;

use crate::engine::{EngineKind, Simulation};
use crate::event::EventEngine;
use crate::handover::EventThenStepped;
use crate::plan::Plan;
use crate::scene::{Scene, SceneError};
use crate::stepped::SteppedEngine;

/// The engine `plan` chose for `scene`, running in `direction`, behind the common
/// [`Simulation`] face: the event engine handing over to the stepped one where the plan
/// says so ([`Plan::hand_over`]).
///
/// # Errors
/// The scene's [`SceneError`] (every engine validates the scene), or an option the
/// engine cannot honour, naming the field or flag.
pub fn build<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    plan: &Plan,
    direction: Direction,
) -> Result<Box<dyn Simulation<T, D>>, SceneError>
where
    Const<D>: Space<T, D>,
{
    match plan.engine {
        EngineKind::Event if plan.hand_over => {
            Ok(Box::new(EventThenStepped::new(scene, plan, direction)?))
        }
        EngineKind::Event => Ok(Box::new(EventEngine::new(scene, plan, direction)?)),
        EngineKind::Stepped => Ok(Box::new(SteppedEngine::new(scene, plan, direction)?)),
    }
}
