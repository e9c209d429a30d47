//! The small mathematical base every carom crate shares.
//!
//! * [`Real`]: the scalar, `f32` or `f64`, with the few conversions physics code needs.
//! * [`Vector`]: `nalgebra::SVector<T, D>`; carom is generic over the dimension `D` (2 or 3)
//!   through nalgebra's const generics, so 2D and 3D, `f32` and `f64` all live in one build.
//! * [`Space`]: the few operations whose form depends on the dimension (cross products,
//!   angular velocity, the inertia of a ball, the edge axes of box–box separation tests),
//!   implemented for [`nalgebra::Const<2>`] and [`nalgebra::Const<3>`] so that generic code
//!   asks for them with a `where Const<D>: Space<T, D>` bound instead of being written twice.
//! * [`robust`]: error-free transformations (FMA-based products, Kahan's difference of
//!   products) for the few places where cancellation matters.
//! * [`InvalidValue`]: the error every validated constructor returns, naming the field.
//!
//! With the `glam` feature, nalgebra's conversions to and from glam 0.33 (the glam of
//! parry 0.31 and rapier 0.36) are enabled, so `Vector2<f32>::from(glam::Vec2)` works.

mod real;
pub mod robust;
mod space;
mod validate;

pub use nalgebra;
pub use real::Real;
pub use space::Space;
pub use validate::{
    InvalidValue, Problem, ensure_finite, ensure_finite_vector, ensure_in_range,
    ensure_non_negative, ensure_positive,
};

/// A column vector of `D` scalars: positions, velocities, normals, half extents.
pub type Vector<T, const D: usize> = nalgebra::SVector<T, D>;

/// A proper rotation of `D`-space (an orthonormal matrix with determinant +1).
pub type Rotation<T, const D: usize> = nalgebra::Rotation<T, D>;

/// The marker type that selects dimension-specific code: `Dim<2>` or `Dim<3>`.
pub type Dim<const D: usize> = nalgebra::Const<D>;

/// `⌊x⌋` as an `i64` (saturating at the `i64` range, 0 for NaN), without calling libm.
///
/// On the baseline x86-64 target (no SSE4.1) `f64::floor` and `f64::round` are library
/// calls costing tens of instructions; cell indices and calendar buckets are computed
/// millions of times per second, so this uses the truncating conversion and corrects
/// it for negative non-integers.
#[inline]
pub fn floor_to_i64<T: Real>(x: T) -> i64 {
    let x = x.to_f64();
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The determinant of a small square matrix by Gaussian elimination with partial
/// pivoting (nalgebra's `determinant` needs type-level dimensions that generic
/// `const D` code cannot name). Exact for permutation and diagonal matrices; otherwise
/// backward stable.
pub fn determinant<T: Real, const D: usize>(m: &nalgebra::SMatrix<T, D, D>) -> T {
    let mut a = *m;
    let mut det = T::one();
    for col in 0..D {
        let pivot = (col..D).max_by(|&i, &j| {
            a[(i, col)]
                .abs()
                .partial_cmp(&a[(j, col)].abs())
                .unwrap_or(core::cmp::Ordering::Equal)
        });
        let Some(p) = pivot else { return T::zero() };
        if a[(p, col)] == T::zero() {
            return T::zero();
        }
        if p != col {
            a.swap_rows(p, col);
            det = -det;
        }
        let d = a[(col, col)];
        det *= d;
        for row in col + 1..D {
            let f = a[(row, col)] / d;
            for k in col..D {
                let sub = f * a[(col, k)];
                a[(row, k)] -= sub;
            }
        }
    }
    det
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn floor_to_i64_matches_floor_and_saturates() {
        for x in [
            -2.5_f64,
            -2.0,
            -1e-300,
            -0.0,
            0.0,
            0.3,
            1.0,
            7.9,
            1e17 + 3.0,
            -1e17 - 3.0,
        ] {
            assert_eq!(super::floor_to_i64(x), x.floor() as i64, "{x}");
        }
        assert_eq!(super::floor_to_i64(-0.5_f32), -1);
        assert_eq!(super::floor_to_i64(1e300_f64), i64::MAX);
        assert_eq!(super::floor_to_i64(-1e300_f64), i64::MIN);
        assert_eq!(super::floor_to_i64(f64::NAN), 0);
    }

    #[test]
    fn determinant_matches_the_closed_forms() {
        assert_eq!(super::determinant(&Matrix2::new(0.0, 1.0, 1.0, 0.0)), -1.0);
        let m = Matrix3::<f64>::new(2.0, -1.0, 0.5, 0.3, 4.0, 1.0, -2.0, 0.0, 3.0);
        assert!((super::determinant(&m) - m.determinant()).abs() < 1e-12);
        assert_eq!(super::determinant(&Matrix3::<f64>::zeros()), 0.0);
    }
}
