//! Ray casts: the first time a ray `origin + t · direction` (`t >= 0`) meets a solid shape.
//!
//! Time is in units of the direction vector, so a ray whose direction is a velocity gives
//! the time of impact of a point moving at that velocity (the time-of-impact crate builds
//! swept-ball tests on these). A ray that starts inside a shape or on its boundary hits at
//! `t = 0`, with the outward normal of the boundary point nearest to the origin.

use carom_math::{InvalidValue, Real, Vector, ensure_finite_vector};

use crate::query::PointQuery;
use crate::query::point::unit_and_length;
use crate::{Aabb, Ball, HalfSpace, Obb};

/// A half-line `origin + t · direction`, `t >= 0`. The direction need not be unit length,
/// and may be zero (such a ray only hits a shape it starts in).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray<T: Real, const D: usize> {
    origin: Vector<T, D>,
    direction: Vector<T, D>,
}

impl<T: Real, const D: usize> Ray<T, D> {
    /// The ray from `origin` along `direction`.
    ///
    /// # Errors
    /// `origin[i]` or `direction[i]` if not finite.
    pub fn new(origin: Vector<T, D>, direction: Vector<T, D>) -> Result<Self, InvalidValue> {
        Ok(Self {
            origin: ensure_finite_vector("origin", &origin)?,
            direction: ensure_finite_vector("direction", &direction)?,
        })
    }

    /// A ray from values the caller has already validated (hot paths).
    #[inline]
    pub fn new_unchecked(origin: Vector<T, D>, direction: Vector<T, D>) -> Self {
        debug_assert!(origin.iter().chain(direction.iter()).all(|x| x.finite()));
        Self { origin, direction }
    }

    /// The start point.
    #[inline]
    pub fn origin(&self) -> Vector<T, D> {
        self.origin
    }

    /// The direction (not normalised).
    #[inline]
    pub fn direction(&self) -> Vector<T, D> {
        self.direction
    }

    /// The point at parameter `t`: `origin + t · direction`.
    #[inline]
    pub fn point_at(&self, t: T) -> Vector<T, D> {
        self.origin + self.direction * t
    }
}

/// Where a ray meets a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit<T: Real, const D: usize> {
    /// The ray parameter of the hit, `0 <= toi <= max_toi` (0 if the ray starts inside).
    pub toi: T,
    /// The unit outward normal of the shape at the hit point.
    pub normal: Vector<T, D>,
}

/// Shapes a ray can be cast against.
pub trait RayCast<T: Real, const D: usize> {
    /// The first hit of `ray` with the solid shape at a parameter in `[0, max_toi]`
    /// (`max_toi` may be infinite), or `None`.
    fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>>;
}

/// [`RayCast::cast_ray`] as a free function.
///
/// ```
/// use carom_geometry::{d2, query::{cast_ray, Ray}};
/// use nalgebra::Vector2;
///
/// let target = d2::Ball::new(Vector2::new(10.0, 0.0), 1.0)?;
/// let ray = Ray::new(Vector2::new(0.0, 0.0), Vector2::new(3.0, 0.0))?; // 3 m/s
/// let hit = cast_ray(&target, &ray, f64::INFINITY).expect("straight at it");
/// assert_eq!(hit.toi, 3.0); // reaches the surface at x = 9 after 3 s
/// assert_eq!(hit.normal, Vector2::new(-1.0, 0.0));
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
#[inline]
pub fn cast_ray<T: Real, const D: usize, S: RayCast<T, D> + ?Sized>(
    shape: &S,
    ray: &Ray<T, D>,
    max_toi: T,
) -> Option<RayHit<T, D>> {
    shape.cast_ray(ray, max_toi)
}

/// The hit at `t = 0` of a ray starting inside `shape`, if `max_toi` allows it.
#[inline]
fn start_inside<T: Real, const D: usize, S: PointQuery<T, D>>(
    shape: &S,
    origin: &Vector<T, D>,
    max_toi: T,
) -> Option<RayHit<T, D>> {
    (max_toi >= T::zero()).then(|| RayHit {
        toi: T::zero(),
        normal: shape.boundary_point(origin).normal,
    })
}

