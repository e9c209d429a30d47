//! How a rigid cluster moves: the [`RigidMotion`] trait and its constant-rate
//! implementation [`ConstantSpin`].
//!
//! Conservative advancement needs two things from a motion: where a body point is (and
//! how fast it moves) at a time, and rigorous bounds on how fast and how sharply any
//! body point within a distance `reach` of the reference point can move over a time
//! interval. Engines with other motions (a torque-free asymmetric top in 3D, a motion
//! integrated numerically with error bounds) implement the trait themselves.

use carom_geometry::Obb;
use carom_math::{InvalidValue, Real, Rotation, Space, Vector, ensure_finite_vector};
use nalgebra::{Const, SMatrix};

use crate::Kinematics;

/// The pose and velocities of a rigid body at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidState<T: Real, const D: usize> {
    /// The world position of the reference point (the centre of mass).
    pub position: Vector<T, D>,
    /// The rotation from the body frame to the world frame.
    pub rotation: Rotation<T, D>,
    /// The velocity of the reference point.
    pub velocity: Vector<T, D>,
    /// The spin as a skew-symmetric matrix `Ω`: a world offset `r` from the reference
    /// point moves at `Ω r` relative to it (`Ω r = ω × r`).
    pub spin: SMatrix<T, D, D>,
}

impl<T: Real, const D: usize> RigidState<T, D> {
    /// The world position of the body point at `offset` (body frame).
    #[inline]
    pub fn point(&self, offset: &Vector<T, D>) -> Vector<T, D> {
        self.position + self.rotation * offset
    }

    /// The world velocity of the body point at `offset` (body frame).
    #[inline]
    pub fn point_velocity(&self, offset: &Vector<T, D>) -> Vector<T, D> {
        let arm: Vector<T, D> = self.rotation * offset;
        self.velocity + self.spin * arm
    }
}

/// A rigid motion that conservative advancement can follow.
///
/// Contract (what makes the advancement rigorous):
///
/// * [`speed_bound`](Self::speed_bound)`(reach, t0, t1)` bounds the speed of every body
///   point at distance `<= reach` from the reference point, at every time between `t0`
///   and `t1` (in either order), and does not decrease when the interval grows;
/// * [`acceleration_bound`](Self::acceleration_bound) bounds their accelerations the same
///   way (return `+∞` if unknown: advancement then uses first-order steps only).
pub trait RigidMotion<T: Real, const D: usize> {
    /// The state at time `t` (any sign).
    fn state_at(&self, t: T) -> RigidState<T, D>;
    /// A bound on the speed of points within `reach` of the reference point, over the
    /// times between `t0` and `t1`.
    fn speed_bound(&self, reach: T, t0: T, t1: T) -> T;
    /// A bound on the acceleration of points within `reach`, over the times between
    /// `t0` and `t1`.
    fn acceleration_bound(&self, reach: T, t0: T, t1: T) -> T;
}

/// A body whose reference point moves with constant acceleration (`p + v t + a t²/2`)
/// while it spins at a constant angular velocity `ω` (world frame): orientation
/// `R(t) = exp(t [ω]×) R₀`.
///
/// Constant `ω` is exact in 2D. In 3D a free body keeps a constant `ω` only when its
/// inertia is spherical (a single ball, a symmetric cluster) or it spins about a
/// principal axis; otherwise it precesses, and an engine should implement
/// [`RigidMotion`] with its own integrator and bounds.
///
/// Bounds: a point at world offset `ρ = R(t) o` moves at `v + a t + ω × ρ`, so its speed
/// is at most `max(|v + a t₀|, |v + a t₁|) + |ω| reach` (`|v + a t|` is convex in `t`)
/// and its acceleration `a + ω × (ω × ρ)` at most `|a| + |ω|² reach`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstantSpin<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    position: Vector<T, D>,
    orientation: Rotation<T, D>,
    kinematics: Kinematics<T, D>,
    angular_velocity: <Const<D> as Space<T, D>>::Angular,
    spin: SMatrix<T, D, D>,
    spin_rate: T,
}

