//! carom's engines and the scene model they run.
//!
//! * [`scene`]: the typed scene (balls, boxes, border, world settings), its validation,
//!   and the TOML scene-file loader of the `carom run` contract (docs/scene-format.md).
//! * [`scenes`]: scenes defined once for tests, benches, examples and the report.
//! * [`plan`]: the planner — which engine, integrator and broad phase a scene needs.
//! * [`event`]: the exact event-driven engine ([`EventEngine`]).
//! * [`Simulation`]: what every engine offers; [`build`] constructs the planned one,
//!   under `--engine auto` an [`EventThenStepped`] that hands a run meeting sustained
//!   contact over to the stepped engine.
//! * [`run`] and [`observe`]: driving a run (sample times, the summary) and measuring it
//!   (energy, momentum, state hashes).
//! * [`stepped`]: the time-stepped engine (any integrator, continuous collision
//!   detection, parallel and deterministic).

mod build;
mod engine;
pub mod event;
mod handover;
pub mod observe;
mod pages;
pub mod plan;
mod prefetch;
pub mod run;
pub mod scene;
pub mod scenes;
pub mod stepped;

pub use build::build;
pub use engine::{
    Angular, BallStates, Collision, Counters, EngineKind, HandOver, Observer, SimError,
    SimErrorKind, Simulation,
};
pub use event::{EventEngine, PairSearch};
pub use handover::EventThenStepped;