/// The slab test against `[min, max]` for a ray starting outside the box.
///
/// Per axis the ray is between the two faces for `t` in `[(min − o)/d, (max − o)/d]`
/// (ordered by the sign of `d`); the ray is in the box where all these intervals overlap.
/// An axis with `d_i = 0` has no interval to intersect: the ray misses unless the origin
/// lies between the faces. Divisions are by `d_i` itself (no reciprocal), so a tiny `d_i`
/// gives an infinite bound and never `0 · ∞ = NaN`. The entry face is the axis of the
/// largest entry time (ties: the lowest axis).
#[inline]
fn slab_entry<T: Real, const D: usize>(
    min: &Vector<T, D>,
    max: &Vector<T, D>,
    o: &Vector<T, D>,
    d: &Vector<T, D>,
    max_toi: T,
) -> Option<RayHit<T, D>> {
    let mut enter = -T::INFINITY;
    let mut exit = T::INFINITY;
    let mut face = (0, T::zero());
    for i in 0..D {
        if d[i] == T::zero() {
            if o[i] < min[i] || o[i] > max[i] {
                return None;
            }
            continue;
        }
        let (to_min, to_max) = ((min[i] - o[i]) / d[i], (max[i] - o[i]) / d[i]);
        let (near, far, sign) = if d[i] > T::zero() {
            (to_min, to_max, -T::one())
        } else {
            (to_max, to_min, T::one())
        };
        if near > enter {
            enter = near;
            face = (i, sign);
        }
        exit = exit.min(far);
        if enter > exit {
            return None;
        }
    }
    // Outside the box some axis has o_i beyond a face and d_i towards it, so enter > 0
    // is finite here unless the ray misses.
    if !(enter >= T::zero() && enter <= max_toi && enter.finite()) {
        return None;
    }
    let mut normal = Vector::<T, D>::zeros();
    normal[face.0] = face.1;
    Some(RayHit { toi: enter, normal })
}

impl<T: Real, const D: usize> RayCast<T, D> for Aabb<T, D> {
    #[inline]
    fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>> {
        if self.contains_point(&ray.origin) {
            return start_inside(self, &ray.origin, max_toi);
        }
        slab_entry(
            &self.min(),
            &self.max(),
            &ray.origin,
            &ray.direction,
            max_toi,
        )
    }
}

/// The slab test in the box frame: origin `Rᵀ (o − c)`, direction `Rᵀ d`.
impl<T: Real, const D: usize> RayCast<T, D> for Obb<T, D> {
    #[inline]
    fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>> {
        let local = Ray {
            origin: self.to_local(&ray.origin),
            direction: self.vector_to_local(&ray.direction),
        };
        self.local_aabb()
            .cast_ray(&local, max_toi)
            .map(|hit| RayHit {
                toi: hit.toi,
                normal: self.vector_to_world(&hit.normal),
            })
    }
}

/// The smaller root of `|o' + t d|² = r²` with `o' = o − c`, written to avoid the two
/// cancellations of the textbook formula (Haines et al., "Precision Improvements for
/// Ray/Sphere Intersection", Ray Tracing Gems, 2019):
///
/// * the discriminant `b² − a c` (`a = d·d`, `b = o'·d`, `c = |o'|² − r²`) equals
///   `a (r² − |l|²)` where `l = o' − (b/a) d` is the offset of the centre from the line,
///   computed directly instead of as a difference of nearly equal products;
/// * the root `(−b − √disc)/a` is taken as `c / (−b + √disc)` (`b < 0` for an approaching
///   ray, so the denominator adds two positive numbers).
impl<T: Real, const D: usize> RayCast<T, D> for Ball<T, D> {
    #[inline]
    fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>> {
        let r = self.radius();
        let oc = ray.origin - self.center();
        if oc.norm_squared() <= r * r {
            return start_inside(self, &ray.origin, max_toi);
        }
        // A direction whose squared length underflows or overflows is cast as a unit
        // direction, and the time scaled back by its length (a zero direction becomes
        // `+x` at speed 0: its infinite time is rejected below).
        let (d, speed) = {
            let a = ray.direction.norm_squared();
            if a >= T::MIN_POSITIVE && a <= T::MAX {
                (ray.direction, T::one())
            } else {
                unit_and_length(&ray.direction)
            }
        };
        let b = oc.dot(&d);
        if b >= T::zero() {
            return None; // moving away
        }
        let a = d.norm_squared();
        let l = oc - d * (b / a);
        let disc = r * r - l.norm_squared();
        if disc < T::zero() {
            return None;
        }
        let t_unit = (oc.norm_squared() - r * r) / (-b + (a * disc).sqrt());
        let t = t_unit / speed;
        if !(t <= max_toi && t.finite()) {
            return None;
        }
        Some(RayHit {
            toi: t.max(T::zero()),
            normal: unit_and_length(&(oc + d * t_unit)).0,
        })
    }
}

