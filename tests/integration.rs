//! The workspace's example programs run headless as tests (Collision Lab, ping-pong, the
//! geometry tour), checked against physical facts.
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom --test integration <file>::`.

// Each example is a program of its own and includes the shared code of
// examples/common/ (pictures, `main`) itself; here two of them are modules of one binary.
#![allow(clippy::duplicate_mod)]

mod collision_lab;
mod geometry_tour;
mod ping_pong;
