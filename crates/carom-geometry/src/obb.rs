//! The oriented box: a table, a paddle, a wall at any angle.

use carom_math::{
    InvalidValue, Problem, Real, Rotation, Vector, ensure_finite, ensure_finite_vector,
    ensure_non_negative,
};
use nalgebra::{Vector2, Vector3};

use crate::Aabb;

/// A box with centre, half extents along its own axes, and a rotation.
///
/// The box's axis `i` in world space is column `i` of the rotation matrix; a point `p`
/// has local coordinates `Rᵀ (p − c)` and lies inside when each `|local[i]| <= h[i]`.
///
/// Invariants (checked by the constructors): finite centre, half extents finite and
/// `>= 0` (zero-size boxes are valid), a rotation that is orthonormal with determinant
/// +1 to within a few ulp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb<T: Real, const D: usize> {
    center: Vector<T, D>,
    half_extents: Vector<T, D>,
    rotation: Rotation<T, D>,
}

impl<T: Real, const D: usize> Obb<T, D> {
    /// A box from its centre, half extents and rotation.
    ///
    /// # Errors
    /// `center[i]`, `half_extents[i]` (not finite or negative), or `rotation` (not finite,
    /// or not orthonormal with determinant +1 within `64·ε`).
    pub fn new(
        center: Vector<T, D>,
        half_extents: Vector<T, D>,
        rotation: Rotation<T, D>,
    ) -> Result<Self, InvalidValue> {
        ensure_finite_vector("center", &center)?;
        for i in 0..D {
            ensure_non_negative("half_extents", half_extents[i])
                .map_err(|e| InvalidValue::new(format!("half_extents[{i}]"), e.problem))?;
        }
        let m = rotation.matrix();
        for x in m.iter() {
            ensure_finite("rotation", *x)?;
        }
        // ‖RᵀR − I‖_max bounds the departure from orthonormality.
        let defect = (m.transpose() * m - nalgebra::SMatrix::<T, D, D>::identity()).amax();
        let tolerance = T::lit(64.0) * T::EPSILON;
        if defect > tolerance || carom_math::determinant(m) < T::zero() {
            return Err(InvalidValue::new(
                "rotation",
                Problem::OutOfRange {
                    value: defect.to_f64(),
                    min: 0.0,
                    max: tolerance.to_f64(),
                },
            ));
        }
        Ok(Self {
            center,
            half_extents,
            rotation,
        })
    }

    /// A box from values the caller has already validated (hot paths).
    #[inline]
    pub fn new_unchecked(
        center: Vector<T, D>,
        half_extents: Vector<T, D>,
        rotation: Rotation<T, D>,
    ) -> Self {
        debug_assert!(half_extents.iter().all(|h| *h >= T::zero()));
        Self {
            center,
            half_extents,
            rotation,
        }
    }

    /// The axis-aligned box `aabb` as an oriented box with the identity rotation.
    pub fn from_aabb(aabb: &Aabb<T, D>) -> Self {
        let half = T::lit(0.5);
        Self {
            center: (aabb.min() + aabb.max()) * half,
            half_extents: aabb.extents() * half,
            rotation: Rotation::identity(),
        }
    }

    /// The centre.
    #[inline]
    pub fn center(&self) -> Vector<T, D> {
        self.center
    }

    /// The half extents along the box's own axes.
    #[inline]
    pub fn half_extents(&self) -> Vector<T, D> {
        self.half_extents
    }

    /// The rotation from box-local to world coordinates.
    #[inline]
    pub fn rotation(&self) -> &Rotation<T, D> {
        &self.rotation
    }

    /// The box's axis `i` in world coordinates (unit length).
    #[inline]
    pub fn axis(&self, i: usize) -> Vector<T, D> {
        self.rotation.matrix().column(i).into_owned()
    }

    /// World point → box-local coordinates `Rᵀ (p − c)`.
    #[inline]
    pub fn to_local(&self, p: &Vector<T, D>) -> Vector<T, D> {
        self.rotation.inverse_transform_vector(&(p - self.center))
    }

    /// World direction → box-local direction `Rᵀ v`.
    #[inline]
    pub fn vector_to_local(&self, v: &Vector<T, D>) -> Vector<T, D> {
        self.rotation.inverse_transform_vector(v)
    }

    /// Box-local point → world coordinates `c + R p`.
    #[inline]
    pub fn to_world(&self, p: &Vector<T, D>) -> Vector<T, D> {
        self.center + self.rotation * p
    }

    /// Box-local direction → world direction `R v`.
    #[inline]
    pub fn vector_to_world(&self, v: &Vector<T, D>) -> Vector<T, D> {
        self.rotation * v
    }

    /// The box in its own frame: centred at the origin with the same half extents.
    pub fn local_aabb(&self) -> Aabb<T, D> {
        Aabb::new_unchecked(-self.half_extents, self.half_extents)
    }

