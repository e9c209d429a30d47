//! Quadratic gap functions `f(t) = a t² + 2 h t + c` and their unique descending root.
//!
//! Derivation. The real roots are `t = (−h ± √Δ)/a` with `Δ = h² − a c`, and
//! `f'(t) = 2(a t + h) = ±2√Δ` there: exactly one root is *descending* (`f' < 0`, the gap
//! closing), `t↓ = (−h − √Δ)/a`, whatever the sign of `a`. Multiplying by
//! `(−h + √Δ)/(−h + √Δ)` and using `h² − Δ = a c` gives the second form
//!
//! ```text
//! t↓ = c / (−h + √Δ)        (used when h < 0: both terms of the denominator positive)
//! t↓ = (−h − √Δ) / a        (used when h ≥ 0: both terms of the numerator non-positive)
//! ```
//!
//! so neither form subtracts nearly equal numbers (no cancellation), and `a = 0` (a
//! linear gap `2 h t + c`) is the first form with `√Δ = |h|`. `Δ` itself is computed to
//! within `3u` (see [`discriminant`]), or supplied by the caller when a better evaluation
//! is known (two balls: `LinearSphere`). `Δ <= 0` means a tangency or no real root: no
//! descending crossing.
//!
//! A quadratic has at most one descending root, so its first descent on an interval is
//! that root if it lies inside.

use carom_math::Real;

use super::Descent;
use super::exact::{two_product, two_square, two_sum};

/// `h² − a c` to within `3u` (`u` the unit roundoff), without the libm `fma` calls of
/// Kahan's algorithm on targets without hardware FMA. The plain `fl(fl(h²) − fl(a c))` errs
/// by at most `u (h² + |a c|) + u |Δ̂|`: when `h² + |a c| <= 2 |Δ̂|` (no cancellation,
/// which includes every `a c < 0`) that is `3u |Δ̂|` and it is kept. Otherwise the two
/// products are split exactly (`p + e = h²`, `q + f = a c`), `p − q` is summed without
/// error, and `Δ = (p − q) + ((e − f) + error)` is rounded once: within `u |Δ|` plus `u²`
/// of the products.
pub(crate) fn discriminant<T: Real>(h: T, a: T, c: T) -> T {
    let (hh, ac) = (h * h, a * c);
    let plain = hh - ac;
    if hh + ac.abs() <= plain.abs() * T::lit(2.0) {
        return plain;
    }
    let ((p, e), (q, f)) = (two_square(h), two_product(a, c));
    let (s, g) = two_sum(p, -q);
    s + (g + (e - f))
}

/// `f(t) = a t² + 2 h t + c` with its discriminant `Δ = h² − a c`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Quadratic<T: Real> {
    a: T,
    h: T,
    c: T,
    disc: T,
}

impl<T: Real> Quadratic<T> {
    /// The quadratic `a t² + 2 h t + c`, its discriminant by [`discriminant`] (`h²`
    /// exactly rounded when `a = 0`: a linear gap has nothing to cancel).
    #[inline]
    pub(crate) fn new(a: T, h: T, c: T) -> Self {
        let disc = if a == T::zero() {
            h * h
        } else {
            discriminant(h, a, c)
        };
        Self { a, h, c, disc }
    }

    /// The quadratic with a discriminant the caller computed more accurately.
    #[inline]
    pub(crate) fn with_discriminant(a: T, h: T, c: T, disc: T) -> Self {
        Self { a, h, c, disc }
    }

    /// The value at `t`.
    #[inline]
    pub(crate) fn eval(&self, t: T) -> T {
        (self.a * t + self.h * T::lit(2.0)) * t + self.c
    }

    /// The derivative at `t`.
    #[inline]
    pub(crate) fn rate(&self, t: T) -> T {
        (self.a * t + self.h) * T::lit(2.0)
    }

    /// `true` if every coefficient is finite (no overflow while forming them).
    #[inline]
    pub(crate) fn is_finite(&self) -> bool {
        self.a.finite() && self.h.finite() && self.c.finite() && self.disc.finite()
    }

    /// The root where the function crosses zero downwards, if there is one.
    #[inline]
    pub(crate) fn descending_root(&self) -> Option<T> {
        if self.disc <= T::zero() {
            return None;
        }
        let sqrt_disc = self.disc.sqrt();
        if self.h < T::zero() {
            Some(self.c / (sqrt_disc - self.h))
        } else if self.a != T::zero() {
            Some((-self.h - sqrt_disc) / self.a)
        } else {
            None
        }
    }

