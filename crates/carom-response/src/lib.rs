//! Collision response: what a collision does to the bodies.
//!
//! Work in progress (issue 3).
