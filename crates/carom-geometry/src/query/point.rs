//! Point queries: the closest point of a shape, the signed distance, containment, and
//! the nearest boundary point with its outward normal (the building block of contacts).

use carom_math::{Real, Vector};

use crate::{Aabb, Ball, HalfSpace, Obb};

/// The point of a shape's boundary nearest to a query point `p`, with the outward normal
/// there and the signed distance of `p`.
///
/// The three parts agree: `p ≈ point + signed_distance · normal` (up to rounding), both
/// outside (`signed_distance > 0`, the normal points from the shape towards `p`) and inside
/// (`signed_distance < 0`, the normal is the outward normal of the nearest face).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryPoint<T: Real, const D: usize> {
    /// The nearest point of the boundary.
    pub point: Vector<T, D>,
    /// The unit outward normal of the boundary at `point`.
    pub normal: Vector<T, D>,
    /// The signed distance of the query point: positive outside, negative inside, zero on
    /// the boundary.
    pub signed_distance: T,
}

/// Queries of a solid shape against a point.
///
/// Degenerate cases have one documented, deterministic answer:
/// * a point at a ball's centre has boundary normal `+x` (the first axis);
/// * a point inside a box (or on its boundary) projects on the face of least penetration;
///   ties go to the lowest axis index and, on one axis, to the upper face (so the centre
///   of a cube projects on its `+x` face);
/// * zero-size boxes are points, segments or faces and follow the same rules.
pub trait PointQuery<T: Real, const D: usize> {
    /// The point of the solid shape closest to `p`: `p` itself when `p` is inside.
    fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D>;

    /// The signed distance from `p` to the shape's boundary: negative inside.
    fn signed_distance_to_point(&self, p: &Vector<T, D>) -> T;

    /// The distance from `p` to the solid shape: zero inside.
    #[inline]
    fn distance_to_point(&self, p: &Vector<T, D>) -> T {
        self.signed_distance_to_point(p).max(T::zero())
    }

    /// `true` if `p` is inside or on the boundary.
    fn contains_point(&self, p: &Vector<T, D>) -> bool;

    /// The nearest boundary point, its outward normal and the signed distance of `p`.
    fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D>;

    /// [`boundary_point`](Self::boundary_point) if the signed distance of `p` is at most
    /// `reach`, else `None`. Shapes override it to reject far points without a square
    /// root (ball contacts call it with `reach` = the radius).
    #[inline]
    fn boundary_point_within(&self, p: &Vector<T, D>, reach: T) -> Option<BoundaryPoint<T, D>> {
        let b = self.boundary_point(p);
        (b.signed_distance <= reach).then_some(b)
    }
}

/// The unit vector along `v` and the length of `v`; `(+x, 0)` for the zero vector.
///
/// Squared lengths below the smallest normal number (|v| < 1e-154 in `f64`) or above the
/// largest finite one (|v| > 1e154) are rescaled by the largest component first, so the
/// direction is unit and finite for every finite non-zero `v`.
#[inline]
pub(crate) fn unit_and_length<T: Real, const D: usize>(v: &Vector<T, D>) -> (Vector<T, D>, T) {
    let n2 = v.norm_squared();
    if n2 >= T::MIN_POSITIVE && n2 <= T::MAX {
        let n = n2.sqrt();
        return (v / n, n);
    }
    let scale = v.amax();
    if scale == T::zero() {
        return (first_axis(), T::zero());
    }
    let s = v / scale;
    let n = s.norm();
    (s / n, n * scale)
}

/// `+x`: the documented normal where none is defined.
#[inline]
pub(crate) fn first_axis<T: Real, const D: usize>() -> Vector<T, D> {
    let mut e = Vector::<T, D>::zeros();
    e[0] = T::one();
    e
}