impl<T: Real, const D: usize> RayCast<T, D> for HalfSpace<T, D> {
    #[inline]
    fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>> {
        let s = self.signed_distance(&ray.origin);
        if s <= T::zero() {
            return start_inside(self, &ray.origin, max_toi);
        }
        let approach = -self.normal().dot(&ray.direction);
        if approach <= T::zero() {
            return None;
        }
        let t = s / approach;
        (t <= max_toi && t.finite()).then(|| RayHit {
            toi: t,
            normal: self.normal(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    fn ray2(o: (f64, f64), d: (f64, f64)) -> Ray<f64, 2> {
        Ray::new(Vector2::new(o.0, o.1), Vector2::new(d.0, d.1)).unwrap()
    }

    #[test]
    fn slabs_handle_zero_direction_components() {
        let b = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        // Parallel to x, inside the y slab: hits the left face.
        let hit = b.cast_ray(&ray2((-2.0, 0.5), (1.0, 0.0)), 10.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (2.0, -Vector2::x()));
        // Parallel to x along the lower face exactly: the face is part of the solid box.
        let hit = b.cast_ray(&ray2((-2.0, 0.0), (1.0, 0.0)), 10.0).unwrap();
        assert_eq!(hit.toi, 2.0);
        // Parallel to x outside the y slab: miss.
        assert!(b.cast_ray(&ray2((-2.0, 1.5), (1.0, 0.0)), 10.0).is_none());
        // A zero direction misses from outside and hits at 0 from inside.
        assert!(b.cast_ray(&ray2((-2.0, 0.5), (0.0, 0.0)), 10.0).is_none());
        let hit = b.cast_ray(&ray2((0.5, 0.9), (0.0, 0.0)), 10.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (0.0, Vector2::y()));
        // A tiny direction gives an infinite time beyond reach, not NaN.
        assert!(
            b.cast_ray(&ray2((-2.0, 0.5), (1e-320, 0.0)), 1e300)
                .is_none()
        );
    }

    #[test]
    fn slabs_report_the_entry_face_and_respect_max_toi() {
        let b = Aabb::new(Vector3::zeros(), Vector3::repeat(1.0)).unwrap();
        let r = Ray::new(Vector3::new(0.5, 3.0, 0.5), Vector3::new(0.0, -2.0, 0.0)).unwrap();
        let hit = b.cast_ray(&r, 1.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (1.0, Vector3::y()));
        assert!(b.cast_ray(&r, 0.999).is_none());
        // Through an edge at 45°: the tie goes to the lowest axis.
        let r = Ray::new(Vector3::new(-1.0, -1.0, 0.5), Vector3::new(1.0, 1.0, 0.0)).unwrap();
        let hit = b.cast_ray(&r, 10.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (1.0, -Vector3::x()));
        // Pointing away.
        let r = Ray::new(Vector3::new(2.0, 0.5, 0.5), Vector3::new(1.0, 0.0, 0.0)).unwrap();
        assert!(b.cast_ray(&r, f64::INFINITY).is_none());
    }

    #[test]
    fn ball_hits_head_on_grazing_and_from_inside() {
        let b = Ball::new(Vector2::new(0.0, 0.0), 1.0).unwrap();
        let hit = b.cast_ray(&ray2((-5.0, 0.0), (2.0, 0.0)), 10.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (2.0, -Vector2::x()));
        // Grazing the top: tangent at (0, 1) after 5 s.
        let hit = b.cast_ray(&ray2((-5.0, 1.0), (1.0, 0.0)), 10.0).unwrap();
        assert_relative_eq!(hit.toi, 5.0, epsilon = 1e-12);
        assert_relative_eq!(hit.normal, Vector2::y(), epsilon = 1e-6);
        assert!(
            b.cast_ray(&ray2((-5.0, 1.0 + 1e-12), (1.0, 0.0)), 10.0)
                .is_none()
        );
        let hit = b.cast_ray(&ray2((0.0, 0.5), (1.0, 0.0)), 10.0).unwrap();
        assert_eq!((hit.toi, hit.normal), (0.0, Vector2::y()));
        // From the centre: the documented +x normal.
        let hit = b.cast_ray(&ray2((0.0, 0.0), (0.0, 1.0)), 10.0).unwrap();
        assert_eq!(hit.normal, Vector2::x());
        assert!(b.cast_ray(&ray2((0.0, 0.5), (1.0, 0.0)), -1.0).is_none());
        // A zero direction from outside never arrives; a tiny one arrives very late.
        assert!(
            b.cast_ray(&ray2((-5.0, 0.0), (0.0, 0.0)), f64::INFINITY)
                .is_none()
        );
        let hit = b
            .cast_ray(&ray2((-5.0, 0.0), (1e-200, 0.0)), f64::INFINITY)
            .unwrap();
        assert_relative_eq!(hit.toi, 4e200, max_relative = 1e-15);
        assert_eq!(hit.normal, -Vector2::x());
    }

    #[test]
    fn ball_hit_far_away_keeps_its_precision() {
        // A 1 mm ball 1 km away along a unit direction: the textbook formula loses
        // the millimetre in |o|² − r²; this one keeps it.
        let b = Ball::new(Vector3::new(1000.0, 0.0, 0.0), 1e-3).unwrap();
        let r = Ray::new(Vector3::zeros(), Vector3::x()).unwrap();
        let hit = b.cast_ray(&r, f64::INFINITY).unwrap();
        assert_relative_eq!(hit.toi, 1000.0 - 1e-3, max_relative = 1e-15);
    }

    #[test]
    fn obb_ray_uses_the_box_frame() {
        let o = Obb::<f64, 2>::from_angle(
            Vector2::zeros(),
            Vector2::new(1.0, 1.0),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        let hit = o.cast_ray(&ray2((-5.0, 0.0), (1.0, 0.0)), 10.0).unwrap();
        assert_relative_eq!(hit.toi, 5.0 - 2f64.sqrt(), epsilon = 1e-12);
        // The corner: either adjacent face normal, pointing back at the ray.
        assert!(hit.normal.x < 0.0);
        assert_relative_eq!(hit.normal.norm(), 1.0, epsilon = 1e-15);
    }

    #[test]
    fn half_space_from_outside_inside_and_parallel() {
        let floor = HalfSpace::new(Vector2::y(), Vector2::zeros()).unwrap();
        let hit = floor
            .cast_ray(&ray2((0.0, 4.0), (1.0, -2.0)), 10.0)
            .unwrap();
        assert_eq!((hit.toi, hit.normal), (2.0, Vector2::y()));
        assert!(
            floor
                .cast_ray(&ray2((0.0, 4.0), (1.0, 0.0)), 10.0)
                .is_none()
        );
        assert!(
            floor
                .cast_ray(&ray2((0.0, 4.0), (0.0, 1.0)), 10.0)
                .is_none()
        );
        let hit = floor
            .cast_ray(&ray2((0.0, -1.0), (0.0, 1.0)), 10.0)
            .unwrap();
        assert_eq!(hit.toi, 0.0);
    }

    #[test]
    fn constructor_rejects_non_finite_values() {
        let e = Ray::new(Vector2::new(0.0, f64::NAN), Vector2::zeros()).unwrap_err();
        assert_eq!(e.field, "origin[1]");
        let e = Ray::new(Vector2::zeros(), Vector2::new(f64::INFINITY, 0.0)).unwrap_err();
        assert_eq!(e.field, "direction[0]");
    }
}
