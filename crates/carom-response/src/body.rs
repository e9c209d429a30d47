//! A body as a collision sees it: inverse mass, inverse inertia, velocity and spin.
//!
//! Collision response needs no shape and no position: only how hard a body is to push
//! (inverse mass `1/m`), how hard to spin (world-frame inverse inertia `I⁻¹`), and how it
//! moves (velocity `v`, angular velocity `ω`). One type covers every case:
//!
//! | body | `1/m` | `I⁻¹` | velocity |
//! |---|---|---|---|
//! | ball | `1/m` | `1/(f m r²)`, `f` = 1/2 (disk) or 2/5 (sphere) | any |
//! | rigid cluster | `1/M` | `R I_body⁻¹ Rᵀ` | any |
//! | static (wall, floor) | 0 | 0 | zero |
//! | kinematic (paddle) | 0 | 0 | prescribed `v`, `ω` |
//!
//! Infinite mass is expressed by a zero inverse mass, so a wall is the same arithmetic
//! as a ball, without special cases and without infinities.

use carom_math::{
    InvalidValue, Problem, Real, Space, Vector, ensure_finite_vector, ensure_positive,
};
use nalgebra::Const;

use crate::{Angular, Inertia};

/// A body taking part in a collision.
///
/// Invariants (checked by the constructors): every field finite; the inverse mass and
/// the inverse inertia are either both positive (definite) — a *dynamic* body — or both
/// zero — an *immovable* body (static or kinematic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    inverse_mass: T,
    inverse_inertia: Inertia<T, D>,
    velocity: Vector<T, D>,
    angular_velocity: Angular<T, D>,
}