/// The face of `[min, max]` nearest to `p` (inside the box): `(gap, axis, upper)` with the
/// gap `max[i] − p[i]` or `p[i] − min[i]`. Ties go to the lowest axis, then the upper face.
#[inline]
fn least_penetration_face<T: Real, const D: usize>(
    min: &Vector<T, D>,
    max: &Vector<T, D>,
    p: &Vector<T, D>,
) -> (T, usize, bool) {
    let mut best = (max[0] - p[0], 0, true);
    for i in 0..D {
        let upper = max[i] - p[i];
        if upper < best.0 {
            best = (upper, i, true);
        }
        let lower = p[i] - min[i];
        if lower < best.0 {
            best = (lower, i, false);
        }
    }
    best
}

/// `p` clamped into `[min, max]`: the closest point of the solid box.
#[inline]
fn clamp<T: Real, const D: usize>(
    min: &Vector<T, D>,
    max: &Vector<T, D>,
    p: &Vector<T, D>,
) -> Vector<T, D> {
    p.sup(min).inf(max)
}

/// The boundary point of `[min, max]` nearest to `p`, given `q = clamp(p)`.
///
/// Outside (`|p − q|² ≥` the smallest normal number) the nearest point is `q` and the
/// normal `(p − q)/|p − q|`. Otherwise `p` is inside, on the boundary, or outside by less
/// than 1e-154, and projects on the face of least penetration (a negative gap there is
/// the tiny outside distance, so the answer stays exact).
#[inline]
fn box_boundary_point<T: Real, const D: usize>(
    min: &Vector<T, D>,
    max: &Vector<T, D>,
    p: &Vector<T, D>,
    q: Vector<T, D>,
) -> BoundaryPoint<T, D> {
    let d = p - q;
    let d2 = d.norm_squared();
    if d2 >= T::MIN_POSITIVE {
        let (normal, dist) = unit_and_length(&d);
        return BoundaryPoint {
            point: q,
            normal,
            signed_distance: dist,
        };
    }
    let (gap, axis, upper) = least_penetration_face(min, max, p);
    let mut point = *p;
    let mut normal = Vector::<T, D>::zeros();
    if upper {
        point[axis] = max[axis];
        normal[axis] = T::one();
    } else {
        point[axis] = min[axis];
        normal[axis] = -T::one();
    }
    BoundaryPoint {
        point,
        normal,
        signed_distance: -gap,
    }
}

/// [`box_boundary_point`] if the signed distance is at most `reach`; far points are
/// rejected by comparing squared distances.
#[inline]
fn box_boundary_point_within<T: Real, const D: usize>(
    min: &Vector<T, D>,
    max: &Vector<T, D>,
    p: &Vector<T, D>,
    reach: T,
) -> Option<BoundaryPoint<T, D>> {
    let q = clamp(min, max, p);
    let d2 = (p - q).norm_squared();
    if d2 >= T::MIN_POSITIVE && (reach < T::zero() || d2 > reach * reach) {
        return None;
    }
    let b = box_boundary_point(min, max, p, q);
    (b.signed_distance <= reach).then_some(b)
}

impl<T: Real, const D: usize> PointQuery<T, D> for Aabb<T, D> {
    #[inline]
    fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D> {
        clamp(&self.min(), &self.max(), p)
    }

    #[inline]
    fn signed_distance_to_point(&self, p: &Vector<T, D>) -> T {
        let (min, max) = (self.min(), self.max());
        box_boundary_point(&min, &max, p, clamp(&min, &max, p)).signed_distance
    }

    #[inline]
    fn distance_to_point(&self, p: &Vector<T, D>) -> T {
        (p - self.closest_point(p)).norm()
    }

    #[inline]
    fn contains_point(&self, p: &Vector<T, D>) -> bool {
        Aabb::contains_point(self, p)
    }

    #[inline]
    fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D> {
        let (min, max) = (self.min(), self.max());
        box_boundary_point(&min, &max, p, clamp(&min, &max, p))
    }

    #[inline]
    fn boundary_point_within(&self, p: &Vector<T, D>, reach: T) -> Option<BoundaryPoint<T, D>> {
        box_boundary_point_within(&self.min(), &self.max(), p, reach)
    }
}

