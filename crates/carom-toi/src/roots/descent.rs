//! The first descent of a continuous gap through zero on an interval split into
//! monotone pieces.
//!
//! Definition. Given a continuous gap `g` on `[lo, hi]` and `armed` (whether `g` was
//! positive somewhere before `lo`), the first descent is
//!
//! ```text
//! t* = inf { t ∈ [lo, hi] : g(t) < 0 and g > 0 somewhere on [start, t) }
//! ```
//!
//! the first moment the bodies start to interpenetrate after having been apart. It skips
//! exact tangencies (`g` touches 0 and rises again: a graze, not a collision) and pairs
//! that start overlapping until they have separated, unless such a pair stops
//! separating first (an acceleration pulls it back while it still overlaps by a
//! rounding): then the descent is where its gap turns and starts to fall,
//!
//! ```text
//! t* = inf { t ∈ [lo, hi] : g ≤ 0 on [start, t] and g falls just after t }
//! ```
//!
//! for otherwise the pair would sink through each other unseen.
//!
//! Method. Between consecutive critical points `g` is monotone, so on a piece
//! `[x₀, x₁]` its extremes are the end values. Walking the pieces in order, the first
//! piece that ends negative while armed contains the descent; a bracketed solver (ITP)
//! narrows it, and the bracket end on the positive side is returned (the last time the
//! bodies are provably apart, to machine precision). A piece that ends positive arms.

use carom_math::Real;

use super::itp;

/// The outcome of searching one interval for the first descent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Descent<T> {
    /// The gap first goes negative at this time.
    At(T),
    /// No descent in the interval; `armed` says whether the gap has been positive by its
    /// end (carry it into the next interval).
    Clear {
        /// The gap has been positive at or before the end of the interval.
        armed: bool,
    },
}

/// The first descent of `gap` on `[lo, hi]` (finite), where `critical` holds the sorted
/// points of `(lo, hi)` between which `gap` is monotone. `None` if `gap` returns NaN.
pub(crate) fn first_descent_monotone<T: Real>(
    mut gap: impl FnMut(T) -> T,
    lo: T,
    hi: T,
    critical: &[T],
    mut armed: bool,
) -> Option<Descent<T>> {
    let mut x0 = lo;
    let mut g0 = gap(lo);
    armed |= g0 > T::zero();
    for &x1 in critical.iter().chain(core::iter::once(&hi)) {
        if x1 <= x0 {
            continue;
        }
        let g1 = gap(x1);
        if super::is_nan(g0) || super::is_nan(g1) {
            return None;
        }
        if !armed && g0 <= T::zero() && g1 < g0 {
            // Never apart, and closing again: it turned back before it separated (see
            // `Quadratic::first_descent`); the contact is where it turned.
            return Some(Descent::At(x0));
        }
        if armed && g1 < T::zero() {
            if g0 <= T::zero() {
                // Already at or below zero at the start of an armed piece: the previous
                // piece ended at a zero (or rounding put the crossing just before x0).
                return Some(Descent::At(x0));
            }
            let (apart, _) = itp(&mut gap, x0, x1, g0, g1, T::zero());
            return Some(Descent::At(apart));
        }
        armed |= g1 > T::zero();
        x0 = x1;
        g0 = g1;
    }
    Some(Descent::Clear { armed })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_of_several_descents() {
        // cos has critical points at multiples of π; descents at π/2 and 5π/2.
        let pi = core::f64::consts::PI;
        let crit = [pi, 2.0 * pi];
        let d = first_descent_monotone(f64::cos, 0.0, 3.0 * pi, &crit, false).unwrap();
        assert!(matches!(d, Descent::At(t) if (t - pi / 2.0).abs() < 1e-15));
        // Starting in the negative half wave: must rise first, then descend at 5π/2.
        let crit = [2.0 * pi];
        let d = first_descent_monotone(f64::cos, 3.0, 3.0 * pi, &crit, false).unwrap();
        assert!(matches!(d, Descent::At(t) if (t - 2.5 * pi).abs() < 1e-14));
    }

    #[test]
    fn a_tangency_is_not_a_descent() {
        let g = |t: f64| (t - 1.0) * (t - 1.0);
        let d = first_descent_monotone(g, 0.0, 2.0, &[1.0], true).unwrap();
        assert_eq!(d, Descent::Clear { armed: true });
    }

    #[test]
    fn nan_is_reported() {
        assert!(first_descent_monotone(|_| f64::NAN, 0.0, 1.0, &[], true).is_none());
    }
}
