//! The motion of a body between events: constant velocity plus constant acceleration.
//!
//! Between two events of the event-driven engine a ball moves on `p(t) = p + v t + a t²/2`
//! (a straight line when `a = 0`, a parabola under gravity). Boxes move the same way
//! without rotating. A query subtracts the two bodies' motions: relative velocity and
//! relative acceleration; equal accelerations (everyone under the same gravity) cancel,
//! and the relative motion is a straight line again.

use carom_math::{InvalidValue, Real, Vector, ensure_finite_vector};

/// The velocity and constant acceleration of a body (both finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics<T: Real, const D: usize> {
    velocity: Vector<T, D>,
    acceleration: Vector<T, D>,
}

impl<T: Real, const D: usize> Kinematics<T, D> {
    /// Moving at `velocity` with constant `acceleration`.
    ///
    /// # Errors
    /// `velocity[i]` or `acceleration[i]` if not finite.
    pub fn new(velocity: Vector<T, D>, acceleration: Vector<T, D>) -> Result<Self, InvalidValue> {
        Ok(Self {
            velocity: ensure_finite_vector("velocity", &velocity)?,
            acceleration: ensure_finite_vector("acceleration", &acceleration)?,
        })
    }

    /// Moving in a straight line at `velocity`.
    ///
    /// # Errors
    /// `velocity[i]` if not finite.
    pub fn linear(velocity: Vector<T, D>) -> Result<Self, InvalidValue> {
        Self::new(velocity, Vector::zeros())
    }

    /// At rest, no acceleration.
    pub fn at_rest() -> Self {
        Self {
            velocity: Vector::zeros(),
            acceleration: Vector::zeros(),
        }
    }

    /// From values the caller has already validated (hot paths).
    #[inline]
    pub fn new_unchecked(velocity: Vector<T, D>, acceleration: Vector<T, D>) -> Self {
        debug_assert!(
            velocity
                .iter()
                .chain(acceleration.iter())
                .all(|x| x.finite())
        );
        Self {
            velocity,
            acceleration,
        }
    }

    /// The velocity at time 0.
    #[inline]
    pub fn velocity(&self) -> Vector<T, D> {
        self.velocity
    }

    /// The constant acceleration.
    #[inline]
    pub fn acceleration(&self) -> Vector<T, D> {
        self.acceleration
    }

    /// The displacement after time `t`: `v t + a t²/2`.
    #[inline]
    pub fn displacement(&self, t: T) -> Vector<T, D> {
        (self.velocity + self.acceleration * (T::lit(0.5) * t)) * t
    }

    /// The velocity at time `t`: `v + a t`.
    #[inline]
    pub fn velocity_at(&self, t: T) -> Vector<T, D> {
        self.velocity + self.acceleration * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn displacement_is_the_parabola() {
        let k = Kinematics::new(Vector2::new(1.0, 2.0), Vector2::new(0.0, -10.0)).unwrap();
        assert_eq!(k.displacement(2.0), Vector2::new(2.0, -16.0));
        assert_eq!(k.velocity_at(2.0), Vector2::new(1.0, -18.0));
        assert_eq!(
            Kinematics::linear(Vector2::new(f64::NAN, 0.0))
                .unwrap_err()
                .field,
            "velocity[0]"
        );
    }
}
