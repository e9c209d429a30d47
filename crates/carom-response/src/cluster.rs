//! Rigid clusters: balls stuck together by a perfectly inelastic "stick" collision.
//!
//! When two bodies (balls or clusters) stick, they become one rigid body that keeps the
//! total linear momentum and the total angular momentum. With masses `m_i`, centres
//! `c_i`, velocities `v_i`, world inertias `I_i` (each about its own centre) and angular
//! momenta `L_i = I_i ω_i`:
//!
//! ```text
//! M = Σ m_i,   c = Σ m_i c_i / M,   v = Σ m_i v_i / M                  (linear momentum)
//! I = Σ [I_i + m_i (|d_i|² 𝟙 − d_i d_iᵀ)],   d_i = c_i − c               (parallel axes)
//! L = Σ [L_i + m_i d_i × (v_i − v)]                                   (about the new c)
//! ω = I⁻¹ L
//! ```
//!
//! (`m_i |d_i|²` in 2D.) Each ball counts with its own inertia, a disk `m r²/2` or a
//! solid sphere `2 m r²/5`, not as a point mass (PhET's Collision Lab treats the balls as
//! points). Subtracting `v` in `L` changes nothing mathematically (`Σ m_i d_i = 0`) and
//! keeps the terms small. The kinetic energy lost is computed in the centre-of-mass frame
//! (König's theorem: the `½ M |v|²` parts are equal before and after and cancel):
//! `ΔE = ½ ω·L − Σ [½ m_i |v_i − v|² + ½ ω_i·L_i] ≤ 0`.
//!
//! # What the type provides and what the engine does
//!
//! A [`RigidCluster`] stores its mass, centre of mass, orientation, body-frame inertia,
//! velocity and angular momentum `L` about its centre. Between collisions, with no
//! torque, `v` and `L` are constant; [`RigidCluster::angular_velocity`] is
//! `ω = R I_body⁻¹ Rᵀ L` for the current orientation `R`. In 2D `ω` is constant too. In
//! 3D a body with a non-spherical inertia precesses: `ω` changes while `L` is kept, so
//! the engine integrates the orientation (`Ṙ = [ω]ₓ R`, with `ω` recomputed from `L`) and
//! sets it with [`RigidCluster::with_pose`]. A collision impulse `P` at offset `r` from
//! the centre changes `v += P/M` and `L += r × P` ([`RigidCluster::with_impulse`]); the
//! impulse itself comes from [`crate::resolve`] with [`RigidCluster::body`].
//!
//! At a fusion the new body frame is the world frame (orientation identity). The member
//! lists live in the engine; [`Fusion`] says how to map each old member offset into the
//! new body frame ([`MemberMap`]), without allocating.

use carom_math::{
    InvalidValue, Problem, Real, Rotation, Space, Vector, ensure_finite_vector, ensure_positive,
};
use nalgebra::Const;

use crate::body::{ensure_finite_angular, inverse_inertia_of};
use crate::{Angular, Body, Inertia};

/// A rigid body made of stuck balls: mass, centre of mass, orientation, inertia,
/// velocity and angular momentum.
///
/// Invariants (checked by the constructors): every field finite, mass `> 0`, the body
/// inertia symmetric positive definite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidCluster<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    mass: T,
    center: Vector<T, D>,
    orientation: Rotation<T, D>,
    body_inertia: Inertia<T, D>,
    inverse_body_inertia: Inertia<T, D>,
    velocity: Vector<T, D>,
    angular_momentum: Angular<T, D>,
}

/// How an old member offset (in the body frame of a cluster that was fused) maps into the
/// body frame of the fused cluster: `new = rotation · old + shift`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemberMap<T: Real, const D: usize> {
    /// The old body frame's orientation (the new body frame is the world frame at fusion).
    pub rotation: Rotation<T, D>,
    /// The old centre of mass relative to the new one.
    pub shift: Vector<T, D>,
}

impl<T: Real, const D: usize> MemberMap<T, D> {
    /// The new body-frame offset of a member that had `offset` in the old body frame.
    #[inline]
    pub fn apply(&self, offset: &Vector<T, D>) -> Vector<T, D> {
        self.rotation * offset + self.shift
    }
}

/// The result of a stick collision: the fused cluster, how to map each side's members,
/// and the kinetic energy lost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fusion<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The fused rigid body.
    pub cluster: RigidCluster<T, D>,
    /// Maps the member offsets of the first cluster (`self` of [`RigidCluster::fuse`]).
    pub members_a: MemberMap<T, D>,
    /// Maps the member offsets of the second cluster.
    pub members_b: MemberMap<T, D>,
    /// The change of kinetic energy (never positive, up to rounding).
    pub kinetic_energy_change: T,
}

