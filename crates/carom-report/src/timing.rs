//! Wall-clock timing for the report: medians of repeated calls, measured in this process.
//!
//! Every figure of the performance sections is the median of several samples, so a
//! sample slowed down by another process on a shared machine moves it little. Calls much
//! shorter than the clock's resolution are timed in batches (a sample is the batch's
//! time divided by its size).

use std::time::{Duration, Instant};

/// How long to sample one case: at least `min_samples` samples, and more until `budget`
/// has passed (at most 200).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// The fewest samples taken, whatever the budget.
    pub min_samples: usize,
    /// Keep sampling until this much time has passed.
    pub budget: Duration,
}

/// The largest number of samples of one case.
const MAX_SAMPLES: usize = 200;

/// The shortest sample: batches of calls last at least this long.
const MIN_SAMPLE: Duration = Duration::from_millis(5);

/// The median of `samples` (the upper median for an even count); zero (the default)
/// when empty. Durations, or ratios of them (`f64`; no sample may be NaN).
pub fn median<T: Copy + Default + PartialOrd>(samples: &mut [T]) -> T {
    if samples.is_empty() {
        return T::default();
    }
    samples.sort_unstable_by(|a, b| a.partial_cmp(b).unwrap_or(core::cmp::Ordering::Equal));
    samples[samples.len() / 2]
}

/// The median duration of one call of `f` (given the call's index), after two warm-up
/// calls, sampled as `sampling` says; short calls are batched (module docs).
pub fn median_per_call(sampling: Sampling, mut f: impl FnMut(usize)) -> Duration {
    let warm = Instant::now();
    f(0);
    f(1);
    let per_call = warm.elapsed() / 2;
    let batch = (MIN_SAMPLE.as_nanos() / per_call.as_nanos().max(1)).clamp(1, 100_000) as usize;
    let mut samples = Vec::new();
    let start = Instant::now();
    let mut k = 2;
    while samples.len() < sampling.min_samples
        || (start.elapsed() < sampling.budget && samples.len() < MAX_SAMPLES)
    {
        let t = Instant::now();
        for _ in 0..batch {
            f(k);
            k += 1;
        }
        samples.push(t.elapsed() / batch as u32);
    }
    median(&mut samples)
}

/// Runs `f` and returns its result with the wall-clock time it took.
pub fn timed<R>(f: impl FnOnce() -> R) -> (R, Duration) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_is_the_middle_sample_whatever_the_order() {
        let ms = Duration::from_millis;
        assert_eq!(median(&mut [ms(5), ms(1), ms(9)]), ms(5));
        assert_eq!(median(&mut [ms(4), ms(1), ms(9), ms(2)]), ms(4));
        assert_eq!(median::<Duration>(&mut []), Duration::ZERO);
        assert_eq!(median(&mut [1.5, 0.5, 2.5, 1.0]), 1.5);
    }

    #[test]
    fn per_call_sampling_takes_at_least_the_minimum_and_counts_calls() {
        let mut calls = Vec::new();
        let sampling = Sampling {
            min_samples: 3,
            budget: Duration::ZERO,
        };
        let d = median_per_call(sampling, |k| {
            calls.push(k);
            std::thread::sleep(Duration::from_millis(6));
        });
        // Two warm-up calls and three unbatched samples (each call exceeds MIN_SAMPLE).
        assert_eq!(calls, [0, 1, 2, 3, 4]);
        assert!(d >= Duration::from_millis(6), "{d:?}");
    }
}