/// An oriented box answers every point query as its local axis-aligned box does, in the
/// box's frame: `p_local = Rᵀ (p − c)`, results mapped back by `c + R x` and `R n`.
impl<T: Real, const D: usize> PointQuery<T, D> for Obb<T, D> {
    #[inline]
    fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D> {
        let local = self.to_local(p);
        let h = self.half_extents();
        let q = clamp(&-h, &h, &local);
        if q == local { *p } else { self.to_world(&q) }
    }

    #[inline]
    fn signed_distance_to_point(&self, p: &Vector<T, D>) -> T {
        self.local_aabb()
            .signed_distance_to_point(&self.to_local(p))
    }

    #[inline]
    fn distance_to_point(&self, p: &Vector<T, D>) -> T {
        self.local_aabb().distance_to_point(&self.to_local(p))
    }

    #[inline]
    fn contains_point(&self, p: &Vector<T, D>) -> bool {
        let local = self.to_local(p);
        let h = self.half_extents();
        (0..D).all(|i| local[i].abs() <= h[i])
    }

    #[inline]
    fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D> {
        self.boundary_to_world(self.local_aabb().boundary_point(&self.to_local(p)))
    }

    #[inline]
    fn boundary_point_within(&self, p: &Vector<T, D>, reach: T) -> Option<BoundaryPoint<T, D>> {
        let h = self.half_extents();
        box_boundary_point_within(&-h, &h, &self.to_local(p), reach)
            .map(|b| self.boundary_to_world(b))
    }
}

impl<T: Real, const D: usize> Obb<T, D> {
    /// A boundary point computed in the box frame, mapped to world coordinates.
    #[inline]
    fn boundary_to_world(&self, b: BoundaryPoint<T, D>) -> BoundaryPoint<T, D> {
        BoundaryPoint {
            point: self.to_world(&b.point),
            normal: self.vector_to_world(&b.normal),
            signed_distance: b.signed_distance,
        }
    }
}

impl<T: Real, const D: usize> PointQuery<T, D> for Ball<T, D> {
    #[inline]
    fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D> {
        let d = p - self.center();
        let r = self.radius();
        if d.norm_squared() <= r * r {
            return *p;
        }
        let (n, _) = unit_and_length(&d);
        self.center() + n * r
    }

    #[inline]
    fn signed_distance_to_point(&self, p: &Vector<T, D>) -> T {
        unit_and_length(&(p - self.center())).1 - self.radius()
    }

    #[inline]
    fn contains_point(&self, p: &Vector<T, D>) -> bool {
        let r = self.radius();
        (p - self.center()).norm_squared() <= r * r
    }

    #[inline]
    fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D> {
        let (normal, dist) = unit_and_length(&(p - self.center()));
        BoundaryPoint {
            point: self.center() + normal * self.radius(),
            normal,
            signed_distance: dist - self.radius(),
        }
    }

    #[inline]
    fn boundary_point_within(&self, p: &Vector<T, D>, reach: T) -> Option<BoundaryPoint<T, D>> {
        // |p − c| − r <= reach  ⇔  |p − c|² <= (r + reach)²  when r + reach >= 0.
        let limit = self.radius() + reach;
        let d2 = (p - self.center()).norm_squared();
        if limit < T::zero() || d2 > limit * limit {
            return None;
        }
        let b = self.boundary_point(p);
        (b.signed_distance <= reach).then_some(b)
    }
}

impl<T: Real, const D: usize> PointQuery<T, D> for HalfSpace<T, D> {
    #[inline]
    fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D> {
        if self.signed_distance(p) > T::zero() {
            self.project(p)
        } else {
            *p
        }
    }

    #[inline]
    fn signed_distance_to_point(&self, p: &Vector<T, D>) -> T {
        self.signed_distance(p)
    }

