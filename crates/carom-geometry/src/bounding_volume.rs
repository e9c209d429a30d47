//! Bounding volumes: what a broad phase needs from a box or a sphere around an object.

use carom_math::{InvalidValue, Real, Vector, ensure_finite_vector, ensure_non_negative};

use crate::Aabb;

/// The operations a broad phase performs on bounding volumes.
///
/// All methods are exact up to one rounding per operation; `merged` and `loosened`
/// never shrink (the result contains the inputs even after rounding, see the impls).
pub trait BoundingVolume<T: Real, const D: usize>: Copy {
    /// The centre of the volume.
    fn center(&self) -> Vector<T, D>;
    /// The half extents of its axis-aligned extent (a sphere: the radius on every axis).
    fn half_extents(&self) -> Vector<T, D>;
    /// The area (2D) or volume (3D).
    fn volume(&self) -> T;
    /// The smallest volume of this kind containing both (exact for boxes; for spheres
    /// the smallest sphere containing both spheres).
    #[must_use]
    fn merged(&self, other: &Self) -> Self;
    /// `true` if `other` lies entirely inside `self` (boundaries may touch).
    fn contains(&self, other: &Self) -> bool;
    /// `true` if the two overlap or touch.
    fn intersects(&self, other: &Self) -> bool;
    /// The volume grown by `margin >= 0` on every side (a fattened broad-phase proxy).
    #[must_use]
    fn loosened(&self, margin: T) -> Self;
}

impl<T: Real, const D: usize> BoundingVolume<T, D> for Aabb<T, D> {
    #[inline]
    fn center(&self) -> Vector<T, D> {
        (self.min() + self.max()) * T::lit(0.5)
    }

    #[inline]
    fn half_extents(&self) -> Vector<T, D> {
        self.extents() * T::lit(0.5)
    }

    #[inline]
    fn volume(&self) -> T {
        self.extents().product()
    }

    #[inline]
    fn merged(&self, other: &Self) -> Self {
        Aabb::new_unchecked(self.min().inf(&other.min()), self.max().sup(&other.max()))
    }

    #[inline]
    fn contains(&self, other: &Self) -> bool {
        (0..D).all(|i| self.min()[i] <= other.min()[i] && other.max()[i] <= self.max()[i])
    }

    /// Branch-free over the axes (`&`, not `&&`): a broad phase sees overlapping and
    /// separate pairs in no predictable order, and mispredicted early exits cost more
    /// than the few comparisons they save.
    #[inline]
    fn intersects(&self, other: &Self) -> bool {
        (0..D).fold(true, |all, i| {
            all & (self.min()[i] <= other.max()[i]) & (other.min()[i] <= self.max()[i])
        })
    }

    #[inline]
    fn loosened(&self, margin: T) -> Self {
        debug_assert!(margin >= T::zero());
        let m = Vector::<T, D>::repeat(margin);
        Aabb::new_unchecked(self.min() - m, self.max() + m)
    }
}

/// A sphere (circle in 2D) used as a bounding volume; unlike a [`Ball`](crate::Ball),
/// its radius may be zero (the bounding sphere of one point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere<T: Real, const D: usize> {
    center: Vector<T, D>,
    radius: T,
}

impl<T: Real, const D: usize> BoundingSphere<T, D> {
    /// A sphere at `center` with `radius >= 0`.
    ///
    /// # Errors
    /// `center[i]` if not finite; `radius` if not finite or negative.
    pub fn new(center: Vector<T, D>, radius: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            center: ensure_finite_vector("center", &center)?,
            radius: ensure_non_negative("radius", radius)?,
        })
    }

    /// A sphere from values the caller has already validated (hot paths).
    #[inline]
    pub fn new_unchecked(center: Vector<T, D>, radius: T) -> Self {
        debug_assert!(radius >= T::zero());
        Self { center, radius }
    }

    /// The radius.
    #[inline]
    pub fn radius(&self) -> T {
        self.radius
    }

    /// `true` if `p` is inside or on the sphere.
    #[inline]
    pub fn contains_point(&self, p: &Vector<T, D>) -> bool {
        (p - self.center).norm_squared() <= self.radius * self.radius
    }

    /// The tight axis-aligned box around the sphere.
    #[inline]
    pub fn aabb(&self) -> Aabb<T, D> {
        let r = Vector::<T, D>::repeat(self.radius);
        Aabb::new_unchecked(self.center - r, self.center + r)
    }
}

/// The content of the unit ball in `D` dimensions: 2, π, 4π/3.
fn unit_ball_volume<T: Real>(d: usize) -> T {
    match d {
        1 => T::lit(2.0),
        2 => T::pi(),
        3 => T::lit(4.0 / 3.0) * T::pi(),
        // V_d = 2π/d · V_{d−2}: carom uses D = 2 and 3, the recurrence keeps this total.
        _ => T::two_pi() / T::from_count(d) * unit_ball_volume::<T>(d - 2),
    }
}

