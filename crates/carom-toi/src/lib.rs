//! Exact time of impact for ball-centred simulation: when, looking forward or backward
//! from now, two bodies first touch.
//!
//! The narrow phase of an event-driven engine. Every query is a pure function of
//! validated inputs, allocates nothing, never panics on finite input, and returns a
//! [`Toi`]: a [`Status`], the signed time, the unit normal and the contact point, never a
//! bare float.
//!
//! | query | bodies | method |
//! |---|---|---|
//! | [`ball_ball`] | two balls, linear, same or differing constant accelerations | filtered cancellation-free quadratic root (plain arithmetic with proven bounds, double-double fallback); quartic with bracketed roots |
//! | [`relative_contact_time`] | two balls in linear relative motion: the time alone, for event calendars | as `ball_ball`, to a resolution of positions the caller gives |
//! | [`ball_plane`] | ball and a static half-space, linear or under gravity | quadratic |
//! | [`ball_border`] | ball inside a reflecting [`Border`](carom_geometry::Border): the first wall | quadratic per wall |
//! | [`plane_crossing`], [`level_crossing`] | a centre crossing a plane or a level (periodic cell faces) | quadratic |
//! | [`ball_aabb`], [`ball_obb`] | ball and a translating box: faces, edges, corners | slab early-out and direct face test; region walk, closed forms and bracketed quartics |
//! | [`cluster_plane`], [`cluster_border`], [`cluster_ball`], [`cluster_cluster`] | a rotating rigid cluster of balls | conservative advancement, then ITP |
//!
//! Conventions (see [`Toi`]): times are signed offsets from now (`>= 0` forward,
//! `<= 0` backward, see [`Window`]); the normal points from the first body to the second;
//! a receding pair is never reported; touching or overlapping and approaching is
//! [`Status::AlreadyTouching`] at time 0; touching at zero normal rate (resting) is not
//! an event. Every type is generic over `f32`/`f64` and the dimension; [`d2`] and [`d3`]
//! give aliases. The derivations are next to the code and in `docs/toi.md`.

mod ball;
mod border;
mod cluster;
mod cuboid;
mod kinematics;
mod outcome;
mod plane;
mod roots;
mod window;

pub use ball::{ball_ball, relative_contact_time};
pub use border::ball_border;
pub use carom_math::{InvalidValue, Real, Vector};
pub use cluster::{
    AdvanceOptions, Cluster, ClusterBall, ConstantSpin, RigidMotion, RigidState, cluster_ball,
    cluster_border, cluster_cluster, cluster_plane,
};
pub use cuboid::{ball_aabb, ball_obb};
pub use kinematics::Kinematics;
pub use outcome::{BoxFeature, Crossing, Side, Status, Toi, Wall};
pub use plane::{ball_plane, level_crossing, plane_crossing};
pub use window::{Direction, Window};

/// The 2D types, `f64` unless a scalar is given (`d2::Kinematics<f32>`).
pub mod d2 {
    /// A 2D time-of-impact result with feature `F`.
    pub type Toi<T = f64, F = ()> = crate::Toi<T, 2, F>;
    /// Velocity and acceleration in 2D.
    pub type Kinematics<T = f64> = crate::Kinematics<T, 2>;
    /// A rigid cluster of discs.
    pub type Cluster<T = f64> = crate::Cluster<T, 2>;
    /// A cluster moving and spinning at constant rates in 2D.
    pub type ConstantSpin<T = f64> = crate::ConstantSpin<T, 2>;
}

/// The 3D types, `f64` unless a scalar is given (`d3::Kinematics<f32>`).
pub mod d3 {
    /// A 3D time-of-impact result with feature `F`.
    pub type Toi<T = f64, F = ()> = crate::Toi<T, 3, F>;
    /// Velocity and acceleration in 3D.
    pub type Kinematics<T = f64> = crate::Kinematics<T, 3>;
    /// A rigid cluster of spheres.
    pub type Cluster<T = f64> = crate::Cluster<T, 3>;
    /// A cluster moving and spinning at constant rates in 3D.
    pub type ConstantSpin<T = f64> = crate::ConstantSpin<T, 3>;
}
