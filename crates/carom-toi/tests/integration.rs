//! The integration tests of carom-toi: times of impact against brute-force sampling and
//! parry as oracles, for balls, boxes, walls and clusters, the filtered predicates against
//! exact arithmetic, and reversibility.
//!
//! Each file of this directory is a module of one test binary, not a binary of its own: every
//! integration-test binary links the workspace and monomorphises its generic engines anew,
//! and one binary instead of many is what keeps the release build of `cargo test` (CI's
//! longest step) short. Run one file's tests with `cargo test --release -p <crate> --test
//! integration <file>::`. This root is not named `main.rs`: proptest keeps a file's failure
//! seeds beside it (`boxes.rs`, `boxes.proptest-regressions`) only while no `main.rs` or
//! `lib.rs` is found in a folder above the file.

mod ball_ball;
mod boxes;
mod clusters;
mod common;
mod filtered;
mod parry_oracle;
mod reversibility;
mod walls;
