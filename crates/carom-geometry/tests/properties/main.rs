//! Property tests of carom-geometry: queries against parry2d/parry3d 0.31 as oracles
//! (carom in `f64` against parry's `f32`, and carom's own `f32` build), the named hard
//! cases (touching, nested, coincident, tiny, far from the origin), bounding-volume
//! properties, and fitting against brute force.

#[macro_use]
mod scene;
mod edge_cases;
mod fitting;
mod parry;
mod precision;
mod queries;
mod volumes;