    /// The real roots in increasing order (a double root once), and how many there are.
    pub(crate) fn roots(&self) -> ([T; 2], usize) {
        let (a, h, c) = (self.a, self.h, self.c);
        if a == T::zero() {
            return if h == T::zero() {
                ([T::zero(); 2], 0)
            } else {
                ([-c / (h * T::lit(2.0)), T::zero()], 1)
            };
        }
        if self.disc < T::zero() {
            return ([T::zero(); 2], 0);
        }
        if self.disc == T::zero() {
            return ([-h / a, T::zero()], 1);
        }
        // q = −(h + sign(h)√Δ) has no cancellation; the roots are q/a and c/q.
        let q = -(h + h.copysign_one() * self.disc.sqrt());
        let (r1, r2) = (q / a, c / q);
        if r1 <= r2 {
            ([r1, r2], 2)
        } else {
            ([r2, r1], 2)
        }
    }

    /// The first time in `[lo, hi]` (`hi` may be `+∞`) at which the function goes from
    /// positive to negative, given whether it was already positive before `lo`.
    ///
    /// The descending root `t↓` counts if `lo < t↓ <= hi` (the function is positive just
    /// before it), or `t↓ = lo` when already armed. Rounding at interval ends (the end of
    /// one region of a piecewise gap is the start of the next) is absorbed: an armed
    /// function that is already negative and decreasing at `lo` descends at `lo`.
    pub(crate) fn first_descent(&self, lo: T, hi: T, armed: bool) -> Descent<T> {
        if let Some(root) = self.descending_root()
            && (root > lo || (armed && root == lo))
            && root <= hi
        {
            return Descent::At(root);
        }
        let at_lo = self.eval(lo);
        if armed && at_lo < T::zero() && self.rate(lo) < T::zero() {
            return Descent::At(lo);
        }
        if !armed
            && at_lo <= T::zero()
            && let Some(turn) = self.turn_while_overlapping(lo, hi)
        {
            return Descent::At(turn);
        }
        Descent::Clear {
            armed: armed || at_lo > T::zero() || self.max_after(lo, hi) > T::zero(),
        }
    }

    /// For a function never positive since time 0 and not positive at `lo`: the first
    /// time in `[lo, hi]` it stops rising while still not positive (its maximum, or `lo`
    /// if it falls there), after which it falls.
    ///
    /// A pair that starts overlapping and separating must be allowed to separate without
    /// colliding, but under an acceleration that pulls it back it may turn before it is
    /// apart: a ball set down on a tilted face overlapping it by a rounding (1e-14 m)
    /// and leaving it at a rounding (4e-16 m/s) turns back at once. Waiting for a
    /// separation that never comes, it fell through the face. Its contact is where it
    /// turns.
    fn turn_while_overlapping(&self, lo: T, hi: T) -> Option<T> {
        if self.rate(lo) < T::zero() {
            return Some(lo);
        }
        if self.a < T::zero() {
            let vertex = -self.h / self.a;
            if vertex <= hi && self.eval(vertex) <= T::zero() {
                return Some(vertex.max(lo));
            }
        }
        None
    }