impl<T: Real, const D: usize> Body<T, D>
where
    Const<D>: Space<T, D>,
{
    /// A uniform ball (disk in 2D, solid sphere in 3D) of `mass` and `radius`, moving at
    /// `velocity` and spinning at `angular_velocity`.
    ///
    /// # Errors
    /// `mass` or `radius` if not finite and `> 0` (or if `m r²` under- or overflows so
    /// that the inverse inertia is not finite and positive); `velocity[i]` or
    /// `angular_velocity[i]` if not finite.
    pub fn ball(
        mass: T,
        radius: T,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        let mass = ensure_positive("mass", mass)?;
        let radius = ensure_positive("radius", radius)?;
        let inverse_mass = T::one() / mass; // > 0 (subnormal at worst) for finite mass > 0
        let inertia = <Const<D> as Space<T, D>>::ball_inertia_factor() * mass * radius * radius;
        let inverse_inertia = ensure_positive("radius", T::one() / inertia)?;
        Self::moving(
            inverse_mass,
            <Const<D> as Space<T, D>>::inertia_isotropic(inverse_inertia),
            velocity,
            angular_velocity,
        )
    }

    /// A dynamic rigid body of `mass` and world-frame `inertia` about its centre of mass.
    ///
    /// # Errors
    /// `mass` if not finite and `> 0`; `inertia` if not finite, symmetric and positive
    /// definite (see [`Space::inertia_inverse`]); `velocity[i]` or `angular_velocity[i]`
    /// if not finite.
    pub fn dynamic(
        mass: T,
        inertia: Inertia<T, D>,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        let mass = ensure_positive("mass", mass)?;
        let inverse_mass = T::one() / mass;
        let inverse_inertia = inverse_inertia_of(&inertia)?;
        Self::moving(inverse_mass, inverse_inertia, velocity, angular_velocity)
    }

    /// An immovable body at rest: a wall, a floor, a fixed obstacle.
    pub fn fixed() -> Self {
        Self {
            inverse_mass: T::zero(),
            inverse_inertia: <Const<D> as Space<T, D>>::inertia_isotropic(T::zero()),
            velocity: Vector::zeros(),
            angular_velocity: <Const<D> as Space<T, D>>::angular_zero(),
        }
    }

    /// An immovable body with prescribed motion (a paddle, a moving piston): collisions
    /// never change its velocity, and its velocity is passed on to what it hits.
    ///
    /// # Errors
    /// `velocity[i]` or `angular_velocity[i]` if not finite.
    pub fn kinematic(
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        let fixed = Self::fixed();
        Self::moving(
            fixed.inverse_mass,
            fixed.inverse_inertia,
            velocity,
            angular_velocity,
        )
    }

    fn moving(
        inverse_mass: T,
        inverse_inertia: Inertia<T, D>,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        ensure_finite_vector("velocity", &velocity)?;
        ensure_finite_angular("angular_velocity", &angular_velocity)?;
        Ok(Self {
            inverse_mass,
            inverse_inertia,
            velocity,
            angular_velocity,
        })
    }

    /// A body from values the caller has already validated (hot paths of an engine that
    /// stores inverse masses and inverse inertias).
    ///
    /// Debug builds assert finiteness and that `inverse_mass >= 0`.
    #[inline]
    pub fn new_unchecked(
        inverse_mass: T,
        inverse_inertia: Inertia<T, D>,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Self {
        debug_assert!(inverse_mass.finite() && inverse_mass >= T::zero());
        debug_assert!(
            <Const<D> as Space<T, D>>::inertia_as_slice(&inverse_inertia)
                .iter()
                .all(|x| x.finite())
        );
        debug_assert!(velocity.iter().all(|x| x.finite()));
        debug_assert!(
            <Const<D> as Space<T, D>>::angular_as_slice(&angular_velocity)
                .iter()
                .all(|x| x.finite())
        );
        Self {
            inverse_mass,
            inverse_inertia,
            velocity,
            angular_velocity,
        }
    }

    /// `1/m`; zero for static and kinematic bodies.
    #[inline]
    pub fn inverse_mass(&self) -> T {
        self.inverse_mass
    }

    /// `I⁻¹` in the world frame; zero for static and kinematic bodies.
    #[inline]
    pub fn inverse_inertia(&self) -> Inertia<T, D> {
        self.inverse_inertia
    }

    /// The velocity of the centre of mass.
    #[inline]
    pub fn velocity(&self) -> Vector<T, D> {
        self.velocity
    }

    /// The angular velocity.
    #[inline]
    pub fn angular_velocity(&self) -> Angular<T, D> {
        self.angular_velocity
    }

    /// `true` for a body with finite mass (collisions change its motion).
    #[inline]
    pub fn is_dynamic(&self) -> bool {
        self.inverse_mass > T::zero()
    }

    /// The velocity of the material point at `offset` from the centre of mass:
    /// `v + ω × offset`.
    #[inline]
    pub fn point_velocity(&self, offset: &Vector<T, D>) -> Vector<T, D> {
        self.velocity + <Const<D> as Space<T, D>>::angular_cross(&self.angular_velocity, offset)
    }

    /// The same body moving at `velocity` and `angular_velocity` (validated values:
    /// typically those of a [`Response`](crate::Response)).
    #[inline]
    #[must_use]
    pub fn with_velocities(&self, velocity: Vector<T, D>, angular_velocity: Angular<T, D>) -> Self {
        Self::new_unchecked(
            self.inverse_mass,
            self.inverse_inertia,
            velocity,
            angular_velocity,
        )
    }
}

/// `Ok(w)` if every component of the angular vector `w` is finite.
pub(crate) fn ensure_finite_angular<T: Real, const D: usize>(
    field: &'static str,
    w: &Angular<T, D>,
) -> Result<Angular<T, D>, InvalidValue>
where
    Const<D>: Space<T, D>,
{
    let components = <Const<D> as Space<T, D>>::angular_as_slice(w);
    match components.iter().position(|c| !c.finite()) {
        None => Ok(*w),
        Some(i) => Err(InvalidValue::new(
            format!("{field}[{i}]"),
            Problem::NotFinite(components[i].to_f64()),
        )),
    }
}

/// The inverse of a validated inertia, or an error naming `inertia`.
pub(crate) fn inverse_inertia_of<T: Real, const D: usize>(
    inertia: &Inertia<T, D>,
) -> Result<Inertia<T, D>, InvalidValue>
where
    Const<D>: Space<T, D>,
{
    <Const<D> as Space<T, D>>::inertia_inverse(inertia).ok_or_else(|| {
        let entries = <Const<D> as Space<T, D>>::inertia_as_slice(inertia);
        if let Some(bad) = entries.iter().find(|x| !x.finite()) {
            InvalidValue::new("inertia", Problem::NotFinite(bad.to_f64()))
        } else {
            InvalidValue::new("inertia", Problem::NotPositiveDefinite)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector1, Vector2, Vector3};

    #[test]
    fn ball_inverse_inertia_is_that_of_a_disk_or_a_solid_sphere() {
        let b2 = Body::<f64, 2>::ball(2.0, 0.5, Vector2::zeros(), Vector1::zeros()).unwrap();
        assert_eq!(b2.inverse_mass(), 0.5);
        assert_eq!(b2.inverse_inertia(), 1.0 / (0.5 * 2.0 * 0.25));
        let b3 = Body::<f64, 3>::ball(2.0, 0.5, Vector3::zeros(), Vector3::zeros()).unwrap();
        assert_eq!(
            b3.inverse_inertia(),
            Matrix3::from_diagonal_element(1.0 / (0.4 * 2.0 * 0.25))
        );
        assert!(b3.is_dynamic());
    }

    #[test]
    fn constructors_name_the_bad_field() {
        let z2 = Vector2::<f64>::zeros();
        let e = Body::<f64, 2>::ball(0.0, 1.0, z2, Vector1::zeros()).unwrap_err();
        assert_eq!(e.field, "mass");
        let e = Body::<f64, 2>::ball(1.0, -1.0, z2, Vector1::zeros()).unwrap_err();
        assert_eq!(e.field, "radius");
        let e = Body::<f64, 2>::ball(1.0, 1.0, Vector2::new(0.0, f64::NAN), Vector1::zeros())
            .unwrap_err();
        assert_eq!(e.field, "velocity[1]");
        let e = Body::<f64, 3>::kinematic(Vector3::zeros(), Vector3::new(0.0, 0.0, f64::INFINITY))
            .unwrap_err();
        assert_eq!(e.field, "angular_velocity[2]");
        // The largest mass still has a positive (subnormal) inverse: it stays dynamic.
        let heavy = Body::<f32, 2>::ball(f32::MAX, 1e-20, Vector2::zeros(), Vector1::zeros());
        assert!(heavy.unwrap().is_dynamic());
        // m r² overflows: the inverse inertia would be zero.
        let e = Body::<f32, 2>::ball(1e30, 1e10, Vector2::zeros(), Vector1::zeros()).unwrap_err();
        assert_eq!(e.field, "radius");
        let bad = Matrix3::from_diagonal(&Vector3::new(1.0, -2.0, 1.0));
        let e = Body::<f64, 3>::dynamic(1.0, bad, Vector3::zeros(), Vector3::zeros()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "inertia: must be symmetric positive definite"
        );
        let e =
            Body::<f64, 2>::dynamic(1.0, f64::NAN, Vector2::zeros(), Vector1::zeros()).unwrap_err();
        assert!(matches!(e.problem, Problem::NotFinite(_)));
    }

    #[test]
    fn fixed_and_kinematic_bodies_are_immovable_and_keep_their_motion() {
        let wall = Body::<f64, 2>::fixed();
        assert!(!wall.is_dynamic());
        assert_eq!(
            wall.point_velocity(&Vector2::new(3.0, 1.0)),
            Vector2::zeros()
        );
        let paddle = Body::<f64, 2>::kinematic(Vector2::new(1.0, 0.0), Vector1::new(2.0)).unwrap();
        assert_eq!(paddle.inverse_mass(), 0.0);
        // v + ω × r with ω = 2 ẑ, r = (0, 1): ω × r = (−2, 0).
        assert_eq!(
            paddle.point_velocity(&Vector2::new(0.0, 1.0)),
            Vector2::new(-1.0, 0.0)
        );
    }
}
