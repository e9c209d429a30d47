//! The ball: a circle in 2D, a sphere in 3D; the body carom simulates.

use carom_math::{
    InvalidValue, Real, Vector, ensure_finite, ensure_finite_vector, ensure_positive,
};

use crate::{Aabb, BoundingSphere};

/// A solid ball of positive radius.
///
/// Invariants (checked by [`Ball::new`]): the centre is finite, the radius finite and `> 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball<T: Real, const D: usize> {
    center: Vector<T, D>,
    radius: T,
}

impl<T: Real, const D: usize> Ball<T, D> {
    /// A ball at `center` with `radius`.
    ///
    /// # Errors
    /// `center[i]` if a component is not finite; `radius` if it is not finite or not `> 0`.
    pub fn new(center: Vector<T, D>, radius: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            center: ensure_finite_vector("center", &center)?,
            radius: ensure_positive("radius", radius)?,
        })
    }

    /// A ball from values the caller has already validated (hot paths).
    ///
    /// Debug builds assert the invariants of [`Ball::new`].
    #[inline]
    pub fn new_unchecked(center: Vector<T, D>, radius: T) -> Self {
        debug_assert!(center.iter().all(|c| c.finite()) && radius.finite() && radius > T::zero());
        Self { center, radius }
    }

    /// The centre.
    #[inline]
    pub fn center(&self) -> Vector<T, D> {
        self.center
    }

    /// The radius.
    #[inline]
    pub fn radius(&self) -> T {
        self.radius
    }

    /// The same ball moved by `offset`.
    #[inline]
    #[must_use]
    pub fn translated(&self, offset: &Vector<T, D>) -> Self {
        Self {
            center: self.center + offset,
            radius: self.radius,
        }
    }

    /// The tight axis-aligned box around the ball.
    #[inline]
    pub fn aabb(&self) -> Aabb<T, D> {
        let r = Vector::<T, D>::repeat(self.radius);
        Aabb::new_unchecked(self.center - r, self.center + r)
    }

    /// The ball as a bounding sphere.
    #[inline]
    pub fn bounding_sphere(&self) -> BoundingSphere<T, D> {
        BoundingSphere::new_unchecked(self.center, self.radius)
    }

    /// The box around every position the ball takes while moving at constant `velocity`
    /// from time `t0` to `t1` (either order; negative times follow the motion backwards).
    ///
    /// # Errors
    /// `velocity[i]`, `t0` or `t1` if not finite.
    pub fn swept_aabb(
        &self,
        velocity: &Vector<T, D>,
        t0: T,
        t1: T,
    ) -> Result<Aabb<T, D>, InvalidValue> {
        self.swept_aabb_accelerated(velocity, &Vector::zeros(), t0, t1)
    }

    /// The box around every position the ball takes on the parabola
    /// `c(t) = c + v t + a t²/2` for `t` between `t0` and `t1` (either order).
    ///
    /// Per axis the coordinate is a quadratic in `t`; its extremes on the interval are
    /// at the two ends and, when `aᵢ ≠ 0` and `t* = −vᵢ/aᵢ` lies inside, at the vertex.
    ///
    /// # Errors
    /// `velocity[i]`, `acceleration[i]`, `t0` or `t1` if not finite.
    pub fn swept_aabb_accelerated(
        &self,
        velocity: &Vector<T, D>,
        acceleration: &Vector<T, D>,
        t0: T,
        t1: T,
    ) -> Result<Aabb<T, D>, InvalidValue> {
        ensure_finite_vector("velocity", velocity)?;
        ensure_finite_vector("acceleration", acceleration)?;
        let (ta, tb) = {
            let (a, b) = (ensure_finite("t0", t0)?, ensure_finite("t1", t1)?);
            if a <= b { (a, b) } else { (b, a) }
        };
        let half = T::lit(0.5);
        let mut lo = Vector::<T, D>::zeros();
        let mut hi = Vector::<T, D>::zeros();
        for i in 0..D {
            let (c, v, a) = (self.center[i], velocity[i], acceleration[i]);
            let at = |t: T| c + v * t + half * a * t * t;
            let (mut mn, mut mx) = (at(ta).min(at(tb)), at(ta).max(at(tb)));
            if a != T::zero() {
                let vertex = -v / a;
                if vertex > ta && vertex < tb {
                    let x = at(vertex);
                    mn = mn.min(x);
                    mx = mx.max(x);
                }
            }
            lo[i] = mn - self.radius;
            hi[i] = mx + self.radius;
        }
        let aabb = Aabb::new(lo, hi)?;
        Ok(aabb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BoundingVolume;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn constructor_rejects_bad_radius_and_centre_naming_the_field() {
        assert_eq!(
            Ball::new(Vector2::new(0.0, 0.0), 0.0).unwrap_err().field,
            "radius"
        );
        assert_eq!(
            Ball::new(Vector2::new(0.0, 0.0), -1.0).unwrap_err().field,
            "radius"
        );
        assert_eq!(
            Ball::new(Vector2::new(0.0, 0.0), f64::NAN)
                .unwrap_err()
                .field,
            "radius"
        );
        let e = Ball::new(Vector3::new(0.0, f32::INFINITY, 0.0), 1.0).unwrap_err();
        assert_eq!(e.field, "center[1]");
        assert!(Ball::new(Vector3::new(1e300, -1e300, 0.0), 1e-300).is_ok());
    }

    #[test]
    fn aabb_is_tight() {
        let b = Ball::new(Vector2::new(1.0, -2.0), 0.5).unwrap();
        let a = b.aabb();
        assert_eq!(a.min(), Vector2::new(0.5, -2.5));
        assert_eq!(a.max(), Vector2::new(1.5, -1.5));
    }

    #[test]
    fn swept_aabb_covers_sampled_positions_forward_and_backward() {
        let b = Ball::new(Vector3::new(0.0, 1.0, 2.0), 0.25).unwrap();
        let v = Vector3::new(3.0, -1.0, 0.5);
        let g = Vector3::new(0.0, -9.81, 4.0);
        for (t0, t1) in [(0.0, 1.0), (1.0, -0.5), (-2.0, -1.0)] {
            let a = b.swept_aabb_accelerated(&v, &g, t0, t1).unwrap();
            for k in 0..=1000 {
                let t = t0 + (t1 - t0) * f64::from(k) / 1000.0;
                let c = b.center() + v * t + g * (0.5 * t * t);
                let s = Ball::new(c, b.radius()).unwrap().aabb();
                assert!(a.contains(&s), "t = {t}: {s:?} not in {a:?}");
            }
        }
    }

    #[test]
    fn swept_aabb_includes_the_apex_of_a_lob() {
        // Thrown up at 10 m/s under g = 10: apex 5 m up at t = 1, back down at t = 2.
        let b = Ball::new(Vector2::new(0.0, 0.0), 0.1).unwrap();
        let a = b
            .swept_aabb_accelerated(
                &Vector2::new(0.0, 10.0),
                &Vector2::new(0.0, -10.0),
                0.0,
                2.0,
            )
            .unwrap();
        assert!((a.max().y - 5.1_f64).abs() < 1e-12);
        assert!((a.min().y + 0.1_f64).abs() < 1e-12);
    }

    #[test]
    fn swept_aabb_rejects_non_finite_motion() {
        let b = Ball::new(Vector2::new(0.0, 0.0), 0.1).unwrap();
        let e = b
            .swept_aabb(&Vector2::new(f64::NAN, 0.0), 0.0, 1.0)
            .unwrap_err();
        assert_eq!(e.field, "velocity[0]");
        assert_eq!(
            b.swept_aabb(&Vector2::zeros(), 0.0, f64::INFINITY)
                .unwrap_err()
                .field,
            "t1"
        );
    }
}