    /// The largest value on `(lo, hi]` (`+∞` if it grows without bound), at the end or at
    /// the vertex.
    fn max_after(&self, lo: T, hi: T) -> T {
        let at_end = if hi.finite() {
            self.eval(hi)
        } else if self.a > T::zero() || (self.a == T::zero() && self.h > T::zero()) {
            T::INFINITY
        } else {
            -T::INFINITY
        };
        if self.a < T::zero() {
            let vertex = -self.h / self.a;
            if vertex > lo && vertex < hi {
                return at_end.max(self.eval(vertex));
            }
        }
        at_end
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descending_root_of_both_signs_of_curvature() {
        // (t − 1)(t − 3): descends at 1.
        let q = Quadratic::new(1.0, -2.0, 3.0);
        assert_eq!(q.descending_root(), Some(1.0));
        // −(t − 1)(t − 3): descends at 3.
        let q = Quadratic::new(-1.0, 2.0, -3.0);
        assert_eq!(q.descending_root(), Some(3.0));
        // Linear 2 − t (h = −1/2).
        assert_eq!(Quadratic::new(0.0, -0.5, 2.0).descending_root(), Some(2.0));
        // Increasing line: none.
        assert_eq!(Quadratic::new(0.0, 0.5, 2.0).descending_root(), None);
        // Tangency (t − 1)²: none.
        assert_eq!(Quadratic::new(1.0, -1.0, 1.0).descending_root(), None);
    }

    #[test]
    fn discriminant_survives_cancellation() {
        // h² − a c with h² and a c equal to 53 bits: (1 + 2^-30)(1 − 2^-30) = 1 − 2^-60.
        let (a, c) = (1.0 + 2f64.powi(-30), 1.0 - 2f64.powi(-30));
        assert_eq!(a * c - 1.0, 0.0);
        assert_eq!(discriminant(1.0, a, c), 2f64.powi(-60));
        assert_eq!(discriminant(3.0, 2.0, -4.0), 17.0);
        assert_eq!(discriminant(3.0_f32, 2.0, 4.0), 1.0);
    }

    proptest::proptest! {
        /// Against exact integer arithmetic, with `c` chosen so that `a c ≈ h²` (heavy
        /// cancellation) half of the time.
        #[test]
        fn discriminant_is_within_three_u(
            h in -(1i64 << 30)..(1 << 30), a in 1i64..(1 << 30), c in -(1i64 << 30)..(1 << 30),
            delta in -64i64..64, cancel in proptest::bool::ANY,
        ) {
            let c = if cancel { (h * h) / a + delta } else { c };
            let exact = i128::from(h) * i128::from(h) - i128::from(a) * i128::from(c);
            let got = discriminant(h as f64, a as f64, c as f64);
            // Every value here is an integer: compare exactly.
            let err = (got as i128 - exact).unsigned_abs() as f64;
            proptest::prop_assert!(err <= 1.5 * f64::EPSILON * exact.unsigned_abs() as f64, "{got} vs {exact}");
        }
    }

    #[test]
    fn roots_are_sorted_and_stable() {
        let (r, n) = Quadratic::<f64>::new(1.0, -1e8, 1.0).roots();
        assert_eq!(n, 2);
        // The small root 1/(2e8) would be lost to cancellation by the textbook formula.
        assert!((r[0] - 0.5e-8).abs() < 1e-22 && (r[1] - 2e8).abs() < 1e-6);
        assert_eq!(Quadratic::new(0.0, 1.0, -4.0).roots(), ([2.0, 0.0], 1));
        assert_eq!(Quadratic::new(1.0, 0.0, 1.0).roots().1, 0);
    }

    #[test]
    fn first_descent_needs_a_positive_value_before_the_root() {
        let q = Quadratic::new(1.0, -2.0, 3.0); // descends at 1, rises at 3
        assert!(matches!(q.first_descent(0.0, 2.0, false), Descent::At(t) if t == 1.0));
        assert!(matches!(
            q.first_descent(0.0, 0.5, false),
            Descent::Clear { armed: true }
        ));
        // Starting at the root, unarmed and falling: it turns there.
        assert!(matches!(q.first_descent(1.0, 2.0, false), Descent::At(t) if t == 1.0));
        assert!(matches!(q.first_descent(1.0, 2.0, true), Descent::At(t) if t == 1.0));
        // Rising part only: arms at the end.
        assert!(matches!(
            q.first_descent(2.0, 4.0, false),
            Descent::Clear { armed: true }
        ));
        assert!(matches!(
            q.first_descent(2.0, 2.5, false),
            Descent::Clear { armed: false }
        ));
    }

    #[test]
    fn an_overlap_that_turns_back_before_it_opens_descends_at_the_turn() {
        // −(t − 1)² − 1: rising to −1 at t = 1, never positive; unarmed, it turns at 1.
        let q = Quadratic::new(-1.0, 1.0, -2.0);
        assert!(matches!(q.first_descent(0.0, 3.0, false), Descent::At(t) if t == 1.0));
        // The turn after the horizon: nothing yet.
        assert!(matches!(
            q.first_descent(0.0, 0.5, false),
            Descent::Clear { armed: false }
        ));
        // −(t − 1)² + 1 opens at 0 and closes at its descending root 2, not at the turn.
        let q = Quadratic::new(-1.0, 1.0, 0.0);
        assert!(matches!(q.first_descent(0.0, 3.0, false), Descent::At(t) if t == 2.0));
        // A convex overlap that keeps opening never turns: open by t = 2 (t² + 2t − 4 = 4).
        let q = Quadratic::new(1.0, 1.0, -4.0);
        assert!(matches!(
            q.first_descent(0.0, 2.0, false),
            Descent::Clear { armed: true }
        ));
    }
}
