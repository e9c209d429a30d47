//! Test scenes: any carom shape behind one enum, carom's queries dispatched over pairs of
//! them, and proptest strategies written once for both dimensions.

use carom_geometry::query::{
    BoundaryPoint, Contact, PointQuery, Ray, RayCast, RayHit, contact, overlaps, signed_distance,
};
use carom_geometry::{Aabb, Ball, BoundingVolume, HalfSpace, Obb, Real, Rotation, Space, Vector};
use nalgebra::Const;
use proptest::prelude::*;

/// One shape of a test scene (`f64` unless said otherwise).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Shape<const D: usize, T: Real = f64> {
    Ball(Ball<T, D>),
    Aabb(Aabb<T, D>),
    Obb(Obb<T, D>),
    HalfSpace(HalfSpace<T, D>),
}

/// Runs `$body` with `$x`, `$y` bound to the concrete shapes of the pair `($a, $b)`; two
/// half-spaces (which carom does not pair) give `None`, every other pair `Some($body)`.
macro_rules! each_pair {
    ($a:expr, $b:expr, |$x:ident, $y:ident| $body:expr) => {{
        use $crate::scene::Shape::{Aabb as A, Ball as B, HalfSpace as H, Obb as O};
        match ($a, $b) {
            (B($x), B($y)) => Some($body),
            (B($x), A($y)) => Some($body),
            (B($x), O($y)) => Some($body),
            (B($x), H($y)) => Some($body),
            (A($x), B($y)) => Some($body),
            (A($x), A($y)) => Some($body),
            (A($x), O($y)) => Some($body),
            (A($x), H($y)) => Some($body),
            (O($x), B($y)) => Some($body),
            (O($x), A($y)) => Some($body),
            (O($x), O($y)) => Some($body),
            (O($x), H($y)) => Some($body),
            (H($x), B($y)) => Some($body),
            (H($x), A($y)) => Some($body),
            (H($x), O($y)) => Some($body),
            (H(_), H(_)) => None,
        }
    }};
}

/// Runs `$body` with `$x` bound to the concrete shape.
macro_rules! each_shape {
    ($a:expr, |$x:ident| $body:expr) => {{
        use $crate::scene::Shape::{Aabb as A, Ball as B, HalfSpace as H, Obb as O};
        match $a {
            B($x) => $body,
            A($x) => $body,
            O($x) => $body,
            H($x) => $body,
        }
    }};
}

impl<const D: usize, T: Real> Shape<D, T>
where
    Const<D>: Space<T, D>,
{
    /// carom's overlap test (`None` for two half-spaces).
    pub(crate) fn overlaps(&self, other: &Self) -> Option<bool> {
        each_pair!(self, other, |a, b| overlaps(a, b))
    }

    /// carom's signed distance (`None` for two half-spaces).
    pub(crate) fn signed_distance(&self, other: &Self) -> Option<T> {
        each_pair!(self, other, |a, b| signed_distance(a, b))
    }

    /// carom's contact of `ball` with this shape.
    pub(crate) fn contact(&self, ball: &Ball<T, D>) -> Option<Contact<T, D>> {
        each_shape!(self, |s| contact(ball, s))
    }

    /// carom's nearest boundary point.
    pub(crate) fn boundary_point(&self, p: &Vector<T, D>) -> BoundaryPoint<T, D> {
        each_shape!(self, |s| s.boundary_point(p))
    }

    /// carom's closest point of the solid shape.
    pub(crate) fn closest_point(&self, p: &Vector<T, D>) -> Vector<T, D> {
        each_shape!(self, |s| s.closest_point(p))
    }

    /// carom's ray cast.
    pub(crate) fn cast_ray(&self, ray: &Ray<T, D>, max_toi: T) -> Option<RayHit<T, D>> {
        each_shape!(self, |s| s.cast_ray(ray, max_toi))
    }

    /// The same shape in `f32` (coordinates rounded to nearest).
    pub(crate) fn to_f32(self) -> Shape<D, f32> {
        let v = |x: &Vector<T, D>| x.map(|c| c.to_f64() as f32);
        match self {
            Shape::Ball(b) => {
                Shape::Ball(Ball::new(v(&b.center()), b.radius().to_f64() as f32).unwrap())
            }
            Shape::Aabb(a) => Shape::Aabb(Aabb::new(v(&a.min()), v(&a.max())).unwrap()),
            Shape::Obb(o) => Shape::Obb(
                Obb::new(
                    v(&o.center()),
                    v(&o.half_extents()),
                    Rotation::from_matrix_unchecked(
                        o.rotation().matrix().map(|c| c.to_f64() as f32),
                    ),
                )
                .unwrap(),
            ),
            Shape::HalfSpace(h) => Shape::HalfSpace(
                HalfSpace::from_normal_offset(v(&h.normal()), h.offset().to_f64() as f32).unwrap(),
            ),
        }
    }
}

