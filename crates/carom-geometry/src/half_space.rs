//! The half-space: the solid side of a line (2D) or plane (3D); an infinite floor or wall.

use carom_math::{InvalidValue, Problem, Real, Vector, ensure_finite, ensure_finite_vector};

/// The set of points `x` with `n · x <= offset`, for a unit outward normal `n`.
///
/// The boundary is the plane `n · x = offset`; `n` points out of the solid, towards the
/// free side. The signed distance of a point is `n · x − offset` (negative inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace<T: Real, const D: usize> {
    normal: Vector<T, D>,
    offset: T,
}

impl<T: Real, const D: usize> HalfSpace<T, D> {
    /// The half-space whose boundary passes through `point` with outward `normal`
    /// (normalised here; any positive length is accepted).
    ///
    /// # Errors
    /// `normal[i]` / `point[i]` if not finite; `normal` with [`Problem::ZeroLength`] if its
    /// length is zero or too small to normalise.
    pub fn new(normal: Vector<T, D>, point: Vector<T, D>) -> Result<Self, InvalidValue> {
        ensure_finite_vector("point", &point)?;
        let n = Self::unit_normal(normal)?;
        let offset = ensure_finite("offset", n.dot(&point))?;
        Ok(Self { normal: n, offset })
    }

    /// The half-space `n̂ · x <= offset` where `n̂` is `normal` normalised.
    ///
    /// # Errors
    /// As [`HalfSpace::new`], and `offset` if not finite.
    pub fn from_normal_offset(normal: Vector<T, D>, offset: T) -> Result<Self, InvalidValue> {
        let n = Self::unit_normal(normal)?;
        // n̂ = normal / |normal|, so the plane normal · x = offset is n̂ · x = offset / |normal|,
        // computed as (offset / scale) / |normal / scale| to avoid overflow.
        let scale = normal.amax();
        let offset = ensure_finite("offset", offset)? / scale / (normal / scale).norm();
        let offset = ensure_finite("offset", offset)?;
        Ok(Self { normal: n, offset })
    }

    /// `normal / |normal|`, scaled by its largest component first so that the squared
    /// length neither underflows (1e-300) nor overflows (1e300).
    fn unit_normal(normal: Vector<T, D>) -> Result<Vector<T, D>, InvalidValue> {
        ensure_finite_vector("normal", &normal)?;
        let scale = normal.amax();
        // scale is finite and >= 0 here (the components were checked).
        if scale < T::MIN_POSITIVE {
            return Err(InvalidValue::new(
                "normal",
                Problem::ZeroLength(normal.norm().to_f64()),
            ));
        }
        let n = normal / scale;
        Ok(n / n.norm())
    }

    /// The unit outward normal.
    #[inline]
    pub fn normal(&self) -> Vector<T, D> {
        self.normal
    }

    /// The plane offset: `normal · x = offset` on the boundary.
    #[inline]
    pub fn offset(&self) -> T {
        self.offset
    }

    /// The signed distance from `p` to the boundary: negative inside the solid.
    #[inline]
    pub fn signed_distance(&self, p: &Vector<T, D>) -> T {
        self.normal.dot(p) - self.offset
    }

    /// The orthogonal projection of `p` on the boundary plane.
    #[inline]
    pub fn project(&self, p: &Vector<T, D>) -> Vector<T, D> {
        p - self.normal * self.signed_distance(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn floor_through_a_point() {
        let h = HalfSpace::new(Vector2::new(0.0, 2.0), Vector2::new(5.0, -1.0)).unwrap();
        assert_eq!(h.normal(), Vector2::new(0.0, 1.0));
        assert_eq!(h.offset(), -1.0);
        assert_eq!(h.signed_distance(&Vector2::new(3.0, 0.5)), 1.5);
        assert_eq!(h.signed_distance(&Vector2::new(3.0, -2.0)), -1.0);
        assert_eq!(h.project(&Vector2::new(3.0, 4.0)), Vector2::new(3.0, -1.0));
    }

    #[test]
    fn from_normal_offset_scales_the_offset_with_the_normal() {
        let h = HalfSpace::from_normal_offset(Vector3::new(0.0, 0.0, 4.0), 8.0).unwrap();
        assert_relative_eq!(h.offset(), 2.0);
        assert_relative_eq!(h.signed_distance(&Vector3::new(1.0, 1.0, 2.0)), 0.0);
    }

    #[test]
    fn zero_and_subnormal_normals_are_rejected() {
        assert_eq!(
            HalfSpace::new(Vector2::new(0.0, 0.0), Vector2::zeros())
                .unwrap_err()
                .field,
            "normal"
        );
        assert_eq!(
            HalfSpace::new(Vector2::new(1e-320, 0.0), Vector2::zeros())
                .unwrap_err()
                .field,
            "normal"
        );
        assert!(HalfSpace::new(Vector2::new(1e-300, 1e-300), Vector2::zeros()).is_ok());
        assert_eq!(
            HalfSpace::new(Vector2::new(f64::NAN, 1.0), Vector2::zeros())
                .unwrap_err()
                .field,
            "normal[0]"
        );
    }
}
