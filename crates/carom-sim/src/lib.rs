//! carom's engines and the scene model they run.
//!
//! * [`scene`]: the typed scene (balls, boxes, border, world settings), its validation,
//!   and the TOML scene-file loader of the `carom run` contract (docs/scene-format.md).
//! * [`plan`]: which engine and which components a scene needs; [`build`] constructs the
//!   chosen engine behind the common [`Simulation`] face.
//! * [`stepped`]: the time-stepped engine (any integrator, continuous collision
//!   detection, parallel and deterministic).

mod build;
mod engine;
pub mod event;
pub mod observe;
pub mod plan;
pub mod run;
pub mod scene;
pub mod scenes;
pub mod stepped;

pub use build::build;
pub use engine::{
    Angular, BallStates, Collision, Counters, EngineKind, Observer, SimError, Simulation,
};
