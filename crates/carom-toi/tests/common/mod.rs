//! Independent oracles shared by the integration tests: brute-force time sampling with
//! bisection, and the naive reference motions.
#![allow(dead_code, unreachable_pub)]

/// The first time in `(0, horizon]` the gap goes from positive to negative, found by
/// sampling `samples` equal steps and bisecting the first sign change (60 halvings).
/// Misses dips shorter than a step: use it as "a contact the query must not miss".
pub fn brute_first_descent(gap: impl Fn(f64) -> f64, horizon: f64, samples: usize) -> Option<f64> {
    let mut armed = gap(0.0) > 0.0;
    let mut prev = 0.0;
    for i in 1..=samples {
        let t = horizon * i as f64 / samples as f64;
        let g = gap(t);
        if armed && g < 0.0 {
            let (mut lo, mut hi) = (prev, t);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if gap(mid) < 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(lo);
        }
        armed |= g > 0.0;
        prev = t;
    }
    None
}

/// The smallest gap over `samples + 1` equally spaced times in `[a, b]`.
pub fn min_gap(gap: impl Fn(f64) -> f64, a: f64, b: f64, samples: usize) -> f64 {
    (0..=samples)
        .map(|i| gap(a + (b - a) * i as f64 / samples as f64))
        .fold(f64::INFINITY, f64::min)
}
