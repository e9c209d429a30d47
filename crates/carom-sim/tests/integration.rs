//! The integration tests of carom-sim: the event-driven engine (scenes, clusters, pair
//! search), scene files, the hand-over between engines, and the stepped engine (bounces,
//! continuous collision, stacks, fuzzing, gas, integrators, planning, resting contact,
//! stick clusters, wedges).
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom-sim --test integration <file>::`.

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
