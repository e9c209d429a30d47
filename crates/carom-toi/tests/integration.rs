//! The integration tests of carom-toi: times of impact against brute-force sampling and
//! parry as oracles, for balls, boxes, walls and clusters, the filtered predicates against
//! exact arithmetic, and reversibility.
//!
//! The files beside this one are its modules: one test binary, not one per file (why, and
//! why this root is not `main.rs`: ARCHITECTURE.md, "Decisions and why"). One file's tests:
//! `cargo test --release -p carom-toi --test integration <file>::`.

mod ball_ball;
mod boxes;
mod clusters;
mod common;
mod filtered;
mod parry_oracle;
mod reversibility;
mod walls;
