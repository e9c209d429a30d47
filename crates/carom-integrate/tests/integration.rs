//! The integration tests of carom-integrate: every integrator against closed forms
//! (projectile, drag, oscillator, Kepler orbit, springs), error signs and fitted orders,
//! and bodies stepped through the field and spring code.
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom-integrate --test integration <file>::`.

mod common;
mod exact;
mod fields;
mod kepler;
mod oscillator;
mod projectile;
mod springs;
mod stepping;
