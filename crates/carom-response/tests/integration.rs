//! The integration tests of carom-response: impulses against closed forms, stick clusters,
//! friction, the inelastic-collapse and resting guards, conservation properties and time
//! reversal.
//!
//! Each file of this directory is a module of one test binary, not a binary of its own: every
//! integration-test binary links the workspace and monomorphises its generic engines anew,
//! and one binary instead of many is what keeps the release build of `cargo test` (CI's
//! longest step) short. Run one file's tests with `cargo test --release -p <crate> --test
//! integration <file>::`. This root is not named `main.rs`: proptest keeps a file's failure
//! seeds beside it (`boxes.rs`, `boxes.proptest-regressions`) only while no `main.rs` or
//! `lib.rs` is found in a folder above the file.

mod closed_forms;
mod clusters;
mod common;
mod friction;
mod guards;
mod properties;
mod time_reversal;
