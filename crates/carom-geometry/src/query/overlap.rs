//! Overlap tests: do two shapes share a point? (See [`Overlap`] for the methods.)

use carom_math::{Real, Space};
use nalgebra::Const;

use crate::query::sat::RelativeBoxes;
use crate::{Aabb, Ball, BoundingVolume, HalfSpace, Obb};

/// Whether two shapes overlap (share at least one point; touching counts).
///
/// | pair | method |
/// |---|---|
/// | ball–ball | `|c₁ − c₂|² <= (r₁ + r₂)²` |
/// | ball–box | the closest-point clamp: `|c − clamp(c)|² <= r²` (in the box frame for an OBB) |
/// | ball–half-space | `n · c − offset <= r` |
/// | AABB–AABB | the intervals overlap on every axis |
/// | box–box with an OBB | the separating-axis test over 4 axes (2D) or 15 (3D), see [`separation`](super::separation) for parallel edges |
/// | box–half-space | the box's deepest point along `−n` is inside (the projected radius) |
///
/// Every test is symmetric (`a.overlaps(&b) == b.overlaps(&a)`), square-root free and
/// allocation-free. Two half-spaces are not covered: their overlap is almost always
/// `true` and no simulation asks for it.
pub trait Overlap<Rhs: ?Sized> {
    /// `true` if `self` and `other` overlap or touch.
    fn overlaps(&self, other: &Rhs) -> bool;
}

/// `true` if `a` and `b` overlap or touch: [`Overlap::overlaps`] as a free function.
///
/// ```
/// use carom_geometry::{d3, query::overlaps};
/// use nalgebra::Vector3;
///
/// let ball = d3::Ball::new(Vector3::new(0.0, 0.0, 2.0), 1.0)?;
/// let crate_ = d3::Aabb::new(Vector3::new(-1.0, -1.0, -1.0), Vector3::new(1.0, 1.0, 1.0))?;
/// assert!(overlaps(&ball, &crate_)); // touching the top face
/// assert!(overlaps(&crate_, &ball));
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
#[inline]
pub fn overlaps<A: Overlap<B> + ?Sized, B: ?Sized>(a: &A, b: &B) -> bool {
    a.overlaps(b)
}

/// Implements `Overlap<$a> for $b` by swapping the arguments of `Overlap<$b> for $a`.
macro_rules! swapped_overlap {
    ($a:ident, $b:ident $(, $bound:tt)?) => {
        impl<T: Real, const D: usize> Overlap<$a<T, D>> for $b<T, D>
        $(where Const<D>: $bound<T, D>)?
        {
            #[inline]
            fn overlaps(&self, other: &$a<T, D>) -> bool {
                other.overlaps(self)
            }
        }
    };
}

impl<T: Real, const D: usize> Overlap<Ball<T, D>> for Ball<T, D> {
    #[inline]
    fn overlaps(&self, other: &Ball<T, D>) -> bool {
        let r = self.radius() + other.radius();
        (self.center() - other.center()).norm_squared() <= r * r
    }
}

impl<T: Real, const D: usize> Overlap<Aabb<T, D>> for Ball<T, D> {
    #[inline]
    fn overlaps(&self, other: &Aabb<T, D>) -> bool {
        let c = self.center();
        let q = c.sup(&other.min()).inf(&other.max());
        (c - q).norm_squared() <= self.radius() * self.radius()
    }
}

impl<T: Real, const D: usize> Overlap<Obb<T, D>> for Ball<T, D> {
    #[inline]
    fn overlaps(&self, other: &Obb<T, D>) -> bool {
        let c = other.to_local(&self.center());
        let h = other.half_extents();
        let q = c.sup(&-h).inf(&h);
        (c - q).norm_squared() <= self.radius() * self.radius()
    }
}

impl<T: Real, const D: usize> Overlap<HalfSpace<T, D>> for Ball<T, D> {
    #[inline]
    fn overlaps(&self, other: &HalfSpace<T, D>) -> bool {
        other.signed_distance(&self.center()) <= self.radius()
    }
}

impl<T: Real, const D: usize> Overlap<Aabb<T, D>> for Aabb<T, D> {
    #[inline]
    fn overlaps(&self, other: &Aabb<T, D>) -> bool {
        self.intersects(other)
    }
}

impl<T: Real, const D: usize> Overlap<Obb<T, D>> for Aabb<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn overlaps(&self, other: &Obb<T, D>) -> bool {
        RelativeBoxes::new(
            (self.center(), self.half_extents(), None),
            (other.center(), other.half_extents(), Some(other.rotation())),
        )
        .overlap()
    }
}

impl<T: Real, const D: usize> Overlap<Obb<T, D>> for Obb<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn overlaps(&self, other: &Obb<T, D>) -> bool {
        RelativeBoxes::of_obbs(self, other).overlap()
    }
}

