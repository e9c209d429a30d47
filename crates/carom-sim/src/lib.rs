//! carom's engines and the scene model they run.
//!
//! * [`scene`]: the typed scene (balls, boxes, border, world settings), its validation,
//!   and the TOML scene-file loader of the `carom run` contract (docs/scene-format.md).

pub mod event;
pub mod scene;
pub mod scenes;
