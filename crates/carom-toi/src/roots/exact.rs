//! Error-free transformations and double-double sums of products: the exact fallback of
//! the filtered predicates, used only when plain arithmetic cannot decide a sign.
//!
//! `two_product(a, b) = (p, e)` with `p = fl(a·b)` and `p + e = a·b` exactly. With
//! hardware FMA in the compilation target (`target_feature = "fma"`) it is the usual
//! `e = fma(a, b, −p)`. Without it (the default x86-64 target) `mul_add` is a call into
//! libm, so the product is split instead (Veltkamp, Dekker 1971): `a = a_hi + a_lo` with
//! `a_hi = c − (c − a)`, `c = (2^s + 1)·a`, `s = ⌈p/2⌉` for a `p`-bit significand (27 for
//! `f64`, 12 for `f32`), so that each half has at most `s` bits and every partial
//! product `a_hi·b_hi`, `a_hi·b_lo`, ... is exact; then
//! `e = ((a_hi·b_hi − p) + a_hi·b_lo + a_lo·b_hi) + a_lo·b_lo` exactly: four operations
//! per split and eight per product, no call. Both forms are exact as long as nothing overflows
//! (`|a| < MAX / 2^s`) and the error term is not below the normal range (products
//! above about `2^(emin + p)`: `1e-291` in `f64`, `1e-30` in `f32`).
//!
//! A [`DoubleDouble`] `hi + lo` (`|lo| <= ulp(hi)/2`) carries about twice the working
//! precision. [`DoubleDouble::add_product`] is the step of Ogita, Rump and Oishi's `Dot2` ("Accurate sum and
//! dot product", SIAM J. Sci. Comput. 26, 2005): the products and the running sum are
//! transformed without error and only the small error terms are added in plain
//! arithmetic, so for `n` terms the result is within `γ_{2n}² Σ|xᵢ yᵢ|` of the exact dot
//! product (`γ_k = k u / (1 − k u)`, `u` the unit roundoff): as if computed in twice the
//! precision.

use carom_math::Real;

/// `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly (Knuth's TwoSum, no
/// ordering requirement).
#[inline]
pub(crate) fn two_sum<T: Real>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// Veltkamp's splitting constant `2^⌈p/2⌉ + 1`.
#[inline]
fn splitter<T: Real>() -> T {
    if T::EPSILON.to_f64() > 1e-10 {
        T::lit(4097.0) // f32: 2^12 + 1
    } else {
        T::lit(134_217_729.0) // f64: 2^27 + 1
    }
}

/// `x = hi + lo`, each half short enough that products of halves are exact.
#[inline]
fn split<T: Real>(x: T) -> (T, T) {
    let c = splitter::<T>() * x;
    let hi = c - (c - x);
    (hi, x - hi)
}

/// `(p, e)` with `p = fl(a·b)` and `p + e = a·b` exactly (module docs): FMA where the
/// target has it, Dekker's product of Veltkamp halves otherwise.
#[inline]
pub(crate) fn two_product<T: Real>(a: T, b: T) -> (T, T) {
    let p = a * b;
    if cfg!(target_feature = "fma") {
        return (p, a.fma(b, -p));
    }
    let (a_hi, a_lo) = split(a);
    let (b_hi, b_lo) = split(b);
    let e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
    (p, e)
}

/// `(p, e)` with `p = fl(a²)` and `p + e = a²` exactly (one split).
#[inline]
pub(crate) fn two_square<T: Real>(a: T) -> (T, T) {
    let p = a * a;
    if cfg!(target_feature = "fma") {
        return (p, a.fma(a, -p));
    }
    let (hi, lo) = split(a);
    let e = ((hi * hi - p) + (hi + hi) * lo) + lo * lo;
    (p, e)
}

/// An unevaluated sum `hi + lo` of about twice the working precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DoubleDouble<T> {
    pub(crate) hi: T,
    pub(crate) lo: T,
}

impl<T: Real> DoubleDouble<T> {
    /// Starts a sum with the exact product `(p, e)` (`p + e` exactly, see
    /// [`two_product`]).
    #[inline]
    pub(crate) fn from_product((p, e): (T, T)) -> Self {
        Self { hi: p, lo: e }
    }

