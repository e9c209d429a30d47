//! The integration tests of carom-report: cross-validation of carom's engines against
//! rapier2d and closed forms, the report's files, and the stepped gas's energy drift beside
//! rapier2d's.
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom-report --test integration <file>::`.

mod cross_validation;
mod report;
mod stepped_gas_vs_rapier;
