//! The integration tests of carom-report: cross-validation of carom's engines against
//! rapier2d and closed forms, the report's files, and the stepped gas's energy drift beside
//! rapier2d's.
//!
//! Each file of this directory is a module of one test binary, not a binary of its own: every
//! integration-test binary links the workspace and monomorphises its generic engines anew,
//! and one binary instead of many is what keeps the release build of `cargo test` (CI's
//! longest step) short. Run one file's tests with `cargo test --release -p <crate> --test
//! integration <file>::`. This root is not named `main.rs`: proptest keeps a file's failure
//! seeds beside it (`boxes.rs`, `boxes.proptest-regressions`) only while no `main.rs` or
//! `lib.rs` is found in a folder above the file.

mod cross_validation;
mod report;
mod stepped_gas_vs_rapier;