    #[inline]
    fn contains_point(&self, p: &Vector<T, D>) -> bool {
        self.signed_distance(p) <= T::zero()
    }

    #[inline]
    fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D> {
        let s = self.signed_distance(p);
        BoundaryPoint {
            point: p - self.normal() * s,
            normal: self.normal(),
            signed_distance: s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn unit_and_length_is_unit_for_tiny_and_huge_vectors_and_x_for_zero() {
        for v in [
            Vector2::new(3e-170, -4e-170),
            Vector2::new(3e170, 4e170),
            Vector2::new(3.0, 4.0),
            Vector2::new(0.0, 1e-320),
        ] {
            let (n, l) = unit_and_length(&v);
            assert_relative_eq!(n.norm(), 1.0, epsilon = 1e-15);
            assert_relative_eq!(n * l, v, max_relative = 1e-15);
        }
        assert_eq!(
            unit_and_length(&Vector3::<f32>::zeros()),
            (Vector3::x(), 0.0)
        );
    }

    #[test]
    fn box_projection_outside_is_the_clamp_and_inside_the_nearest_face() {
        let b = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(4.0, 2.0)).unwrap();
        // Outside a corner: 3-4-5 triangle.
        let bp = b.boundary_point(&Vector2::new(7.0, 6.0));
        assert_eq!(bp.point, Vector2::new(4.0, 2.0));
        assert_eq!(bp.signed_distance, 5.0);
        assert_relative_eq!(bp.normal, Vector2::new(0.6, 0.8));
        // Inside, nearest to the lower y face.
        let bp = b.boundary_point(&Vector2::new(1.5, 0.5));
        assert_eq!(bp.point, Vector2::new(1.5, 0.0));
        assert_eq!(bp.normal, Vector2::new(0.0, -1.0));
        assert_eq!(bp.signed_distance, -0.5);
        assert_eq!(
            b.closest_point(&Vector2::new(1.5, 0.5)),
            Vector2::new(1.5, 0.5)
        );
        assert_eq!(b.signed_distance_to_point(&Vector2::new(-1.0, 1.0)), 1.0);
        assert_eq!(b.distance_to_point(&Vector2::new(1.0, 1.0)), 0.0);
    }

    #[test]
    fn ties_inside_a_box_go_to_the_lowest_axis_then_the_upper_face() {
        let cube = Aabb::new(Vector3::repeat(-1.0), Vector3::repeat(1.0)).unwrap();
        let bp = cube.boundary_point(&Vector3::zeros());
        assert_eq!(bp.normal, Vector3::x());
        assert_eq!(bp.point, Vector3::x());
        assert_eq!(bp.signed_distance, -1.0);
        // Equidistant from the x and y faces: the x face wins.
        let bp = cube.boundary_point(&Vector3::new(-0.5, -0.5, 0.0));
        assert_eq!(bp.normal, -Vector3::x());
        // A zero-size box: the point itself, upper x face.
        let dot = Aabb::new(Vector2::new(1.0, 1.0), Vector2::new(1.0, 1.0)).unwrap();
        let bp = dot.boundary_point(&Vector2::new(1.0, 1.0));
        assert_eq!((bp.normal, bp.signed_distance), (Vector2::x(), 0.0));
        let bp = dot.boundary_point(&Vector2::new(1.0, 3.0));
        assert_eq!((bp.normal, bp.signed_distance), (Vector2::y(), 2.0));
    }

    #[test]
    fn a_point_outside_by_less_than_the_underflow_limit_still_projects_exactly() {
        let b = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        let bp = b.boundary_point(&Vector2::new(1.0 + 1e-200, 0.5));
        // 1 + 1e-200 rounds to 1: on the face.
        assert_eq!(bp.signed_distance, 0.0);
        let tiny = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1e-300, 1e-300)).unwrap();
        let bp = tiny.boundary_point(&Vector2::new(2e-300, 5e-301));
        assert_eq!(bp.normal, Vector2::x());
        assert_eq!(bp.signed_distance, 1e-300);
        assert_eq!(bp.point, Vector2::new(1e-300, 5e-301));
    }

    #[test]
    fn obb_queries_are_the_local_box_queries_rotated() {
        let o = Obb::<f64, 2>::from_angle(
            Vector2::new(1.0, 1.0),
            Vector2::new(2.0, 1.0),
            core::f64::consts::FRAC_PI_2,
        )
        .unwrap();
        // Rotated by 90°: the long axis is along y. A point 3 above the centre is 1 past
        // the end face.
        let p = Vector2::new(1.0, 4.0);
        let bp = o.boundary_point(&p);
        assert_relative_eq!(bp.point, Vector2::new(1.0, 3.0), epsilon = 1e-15);
        assert_relative_eq!(bp.normal, Vector2::y(), epsilon = 1e-15);
        assert_relative_eq!(bp.signed_distance, 1.0, epsilon = 1e-15);
        assert!(o.contains_point(&Vector2::new(1.5, 2.5)));
        assert!(!o.contains_point(&Vector2::new(2.5, 1.0)));
        assert_eq!(
            o.closest_point(&Vector2::new(1.5, 2.5)),
            Vector2::new(1.5, 2.5)
        );
    }

    #[test]
    fn ball_projection_and_the_centre_convention() {
        let b = Ball::new(Vector3::new(1.0, 2.0, 3.0), 2.0).unwrap();
        let bp = b.boundary_point(&Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(bp.normal, Vector3::x());
        assert_eq!(bp.point, Vector3::new(3.0, 2.0, 3.0));
        assert_eq!(bp.signed_distance, -2.0);
        assert_eq!(
            b.signed_distance_to_point(&Vector3::new(1.0, 7.0, 3.0)),
            3.0
        );
        assert_eq!(
            b.closest_point(&Vector3::new(1.0, 7.0, 3.0)),
            Vector3::new(1.0, 4.0, 3.0)
        );
        assert!(
            b.boundary_point_within(&Vector3::new(1.0, 7.0, 3.0), 2.9)
                .is_none()
        );
        assert!(
            b.boundary_point_within(&Vector3::new(1.0, 7.0, 3.0), 3.0)
                .is_some()
        );
        assert!(
            b.boundary_point_within(&Vector3::new(1.0, 2.5, 3.0), -1.6)
                .is_none()
        );
        assert!(
            b.boundary_point_within(&Vector3::new(1.0, 2.5, 3.0), -1.5)
                .is_some()
        );
    }

    #[test]
    fn half_space_points_project_on_the_plane() {
        let h = HalfSpace::new(Vector2::new(0.0, 1.0), Vector2::new(0.0, -1.0)).unwrap();
        let p = Vector2::new(3.0, 2.0);
        let bp = h.boundary_point(&p);
        assert_eq!(bp.point, Vector2::new(3.0, -1.0));
        assert_eq!(bp.signed_distance, 3.0);
        assert_eq!(h.closest_point(&p), Vector2::new(3.0, -1.0));
        assert_eq!(
            h.closest_point(&Vector2::new(3.0, -2.0)),
            Vector2::new(3.0, -2.0)
        );
        assert!(h.contains_point(&Vector2::new(0.0, -1.0)));
    }

    #[test]
    fn within_rejects_far_points_for_boxes() {
        let b = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        assert!(
            b.boundary_point_within(&Vector2::new(3.0, 0.5), 1.999)
                .is_none()
        );
        assert!(
            b.boundary_point_within(&Vector2::new(3.0, 0.5), 2.0)
                .is_some()
        );
        assert!(
            b.boundary_point_within(&Vector2::new(0.5, 0.5), -0.6)
                .is_none()
        );
        assert!(
            b.boundary_point_within(&Vector2::new(0.5, 0.5), -0.5)
                .is_some()
        );
        assert!(
            b.boundary_point_within(&Vector2::new(3.0, 0.5), -1.0)
                .is_none()
        );
    }
}
