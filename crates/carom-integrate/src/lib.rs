//! Integrators and force fields.
//!
//! Work in progress (issue 3).