impl<T: Real, const D: usize> RigidCluster<T, D>
where
    Const<D>: Space<T, D>,
{
    /// A single uniform ball (disk in 2D, solid sphere in 3D) as a cluster of one.
    ///
    /// # Errors
    /// `mass`, `radius` if not finite and `> 0`; `center[i]`, `velocity[i]`,
    /// `angular_velocity[i]` if not finite; `inertia` if `f m r²` is not finite and
    /// positive.
    pub fn ball(
        mass: T,
        radius: T,
        center: Vector<T, D>,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        let mass = ensure_positive("mass", mass)?;
        let radius = ensure_positive("radius", radius)?;
        let inertia = <Const<D> as Space<T, D>>::inertia_isotropic(
            <Const<D> as Space<T, D>>::ball_inertia_factor() * mass * radius * radius,
        );
        Self::new(
            mass,
            center,
            Rotation::identity(),
            inertia,
            velocity,
            angular_velocity,
        )
    }

    /// A rigid body of `mass` with centre of mass at `center`, `orientation`, inertia
    /// `body_inertia` about its centre in its body frame, moving at `velocity` and
    /// spinning at `angular_velocity` (world frame).
    ///
    /// # Errors
    /// `mass` if not finite and `> 0`; `center[i]`, `velocity[i]`, `angular_velocity[i]`
    /// if not finite; `inertia` if not finite, symmetric and positive definite;
    /// `orientation` if not finite.
    pub fn new(
        mass: T,
        center: Vector<T, D>,
        orientation: Rotation<T, D>,
        body_inertia: Inertia<T, D>,
        velocity: Vector<T, D>,
        angular_velocity: Angular<T, D>,
    ) -> Result<Self, InvalidValue> {
        let mass = ensure_positive("mass", mass)?;
        let center = ensure_finite_vector("center", &center)?;
        if let Some(bad) = orientation.matrix().iter().find(|x| !x.finite()) {
            return Err(InvalidValue::new(
                "orientation",
                Problem::NotFinite(bad.to_f64()),
            ));
        }
        let inverse_body_inertia = inverse_inertia_of::<T, D>(&body_inertia)?;
        let velocity = ensure_finite_vector("velocity", &velocity)?;
        let angular_velocity =
            ensure_finite_angular::<T, D>("angular_velocity", &angular_velocity)?;
        let world_inertia = <Const<D> as Space<T, D>>::inertia_rotated(&body_inertia, &orientation);
        Ok(Self {
            mass,
            center,
            orientation,
            body_inertia,
            inverse_body_inertia,
            velocity,
            angular_momentum: <Const<D> as Space<T, D>>::inertia_apply(
                &world_inertia,
                &angular_velocity,
            ),
        })
    }

    /// The total mass.
    #[inline]
    pub fn mass(&self) -> T {
        self.mass
    }

    /// The centre of mass (world frame).
    #[inline]
    pub fn center(&self) -> Vector<T, D> {
        self.center
    }

    /// The orientation of the body frame.
    #[inline]
    pub fn orientation(&self) -> Rotation<T, D> {
        self.orientation
    }

    /// The velocity of the centre of mass.
    #[inline]
    pub fn velocity(&self) -> Vector<T, D> {
        self.velocity
    }

    /// The angular momentum about the centre of mass (world frame).
    #[inline]
    pub fn angular_momentum(&self) -> Angular<T, D> {
        self.angular_momentum
    }

    /// The inertia about the centre of mass in the body frame.
    #[inline]
    pub fn body_inertia(&self) -> Inertia<T, D> {
        self.body_inertia
    }

    /// The inertia about the centre of mass in the world frame, `R I_body Rᵀ`.
    #[inline]
    pub fn world_inertia(&self) -> Inertia<T, D> {
        <Const<D> as Space<T, D>>::inertia_rotated(&self.body_inertia, &self.orientation)
    }

    /// The inverse inertia in the world frame, `R I_body⁻¹ Rᵀ`.
    #[inline]
    pub fn world_inverse_inertia(&self) -> Inertia<T, D> {
        <Const<D> as Space<T, D>>::inertia_rotated(&self.inverse_body_inertia, &self.orientation)
    }

    /// The angular velocity for the current orientation, `ω = I_world⁻¹ L`.
    #[inline]
    pub fn angular_velocity(&self) -> Angular<T, D> {
        <Const<D> as Space<T, D>>::inertia_apply(
            &self.world_inverse_inertia(),
            &self.angular_momentum,
        )
    }

    /// The angular speed `|ω|` (rad/s).
    #[inline]
    pub fn angular_speed(&self) -> T {
        let w = self.angular_velocity();
        <Const<D> as Space<T, D>>::angular_dot(&w, &w).sqrt()
    }

    /// The linear momentum `M v`.
    #[inline]
    pub fn linear_momentum(&self) -> Vector<T, D> {
        self.velocity * self.mass
    }

    /// The angular momentum about the fixed point `origin`: `M (c − o) × v + L`.
    #[inline]
    pub fn angular_momentum_about(&self, origin: &Vector<T, D>) -> Angular<T, D> {
        <Const<D> as Space<T, D>>::cross(&(self.center - origin), &self.linear_momentum())
            + self.angular_momentum
    }

    /// The kinetic energy `½ M |v|² + ½ ω·L`.
    #[inline]
    pub fn kinetic_energy(&self) -> T {
        let half = T::lit(0.5);
        half * self.mass * self.velocity.norm_squared()
            + half
                * <Const<D> as Space<T, D>>::angular_dot(
                    &self.angular_velocity(),
                    &self.angular_momentum,
                )
    }

    /// The cluster as a collision body (for [`crate::resolve`]).
    #[inline]
    pub fn body(&self) -> Body<T, D> {
        Body::new_unchecked(
            T::one() / self.mass,
            self.world_inverse_inertia(),
            self.velocity,
            self.angular_velocity(),
        )
    }

    /// The cluster after receiving `impulse` at `offset` from its centre of mass:
    /// `v += P/M`, `L += offset × P`. With a [`crate::Response`] where the cluster is body
    /// `b`, pass `response.impulse` and `contact.offset_b()`; where it is `a`, pass
    /// `-response.impulse` and `contact.offset_a()`.
    #[inline]
    #[must_use]
    pub fn with_impulse(&self, impulse: &Vector<T, D>, offset: &Vector<T, D>) -> Self {
        Self {
            velocity: self.velocity + impulse / self.mass,
            angular_momentum: self.angular_momentum
                + <Const<D> as Space<T, D>>::cross(offset, impulse),
            ..*self
        }
    }

    /// The cluster moved to `center` and turned to `orientation` by the engine's
    /// integration of its free motion (velocity and angular momentum unchanged).
    ///
    /// Debug builds assert finiteness.
    #[inline]
    #[must_use]
    pub fn with_pose(&self, center: Vector<T, D>, orientation: Rotation<T, D>) -> Self {
        debug_assert!(
            center
                .iter()
                .chain(orientation.matrix().iter())
                .all(|x| x.finite())
        );
        Self {
            center,
            orientation,
            ..*self
        }
    }

    /// The cluster moving at `velocity` with angular momentum `angular_momentum` about its
    /// centre (world frame), as an engine's integration of forces and torques sets them
    /// (pose, mass and inertia unchanged).
    ///
    /// Debug builds assert finiteness.
    #[inline]
    #[must_use]
    pub fn with_motion(&self, velocity: Vector<T, D>, angular_momentum: Angular<T, D>) -> Self {
        debug_assert!(
            velocity
                .iter()
                .chain(<Const<D> as Space<T, D>>::angular_as_slice(
                    &angular_momentum
                ))
                .all(|x| x.finite())
        );
        Self {
            velocity,
            angular_momentum,
            ..*self
        }
    }

    /// Fuses two clusters (or balls) that stick together: one rigid body with their
    /// total linear and angular momentum (see the module documentation).
    ///
    /// # Errors
    /// `mass` or `inertia` if the fused mass or inertia overflows (only for values near
    /// the floating-point limits).
    pub fn fuse(&self, other: &Self) -> Result<Fusion<T, D>, InvalidValue> {
        let mass = ensure_positive("mass", self.mass + other.mass)?;
        let share_b = other.mass / mass;
        // c = c_a + (m_b/M)(c_b − c_a): exact for equal centres and accurate far from the origin.
        let center = self.center + (other.center - self.center) * share_b;
        let velocity = self.velocity + (other.velocity - self.velocity) * share_b;

        let half = T::lit(0.5);
        let mut inertia = <Const<D> as Space<T, D>>::inertia_isotropic(T::zero());
        let mut angular_momentum = <Const<D> as Space<T, D>>::angular_zero();
        let mut energy_before = T::zero();
        for part in [self, other] {
            let d = part.center - center;
            let relative = part.velocity - velocity;
            inertia = inertia
                + part.world_inertia()
                + <Const<D> as Space<T, D>>::inertia_parallel_axis(part.mass, &d);
            angular_momentum +=
                part.angular_momentum + <Const<D> as Space<T, D>>::cross(&d, &relative) * part.mass;
            energy_before += half * part.mass * relative.norm_squared()
                + half
                    * <Const<D> as Space<T, D>>::angular_dot(
                        &part.angular_velocity(),
                        &part.angular_momentum,
                    );
        }
        let inverse_inertia = inverse_inertia_of::<T, D>(&inertia)?;
        let cluster = Self {
            mass,
            center,
            orientation: Rotation::identity(),
            body_inertia: inertia,
            inverse_body_inertia: inverse_inertia,
            velocity,
            angular_momentum,
        };
        let energy_after = half
            * <Const<D> as Space<T, D>>::angular_dot(
                &cluster.angular_velocity(),
                &angular_momentum,
            );
        Ok(Fusion {
            cluster,
            members_a: MemberMap {
                rotation: self.orientation,
                shift: self.center - center,
            },
            members_b: MemberMap {
                rotation: other.orientation,
                shift: other.center - center,
            },
            kinetic_energy_change: energy_after - energy_before,
        })
    }
}
