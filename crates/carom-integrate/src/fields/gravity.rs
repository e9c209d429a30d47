//! Uniform gravity: the same acceleration `g` for every ball of finite mass.

use carom_math::{InvalidValue, Real, Space, Vector, ensure_finite_vector};
use nalgebra::Const;

use crate::{Acceleration, BallState, ClosedForm, ForceField};

/// Uniform gravity: `dv/dt = g`, whatever the mass.
///
/// Invariant (checked by [`Gravity::new`]): `g` is finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gravity<T: Real, const D: usize> {
    g: Vector<T, D>,
}

impl<T: Real, const D: usize> Gravity<T, D> {
    /// Gravity of acceleration `g` (for example `(0, −9.81)` m/s²).
    ///
    /// # Errors
    /// `g[i]` if a component is not finite.
    pub fn new(g: Vector<T, D>) -> Result<Self, InvalidValue> {
        Ok(Self {
            g: ensure_finite_vector("g", &g)?,
        })
    }

    /// The acceleration `g`.
    #[inline]
    pub fn g(&self) -> Vector<T, D> {
        self.g
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for Gravity<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        if ball.inverse_mass > T::zero() {
            Acceleration::linear(self.g)
        } else {
            Acceleration::zero()
        }
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        Some(ClosedForm {
            gravity: self.g,
            ..ClosedForm::free()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn gravity_accelerates_every_finite_mass_alike_and_no_infinite_one() {
        let g = Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap();
        let mut ball = BallState {
            position: Vector3::zeros(),
            velocity: Vector3::new(1.0, 2.0, 3.0),
            spin: Vector3::zeros(),
            inverse_mass: 1e-6,
            time: 0.0,
        };
        assert_eq!(g.acceleration(&ball).linear, g.g());
        ball.inverse_mass = 1e6;
        assert_eq!(g.acceleration(&ball).linear, g.g());
        ball.inverse_mass = 0.0;
        assert_eq!(g.acceleration(&ball), Acceleration::zero());
        assert_eq!(
            Gravity::new(Vector2::new(0.0, f32::NAN)).unwrap_err().field,
            "g[1]"
        );
    }
}
