//! The workspace's example programs run headless as tests (Collision Lab, ping-pong, the
//! geometry tour), checked against physical facts.
//!
//! Each file of this directory is a module of one test binary, not a binary of its own: every
//! integration-test binary links the workspace and monomorphises its generic engines anew,
//! and one binary instead of many is what keeps the release build of `cargo test` (CI's
//! longest step) short. Run one file's tests with `cargo test --release -p <crate> --test
//! integration <file>::`. This root is not named `main.rs`: proptest keeps a file's failure
//! seeds beside it (`boxes.rs`, `boxes.proptest-regressions`) only while no `main.rs` or
//! `lib.rs` is found in a folder above the file.

// Each example is a program of its own and includes the shared picture code
// (examples/common/picture.rs) itself; here two of them are modules of one binary.
#![allow(clippy::duplicate_mod)]

mod collision_lab;
mod geometry_tour;
mod ping_pong;
