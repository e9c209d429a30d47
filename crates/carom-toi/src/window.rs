//! The time window of a query: which way time runs and how far to look.
//!
//! The event-driven engine asks "when, relative to now, do these two first touch?",
//! looking forward, or backward when the simulation runs in reverse, and only as far as
//! its horizon. Every query takes a [`Window`]; the times it returns are signed offsets
//! from now: `t >= 0` forward, `t <= 0` backward.
//!
//! Backward in time means the substitution `t = −s`, `s >= 0`: a body at `p + v t + a t²/2`
//! is at `p − v s + a s²/2`. So a backward query is the forward query with every velocity
//! negated (accelerations unchanged), and its answer `s` is reported as `t = −s`. A pair
//! that approaches when time runs backwards is one that recedes forwards.

use carom_math::{InvalidValue, Problem, Real, Vector};

/// Which way time runs for a query.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Towards the future: returned times are `>= 0`.
    Forward,
    /// Towards the past (a reversed simulation): returned times are `<= 0`.
    Backward,
}

impl Direction {
    /// `+1` forward, `−1` backward: the sign of every returned time.
    #[inline]
    pub fn sign<T: Real>(self) -> T {
        match self {
            Direction::Forward => T::one(),
            Direction::Backward => -T::one(),
        }
    }

    /// A velocity as seen when time runs this way (negated backward).
    #[inline]
    pub fn orient<T: Real, const D: usize>(self, v: &Vector<T, D>) -> Vector<T, D> {
        match self {
            Direction::Forward => *v,
            Direction::Backward => -v,
        }
    }
}

/// The direction and horizon of a time-of-impact query.
///
/// Invariant (checked by [`Window::new`]): the horizon is `>= 0` and not NaN; `+∞` means
/// no limit. Events farther than the horizon are reported as [`Status::NoHit`]; an event
/// exactly at the horizon is reported.
///
/// [`Status::NoHit`]: crate::Status::NoHit
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window<T: Real> {
    direction: Direction,
    horizon: T,
}

impl<T: Real> Window<T> {
    /// A window looking `horizon` time units in `direction`.
    ///
    /// # Errors
    /// `horizon` if NaN or negative (`+∞` is accepted: no limit).
    pub fn new(direction: Direction, horizon: T) -> Result<Self, InvalidValue> {
        if crate::roots::is_nan(horizon) {
            return Err(InvalidValue::new(
                "horizon",
                Problem::NotFinite(horizon.to_f64()),
            ));
        }
        if horizon < T::zero() {
            return Err(InvalidValue::new(
                "horizon",
                Problem::Negative(horizon.to_f64()),
            ));
        }
        Ok(Self { direction, horizon })
    }

    /// Looking forward up to `horizon`.
    ///
    /// # Errors
    /// As [`Window::new`].
    pub fn forward(horizon: T) -> Result<Self, InvalidValue> {
        Self::new(Direction::Forward, horizon)
    }

    /// Looking backward up to `horizon` (returned times are in `[−horizon, 0]`).
    ///
    /// # Errors
    /// As [`Window::new`].
    pub fn backward(horizon: T) -> Result<Self, InvalidValue> {
        Self::new(Direction::Backward, horizon)
    }

    /// Looking in `direction` without limit.
    pub fn unbounded(direction: Direction) -> Self {
        Self {
            direction,
            horizon: T::INFINITY,
        }
    }

    /// The direction.
    #[inline]
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// The horizon, `>= 0` (`+∞` for none).
    #[inline]
    pub fn horizon(&self) -> T {
        self.horizon
    }

    /// A forward search time `s >= 0` as the signed time reported to the caller.
    #[inline]
    pub(crate) fn signed(&self, s: T) -> T {
        s * self.direction.sign() + T::zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizon_must_be_non_negative_and_not_nan() {
        assert_eq!(Window::forward(-1.0_f64).unwrap_err().field, "horizon");
        assert_eq!(Window::backward(f32::NAN).unwrap_err().field, "horizon");
        assert!(Window::forward(f64::INFINITY).is_ok());
        assert!(Window::forward(0.0_f64).is_ok());
    }

    #[test]
    fn backward_negates_velocities_and_times() {
        let w = Window::<f64>::unbounded(Direction::Backward);
        assert_eq!(w.signed(2.0), -2.0);
        let v = nalgebra::Vector2::new(1.0, -2.0);
        assert_eq!(w.direction().orient(&v), -v);
        assert_eq!(Direction::Forward.orient(&v), v);
    }
}
