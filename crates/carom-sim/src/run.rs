//! Driving a simulation for `carom run`: sample times, collisions, and the summary.
//!
//! [`sample_times`] turns `--until`, `--at` and `--every` into the ordered list of
//! sample times; [`drive`] advances a [`Simulation`] through them, hands each sample
//! and (optionally) each collision to a [`RunSink`], and returns the [`Summary`] of the
//! contract: engine, pipeline, counts, energy and momentum before and after, wall time,
//! and the hand-over from the event to the stepped engine if the run had one.

use std::time::Instant;

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::engine::{
    BallStates, Collision, Counters, EngineKind, HandOver, Observer, SimError, Simulation,
};
use crate::observe::{energy, momentum};
use crate::plan::PlanError;
use crate::scene::Scene;

/// The sample times of a run to `until`: the `at` times, the multiples of `every`
/// (starting at 0), and `until` itself, sorted in the run's direction without
/// duplicates. Negative `until` runs backwards: `at` times are then `<= 0`.
///
/// # Errors
/// `--until` not finite, `--every` not positive, or an `--at` time outside `[0, until]`.
pub fn sample_times(until: f64, at: &[f64], every: Option<f64>) -> Result<Vec<f64>, PlanError> {
    if !until.is_finite() {
        return Err(PlanError(format!("--until: must be finite, got {until}")));
    }
    let sign = if until < 0.0 { -1.0 } else { 1.0 };
    let span = until.abs();
    let mut times = Vec::new();
    for &t in at {
        if !(t.is_finite() && t * sign >= 0.0 && t.abs() <= span) {
            return Err(PlanError(format!(
                "--at: {t} is not between 0 and --until {until}"
            )));
        }
        times.push(t.abs());
    }
    if let Some(step) = every {
        if !(step.is_finite() && step > 0.0) {
            return Err(PlanError(format!("--every: must be > 0, got {step}")));
        }
        let count = (span / step).floor();
        if count > 1e7 {
            return Err(PlanError(format!(
                "--every {step}: {count} samples is more than 10^7"
            )));
        }
        // k·step, not a running sum: no drift over many samples.
        times.extend(
            (0..=count as u64)
                .map(|k| k as f64 * step)
                .filter(|&t| t <= span),
        );
    }
    times.push(span);
    times.sort_by(f64::total_cmp);
    // Samples closer than rounding (k·step just below `until`) are one sample; the later
    // one (`until` itself where it is involved) is kept.
    let close = 1e-12 * span.max(f64::MIN_POSITIVE);
    let mut merged: Vec<f64> = Vec::with_capacity(times.len());
    for t in times {
        match merged.last_mut() {
            Some(last) if t - *last <= close => *last = t,
            _ => merged.push(t),
        }
    }
    let times = merged;
    Ok(times.into_iter().map(|t| t * sign).collect())
}

/// Where a run's output goes.
pub trait RunSink<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The state at a sample time.
    fn sample(&mut self, t: T, states: &BallStates<T, D>);
    /// A collision (only called when collisions are requested).
    fn collision(&mut self, collision: &Collision<T>);
    /// Progress: the simulation reached `t` of `until`.
    fn progress(&mut self, t: T, until: T) {
        let _ = (t, until);
    }
}

/// The summary line of the contract.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary<T: Real, const D: usize> {
    /// The engine that ran (at the end of the run).
    pub engine: EngineKind,
    /// When and why the run went over from the event engine to the stepped one, if it
    /// did ([`Simulation::hand_over`]).
    pub hand_over: Option<HandOver<T>>,
    /// The components it used.
    pub pipeline: Vec<String>,
    /// Collision counts.
    pub counters: Counters,
    /// Kinetic plus potential energy at the start.
    pub energy_initial: T,
    /// ... and at the end.
    pub energy_final: T,
    /// Total momentum at the start.
    pub momentum_initial: Vector<T, D>,
    /// ... and at the end.
    pub momentum_final: Vector<T, D>,
    /// Wall-clock seconds spent advancing the simulation.
    pub wall_s: f64,
}

struct Forward<'a, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    sink: &'a mut dyn RunSink<T, D>,
    events: bool,
    until: T,
}

impl<T: Real, const D: usize> Observer<T> for Forward<'_, T, D>
where
    Const<D>: Space<T, D>,
{
    fn collision(&mut self, collision: &Collision<T>) {
        if self.events {
            self.sink.collision(collision);
        }
    }
    fn progress(&mut self, t: T) {
        self.sink.progress(t, self.until);
    }
}

/// Runs `sim` (built from `scene`) through `times`, sampling at each.
///
/// # Errors
/// The engine's [`SimError`]; samples before the failure have been written.
pub fn drive<T: Real, const D: usize>(
    sim: &mut dyn Simulation<T, D>,
    scene: &Scene<T, D>,
    times: &[T],
    sink: &mut dyn RunSink<T, D>,
    events: bool,
) -> Result<Summary<T, D>, SimError>
where
    Const<D>: Space<T, D>,
{
    let mut states = BallStates::default();
    sim.states(&mut states);
    let (energy_initial, momentum_initial) = (energy(scene, &states), momentum(scene, &states));
    let until = times.last().copied().unwrap_or_else(T::zero);
    let mut observer = Forward {
        sink,
        events,
        until,
    };
    let mut wall = 0.0;
    for &t in times {
        let start = Instant::now();
        sim.advance_to(t, &mut observer)?;
        wall += start.elapsed().as_secs_f64();
        sim.states(&mut states);
        observer.sink.sample(t, &states);
        observer.sink.progress(t, until);
    }
    Ok(Summary {
        engine: sim.kind(),
        hand_over: sim.hand_over().cloned(),
        pipeline: sim.pipeline(),
        counters: sim.counters(),
        energy_initial,
        energy_final: energy(scene, &states),
        momentum_initial,
        momentum_final: momentum(scene, &states),
        wall_s: wall,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_times_merge_at_every_and_until_in_the_run_direction() {
        assert_eq!(sample_times(1.5, &[], None).unwrap(), vec![1.5]);
        assert_eq!(
            sample_times(1.0, &[0.25, 1.0], Some(0.5)).unwrap(),
            vec![0.0, 0.25, 0.5, 1.0]
        );
        assert_eq!(
            sample_times(-1.0, &[-0.25], Some(0.5)).unwrap(),
            vec![0.0, -0.25, -0.5, -1.0]
        );
        // 0.3 / 0.1 rounds below 3: the last multiple is 0.2, then `until` itself.
        assert_eq!(
            sample_times(0.3, &[], Some(0.1)).unwrap(),
            vec![0.0, 0.1, 0.2, 0.3]
        );
        // 3 · 0.1 = 0.30000000000000004 is within rounding of 0.3 + 1e-17: one sample.
        assert_eq!(
            sample_times(0.30000000000000004, &[], Some(0.1)).unwrap(),
            vec![0.0, 0.1, 0.2, 0.30000000000000004]
        );
    }

    #[test]
    fn bad_sample_requests_name_the_flag() {
        assert!(
            sample_times(f64::NAN, &[], None)
                .unwrap_err()
                .0
                .starts_with("--until")
        );
        assert!(
            sample_times(1.0, &[2.0], None)
                .unwrap_err()
                .0
                .starts_with("--at")
        );
        assert!(
            sample_times(-1.0, &[0.5], None)
                .unwrap_err()
                .0
                .starts_with("--at")
        );
        assert!(
            sample_times(1.0, &[], Some(0.0))
                .unwrap_err()
                .0
                .starts_with("--every")
        );
    }
}