impl<T: Real, const D: usize> Overlap<HalfSpace<T, D>> for Aabb<T, D> {
    /// The corner deepest along `−n` (the support point) is inside: exact, as it picks
    /// `min[i]` or `max[i]` per axis without arithmetic.
    #[inline]
    fn overlaps(&self, other: &HalfSpace<T, D>) -> bool {
        other.signed_distance(&support_corner(self, other)) <= T::zero()
    }
}

impl<T: Real, const D: usize> Overlap<HalfSpace<T, D>> for Obb<T, D> {
    /// `n · c − offset <= Σ h_i |n · a_i|`: the centre within the box's projected radius.
    #[inline]
    fn overlaps(&self, other: &HalfSpace<T, D>) -> bool {
        other.signed_distance(&self.center()) <= projected_radius(self, other)
    }
}

/// The corner of `aabb` deepest in `half_space` (smallest `n · x`).
#[inline]
pub(crate) fn support_corner<T: Real, const D: usize>(
    aabb: &Aabb<T, D>,
    half_space: &HalfSpace<T, D>,
) -> carom_math::Vector<T, D> {
    let n = half_space.normal();
    let (lo, hi) = (aabb.min(), aabb.max());
    carom_math::Vector::<T, D>::from_fn(|i, _| if n[i] > T::zero() { lo[i] } else { hi[i] })
}

/// The half-length of the box's projection on the half-space normal: `Σ h_i |n · a_i|`.
#[inline]
pub(crate) fn projected_radius<T: Real, const D: usize>(
    obb: &Obb<T, D>,
    half_space: &HalfSpace<T, D>,
) -> T {
    obb.vector_to_local(&half_space.normal())
        .abs()
        .dot(&obb.half_extents())
}

swapped_overlap!(Ball, Aabb);
swapped_overlap!(Ball, Obb);
swapped_overlap!(Ball, HalfSpace);
swapped_overlap!(Aabb, Obb, Space);
swapped_overlap!(Aabb, HalfSpace);
swapped_overlap!(Obb, HalfSpace);

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn ball_pairs_touching_and_apart() {
        let a = Ball::new(Vector2::new(0.0, 0.0), 1.0).unwrap();
        let b = Ball::new(Vector2::new(3.0, 4.0), 4.0).unwrap();
        assert!(overlaps(&a, &b) && overlaps(&b, &a));
        let c = Ball::new(Vector2::new(3.0, 4.0), 3.999_999_999).unwrap();
        assert!(!overlaps(&a, &c));
        let floor = HalfSpace::new(Vector2::new(0.0, 1.0), Vector2::new(0.0, -1.0)).unwrap();
        assert!(overlaps(&a, &floor) && overlaps(&floor, &a));
        assert!(!overlaps(&a.translated(&Vector2::new(0.0, 1e-12)), &floor));
    }

    #[test]
    fn ball_box_at_a_corner_uses_the_euclidean_distance() {
        let b = Aabb::new(Vector3::zeros(), Vector3::repeat(1.0)).unwrap();
        // 0.9 past the corner on each axis: distance 0.9·√3 ≈ 1.56 > 1.5.
        let ball = Ball::new(Vector3::repeat(1.9), 1.5).unwrap();
        assert!(!overlaps(&ball, &b));
        assert!(overlaps(&ball.translated(&Vector3::repeat(-0.05)), &b));
        let o = Obb::from_aabb(&b);
        assert!(!overlaps(&ball, &o));
        assert!(overlaps(&o, &ball.translated(&Vector3::repeat(-0.05))));
    }

    #[test]
    fn boxes_against_half_spaces() {
        let h = HalfSpace::new(Vector2::new(1.0, 1.0), Vector2::new(0.0, 0.0)).unwrap();
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        assert!(overlaps(&a, &h), "the corner at the origin touches");
        assert!(!overlaps(&a.translated(&Vector2::new(1e-9, 0.0)), &h));
        let o = Obb::<f64, 2>::from_angle(
            Vector2::new(1.0, 1.0),
            Vector2::new(2f64.sqrt() - 1e-9, 0.1),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        // The long axis is along (1, 1)/√2, centre at distance √2 from the line.
        assert!(!overlaps(&o, &h));
        let o2 = Obb::<f64, 2>::from_angle(
            Vector2::new(1.0, 1.0),
            Vector2::new(2f64.sqrt() + 1e-9, 0.1),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        assert!(overlaps(&h, &o2));
    }

    #[test]
    fn aabb_obb_uses_the_sat() {
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        // A diamond whose left corner is at x = 1 + 1e-9: no face of the AABB is crossed.
        let d = Obb::<f64, 2>::from_angle(
            Vector2::new(1.0 + 1e-9 + 0.5f64.sqrt(), 0.5),
            Vector2::new(0.5, 0.5),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        assert!(!overlaps(&a, &d) && !overlaps(&d, &a));
        let d = d.translated(&Vector2::new(-2e-9, 0.0));
        assert!(overlaps(&a, &d) && overlaps(&d, &a));
    }
}