impl<T: Real, const D: usize> BoundingVolume<T, D> for BoundingSphere<T, D> {
    #[inline]
    fn center(&self) -> Vector<T, D> {
        self.center
    }

    #[inline]
    fn half_extents(&self) -> Vector<T, D> {
        Vector::repeat(self.radius)
    }

    #[inline]
    fn volume(&self) -> T {
        (0..D).fold(unit_ball_volume::<T>(D), |v, _| v * self.radius)
    }

    /// The smallest sphere containing both. With `d = |c₂ − c₁|`: if one contains the
    /// other, that one; otherwise radius `(d + r₁ + r₂)/2` and centre on the segment
    /// between the centres, `(R − r₁)/d` of the way from `c₁`. The radius is then bumped
    /// by the rounding error so the result really contains both inputs.
    fn merged(&self, other: &Self) -> Self {
        let delta = other.center - self.center;
        let d = delta.norm();
        if d + other.radius <= self.radius {
            return *self;
        }
        if d + self.radius <= other.radius {
            return *other;
        }
        let r = (d + self.radius + other.radius) * T::lit(0.5);
        let center = self.center + delta * ((r - self.radius) / d);
        // Up to a few ulp of the coordinates can separate the computed centre from the
        // true one; grow the radius by that much.
        let slack = T::lit(4.0) * T::EPSILON * (r + self.center.amax().max(other.center.amax()));
        Self {
            center,
            radius: r + slack,
        }
    }

    #[inline]
    fn contains(&self, other: &Self) -> bool {
        (other.center - self.center).norm() + other.radius <= self.radius
    }

    #[inline]
    fn intersects(&self, other: &Self) -> bool {
        let r = self.radius + other.radius;
        (other.center - self.center).norm_squared() <= r * r
    }

    #[inline]
    fn loosened(&self, margin: T) -> Self {
        debug_assert!(margin >= T::zero());
        Self {
            center: self.center,
            radius: self.radius + margin,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn aabb_operations() {
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(2.0, 1.0)).unwrap();
        let b = Aabb::new(Vector2::new(2.0, -1.0), Vector2::new(3.0, 0.0)).unwrap();
        assert!(a.intersects(&b), "touching at a corner counts");
        let m = a.merged(&b);
        assert!(m.contains(&a) && m.contains(&b));
        assert_eq!(m.volume(), 6.0);
        assert_eq!(a.center(), Vector2::new(1.0, 0.5));
        assert_eq!(a.loosened(0.5).extents(), Vector2::new(3.0, 2.0));
        let far = b.translated(&Vector2::new(0.0, -1e-12));
        assert!(!a.intersects(&far));
    }

    #[test]
    fn sphere_volumes_are_disk_area_and_ball_volume() {
        let c = BoundingSphere::new(Vector2::new(0.0, 0.0), 2.0).unwrap();
        assert_relative_eq!(c.volume(), 4.0 * std::f64::consts::PI);
        let s = BoundingSphere::new(Vector3::new(0.0, 0.0, 0.0), 2.0).unwrap();
        assert_relative_eq!(s.volume(), 32.0 / 3.0 * std::f64::consts::PI);
    }

    #[test]
    fn sphere_merge_is_minimal_and_contains_both() {
        let a = BoundingSphere::new(Vector2::new(0.0, 0.0), 1.0).unwrap();
        let b = BoundingSphere::new(Vector2::new(4.0, 0.0), 1.0).unwrap();
        let m = a.merged(&b);
        assert!(m.contains(&a) && m.contains(&b));
        assert_relative_eq!(m.radius(), 3.0, epsilon = 1e-12);
        assert_relative_eq!(m.center(), Vector2::new(2.0, 0.0), epsilon = 1e-12);
        let inner = BoundingSphere::new(Vector2::new(0.5, 0.0), 0.25).unwrap();
        assert_eq!(a.merged(&inner), a);
        assert_eq!(inner.merged(&a), a);
    }

    #[test]
    fn sphere_merge_contains_both_far_from_the_origin() {
        let a = BoundingSphere::new(Vector3::new(1e6, 1e6, -1e6), 1e-3).unwrap();
        let b = BoundingSphere::new(Vector3::new(1e6 + 0.1, 1e6 - 0.3, -1e6 + 0.2), 2e-3).unwrap();
        let m = a.merged(&b);
        assert!(m.contains(&a) && m.contains(&b));
    }

    #[test]
    fn bounding_sphere_rejects_negative_radius_but_allows_zero() {
        assert!(BoundingSphere::new(Vector2::new(0.0, 0.0), 0.0).is_ok());
        assert_eq!(
            BoundingSphere::new(Vector2::new(0.0, 0.0), -1.0)
                .unwrap_err()
                .field,
            "radius"
        );
    }
}
