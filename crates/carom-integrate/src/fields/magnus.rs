//! Spin: the Magnus force on a spinning ball and the damping of its spin by the air.
//!
//! A ball spinning at `ω` through air at velocity `v` drags a boundary layer around with
//! it; the asymmetric flow pushes it sideways with `F = S ω × v` (topspin dips a
//! ping-pong ball, backspin floats it). In 2D the spin is the z component `ω` and
//! `ω × v = ω (−v_y, v_x)`, the velocity turned a quarter to the left
//! ([`Space::angular_cross`]). `S` lumps `½ ρ A r C_L`; for a table-tennis ball it is
//! about `4e-6` kg. The Magnus force is perpendicular to `v`, so it does no work.
//!
//! Air torque slows the spin; [`SpinDamping`] models it as `dω/dt = −λ ω`
//! (exponential decay with time constant `1/λ`), which keeps the family of closed-form
//! fields (gravity, linear drag) closed.

use carom_math::{InvalidValue, Real, Space, ensure_non_negative};
use nalgebra::Const;

use crate::{Acceleration, BallState, ClosedForm, ForceField};

/// The Magnus force `F = S ω × v`.
///
/// Invariant (checked by [`Magnus::new`]): `S` is finite and `>= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnus<T: Real> {
    coefficient: T,
}

impl<T: Real> Magnus<T> {
    /// The Magnus force with `coefficient` `S` (kg).
    ///
    /// # Errors
    /// `coefficient` if not finite or negative.
    pub fn new(coefficient: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            coefficient: ensure_non_negative("coefficient", coefficient)?,
        })
    }

    /// The coefficient `S`.
    #[inline]
    pub fn coefficient(&self) -> T {
        self.coefficient
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for Magnus<T>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        let w_cross_v = <Const<D> as Space<T, D>>::angular_cross(&ball.spin, &ball.velocity);
        Acceleration::linear(w_cross_v * (self.coefficient * ball.inverse_mass))
    }

    /// Free flight when the coefficient is zero; otherwise none.
    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        (self.coefficient == T::zero()).then(ClosedForm::free)
    }
}

/// Spin damping `dω/dt = −λ ω` for balls of finite mass: the spin decays as `e^{−λ t}`.
///
/// Invariant (checked by [`SpinDamping::new`]): `λ` is finite and `>= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinDamping<T: Real> {
    rate: T,
}

impl<T: Real> SpinDamping<T> {
    /// Spin damping at `rate` `λ` (per second).
    ///
    /// # Errors
    /// `rate` if not finite or negative.
    pub fn new(rate: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            rate: ensure_non_negative("rate", rate)?,
        })
    }

    /// The rate `λ`.
    #[inline]
    pub fn rate(&self) -> T {
        self.rate
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for SpinDamping<T>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        if ball.inverse_mass > T::zero() {
            Acceleration::angular(ball.spin * -self.rate)
        } else {
            Acceleration::zero()
        }
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        Some(ClosedForm {
            spin_damping: self.rate,
            ..ClosedForm::free()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2, Vector3};

    #[test]
    fn magnus_in_3d_is_s_omega_cross_v_over_m_and_topspin_dips() {
        let ball = BallState {
            position: Vector3::zeros(),
            velocity: Vector3::new(10.0, 0.0, 0.0),
            // Topspin: the top of the ball (+z) moves forward (+x), ω × (0, 0, r) ∥ +x.
            spin: Vector3::new(0.0, 100.0, 0.0),
            inverse_mass: 1.0 / 0.0027,
            time: 0.0,
        };
        let a = Magnus::new(4e-6).unwrap().acceleration(&ball).linear;
        // ω × v = (ω_y v_z − ω_z v_y, ω_z v_x − ω_x v_z, ω_x v_y − ω_y v_x) = (0, 0, −1000):
        // topspin pushes the ball down.
        let expected = Vector3::new(0.0, 0.0, -1000.0) * (4e-6 / 0.0027);
        assert!((a - expected).norm() < 1e-12);
        assert_eq!(a.dot(&ball.velocity), 0.0);
    }

    #[test]
    fn magnus_in_2d_turns_the_velocity_left_for_positive_spin() {
        let ball = BallState {
            position: Vector2::zeros(),
            velocity: Vector2::new(3.0, 4.0),
            spin: Vector1::new(2.0),
            inverse_mass: 0.5,
            time: 0.0,
        };
        let a = Magnus::new(0.1).unwrap().acceleration(&ball).linear;
        assert!((a - Vector2::new(-4.0, 3.0) * (2.0 * 0.1 * 0.5)).norm() < 1e-15);
    }

    #[test]
    fn spin_damping_decays_finite_masses_only() {
        let mut ball = BallState {
            position: Vector3::zeros(),
            velocity: Vector3::zeros(),
            spin: Vector3::new(1.0, -2.0, 3.0),
            inverse_mass: 2.0,
            time: 0.0,
        };
        let damping = SpinDamping::new(0.5).unwrap();
        assert_eq!(
            damping.acceleration(&ball).angular,
            Vector3::new(-0.5, 1.0, -1.5)
        );
        ball.inverse_mass = 0.0;
        assert_eq!(damping.acceleration(&ball), Acceleration::zero());
        assert_eq!(SpinDamping::new(-1.0_f32).unwrap_err().field, "rate");
        assert_eq!(Magnus::new(f64::NAN).unwrap_err().field, "coefficient");
        let off = Magnus::new(0.0).unwrap();
        assert_eq!(
            ForceField::<f64, 3>::closed_form(&off),
            Some(ClosedForm::free())
        );
        assert_eq!(
            ForceField::<f64, 3>::closed_form(&Magnus::new(1e-6).unwrap()),
            None
        );
    }
}
