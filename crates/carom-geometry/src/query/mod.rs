//! Geometric queries between balls, boxes and half-spaces, free of allocation.
//!
//! | query | what it answers | for |
//! |---|---|---|
//! | [`PointQuery`] | closest point, signed distance, containment, nearest boundary point | every shape |
//! | [`Overlap`] / [`overlaps`] | do two shapes share a point? (touching counts) | every pair but half-space–half-space |
//! | [`Distance`] / [`distance`], [`signed_distance`] | the gap between two shapes, negative when they overlap | every pair but half-space–half-space |
//! | [`contact`] | unit normal, penetration depth and contact points | a ball against any shape |
//! | [`separation`] | the best separating axis of two boxes and the signed gap along it (SAT) | box–box |
//! | [`RayCast`] / [`cast_ray`] | first time of impact of a ray and the surface normal | every shape |
//!
//! # Conventions (the same everywhere)
//!
//! * **Shapes are closed and solid.** Touching shapes overlap; a point on the boundary is
//!   inside; a ray starting inside or on the boundary hits at time 0.
//! * **Signed distances are positive apart, negative in penetration.** A signed distance
//!   `s < 0` means the shapes overlap and `−s` is the penetration depth: the length of the
//!   shortest translation that separates them.
//! * **Normals point from the other shape towards the first argument** (for [`contact`],
//!   from the shape towards the ball): moving the ball by `depth · normal` separates it.
//!   Boundary normals of [`PointQuery::boundary_point`] point out of the shape, towards the
//!   query point when it is outside.
//! * **Degenerate directions are deterministic and finite.** Where the normal is not
//!   defined (coincident ball centres, a point at a ball's centre) it is `+x` (the first
//!   axis). Inside a box the normal is that of the face of least penetration; ties go to
//!   the lowest axis index and, on one axis, to the upper face (see [`PointQuery`]).
//!
//! # Numerical range
//!
//! Queries take validated (finite) shapes and do not panic on any finite input. Squared
//! lengths are compared where that avoids a square root, so results are accurate while
//! squared distances are representable: coordinates and sizes below about `1e150` in
//! `f64` and `1e18` in `f32`. Differences are taken before products (the centre offset of a
//! pair first), so shapes far from the origin (`1e6`) keep the precision of their
//! relative positions.

mod box_distance;
mod contact;
mod distance;
mod overlap;
mod point;
mod ray;
mod sat;

pub use contact::{Contact, contact};
pub use distance::{Distance, distance, signed_distance};
pub use overlap::{Overlap, overlaps};
pub use point::{BoundaryPoint, PointQuery};
pub use ray::{Ray, RayCast, RayHit, cast_ray};
pub use sat::{Separation, separation};
