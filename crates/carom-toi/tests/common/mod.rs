//! Independent oracles shared by the integration tests: brute-force time sampling with
//! bisection, and the naive reference motions.

/// The first time in `(0, horizon]` the gap goes from positive to negative, found by
/// sampling `samples` equal steps and bisecting the first sign change (60 halvings).
/// Misses dips shorter than a step: use it as "a contact the query must not miss".
pub(crate) fn brute_first_descent(
    gap: impl Fn(f64) -> f64,
    horizon: f64,
    samples: usize,
) -> Option<f64> {
    let mut armed = gap(0.0) > 0.0;
    let mut prev = 0.0;
    for i in 1..=samples {
        let t = horizon * i as f64 / samples as f64;
        let g = gap(t);
        if armed && g < 0.0 {
            return Some(last_apart(&gap, prev, t));
        }
        armed |= g > 0.0;
        prev = t;
    }
    None
}

/// The last time in `[lo, hi]` the gap is not negative, given `gap(lo) >= 0 > gap(hi)`
/// (60 halvings).
fn last_apart(gap: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if gap(mid) < 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// The first contact in `(0, horizon]` by carom-toi's definition, sampled as
/// [`brute_first_descent`]: the first descent through zero after the gap has been
/// positive, or, for a gap never positive since 0, the first time it stops rising and
/// falls (a pair overlapping and receding that turns back before it is apart), refined
/// by golden-section search for the maximum. Returns the time and `true` for a turn.
pub(crate) fn brute_first_contact(
    gap: impl Fn(f64) -> f64,
    horizon: f64,
    samples: usize,
) -> Option<(f64, bool)> {
    let mut armed = gap(0.0) > 0.0;
    let (mut before, mut prev, mut prev_gap) = (0.0, 0.0, gap(0.0));
    for i in 1..=samples {
        let t = horizon * i as f64 / samples as f64;
        let g = gap(t);
        if armed && g < 0.0 {
            return Some((last_apart(&gap, prev, t), false));
        }
        if !armed && g <= 0.0 && g < prev_gap - 1e-12 {
            // The maximum lies in [before, t].
            let (mut lo, mut hi) = (before, t);
            let phi = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..100 {
                let (a, b) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
                if gap(a) < gap(b) {
                    lo = a;
                } else {
                    hi = b;
                }
            }
            return Some((0.5 * (lo + hi), true));
        }
        armed |= g > 0.0;
        (before, prev, prev_gap) = (prev, t, g);
    }
    None
}

/// Whether `t` is a turn of a gap never positive before it: no sample of `[0, t]` is
/// above `1e-9`, and none is above the gap at `t` by more than `1e-9`.
pub(crate) fn is_turn(gap: impl Fn(f64) -> f64, t: f64) -> bool {
    let highest = (0..=2000)
        .map(|i| gap(t * f64::from(i) / 2000.0))
        .fold(f64::NEG_INFINITY, f64::max);
    highest <= 1e-9 && gap(t) >= highest - 1e-9
}

/// The smallest gap over `samples + 1` equally spaced times in `[a, b]`.
pub(crate) fn min_gap(gap: impl Fn(f64) -> f64, a: f64, b: f64, samples: usize) -> f64 {
    (0..=samples)
        .map(|i| gap(a + (b - a) * i as f64 / samples as f64))
        .fold(f64::INFINITY, f64::min)
}