impl<const D: usize> Shape<D>
where
    Const<D>: Space<f64, D>,
{
    /// The size of the numbers in this shape: coordinates and extents.
    pub(crate) fn magnitude(&self) -> f64 {
        match self {
            Shape::Ball(b) => b.center().amax() + b.radius(),
            Shape::Aabb(a) => a.min().amax().max(a.max().amax()),
            Shape::Obb(o) => o.center().amax() + o.half_extents().sum(),
            Shape::HalfSpace(h) => h.offset().abs(),
        }
    }

    /// The shape grown (`delta > 0`) or shrunk (`delta < 0`) by `|delta|` on every side,
    /// shrinking no further than to zero size (a ball keeps a tiny radius).
    pub(crate) fn offset(&self, delta: f64) -> Self {
        match self {
            Shape::Ball(b) => {
                Shape::Ball(Ball::new(b.center(), (b.radius() + delta).max(1e-12)).unwrap())
            }
            Shape::Aabb(a) => Shape::Aabb(
                Aabb::from_center_half_extents(
                    a.center(),
                    a.half_extents().add_scalar(delta).sup(&Vector::zeros()),
                )
                .unwrap(),
            ),
            Shape::Obb(o) => Shape::Obb(
                Obb::new(
                    o.center(),
                    o.half_extents().add_scalar(delta).sup(&Vector::zeros()),
                    *o.rotation(),
                )
                .unwrap(),
            ),
            Shape::HalfSpace(h) => Shape::HalfSpace(
                HalfSpace::from_normal_offset(h.normal(), h.offset() + delta).unwrap(),
            ),
        }
    }

    /// The shape scaled about the origin by `s > 0`.
    pub(crate) fn scaled(&self, s: f64) -> Self {
        match self {
            Shape::Ball(b) => Shape::Ball(Ball::new(b.center() * s, b.radius() * s).unwrap()),
            Shape::Aabb(a) => Shape::Aabb(Aabb::new(a.min() * s, a.max() * s).unwrap()),
            Shape::Obb(o) => {
                Shape::Obb(Obb::new(o.center() * s, o.half_extents() * s, *o.rotation()).unwrap())
            }
            Shape::HalfSpace(h) => {
                Shape::HalfSpace(HalfSpace::from_normal_offset(h.normal(), h.offset() * s).unwrap())
            }
        }
    }

    /// The shape moved by `v`.
    pub(crate) fn translated(&self, v: &Vector<f64, D>) -> Self {
        match self {
            Shape::Ball(b) => Shape::Ball(b.translated(v)),
            Shape::Aabb(a) => Shape::Aabb(a.translated(v)),
            Shape::Obb(o) => Shape::Obb(o.translated(v)),
            Shape::HalfSpace(h) => {
                Shape::HalfSpace(HalfSpace::new(h.normal(), h.normal() * h.offset() + v).unwrap())
            }
        }
    }

    /// The corners of a box shape (empty for balls and half-spaces).
    pub(crate) fn corners(&self) -> Vec<Vector<f64, D>> {
        match self {
            Shape::Aabb(a) => a.corners().collect(),
            Shape::Obb(o) => o.corners().collect(),
            _ => Vec::new(),
        }
    }
}

