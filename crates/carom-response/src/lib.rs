//! Collision response: what a collision does to the bodies.
//!
//! One mechanism covers every collision carom simulates: a rigid-body contact impulse
//! between two [`Body`]s, each described by its inverse mass, world-frame inverse
//! inertia, velocity and angular velocity, at a [`Contact`] (unit normal, contact offsets
//! from the centres of mass). A spinning ball, a static wall (inverse mass 0), a moving
//! paddle (inverse mass 0 with a velocity) and a cluster of stuck balls are all bodies.
//!
//! * [`resolve`]: the impulse with restitution `e ∈ [0, 1]` and optional Coulomb friction
//!   ([`Coefficients`]); returns a [`Response`] with the impulse, the new velocities and
//!   the change of kinetic energy. Never applied to a receding pair.
//! * [`central_impulse`]: the same for two smooth balls (no friction), along the line of
//!   centres, without spins: what an event-driven gas needs per collision.
//! * [`RigidCluster`]: perfectly inelastic "stick" collisions fuse bodies into one rigid
//!   body that keeps linear and angular momentum, each ball counting with its own inertia
//!   (disk `m r²/2` in 2D, solid sphere `2 m r²/5` in 3D).
//! * [`guard`]: the inelastic-collapse guard ([`CollapseGuard`]: TC model or an elastic
//!   threshold) and the Zeno guard ([`RestingGuard`]: a bouncing ball comes to rest).
//!
//! Pure functions of validated inputs, no allocation, generic over `f32`/`f64` and
//! 2D/3D; [`d2`] and [`d3`] give concrete aliases. The derivations are in each module
//! and in `docs/response.md`.
//!
//! ```
//! use carom_response::{d2, resolve, Coefficients, Contact};
//! use nalgebra::{Vector1, Vector2};
//!
//! // Collision Lab's Intro screen: 0.5 kg at 1 m/s hits 1.5 kg at −0.5 m/s head on.
//! let a: d2::Body = d2::Body::ball(0.5, 0.1, Vector2::new(1.0, 0.0), Vector1::zeros())?;
//! let b: d2::Body = d2::Body::ball(1.5, 0.1, Vector2::new(-0.5, 0.0), Vector1::zeros())?;
//! let contact = Contact::between_balls(&Vector2::zeros(), 0.1, &Vector2::new(0.2, 0.0), 0.1)?;
//! let r = resolve(&a, &b, &contact, &Coefficients::elastic());
//! assert!((r.velocity[0].x - -1.25).abs() < 1e-15);
//! assert!((r.velocity[1].x - 0.25).abs() < 1e-15);
//! assert!(r.kinetic_energy_change.abs() < 1e-15);
//! # Ok::<(), carom_math::InvalidValue>(())
//! ```

mod body;
mod cluster;
mod coefficients;
mod contact;
pub mod guard;
mod impulse;

pub use body::Body;
pub use carom_math::{InvalidValue, Real, Space, Vector};
pub use cluster::{Fusion, MemberMap, RigidCluster};
pub use coefficients::Coefficients;
pub use contact::Contact;
pub use guard::{Bounce, CollapseGuard, RestingGuard};
pub use impulse::{Friction, Outcome, Response, central_impulse, normal_velocity, resolve};

/// An angular velocity, momentum or impulse: `Vector1` (the z component) in 2D, `Vector3`
/// in 3D.
pub type Angular<T, const D: usize> = <nalgebra::Const<D> as Space<T, D>>::Angular;

/// A moment of inertia (or its inverse): `T` in 2D, a symmetric `Matrix3` in 3D.
pub type Inertia<T, const D: usize> = <nalgebra::Const<D> as Space<T, D>>::Inertia;

/// The 2D types, `f64` unless a scalar is given (`d2::Body<f32>`).
pub mod d2 {
    /// A body in a 2D collision.
    pub type Body<T = f64> = crate::Body<T, 2>;
    /// A 2D contact.
    pub type Contact<T = f64> = crate::Contact<T, 2>;
    /// What a 2D collision did.
    pub type Response<T = f64> = crate::Response<T, 2>;
    /// A 2D rigid cluster of stuck balls.
    pub type RigidCluster<T = f64> = crate::RigidCluster<T, 2>;
    /// The result of a 2D stick collision.
    pub type Fusion<T = f64> = crate::Fusion<T, 2>;
}

/// The 3D types, `f64` unless a scalar is given (`d3::Body<f32>`).
pub mod d3 {
    /// A body in a 3D collision.
    pub type Body<T = f64> = crate::Body<T, 3>;
    /// A 3D contact.
    pub type Contact<T = f64> = crate::Contact<T, 3>;
    /// What a 3D collision did.
    pub type Response<T = f64> = crate::Response<T, 3>;
    /// A 3D rigid cluster of stuck balls.
    pub type RigidCluster<T = f64> = crate::RigidCluster<T, 3>;
    /// The result of a 3D stick collision.
    pub type Fusion<T = f64> = crate::Fusion<T, 3>;
}