    /// The tight axis-aligned box around the oriented box: half extents `|R| h`.
    pub fn aabb(&self) -> Aabb<T, D> {
        let h = self.rotation.matrix().abs() * self.half_extents;
        Aabb::new_unchecked(self.center - h, self.center + h)
    }

    /// The box moved by `offset`.
    #[inline]
    #[must_use]
    pub fn translated(&self, offset: &Vector<T, D>) -> Self {
        Self {
            center: self.center + offset,
            ..*self
        }
    }

    /// The `2^D` corners in world coordinates; corner `k` is at `+h[i]` along axis `i`
    /// where bit `i` of `k` is set, `−h[i]` otherwise.
    pub fn corners(&self) -> impl Iterator<Item = Vector<T, D>> + '_ {
        (0..1usize << D).map(move |k| {
            let local = Vector::<T, D>::from_fn(|i, _| {
                if k >> i & 1 == 1 {
                    self.half_extents[i]
                } else {
                    -self.half_extents[i]
                }
            });
            self.to_world(&local)
        })
    }
}

impl<T: Real> Obb<T, 2> {
    /// A rectangle rotated counter-clockwise by `angle` radians.
    ///
    /// # Errors
    /// `center[i]`, `half_extents[i]` or `angle` if invalid.
    pub fn from_angle(
        center: Vector2<T>,
        half_extents: Vector2<T>,
        angle: T,
    ) -> Result<Self, InvalidValue> {
        ensure_finite("angle", angle)?;
        Self::new(center, half_extents, Rotation::<T, 2>::new(angle))
    }
}

impl<T: Real> Obb<T, 3> {
    /// A box rotated by the rotation vector `axis_angle` (unit axis times angle in radians).
    ///
    /// # Errors
    /// `center[i]`, `half_extents[i]` or `axis_angle[i]` if invalid.
    pub fn from_axis_angle(
        center: Vector3<T>,
        half_extents: Vector3<T>,
        axis_angle: Vector3<T>,
    ) -> Result<Self, InvalidValue> {
        ensure_finite_vector("axis_angle", &axis_angle)?;
        Self::new(
            center,
            half_extents,
            Rotation::<T, 3>::from_scaled_axis(axis_angle),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Matrix2;

    #[test]
    fn aabb_of_a_rotated_square_contains_its_corners_tightly() {
        let o =
            Obb::<f64, 2>::from_angle(Vector2::new(1.0, 2.0), Vector2::new(1.0, 0.5), 0.3).unwrap();
        let a = o.aabb();
        let mut touched = [false; 4];
        for c in o.corners() {
            assert!(a.min().x - 1e-12 <= c.x && c.x <= a.max().x + 1e-12);
            assert!(a.min().y - 1e-12 <= c.y && c.y <= a.max().y + 1e-12);
            touched[0] |= (c.x - a.min().x).abs() < 1e-12;
            touched[1] |= (c.x - a.max().x).abs() < 1e-12;
            touched[2] |= (c.y - a.min().y).abs() < 1e-12;
            touched[3] |= (c.y - a.max().y).abs() < 1e-12;
        }
        assert_eq!(
            touched, [true; 4],
            "every face of the AABB touches a corner"
        );
    }

    #[test]
    fn local_and_world_coordinates_are_inverse() {
        let o = Obb::from_axis_angle(
            Vector3::new(1.0, -2.0, 0.5),
            Vector3::new(0.3, 0.2, 0.1),
            Vector3::new(0.2, -0.7, 0.4),
        )
        .unwrap();
        let p = Vector3::new(0.3, 0.9, -4.0);
        assert_relative_eq!(o.to_world(&o.to_local(&p)), p, epsilon = 1e-14);
        assert_relative_eq!(o.axis(2).norm(), 1.0, epsilon = 1e-15);
    }

    #[test]
    fn constructor_rejects_non_rotations_and_negative_extents() {
        let shear = Rotation::from_matrix_unchecked(Matrix2::new(1.0, 0.1, 0.0, 1.0));
        assert_eq!(
            Obb::new(Vector2::zeros(), Vector2::new(1.0, 1.0), shear)
                .unwrap_err()
                .field,
            "rotation"
        );
        let mirror = Rotation::from_matrix_unchecked(Matrix2::new(-1.0, 0.0, 0.0, 1.0));
        assert_eq!(
            Obb::new(Vector2::zeros(), Vector2::new(1.0, 1.0), mirror)
                .unwrap_err()
                .field,
            "rotation"
        );
        assert_eq!(
            Obb::from_angle(Vector2::zeros(), Vector2::new(1.0, -1e-9), 0.0)
                .unwrap_err()
                .field,
            "half_extents[1]"
        );
        assert_eq!(
            Obb::from_angle(Vector2::zeros(), Vector2::new(1.0, 1.0), f64::NAN)
                .unwrap_err()
                .field,
            "angle"
        );
        assert!(Obb::from_angle(Vector2::<f32>::zeros(), Vector2::new(0.0, 0.0), 1e6).is_ok());
    }
}
