//! Distances between shapes, and signed distances that go negative in penetration.
//! (See [`Distance`] for the methods.)

use carom_math::{Real, Space};
use nalgebra::Const;

use crate::query::PointQuery;
use crate::query::overlap::{projected_radius, support_corner};
use crate::query::sat::RelativeBoxes;
use crate::{Aabb, Ball, BoundingVolume, HalfSpace, Obb};

/// The distance between two shapes, and its signed form.
///
/// The signed distance of two shapes is their distance when apart and minus their
/// penetration depth (the length of the shortest translation that separates them) when
/// they overlap. Every pair has it exactly, up to rounding:
///
/// | pair | signed distance |
/// |---|---|
/// | ball–shape | the signed distance of the centre to the shape, minus the radius |
/// | AABB–AABB | apart: the length of the per-axis gaps; overlapping: the largest (least negative) per-axis gap |
/// | box–half-space | the signed distance of the box's deepest point along `−n` |
/// | box–box with an OBB | apart: the smallest of the corner–box and (3D) edge–edge distances; overlapping: the SAT depth ([`separation`](super::separation)) |
///
/// The box–box distance with an OBB is the expensive one: when the boxes are apart it
/// measures the closest-feature candidates (corner–box, and in 3D edge–edge) that the
/// separating axis cannot rule out, typically a handful, at most 8 corner–box tests in
/// 2D and 16 corner–box plus 144 edge–edge tests in 3D; no allocation. Everything else
/// is a handful of operations. Two half-spaces are not covered.
pub trait Distance<T: Real, Rhs: ?Sized> {
    /// The distance when apart, minus the penetration depth when overlapping.
    fn signed_distance(&self, other: &Rhs) -> T;

    /// The distance between the two solid shapes: zero when they overlap or touch.
    #[inline]
    fn distance(&self, other: &Rhs) -> T {
        self.signed_distance(other).max(T::zero())
    }
}

/// The distance between `a` and `b` (zero when they overlap).
///
/// ```
/// use carom_geometry::{d2, query::distance};
/// use nalgebra::Vector2;
///
/// let a = d2::Ball::new(Vector2::new(0.0, 0.0), 1.0)?;
/// let b = d2::Ball::new(Vector2::new(3.0, 4.0), 1.0)?;
/// assert_eq!(distance(&a, &b), 3.0);
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
#[inline]
pub fn distance<T: Real, A: Distance<T, B> + ?Sized, B: ?Sized>(a: &A, b: &B) -> T {
    a.distance(b)
}

/// The signed distance between `a` and `b`: negative (minus the penetration depth) when
/// they overlap.
#[inline]
pub fn signed_distance<T: Real, A: Distance<T, B> + ?Sized, B: ?Sized>(a: &A, b: &B) -> T {
    a.signed_distance(b)
}

/// A ball against any shape with point queries: `sd_shape(centre) − radius`.
impl<T: Real, const D: usize, S: PointQuery<T, D>> Distance<T, S> for Ball<T, D> {
    #[inline]
    fn signed_distance(&self, other: &S) -> T {
        other.signed_distance_to_point(&self.center()) - self.radius()
    }
}

/// Implements `Distance<T, $a> for $b` by swapping the arguments of `Distance<T, $b> for $a`.
macro_rules! swapped_distance {
    ($a:ident, $b:ident $(, $bound:tt)?) => {
        impl<T: Real, const D: usize> Distance<T, $a<T, D>> for $b<T, D>
        $(where Const<D>: $bound<T, D>)?
        {
            #[inline]
            fn signed_distance(&self, other: &$a<T, D>) -> T {
                other.signed_distance(self)
            }
        }
    };
}

impl<T: Real, const D: usize> Distance<T, Aabb<T, D>> for Aabb<T, D> {
    /// Per axis the gap `g_i = max(min_b − max_a, min_a − max_b)`. Apart: `|max(g, 0)|`.
    /// Overlapping: every `g_i <= 0` is minus the shift along axis `i` that separates them,
    /// and the shortest is `max_i g_i`.
    #[inline]
    fn signed_distance(&self, other: &Aabb<T, D>) -> T {
        let gaps = (other.min() - self.max()).sup(&(self.min() - other.max()));
        let outside = gaps.sup(&carom_math::Vector::<T, D>::zeros());
        if outside == carom_math::Vector::<T, D>::zeros() {
            gaps.max()
        } else {
            outside.norm()
        }
    }
}

/// Boxes at least one of which is oriented: SAT first; apart, the exact closest features.
fn box_box_signed_distance<T: Real, const D: usize>(rel: &RelativeBoxes<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    let (axis, gap) = rel.separation();
    if gap > T::zero() {
        rel.disjoint_distance(&axis)
    } else {
        gap
    }
}

impl<T: Real, const D: usize> Distance<T, Obb<T, D>> for Obb<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn signed_distance(&self, other: &Obb<T, D>) -> T {
        box_box_signed_distance(&RelativeBoxes::of_obbs(self, other))
    }
}