impl<T: Real, const D: usize> ConstantSpin<T, D>
where
    Const<D>: Space<T, D>,
{
    /// A body at `position` with `orientation` at time 0, moving with `kinematics` and
    /// spinning at `angular_velocity` (`Vector1` in 2D, `Vector3` in 3D, world frame).
    ///
    /// # Errors
    /// `position[i]` if not finite; `rotation` if `orientation` is not a proper rotation
    /// (the check of [`Obb::new`]); `angular_velocity` if not finite.
    pub fn new(
        position: Vector<T, D>,
        orientation: Rotation<T, D>,
        kinematics: Kinematics<T, D>,
        angular_velocity: <Const<D> as Space<T, D>>::Angular,
    ) -> Result<Self, InvalidValue> {
        ensure_finite_vector("position", &position)?;
        Obb::new(position, Vector::zeros(), orientation)?;
        let rate_sq = <Const<D> as Space<T, D>>::angular_dot(&angular_velocity, &angular_velocity);
        carom_math::ensure_finite("angular_velocity", rate_sq)?;
        Ok(Self::new_unchecked(
            position,
            orientation,
            kinematics,
            angular_velocity,
        ))
    }

    /// From values the caller has already validated (hot paths).
    pub fn new_unchecked(
        position: Vector<T, D>,
        orientation: Rotation<T, D>,
        kinematics: Kinematics<T, D>,
        angular_velocity: <Const<D> as Space<T, D>>::Angular,
    ) -> Self {
        let columns: [Vector<T, D>; D] = core::array::from_fn(|j| {
            let mut e = Vector::<T, D>::zeros();
            e[j] = T::one();
            <Const<D> as Space<T, D>>::angular_cross(&angular_velocity, &e)
        });
        let spin = SMatrix::<T, D, D>::from_columns(&columns);
        let spin_rate =
            <Const<D> as Space<T, D>>::angular_dot(&angular_velocity, &angular_velocity).sqrt();
        Self {
            position,
            orientation,
            kinematics,
            angular_velocity,
            spin,
            spin_rate,
        }
    }

    /// A body that translates without spinning.
    pub(crate) fn translating(position: Vector<T, D>, kinematics: Kinematics<T, D>) -> Self {
        Self::new_unchecked(
            position,
            Rotation::identity(),
            kinematics,
            <Const<D> as Space<T, D>>::angular_zero(),
        )
    }

    /// The angular velocity.
    pub fn angular_velocity(&self) -> <Const<D> as Space<T, D>>::Angular {
        self.angular_velocity
    }

    /// The translational motion of the reference point.
    pub fn kinematics(&self) -> &Kinematics<T, D> {
        &self.kinematics
    }
}

impl<T: Real, const D: usize> RigidMotion<T, D> for ConstantSpin<T, D>
where
    Const<D>: Space<T, D>,
{
    fn state_at(&self, t: T) -> RigidState<T, D> {
        RigidState {
            position: self.position + self.kinematics.displacement(t),
            rotation: <Const<D> as Space<T, D>>::rotation_from_angular(&self.angular_velocity, t)
                * self.orientation,
            velocity: self.kinematics.velocity_at(t),
            spin: self.spin,
        }
    }

    fn speed_bound(&self, reach: T, t0: T, t1: T) -> T {
        let (k, spin) = (&self.kinematics, self.spin_rate);
        k.velocity_at(t0).norm().max(k.velocity_at(t1).norm()) + spin * reach
    }

    fn acceleration_bound(&self, reach: T, _t0: T, _t1: T) -> T {
        self.kinematics.acceleration().norm() + self.spin_rate * self.spin_rate * reach
    }
}

/// A motion seen in search time `s >= 0` for a window's direction: `t = sign · s`, so
/// velocities and spins are multiplied by `sign` (time reversal) and positions are those
/// of the original motion at `t`.
pub(crate) struct Oriented<'a, T, M> {
    pub(crate) motion: &'a M,
    pub(crate) sign: T,
}

impl<T: Real, const D: usize, M: RigidMotion<T, D>> RigidMotion<T, D> for Oriented<'_, T, M> {
    fn state_at(&self, s: T) -> RigidState<T, D> {
        let sign = self.sign;
        let mut state = self.motion.state_at(s * sign);
        state.velocity *= sign;
        state.spin *= sign;
        state
    }

    fn speed_bound(&self, reach: T, s0: T, s1: T) -> T {
        let sign = self.sign;
        self.motion.speed_bound(reach, s0 * sign, s1 * sign)
    }

    fn acceleration_bound(&self, reach: T, s0: T, s1: T) -> T {
        let sign = self.sign;
        self.motion.acceleration_bound(reach, s0 * sign, s1 * sign)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2, Vector3};

    #[test]
    fn spin_matrix_is_the_cross_product() {
        let w = Vector3::new(0.3, -1.0, 2.0);
        let m = ConstantSpin::new(
            Vector3::zeros(),
            Rotation::identity(),
            Kinematics::at_rest(),
            w,
        )
        .unwrap();
        let r = Vector3::new(1.0, 2.0, -0.5);
        assert!((m.state_at(0.0).spin * r - w.cross(&r)).norm() < 1e-15);
    }

    #[test]
    fn a_point_on_a_spinning_disc_moves_on_its_circle_within_the_speed_bound() {
        let m = ConstantSpin::new(
            Vector2::new(1.0, 1.0),
            Rotation::identity(),
            Kinematics::new(Vector2::new(1.0, 0.0), Vector2::new(0.0, -2.0)).unwrap(),
            Vector1::new(3.0),
        )
        .unwrap();
        let o = Vector2::new(0.5, 0.0);
        for k in 0..20 {
            let t = f64::from(k) * 0.1;
            let s = m.state_at(t);
            let expected = Vector2::new(1.0 + t, 1.0 - t * t)
                + Vector2::new((3.0 * t).cos(), (3.0 * t).sin()) * 0.5;
            assert!((s.point(&o) - expected).norm() < 1e-14);
            assert!(s.point_velocity(&o).norm() <= m.speed_bound(0.5, 0.0, 2.0) + 1e-14);
        }
        assert_eq!(
            ConstantSpin::new(
                Vector2::new(0.0, 0.0),
                Rotation::identity(),
                Kinematics::at_rest(),
                Vector1::new(f64::NAN)
            )
            .unwrap_err()
            .field,
            "angular_velocity"
        );
    }
}
