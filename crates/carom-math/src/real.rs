//! The scalar trait: `f32` or `f64`.

use core::fmt::{Debug, Display};

use nalgebra::RealField;

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A floating-point scalar carom computes in: `f32` or `f64`.
///
/// It is nalgebra's [`RealField`] plus `Copy` and the conversions physics code needs
/// to write constants once for both precisions (`T::lit(0.5)`). The trait is sealed:
/// the numerical tolerances in carom are derived for IEEE binary32 and binary64.
pub trait Real:
    RealField + Copy + Default + Debug + Display + Send + Sync + 'static + sealed::Sealed
{
    /// The machine epsilon: the gap between 1 and the next representable number.
    const EPSILON: Self;
    /// The largest finite value.
    const MAX: Self;
    /// The smallest positive normal value.
    const MIN_POSITIVE: Self;
    /// Positive infinity: "never" for times of impact.
    const INFINITY: Self;

    /// Converts an `f64` literal or computed constant (rounding to nearest for `f32`).
    fn lit(x: f64) -> Self;
    /// Converts to `f64` exactly.
    fn to_f64(self) -> f64;
    /// Converts a count.
    fn from_count(n: usize) -> Self;
    /// `true` if neither NaN nor infinite.
    fn finite(self) -> bool;
    /// The sign bit as `±1`, also for zeros (`-0.0` gives `-1`).
    fn copysign_one(self) -> Self;
    /// `self * a + b` with one rounding (hardware FMA where the target has it,
    /// otherwise a correctly rounded software fallback: slower, still exact).
    fn fma(self, a: Self, b: Self) -> Self;
}

macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            const EPSILON: Self = <$t>::EPSILON;
            const MAX: Self = <$t>::MAX;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;
            const INFINITY: Self = <$t>::INFINITY;

            #[inline(always)]
            fn lit(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            #[inline(always)]
            fn from_count(n: usize) -> Self {
                n as $t
            }
            #[inline(always)]
            fn finite(self) -> bool {
                self.is_finite()
            }
            #[inline(always)]
            fn copysign_one(self) -> Self {
                <$t>::copysign(1.0, self)
            }
            #[inline(always)]
            fn fma(self, a: Self, b: Self) -> Self {
                <$t>::mul_add(self, a, b)
            }
        }
    };
}

impl_real!(f32);
impl_real!(f64);

#[cfg(test)]
mod tests {
    use super::Real;

    #[test]
    fn literals_round_to_nearest_in_each_precision() {
        assert_eq!(f32::lit(0.1), 0.1_f32);
        assert_eq!(f64::lit(0.1), 0.1_f64);
        assert_eq!(f32::lit(1e300), f32::INFINITY);
    }

    #[test]
    fn copysign_one_sees_the_sign_of_zero() {
        assert_eq!((-0.0_f64).copysign_one(), -1.0);
        assert_eq!(0.0_f64.copysign_one(), 1.0);
        assert_eq!((-3.0_f32).copysign_one(), -1.0);
    }

    #[test]
    fn fma_rounds_once() {
        // (1 + 2^-27)^2 = 1 + 2^-26 + 2^-54: the last term is lost by a rounded product
        // but kept by a fused multiply-add that subtracts the rounded product.
        let a = 1.0 + 2f64.powi(-27);
        let p = a * a;
        let err = a.fma(a, -p);
        assert_eq!(err, 2f64.powi(-54));
    }
}