impl<T: Real, const D: usize> Distance<T, Obb<T, D>> for Aabb<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn signed_distance(&self, other: &Obb<T, D>) -> T {
        box_box_signed_distance(&RelativeBoxes::new(
            (self.center(), self.half_extents(), None),
            (other.center(), other.half_extents(), Some(other.rotation())),
        ))
    }
}

impl<T: Real, const D: usize> Distance<T, HalfSpace<T, D>> for Aabb<T, D> {
    #[inline]
    fn signed_distance(&self, other: &HalfSpace<T, D>) -> T {
        other.signed_distance(&support_corner(self, other))
    }
}

impl<T: Real, const D: usize> Distance<T, HalfSpace<T, D>> for Obb<T, D> {
    #[inline]
    fn signed_distance(&self, other: &HalfSpace<T, D>) -> T {
        other.signed_distance(&self.center()) - projected_radius(self, other)
    }
}

swapped_distance!(Ball, Aabb);
swapped_distance!(Ball, Obb);
swapped_distance!(Ball, HalfSpace);
swapped_distance!(Aabb, Obb, Space);
swapped_distance!(Aabb, HalfSpace);
swapped_distance!(Obb, HalfSpace);

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn aabb_aabb_apart_nested_and_overlapping() {
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(10.0, 10.0)).unwrap();
        let corner = Aabb::new(Vector2::new(13.0, 14.0), Vector2::new(15.0, 15.0)).unwrap();
        assert_eq!(distance(&a, &corner), 5.0);
        assert_eq!(signed_distance(&corner, &a), 5.0);
        // Nested: the shortest way out of [0, 10] for [4, 5] × [1, 2] is 2 down in y.
        let inner = Aabb::new(Vector2::new(4.0, 1.0), Vector2::new(5.0, 2.0)).unwrap();
        assert_eq!(signed_distance(&a, &inner), -2.0);
        assert_eq!(distance(&a, &inner), 0.0);
    }

    #[test]
    fn ball_distances_are_centre_distances_minus_the_radius() {
        let b = Ball::new(Vector3::new(0.0, 0.0, 5.0), 1.0).unwrap();
        let floor = HalfSpace::new(Vector3::z(), Vector3::zeros()).unwrap();
        assert_eq!(signed_distance(&b, &floor), 4.0);
        assert_eq!(signed_distance(&floor, &b), 4.0);
        let cube = Aabb::new(Vector3::repeat(-1.0), Vector3::repeat(1.0)).unwrap();
        assert_eq!(signed_distance(&b, &cube), 3.0);
        let inside = Ball::new(Vector3::new(0.0, 0.0, 0.5), 0.25).unwrap();
        assert_eq!(signed_distance(&inside, &cube), -0.75);
        assert_eq!(signed_distance(&inside, &b), 3.25);
    }

    #[test]
    fn boxes_against_half_spaces_use_the_deepest_point() {
        let floor = HalfSpace::new(Vector2::y(), Vector2::zeros()).unwrap();
        let a = Aabb::new(Vector2::new(-1.0, 0.5), Vector2::new(1.0, 2.0)).unwrap();
        assert_eq!(signed_distance(&a, &floor), 0.5);
        let o = Obb::<f64, 2>::from_angle(
            Vector2::new(0.0, 0.5),
            Vector2::new(1.0, 1.0),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        assert_relative_eq!(
            signed_distance(&floor, &o),
            0.5 - 2f64.sqrt(),
            epsilon = 1e-15
        );
    }

    #[test]
    fn obb_pairs_apart_and_overlapping() {
        let a = Obb::<f64, 2>::from_angle(Vector2::zeros(), Vector2::new(1.0, 1.0), 0.0).unwrap();
        let diamond = Obb::<f64, 2>::from_angle(
            Vector2::new(1.0 + 0.75 + 2f64.sqrt(), 1.0 + 0.75),
            Vector2::new(1.0, 1.0),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        // Diamond's left corner at (1.75, 1.75); closest point of a is its corner (1, 1).
        assert_relative_eq!(distance(&a, &diamond), 0.75 * 2f64.sqrt(), epsilon = 1e-12);
        let aabb = Aabb::new(Vector2::new(-1.0, -1.0), Vector2::new(1.0, 1.0)).unwrap();
        assert_relative_eq!(
            distance(&aabb, &diamond),
            0.75 * 2f64.sqrt(),
            epsilon = 1e-12
        );
        assert_relative_eq!(
            distance(&diamond, &aabb),
            0.75 * 2f64.sqrt(),
            epsilon = 1e-12
        );
        let b =
            Obb::<f64, 2>::from_angle(Vector2::new(1.5, 0.0), Vector2::new(1.0, 1.0), 0.0).unwrap();
        assert_eq!(signed_distance(&a, &b), -0.5);
    }
}
