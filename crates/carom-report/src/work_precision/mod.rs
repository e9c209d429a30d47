//! Section 1 of the report: error against run time (work-precision diagrams).
//!
//! Each problem has a closed-form reference ([`crate::reference`]) or a conserved
//! quantity, and every method runs it at several steps: one row per method and step with
//! the error at the final time and the minimum wall-clock seconds of several runs (only
//! the stepping is timed; building the world is not). The problems:
//!
//! | problem | what is integrated | error | methods |
//! |---|---|---|---|
//! | `projectile-drag` | one ball, gravity + linear drag, 2 s | distance to the closed form (m) | stepped engine × integrator, rapier2d (linear damping); the event engine refuses drag (no exact time of impact) |
//! | `bouncing-ball` | a ball dropped from 1 m, restitution 0.8, 2 s (3 bounces) | distance to the closed form (m) | stepped engine × integrator, event engine, rapier2d |
//! | `stiff-spring` | one ball on a damped spring to a fixed point, `ω = 100 rad/s`, `ζ = 0.02`, 1 s | distance to the closed form (m) | carom-integrate × integrator (the engines have no springs; the exact integrator has no closed form for springs), rapier2d's spring joint |
//! | `two-ball` | an oblique collision, masses 1:3, restitution 0.9, 2 s | largest distance to the closed form (m) | stepped engine × integrator, event engine, rapier2d |
//! | `elastic-gas` | an elastic gas in a box (area fraction 0.3) | relative energy error | stepped engine × integrator, event engine, rapier2d |
//!
//! Without forces (two balls, the gas) every integrator flies the same straight lines, so
//! their errors coincide and only their costs differ. [`plot`] draws one log-log SVG per
//! problem.

mod plot;
mod problems;

use std::time::Instant;

pub use plot::{Format, plot, plot_as};

use crate::model::{Mode, WorkPrecisionRow};

/// The problems, in report order.
pub const PROBLEMS: [&str; 5] = [
    "projectile-drag",
    "bouncing-ball",
    "stiff-spring",
    "two-ball",
    "elastic-gas",
];

/// How much each problem measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Sizes {
    /// The steps of the engines' problems (s), coarse to fine.
    pub steps: Vec<f64>,
    /// The steps of the stiff spring (s), coarse to fine.
    pub spring_steps: Vec<f64>,
    /// Balls of the elastic gas.
    pub gas_balls: usize,
    /// Seconds the gas runs.
    pub gas_seconds: f64,
    /// Timed runs per point (the minimum is kept).
    pub repeats: usize,
}

impl Sizes {
    /// The sizes of a report mode.
    pub fn for_mode(mode: Mode) -> Self {
        let halvings = |first: f64, count: i32| (0..count).map(|k| first / 2f64.powi(k)).collect();
        match mode {
            Mode::Quick => Self {
                steps: halvings(1.0 / 30.0, 8),
                spring_steps: halvings(1e-2, 9),
                gas_balls: 300,
                gas_seconds: 2.0,
                repeats: 3,
            },
            Mode::Full => Self {
                steps: halvings(1.0 / 30.0, 9),
                spring_steps: halvings(1e-2, 12),
                gas_balls: 1000,
                gas_seconds: 5.0,
                repeats: 5,
            },
        }
    }

    /// The smallest sizes that still draw a line per method: for tests of the report code.
    pub fn tiny() -> Self {
        Self {
            steps: vec![1.0 / 30.0, 1.0 / 60.0],
            spring_steps: vec![1e-2, 5e-3],
            gas_balls: 30,
            gas_seconds: 0.5,
            repeats: 1,
        }
    }
}

/// Runs every problem at the sizes of `mode`, reporting each problem to `progress`.
pub fn run(mode: Mode, progress: &dyn Fn(&str)) -> Vec<WorkPrecisionRow> {
    run_with(&Sizes::for_mode(mode), progress)
}

/// Runs every problem at `sizes`.
pub fn run_with(sizes: &Sizes, progress: &dyn Fn(&str)) -> Vec<WorkPrecisionRow> {
    let mut rows = Vec::new();
    for problem in PROBLEMS {
        progress(&format!("work-precision: {problem}"));
        rows.extend(problems::run(problem, sizes));
    }
    rows
}

/// One measured point: the error and the fastest of `repeats` timed runs. `once` does a
/// whole run and returns its error and the seconds its timed part took; runs whose error
/// is not finite (an unstable scheme) give no point.
fn measure(
    problem: &str,
    method: &str,
    dt: Option<f64>,
    repeats: usize,
    mut once: impl FnMut() -> Option<(f64, f64)>,
) -> Option<WorkPrecisionRow> {
    let mut best: Option<(f64, f64)> = None;
    for _ in 0..repeats.max(1) {
        let (error, seconds) = once()?;
        if !error.is_finite() {
            return None;
        }
        best = Some(match best {
            Some((e, s)) => (e, s.min(seconds)),
            None => (error, seconds),
        });
    }
    best.map(|(error, seconds)| WorkPrecisionRow {
        problem: problem.to_owned(),
        method: method.to_owned(),
        dt,
        error,
        seconds,
    })
}

/// Seconds `f` takes, and what it returns.
fn timed<R>(f: impl FnOnce() -> R) -> (R, f64) {
    let start = Instant::now();
    let r = f();
    (r, start.elapsed().as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiny_runs_give_every_problem_its_methods_and_errors_shrink_with_the_step() {
        let rows = run_with(&Sizes::tiny(), &|_| {});
        for problem in PROBLEMS {
            let of: Vec<_> = rows.iter().filter(|r| r.problem == problem).collect();
            assert!(!of.is_empty(), "{problem}");
            assert!(of.iter().all(|r| r.error >= 0.0 && r.seconds > 0.0));
            #[cfg(feature = "rapier")]
            assert!(
                of.iter().any(|r| r.method.starts_with("rapier2d")),
                "{problem}"
            );
        }
        // RK4 on the drag problem: fourth order, the error falls ~16× per halving.
        let rk4: Vec<f64> = rows
            .iter()
            .filter(|r| r.problem == "projectile-drag" && r.method == "carom-stepped/rk4")
            .map(|r| r.error)
            .collect();
        assert_eq!(rk4.len(), 2);
        assert!(rk4[0] / rk4[1] > 10.0, "{rk4:?}");
        // The event engine is one point, exact to rounding, on the two-ball problem.
        let event: Vec<_> = rows
            .iter()
            .filter(|r| r.problem == "two-ball" && r.method == "carom-event")
            .collect();
        assert_eq!(event.len(), 1);
        assert!(event[0].error < 1e-12 && event[0].dt.is_none());
    }
}
