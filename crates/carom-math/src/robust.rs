//! Error-free transformations for the few computations that cancel catastrophically.
//!
//! The discriminant `b² − a·c` of a time-of-impact quadratic loses every significant
//! digit when a pair grazes (`b² ≈ a·c`). Kahan's algorithm computes `a·b − c·d` with
//! an error of at most 1.5 ulp using two fused multiply-adds:
//!
//! ```text
//! w = c·d            (rounded)
//! e = fma(−c, d, w)  (= w − c·d exactly: the rounding error of w)
//! f = fma(a, b, −w)  (= a·b − w, rounded once)
//! a·b − c·d = f + e
//! ```
//!
//! (Jeannerod, Louvet and Muller, "Further analysis of Kahan's algorithm for the
//! accurate computation of 2×2 determinants", Math. Comp. 82, 2013.)
//!
//! Without hardware FMA in the compilation target, `fma` is a correctly rounded libm
//! call: still exact, a few nanoseconds slower. Callers use these functions only where
//! the plain formula is known to cancel.

use crate::Real;

/// `a·b − c·d` to within 1.5 ulp, however close the two products are (Kahan).
#[inline]
pub fn diff_of_products<T: Real>(a: T, b: T, c: T, d: T) -> T {
    let w = c * d;
    let e = (-c).fma(d, w);
    let f = a.fma(b, -w);
    f + e
}

/// The exact product as an unevaluated sum `(p, e)` with `p = fl(a·b)` and `p + e = a·b`.
#[inline]
pub fn two_product<T: Real>(a: T, b: T) -> (T, T) {
    let p = a * b;
    (p, a.fma(b, -p))
}

/// The exact sum as an unevaluated sum `(s, e)` with `s = fl(a + b)` and `s + e = a + b`
/// (Knuth's TwoSum: no ordering requirement on `a` and `b`).
#[inline]
pub fn two_sum<T: Real>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_of_nearly_equal_products_is_exact_where_the_naive_one_is_zero() {
        // a·b − c·d with a·b and c·d equal to 53 bits: the naive formula returns 0.
        let a = 1.0 + 2f64.powi(-30);
        let b = 1.0 - 2f64.powi(-30);
        // a·b = 1 − 2^-60 exactly; c·d = 1.
        let naive = a * b - 1.0 * 1.0;
        assert_eq!(naive, 0.0);
        assert_eq!(diff_of_products(a, b, 1.0, 1.0), -(2f64.powi(-60)));
    }

    #[test]
    fn two_product_and_two_sum_recover_the_rounding_error() {
        let a = 0.1_f64;
        let b = 0.3_f64;
        let (p, e) = two_product(a, b);
        assert_eq!(p, a * b);
        assert!(e != 0.0);
        let (s, e) = two_sum(1e16_f64, 1.0);
        assert_eq!(s, 1e16);
        assert_eq!(e, 1.0);
    }
}
