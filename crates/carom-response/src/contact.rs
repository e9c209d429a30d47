//! Where and along which direction two bodies touch.
//!
//! A contact is the unit normal `n`, pointing from body `a` to body `b`, and the offsets
//! `r_a`, `r_b` of the contact point from each body's centre of mass. The relative
//! velocity of the touching material points is `v_rel = (v_b + ω_b × r_b) − (v_a + ω_a × r_a)`;
//! the pair approaches when `v_rel · n < 0`. An impulse `P` acts on `b` and `−P` on `a`.

use carom_math::{InvalidValue, Problem, Real, Vector, ensure_finite, ensure_finite_vector};

/// The geometry of a contact: unit normal from `a` to `b` and the contact point's offset
/// from each centre of mass.
///
/// Invariants (checked by the constructors): the normal has unit length (to rounding),
/// every component is finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact<T: Real, const D: usize> {
    normal: Vector<T, D>,
    offset_a: Vector<T, D>,
    offset_b: Vector<T, D>,
}

impl<T: Real, const D: usize> Contact<T, D> {
    /// A contact with `normal` (any non-zero length: it is normalised) pointing from `a`
    /// to `b`, and the contact point at `offset_a` from `a`'s centre of mass and
    /// `offset_b` from `b`'s.
    ///
    /// # Errors
    /// `normal[i]`, `offset_a[i]`, `offset_b[i]` if not finite; `normal` if zero.
    pub fn new(
        normal: Vector<T, D>,
        offset_a: Vector<T, D>,
        offset_b: Vector<T, D>,
    ) -> Result<Self, InvalidValue> {
        Ok(Self {
            normal: unit("normal", &normal)?,
            offset_a: ensure_finite_vector("offset_a", &offset_a)?,
            offset_b: ensure_finite_vector("offset_b", &offset_b)?,
        })
    }

    /// The contact of two balls: the normal along the line of centres, the contact point
    /// on each surface along it (`r_a = ρ_a n`, `r_b = −ρ_b n`). For touching balls both
    /// offsets name the same point; for slightly overlapping or separated balls (an
    /// engine's rounding) each is the point on its own ball's surface, which keeps
    /// `r × n = 0`: the impulse of a frictionless ball contact never spins the balls.
    ///
    /// # Errors
    /// `center_a[i]`, `center_b[i]` if not finite; `radius_a`, `radius_b` if not finite;
    /// `normal` if the centres coincide.
    pub fn between_balls(
        center_a: &Vector<T, D>,
        radius_a: T,
        center_b: &Vector<T, D>,
        radius_b: T,
    ) -> Result<Self, InvalidValue> {
        let ca = ensure_finite_vector("center_a", center_a)?;
        let cb = ensure_finite_vector("center_b", center_b)?;
        let ra = ensure_finite("radius_a", radius_a)?;
        let rb = ensure_finite("radius_b", radius_b)?;
        let normal = unit("normal", &(cb - ca))?;
        Ok(Self {
            normal,
            offset_a: normal * ra,
            offset_b: normal * -rb,
        })
    }

    /// A ball (body `a`) touching a surface (body `b`: a wall, a paddle, a cluster) along
    /// `normal`, pointing from the ball into the surface. The contact point is at
    /// `radius · n` from the ball's centre and at `surface_offset` from the surface
    /// body's centre of mass (or any reference point of a static body without spin).
    ///
    /// # Errors
    /// `normal[i]`, `surface_offset[i]` if not finite, `radius` if not finite, `normal` if
    /// zero.
    pub fn ball_surface(
        radius: T,
        normal: &Vector<T, D>,
        surface_offset: &Vector<T, D>,
    ) -> Result<Self, InvalidValue> {
        let normal = unit("normal", normal)?;
        Ok(Self {
            normal,
            offset_a: normal * ensure_finite("radius", radius)?,
            offset_b: ensure_finite_vector("surface_offset", surface_offset)?,
        })
    }

    /// A contact from validated values (hot paths): `normal` must have unit length.
    ///
    /// Debug builds assert finiteness and `| |n| − 1 | ≤ 8 ε`.
    #[inline]
    pub fn new_unchecked(
        normal: Vector<T, D>,
        offset_a: Vector<T, D>,
        offset_b: Vector<T, D>,
    ) -> Self {
        debug_assert!((normal.norm() - T::one()).abs() <= T::lit(8.0) * T::EPSILON);
        debug_assert!(offset_a.iter().chain(offset_b.iter()).all(|x| x.finite()));
        Self {
            normal,
            offset_a,
            offset_b,
        }
    }

    /// The unit normal, from `a` to `b`.
    #[inline]
    pub fn normal(&self) -> Vector<T, D> {
        self.normal
    }

    /// The contact point relative to `a`'s centre of mass.
    #[inline]
    pub fn offset_a(&self) -> Vector<T, D> {
        self.offset_a
    }

    /// The contact point relative to `b`'s centre of mass.
    #[inline]
    pub fn offset_b(&self) -> Vector<T, D> {
        self.offset_b
    }

    /// The same contact seen from the other side: `a` and `b` swapped, normal reversed.
    #[inline]
    #[must_use]
    pub fn swapped(&self) -> Self {
        Self {
            normal: -self.normal,
            offset_a: self.offset_b,
            offset_b: self.offset_a,
        }
    }
}

/// `v / |v|`, scaling by the largest component first so that neither tiny (1e-200) nor
/// huge (1e200) vectors under- or overflow in `|v|²`.
fn unit<T: Real, const D: usize>(
    field: &'static str,
    v: &Vector<T, D>,
) -> Result<Vector<T, D>, InvalidValue> {
    let v = ensure_finite_vector(field, v)?;
    let scale = v.amax();
    if scale == T::zero() {
        return Err(InvalidValue::new(field, Problem::ZeroLength(0.0)));
    }
    let scaled = v / scale;
    Ok(scaled / scaled.norm())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn ball_contact_points_lie_on_each_surface_along_the_line_of_centres() {
        let c = Contact::between_balls(&Vector2::new(0.0, 0.0), 1.0, &Vector2::new(3.0, 4.0), 4.0)
            .unwrap();
        assert_eq!(c.normal(), Vector2::new(0.6, 0.8));
        assert_eq!(c.offset_a(), Vector2::new(0.6, 0.8));
        assert_eq!(c.offset_b(), Vector2::new(-2.4, -3.2));
        let s = c.swapped();
        assert_eq!(s.normal(), -c.normal());
        assert_eq!(s.offset_a(), c.offset_b());
    }

    #[test]
    fn normals_are_normalised_at_any_scale_and_zero_is_rejected() {
        for scale in [1e-200, 1.0, 1e200] {
            let c = Contact::new(
                Vector3::new(0.0, 3.0, 4.0) * scale,
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
            assert!((c.normal() - Vector3::new(0.0, 0.6, 0.8)).amax() <= 2.0 * f64::EPSILON);
        }
        let e = Contact::<f64, 2>::between_balls(
            &Vector2::new(1.0, 1.0),
            1.0,
            &Vector2::new(1.0, 1.0),
            1.0,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "normal: must have non-zero length, got length 0"
        );
        let e = Contact::<f64, 2>::ball_surface(
            1.0,
            &Vector2::new(0.0, 1.0),
            &Vector2::new(f64::NAN, 0.0),
        )
        .unwrap_err();
        assert_eq!(e.field, "surface_offset[0]");
    }
}
