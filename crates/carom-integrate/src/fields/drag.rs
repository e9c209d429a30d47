//! Air drag: linear (Stokes, `F = −b v`) and quadratic (Newton, `F = −c |v| v`).
//!
//! Linear drag models slow motion in a viscous medium and has a closed-form solution
//! together with gravity (see [`exact`](crate::exact)); quadratic drag models a ball
//! flying fast through air (`c = ½ ρ C_d A`; a table-tennis ball, `C_d ≈ 0.5`, has `c ≈ 3.8e-4` kg/m)
//! and has none in more than one dimension.

use carom_math::{InvalidValue, Real, Space, ensure_non_negative};
use nalgebra::Const;

use crate::{Acceleration, BallState, ClosedForm, ForceField};

/// Linear drag `F = −b v`: the acceleration is `−(b/m) v`.
///
/// Invariant (checked by [`LinearDrag::new`]): `b` is finite and `>= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearDrag<T: Real> {
    coefficient: T,
}

impl<T: Real> LinearDrag<T> {
    /// Linear drag with `coefficient` `b` (force per velocity, kg/s).
    ///
    /// # Errors
    /// `coefficient` if not finite or negative.
    pub fn new(coefficient: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            coefficient: ensure_non_negative("coefficient", coefficient)?,
        })
    }

    /// The coefficient `b`.
    #[inline]
    pub fn coefficient(&self) -> T {
        self.coefficient
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for LinearDrag<T>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        Acceleration::linear(ball.velocity * -(self.coefficient * ball.inverse_mass))
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        Some(ClosedForm {
            linear_drag: self.coefficient,
            ..ClosedForm::free()
        })
    }
}

/// Quadratic drag `F = −c |v| v`: opposite to the velocity, growing with its square.
///
/// Invariant (checked by [`QuadraticDrag::new`]): `c` is finite and `>= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadraticDrag<T: Real> {
    coefficient: T,
}

impl<T: Real> QuadraticDrag<T> {
    /// Quadratic drag with `coefficient` `c` (kg/m).
    ///
    /// # Errors
    /// `coefficient` if not finite or negative.
    pub fn new(coefficient: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            coefficient: ensure_non_negative("coefficient", coefficient)?,
        })
    }

    /// The coefficient `c`.
    #[inline]
    pub fn coefficient(&self) -> T {
        self.coefficient
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for QuadraticDrag<T>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        let speed = ball.velocity.norm();
        Acceleration::linear(ball.velocity * -(self.coefficient * ball.inverse_mass * speed))
    }

    /// Free flight when the coefficient is zero (so a fixed composition with unused
    /// parts set to zero keeps the exact integrator); otherwise none.
    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        (self.coefficient == T::zero()).then(ClosedForm::free)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2};

    fn ball(v: Vector2<f64>, inverse_mass: f64) -> BallState<f64, 2> {
        BallState {
            position: Vector2::zeros(),
            velocity: v,
            spin: Vector1::zeros(),
            inverse_mass,
            time: 0.0,
        }
    }

    #[test]
    fn drags_oppose_the_velocity_with_the_right_magnitude() {
        let v = Vector2::new(-3.0, 4.0); // speed 5
        let lin = LinearDrag::new(0.2).unwrap().acceleration(&ball(v, 0.5));
        assert!((lin.linear - Vector2::new(0.3, -0.4)).norm() < 1e-15); // −(0.2·0.5)·v
        let quad = QuadraticDrag::new(0.2).unwrap().acceleration(&ball(v, 0.5));
        assert!((quad.linear - Vector2::new(1.5, -2.0)).norm() < 1e-15); // −(0.2·0.5·5)·v
        assert_eq!(
            QuadraticDrag::new(0.2).unwrap().acceleration(&ball(v, 0.0)),
            Acceleration::zero()
        );
    }

    #[test]
    fn coefficients_must_be_finite_and_non_negative() {
        assert_eq!(LinearDrag::new(-0.1).unwrap_err().field, "coefficient");
        assert!(QuadraticDrag::new(f32::INFINITY).is_err());
        assert!(LinearDrag::new(0.0_f32).is_ok());
    }

    #[test]
    fn quadratic_drag_has_a_closed_form_only_when_it_is_zero() {
        let zero = QuadraticDrag::new(0.0).unwrap();
        assert_eq!(
            ForceField::<f64, 2>::closed_form(&zero),
            Some(ClosedForm::free())
        );
        let some = QuadraticDrag::new(1e-4).unwrap();
        assert_eq!(ForceField::<f64, 2>::closed_form(&some), None);
    }
}
