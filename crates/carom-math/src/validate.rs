//! Validation of user input: one error type that names the offending field.
//!
//! Every validated constructor in carom returns `Result<_, InvalidValue>`. The error
//! names the field (`radius`, `center[1]`) and what is wrong with the value; callers
//! that know more context prepend it with [`InvalidValue::within`], so a scene loader
//! reports `balls[3].radius: must be > 0, got -0.1`.

use std::borrow::Cow;
use std::fmt;

use nalgebra::SVector;

use crate::Real;

/// What is wrong with a value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Problem {
    /// NaN or infinite.
    NotFinite(f64),
    /// Must be strictly positive.
    NotPositive(f64),
    /// Must be zero or positive.
    Negative(f64),
    /// Must lie in the closed interval `[min, max]`.
    OutOfRange {
        /// The value given.
        value: f64,
        /// The smallest allowed value.
        min: f64,
        /// The largest allowed value.
        max: f64,
    },
    /// A direction that must have non-zero length (it is normalised) was zero or tiny.
    ZeroLength(f64),
    /// A lower bound exceeds its upper bound.
    Inverted {
        /// The lower bound given.
        min: f64,
        /// The upper bound given.
        max: f64,
    },
    /// A set that must not be empty was empty.
    Empty,
    /// A matrix (an inertia tensor) that must be symmetric positive definite is not.
    NotPositiveDefinite,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Problem::NotFinite(v) => write!(f, "must be finite, got {v}"),
            Problem::NotPositive(v) => write!(f, "must be > 0, got {v}"),
            Problem::Negative(v) => write!(f, "must be >= 0, got {v}"),
            Problem::OutOfRange { value, min, max } => {
                write!(f, "must be in [{min}, {max}], got {value}")
            }
            Problem::ZeroLength(n) => write!(f, "must have non-zero length, got length {n}"),
            Problem::Inverted { min, max } => {
                write!(f, "lower bound {min} exceeds upper bound {max}")
            }
            Problem::Empty => write!(f, "must not be empty"),
            Problem::NotPositiveDefinite => write!(f, "must be symmetric positive definite"),
        }
    }
}

/// A rejected input value: which field, and what is wrong with it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct InvalidValue {
    /// The field path, e.g. `radius`, `center[1]` or, with context, `balls[3].radius`.
    pub field: Cow<'static, str>,
    /// What is wrong.
    pub problem: Problem,
}

impl InvalidValue {
    /// An error for `field`.
    pub fn new(field: impl Into<Cow<'static, str>>, problem: Problem) -> Self {
        Self {
            field: field.into(),
            problem,
        }
    }

    /// Prepends the enclosing context: `radius` within `balls[3]` becomes `balls[3].radius`.
    #[must_use]
    pub fn within(mut self, context: &str) -> Self {
        self.field = Cow::Owned(format!("{context}.{}", self.field));
        self
    }
}

/// `Ok(x)` if `x` is finite.
///
/// # Errors
/// [`Problem::NotFinite`] naming `field`.
pub fn ensure_finite<T: Real>(field: &'static str, x: T) -> Result<T, InvalidValue> {
    if x.finite() {
        Ok(x)
    } else {
        Err(InvalidValue::new(field, Problem::NotFinite(x.to_f64())))
    }
}

/// `Ok(v)` if every component of `v` is finite.
///
/// # Errors
/// [`Problem::NotFinite`] naming `field[i]` for the first bad component.
pub fn ensure_finite_vector<T: Real, const D: usize>(
    field: &'static str,
    v: &SVector<T, D>,
) -> Result<SVector<T, D>, InvalidValue> {
    match v.iter().position(|c| !c.finite()) {
        None => Ok(*v),
        Some(i) => Err(InvalidValue::new(
            format!("{field}[{i}]"),
            Problem::NotFinite(v[i].to_f64()),
        )),
    }
}

/// `Ok(x)` if `x` is finite and `> 0`.
///
/// # Errors
/// [`Problem::NotFinite`] or [`Problem::NotPositive`] naming `field`.
pub fn ensure_positive<T: Real>(field: &'static str, x: T) -> Result<T, InvalidValue> {
    let x = ensure_finite(field, x)?;
    if x > T::zero() {
        Ok(x)
    } else {
        Err(InvalidValue::new(field, Problem::NotPositive(x.to_f64())))
    }
}

/// `Ok(x)` if `x` is finite and `>= 0`.
///
/// # Errors
/// [`Problem::NotFinite`] or [`Problem::Negative`] naming `field`.
pub fn ensure_non_negative<T: Real>(field: &'static str, x: T) -> Result<T, InvalidValue> {
    let x = ensure_finite(field, x)?;
    if x >= T::zero() {
        Ok(x)
    } else {
        Err(InvalidValue::new(field, Problem::Negative(x.to_f64())))
    }
}

/// `Ok(x)` if `x` is finite and in `[min, max]`.
///
/// # Errors
/// [`Problem::NotFinite`] or [`Problem::OutOfRange`] naming `field`.
pub fn ensure_in_range<T: Real>(
    field: &'static str,
    x: T,
    min: T,
    max: T,
) -> Result<T, InvalidValue> {
    let x = ensure_finite(field, x)?;
    if x >= min && x <= max {
        Ok(x)
    } else {
        Err(InvalidValue::new(
            field,
            Problem::OutOfRange {
                value: x.to_f64(),
                min: min.to_f64(),
                max: max.to_f64(),
            },
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn errors_name_the_field_and_the_value() {
        let e = ensure_positive("radius", -0.1_f64).unwrap_err();
        assert_eq!(e.to_string(), "radius: must be > 0, got -0.1");
        let e = e.within("balls[3]");
        assert_eq!(e.to_string(), "balls[3].radius: must be > 0, got -0.1");
    }

    #[test]
    fn vector_errors_name_the_component() {
        let e = ensure_finite_vector("center", &Vector3::new(0.0, f64::NAN, 1.0)).unwrap_err();
        assert_eq!(e.field, "center[1]");
        assert!(matches!(e.problem, Problem::NotFinite(v) if v.is_nan()));
    }

    #[test]
    fn range_and_sign_checks_accept_their_bounds_and_reject_outside() {
        assert_eq!(ensure_in_range("restitution", 1.0_f32, 0.0, 1.0), Ok(1.0));
        assert_eq!(ensure_in_range("restitution", 0.0_f32, 0.0, 1.0), Ok(0.0));
        assert!(ensure_in_range("restitution", 1.0000001_f32, 0.0, 1.0).is_err());
        assert_eq!(ensure_non_negative("half_extents", 0.0_f64), Ok(0.0));
        assert!(ensure_non_negative("half_extents", -0.0_f64).is_ok());
        assert!(ensure_positive("mass", 0.0_f64).is_err());
        assert!(ensure_positive("mass", f64::INFINITY).is_err());
    }
}
