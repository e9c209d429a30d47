//! The ITP bracketed root finder (Oliveira and Takahashi, "An enhancement of the
//! bisection method average performance preserving minmax optimality", ACM TOMS 47, 2021).
//!
//! Given `f(a)` and `f(b)` of opposite signs, each step interpolates (regula falsi),
//! truncates the interpolant towards the midpoint by `κ₁ (b − a)²`, and projects it into
//! a shrinking window around the midpoint so that the bracket never shrinks slower than
//! bisection would after one extra step: at most `⌈log₂((b − a)/(2ε))⌉ + 1` evaluations
//! reach a bracket of width `2ε` (minmax optimality), and on smooth functions the
//! interpolation step converges superlinearly.
//!
//! Here `ε` is `max(tol, 4 ε_mach |b|)/2`. After the ITP phase, plain bisection continues
//! until the bracket is within `max(tol, 4 ε_mach max(|a|, |b|))`, which matters only when
//! the root is far smaller than the bracket's end. The bracket is always kept: the
//! answer is the final bracket, not one point, so callers pick the side they need (the
//! side where the bodies are still apart).

use carom_math::Real;

/// The most evaluations one call makes, whatever the input: ITP reaches `4 ε_mach |b|` in
/// at most 60 (f64), and bisection from there to a root `2^k` times smaller takes `k` more.
const MAX_EVALUATIONS: i32 = 400;

/// Narrows `[a, b]`, where `fa = f(a)` and `fb = f(b)` are non-zero with opposite signs,
/// around a sign change of `f`. Returns `(x_a, x_b)`: the final bracket, `x_a` on the side
/// with the sign of `fa`, `x_b` on the side of `fb` (equal if `f` hit zero exactly).
/// A NaN value of `f` ends the search with the bracket reached so far.
pub(crate) fn itp<T: Real>(mut f: impl FnMut(T) -> T, a: T, b: T, fa: T, fb: T, tol: T) -> (T, T) {
    debug_assert!(a < b && fa * fb < T::zero());
    // Orient so that g = s·f has g(lo) < 0 < g(hi); lo stays on the side of `a`.
    let s = if fa > T::zero() { -T::one() } else { T::one() };
    let (mut lo, mut hi, mut glo, mut ghi) = (a, b, s * fa, s * fb);
    let four_eps = T::lit(4.0) * T::EPSILON;
    let goal = |lo: T, hi: T| tol.max(four_eps * lo.abs().max(hi.abs()));
    let half_width = goal(lo, hi) * T::lit(0.5);
    let n_max = ((hi - lo) / (T::lit(2.0) * half_width))
        .log2()
        .ceil()
        .max(T::zero())
        .to_f64() as i32
        + 1;
    let kappa1 = T::lit(0.2) / (hi - lo);
    for j in 0..MAX_EVALUATIONS {
        let width = hi - lo;
        if width <= goal(lo, hi) {
            break;
        }
        let mid = lo + width * T::lit(0.5);
        if mid <= lo || mid >= hi {
            break; // no representable point strictly inside
        }
        let x = if j < n_max {
            // Interpolation, truncation, projection.
            let falsi = (ghi * lo - glo * hi) / (ghi - glo);
            let sigma = (mid - falsi).copysign_one();
            let delta = kappa1 * width * width;
            let truncated = if delta <= (mid - falsi).abs() {
                falsi + sigma * delta
            } else {
                mid
            };
            let radius = half_width * T::lit(2.0).powi(n_max - j) - width * T::lit(0.5);
            let projected = if (truncated - mid).abs() <= radius {
                truncated
            } else {
                mid - sigma * radius
            };
            if projected > lo && projected < hi {
                projected
            } else {
                mid
            }
        } else {
            mid
        };
        let gx = s * f(x);
        if super::is_nan(gx) {
            break;
        }
        if gx > T::zero() {
            hi = x;
            ghi = gx;
        } else if gx < T::zero() {
            lo = x;
            glo = gx;
        } else {
            return (x, x);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_simple_roots_to_machine_precision_in_few_steps() {
        let mut calls = 0;
        let (a, b) = itp(
            |x: f64| {
                calls += 1;
                x * x - 2.0
            },
            0.0,
            2.0,
            -2.0,
            2.0,
            0.0,
        );
        assert!(a <= 2f64.sqrt() && 2f64.sqrt() <= b || (a - 2f64.sqrt()).abs() < 1e-15);
        assert!(b - a <= 4.0 * f64::EPSILON * 2.0);
        assert!(calls < 15, "{calls} evaluations");
    }

    #[test]
    fn keeps_the_bracket_orientation() {
        // Decreasing function: positive at a.
        let (a, b) = itp(|x: f64| 1.0 - x, 0.0, 3.0, 1.0, -2.0, 0.0);
        assert!(1.0 - a >= 0.0 && 1.0 - b <= 0.0);
        assert!((a - 1.0).abs() < 1e-15);
    }

    #[test]
    fn worst_case_is_bisection_plus_one_on_a_step_function() {
        // A discontinuous sign change defeats interpolation; ITP must still bisect.
        let mut calls = 0;
        let (a, b) = itp(
            |x: f64| {
                calls += 1;
                if x < 0.3 { -1.0 } else { 1.0 }
            },
            0.0,
            1.0,
            -1.0,
            1.0,
            1e-9,
        );
        assert!(a < 0.3 && 0.3 <= b && b - a <= 1e-9);
        assert!(calls <= 31, "{calls} evaluations");
    }

    #[test]
    fn small_roots_in_wide_brackets_are_found_relatively() {
        let root = 1e-20_f64;
        let (a, b) = itp(|x| x - root, 0.0, 1e10, -root, 1e10, 0.0);
        assert!((a - root).abs() <= 1e-35 && (b - root).abs() <= 1e-35);
    }
}