/// A vector with coordinates in `[lo, hi)`.
pub(crate) fn vector<const D: usize>(lo: f64, hi: f64) -> impl Strategy<Value = Vector<f64, D>> {
    proptest::array::uniform::<_, D>(lo..hi).prop_map(Vector::from)
}

/// A rotation: the exponential of the angular vector `u × v` (an angle up to 8 rad about
/// a random axis in 3D), written once for both dimensions through [`Space`].
pub(crate) fn rotation<const D: usize>() -> impl Strategy<Value = Rotation<f64, D>>
where
    Const<D>: Space<f64, D>,
{
    (vector::<D>(-2.0, 2.0), vector::<D>(-2.0, 2.0)).prop_map(|(u, v)| {
        let w = <Const<D> as Space<f64, D>>::cross(&u, &v);
        <Const<D> as Space<f64, D>>::rotation_from_angular(&w, 1.0)
    })
}

/// Half extents, each zero one time in ten (zero-size boxes are valid).
pub(crate) fn half_extents<const D: usize>() -> impl Strategy<Value = Vector<f64, D>> {
    proptest::array::uniform::<_, D>(prop_oneof![1 => Just(0.0), 9 => 0.01..3.0])
        .prop_map(Vector::from)
}

pub(crate) fn ball<const D: usize>() -> impl Strategy<Value = Ball<f64, D>> {
    (vector::<D>(-5.0, 5.0), 0.05..3.0).prop_map(|(c, r)| Ball::new(c, r).unwrap())
}

pub(crate) fn aabb<const D: usize>() -> impl Strategy<Value = Aabb<f64, D>> {
    (vector::<D>(-5.0, 5.0), half_extents::<D>())
        .prop_map(|(c, h)| Aabb::from_center_half_extents(c, h).unwrap())
}

pub(crate) fn obb<const D: usize>() -> impl Strategy<Value = Obb<f64, D>>
where
    Const<D>: Space<f64, D>,
{
    (vector::<D>(-5.0, 5.0), half_extents::<D>(), rotation::<D>())
        .prop_map(|(c, h, r)| Obb::new(c, h, r).unwrap())
}

pub(crate) fn half_space<const D: usize>() -> impl Strategy<Value = HalfSpace<f64, D>> {
    (vector::<D>(-1.0, 1.0), vector::<D>(-4.0, 4.0))
        .prop_filter("a normal of usable length", |(n, _)| n.norm() > 0.1)
        .prop_map(|(n, p)| HalfSpace::new(n, p).unwrap())
}

pub(crate) fn shape<const D: usize>() -> impl Strategy<Value = Shape<D>>
where
    Const<D>: Space<f64, D>,
{
    prop_oneof![
        ball::<D>().prop_map(Shape::Ball),
        aabb::<D>().prop_map(Shape::Aabb),
        obb::<D>().prop_map(Shape::Obb),
        half_space::<D>().prop_map(Shape::HalfSpace),
    ]
}

pub(crate) fn ray<const D: usize>() -> impl Strategy<Value = Ray<f64, D>> {
    (vector::<D>(-8.0, 8.0), vector::<D>(-3.0, 3.0)).prop_map(|(o, d)| Ray::new(o, d).unwrap())
}

/// The scale of a scene: the largest magnitude of its numbers.
pub(crate) fn scale<const D: usize>(shapes: &[&Shape<D>]) -> f64
where
    Const<D>: Space<f64, D>,
{
    shapes
        .iter()
        .map(|s| s.magnitude())
        .fold(f64::MIN_POSITIVE, f64::max)
}
