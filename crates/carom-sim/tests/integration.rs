//! The integration tests of carom-sim: the event-driven engine (scenes, clusters, pair
//! search), scene files, the hand-over between engines, and the stepped engine (bounces,
//! continuous collision, stacks, fuzzing, gas, integrators, planning, resting contact,
//! stick clusters, wedges).
//!
//! Each file of this directory is a module of one test binary, not a binary of its own: every
//! integration-test binary links the workspace and monomorphises its generic engines anew,
//! and one binary instead of many is what keeps the release build of `cargo test` (CI's
//! longest step) short. Run one file's tests with `cargo test --release -p <crate> --test
//! integration <file>::`. This root is not named `main.rs`: proptest keeps a file's failure
//! seeds beside it (`boxes.rs`, `boxes.proptest-regressions`) only while no `main.rs` or
//! `lib.rs` is found in a folder above the file.

mod common;
mod event_clusters;
mod event_engine;
mod event_pair_search;
mod hand_over;
mod scene_file;
mod stepped_bounce;
mod stepped_ccd;
mod stepped_cluster_stack;
mod stepped_fuzz;
mod stepped_gas;
mod stepped_integrators;
mod stepped_plan;
mod stepped_resting;
mod stepped_stick;
mod stepped_wedge;
