//! Shapes and bounding volumes in 2D and 3D, generic over `f32`/`f64`.
//!
//! * Shapes: [`Ball`] (circle or sphere), [`Aabb`], [`Obb`] (centre, half extents,
//!   rotation), [`HalfSpace`] (the solid side of a plane) and [`Border`], the axis-aligned
//!   container a simulation reflects from or wraps around.
//! * Bounding volumes: the [`BoundingVolume`] trait (merge, contains, intersects,
//!   loosen, centre, extents, volume) for [`Aabb`] and [`BoundingSphere`], with
//!   conversions (ball → AABB, OBB → AABB, swept ball → AABB).
//!
//! * Queries ([`query`]): point queries, overlap tests, distances and signed distances,
//!   ball contacts (normal, depth, points), the box–box separating-axis test, ray casts.
//! * Fitting ([`fit`]): bounding volumes around point sets (Ritter and Welzl spheres, PCA
//!   boxes, the minimum-area rectangle).
//!
//! Every type is generic over the scalar `T` ([`Real`]: `f32` or `f64`) and the
//! dimension `D` (2 or 3). The [`d2`] and [`d3`] modules give concrete aliases
//! (`d2::Ball` = `Ball<f64, 2>`, `d3::Obb<f32>` = `Obb<f32, 3>`).
//!
//! Constructors validate and return `Result<_, InvalidValue>` naming the bad field;
//! queries take validated shapes and never panic on finite input.

mod aabb;
mod ball;
mod border;
mod bounding_volume;
pub mod fit;
mod half_space;
mod obb;
pub mod query;

pub use aabb::Aabb;
pub use ball::Ball;
pub use border::{Border, Period};
pub use bounding_volume::{BoundingSphere, BoundingVolume};
pub use carom_math::{InvalidValue, Problem, Real, Rotation, Space, Vector};
pub use half_space::HalfSpace;
pub use obb::Obb;

/// The 2D shapes, `f64` unless a scalar is given (`d2::Ball<f32>`).
pub mod d2 {
    /// A circle.
    pub type Ball<T = f64> = crate::Ball<T, 2>;
    /// An axis-aligned rectangle.
    pub type Aabb<T = f64> = crate::Aabb<T, 2>;
    /// A rotated rectangle.
    pub type Obb<T = f64> = crate::Obb<T, 2>;
    /// The solid side of a line.
    pub type HalfSpace<T = f64> = crate::HalfSpace<T, 2>;
    /// A rectangular container.
    pub type Border<T = f64> = crate::Border<T, 2>;
    /// A bounding circle.
    pub type BoundingSphere<T = f64> = crate::BoundingSphere<T, 2>;
    /// A 2D vector.
    pub type Vector<T = f64> = crate::Vector<T, 2>;
    /// A 2D ray.
    pub type Ray<T = f64> = crate::query::Ray<T, 2>;
    /// Where a 2D ray hits a shape.
    pub type RayHit<T = f64> = crate::query::RayHit<T, 2>;
    /// A ball's contact with a 2D shape.
    pub type Contact<T = f64> = crate::query::Contact<T, 2>;
    /// The nearest boundary point of a 2D shape.
    pub type BoundaryPoint<T = f64> = crate::query::BoundaryPoint<T, 2>;
    /// The best separating axis of two rectangles.
    pub type Separation<T = f64> = crate::query::Separation<T, 2>;
}

/// The 3D shapes, `f64` unless a scalar is given (`d3::Ball<f32>`).
pub mod d3 {
    /// A sphere.
    pub type Ball<T = f64> = crate::Ball<T, 3>;
    /// An axis-aligned box.
    pub type Aabb<T = f64> = crate::Aabb<T, 3>;
    /// A rotated box.
    pub type Obb<T = f64> = crate::Obb<T, 3>;
    /// The solid side of a plane.
    pub type HalfSpace<T = f64> = crate::HalfSpace<T, 3>;
    /// A box-shaped container.
    pub type Border<T = f64> = crate::Border<T, 3>;
    /// A bounding sphere.
    pub type BoundingSphere<T = f64> = crate::BoundingSphere<T, 3>;
    /// A 3D vector.
    pub type Vector<T = f64> = crate::Vector<T, 3>;
    /// A 3D ray.
    pub type Ray<T = f64> = crate::query::Ray<T, 3>;
    /// Where a 3D ray hits a shape.
    pub type RayHit<T = f64> = crate::query::RayHit<T, 3>;
    /// A ball's contact with a 3D shape.
    pub type Contact<T = f64> = crate::query::Contact<T, 3>;
    /// The nearest boundary point of a 3D shape.
    pub type BoundaryPoint<T = f64> = crate::query::BoundaryPoint<T, 3>;
    /// The best separating axis of two boxes.
    pub type Separation<T = f64> = crate::query::Separation<T, 3>;
}