    /// Adds the exact product `(p, e)`, as Dot2 does: the running sum of the `p` is
    /// transformed without error and the error terms are added in plain arithmetic
    /// (module docs). The sum is not normalised until [`finish`](Self::finish).
    #[inline]
    pub(crate) fn add_product(self, (p, e): (T, T)) -> Self {
        let (s, f) = two_sum(self.hi, p);
        Self {
            hi: s,
            lo: self.lo + (e + f),
        }
    }

    /// The sum normalised: `hi = fl(hi + lo)`.
    #[inline]
    pub(crate) fn finish(self) -> Self {
        let (hi, lo) = two_sum(self.hi, self.lo);
        Self { hi, lo }
    }

    /// `self² − a·c`: the discriminant of `a t² + 2 h t + c` from double-double
    /// coefficients, rounded once at the end. The neglected terms (`lo²` and the products
    /// of two `lo` parts) are below `u²` times the squares of the coefficients.
    #[inline]
    pub(crate) fn square_minus_product(self, a: Self, c: Self) -> T {
        let (hh, he) = two_square(self.hi);
        let (ac, ae) = two_product(a.hi, c.hi);
        let (s, f) = two_sum(hh, -ac);
        let cross = (self.hi + self.hi) * self.lo - (a.hi * c.lo + a.lo * c.hi);
        s + (f + (he - ae) + cross)
    }

    /// The nearest working-precision value.
    #[inline]
    pub(crate) fn value(self) -> T {
        self.hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a·b` in exact rational arithmetic on the integer significands.
    fn exact_product_minus(a: f64, b: f64, p: f64) -> f64 {
        // a·b − p computed from i128 significands: both are multiples of 2^(ea + eb).
        let (ma, ea) = decompose(a);
        let (mb, eb) = decompose(b);
        let (mp, ep) = decompose(p);
        let e = ea + eb;
        let shift = ep - e;
        assert!(shift >= 0);
        let diff = ma * mb - (mp << shift);
        diff as f64 * 2f64.powi(e as i32)
    }

    fn decompose(x: f64) -> (i128, i64) {
        if x == 0.0 {
            return (0, 0);
        }
        let bits = x.to_bits();
        let exp = i64::try_from((bits >> 52) & 0x7ff).unwrap();
        let frac = i128::from(bits & ((1 << 52) - 1));
        let m = if exp == 0 { frac } else { frac | (1 << 52) };
        let m = if x < 0.0 { -m } else { m };
        (m, exp.max(1) - 1075)
    }

    #[test]
    fn split_products_are_exact() {
        let mut x = 0.1234_f64;
        for k in 0..200 {
            let a = x * 2f64.powi(k % 40 - 20);
            let b = (1.0 - x) * 3.7 * 2f64.powi(7 - k % 13);
            let (p, e) = two_product(a, b);
            assert_eq!(p, a * b);
            assert_eq!(e, exact_product_minus(a, b, p), "{a} {b}");
            let (q, f) = two_square(a);
            assert_eq!(f, exact_product_minus(a, a, q));
            x = (x * 7.77).fract();
        }
    }

    #[test]
    fn f32_split_products_are_exact() {
        for (a, b) in [(0.1_f32, 0.3_f32), (1.0 + f32::EPSILON, 1.0 - f32::EPSILON)] {
            let (p, e) = two_product(a, b);
            let exact = f64::from(a) * f64::from(b);
            assert_eq!(f64::from(p) + f64::from(e), exact);
        }
    }

    #[test]
    fn sums_of_products_recover_what_plain_sums_lose() {
        // 1e16·1 + 1·1 − 1e16·1 = 1, plain gives 0.
        let d = DoubleDouble::from_product(two_product(1e16, 1.0))
            .add_product(two_product(1.0, 1.0))
            .add_product(two_product(-1e16, 1.0))
            .finish();
        assert_eq!(d.value(), 1.0);
        // (1 + 2^-30)² + 1 − fl(√2)², exactly from the decomposition.
        let r = 2f64.sqrt();
        let (p, e) = two_square(r);
        let s = DoubleDouble::from_product(two_square(1.0 + 2f64.powi(-30)))
            .add_product((1.0, 0.0))
            .add_product((-p, -e))
            .finish();
        let exact = 2f64.powi(-29) + 2f64.powi(-60) - exact_product_minus(r, r, 2.0);
        assert!((s.value() - exact).abs() <= 1e-30, "{} {exact}", s.value());
    }
}
