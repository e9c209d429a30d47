//! Section 2 of the report: stability on stiff and extreme cases.
//!
//! Every case runs a scene or an integrator where numerical methods break (stiff springs
//! at and beyond the stability limit, mass ratios to 1e6, speeds to 1e6 m/s, coordinates
//! at 1e7, grazing and touching contacts, coincident centres, restitution 0 and 1,
//! inelastic collapse, Zeno bouncing, `f32`, threads, bad input) and produces one
//! [`StabilityRow`] per engine or integrator: what the row asserts is in its `case`, the
//! measured figure and the bound it was held to in its `figure`, and whether the
//! measurement met the bound in `pass`. A case "beyond the limit" passes when the
//! instability the theory predicts is measured (the prediction holds), not when the run
//! stays bounded. rapier2d rows are for reference: they are held to the same bound as
//! carom's, and a failing rapier2d row is a finding about the peer, not about carom.
//!
//! * `springs`: the integrators on a stiff spring (carom-integrate directly).
//! * `collisions`: both engines (and rapier2d) on extreme collisions.
//! * `robustness`: `f32` against `f64`, 1 against 2 threads, bad input.

mod collisions;
mod robustness;
mod springs;

use crate::model::{Mode, StabilityRow};

/// How large the cases that have a size are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    /// Balls of the stepped-engine gas run on 1 and 2 threads (the engine steps on one
    /// thread below 2048 balls, so this must be above to measure anything).
    pub threads_gas: usize,
    /// Steps of that run.
    pub threads_steps: usize,
    /// Balls of the gas run in `f32` and `f64`.
    pub precision_gas: usize,
    /// Seconds of that run.
    pub precision_seconds: f64,
}

impl Sizes {
    /// The sizes of a report mode.
    pub fn for_mode(mode: Mode) -> Self {
        match mode {
            Mode::Quick => Self {
                threads_gas: 10_000,
                threads_steps: 60,
                precision_gas: 1000,
                precision_seconds: 5.0,
            },
            Mode::Full => Self {
                threads_gas: 100_000,
                threads_steps: 120,
                precision_gas: 10_000,
                precision_seconds: 10.0,
            },
        }
    }

    /// The smallest sizes that still measure every case: for tests of the report code.
    pub fn tiny() -> Self {
        Self {
            threads_gas: 2500,
            threads_steps: 5,
            precision_gas: 50,
            precision_seconds: 0.5,
        }
    }
}

/// Runs every case at the sizes of `mode`, reporting each case's name to `progress`.
pub fn run(mode: Mode, progress: &dyn Fn(&str)) -> Vec<StabilityRow> {
    run_with(&Sizes::for_mode(mode), progress)
}

/// Runs every case at `sizes`.
pub fn run_with(sizes: &Sizes, progress: &dyn Fn(&str)) -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    progress("stability: stiff springs");
    rows.extend(springs::rows());
    progress("stability: extreme collisions");
    rows.extend(collisions::rows());
    progress("stability: f32, threads, bad input");
    rows.extend(robustness::rows(sizes));
    rows
}

/// A row.
fn row(case: impl Into<String>, pass: bool, figure: impl Into<String>) -> StabilityRow {
    StabilityRow {
        case: case.into(),
        pass,
        figure: figure.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_carom_case_passes_at_tiny_sizes() {
        let rows = run_with(&Sizes::tiny(), &|_| {});
        assert!(rows.len() > 40, "{}", rows.len());
        for r in rows.iter().filter(|r| !r.case.contains("rapier2d")) {
            assert!(r.pass, "{}: {}", r.case, r.figure);
        }
        // Every case of the issue has a row.
        for needle in [
            "stiff spring",
            "mass ratio 1e6",
            "speed 1e6",
            "1e7 m from the origin",
            "grazing",
            "touching chain",
            "coincident centres",
            "restitution 0",
            "restitution 1",
            "inelastic collapse",
            "Zeno",
            "f32 against f64",
            "1 against 2 threads",
            "bad input",
        ] {
            assert!(rows.iter().any(|r| r.case.contains(needle)), "{needle}");
        }
    }
}
