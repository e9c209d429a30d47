//! The integration tests of carom-response: impulses against closed forms, stick clusters,
//! friction, the inelastic-collapse and resting guards, conservation properties and time
//! reversal.
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom-response --test integration <file>::`.

mod closed_forms;
mod clusters;
mod common;
mod friction;
mod guards;
mod properties;
mod time_reversal;
