//! carom's engines and the scene model they run.
//!
//! * [`scene`]: the typed scene (balls, boxes, border, world settings), its validation,
//!   and the TOML scene-file loader of the `carom run` contract (docs/scene-format.md).

mod engine;
pub mod event;
pub mod observe;
pub mod plan;
pub mod run;
pub mod scene;
pub mod scenes;

pub use engine::{
    Angular, BallStates, Collision, Counters, EngineKind, Observer, SimError, Simulation,
};
