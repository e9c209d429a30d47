//! The two numbers that say what kind of collision it is: restitution and friction.
//!
//! * Restitution `e ∈ [0, 1]`: the normal relative velocity after the collision is `−e`
//!   times the one before (Newton's law). `e = 1` is elastic, `e = 0` removes the normal
//!   relative velocity (Collision Lab's inelastic "slide").
//! * Friction `μ ≥ 0`: the tangential impulse is at most `μ` times the normal one
//!   (Coulomb's cone, applied to impulses).
//!
//! Per-body values combine for a pair with [`Coefficients::for_pair`]: restitution takes
//! the minimum of the two (the scene contract: the less bouncy body decides), friction
//! the geometric mean `√(μ_a μ_b)` (Box2D's mixing rule: a frictionless body makes the
//! contact frictionless, and equal values are kept).

use carom_math::{InvalidValue, Real, ensure_in_range, ensure_non_negative};

/// Restitution and friction of a contact.
///
/// Invariants (checked by [`Coefficients::new`]): `0 ≤ restitution ≤ 1`, `friction`
/// finite and `≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients<T: Real> {
    restitution: T,
    friction: T,
}

impl<T: Real> Coefficients<T> {
    /// Restitution `e` and friction `μ`.
    ///
    /// # Errors
    /// `restitution` if not in `[0, 1]`; `friction` if not finite and `≥ 0`.
    pub fn new(restitution: T, friction: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            restitution: ensure_in_range("restitution", restitution, T::zero(), T::one())?,
            friction: ensure_non_negative("friction", friction)?,
        })
    }

    /// A frictionless contact with restitution `e`.
    ///
    /// # Errors
    /// `restitution` if not in `[0, 1]`.
    pub fn frictionless(restitution: T) -> Result<Self, InvalidValue> {
        Self::new(restitution, T::zero())
    }

    /// Elastic and frictionless (`e = 1`, `μ = 0`): kinetic energy is conserved.
    pub fn elastic() -> Self {
        Self::new_unchecked(T::one(), T::zero())
    }

    /// Collision Lab's inelastic "slide" (`e = 0`, `μ = 0`): only the normal relative
    /// velocity is removed; the balls slide past each other tangentially.
    pub fn slide() -> Self {
        Self::new_unchecked(T::zero(), T::zero())
    }

    /// Coefficients from validated values (hot paths). Debug builds assert the invariants.
    #[inline]
    pub fn new_unchecked(restitution: T, friction: T) -> Self {
        debug_assert!(restitution >= T::zero() && restitution <= T::one());
        debug_assert!(friction.finite() && friction >= T::zero());
        Self {
            restitution,
            friction,
        }
    }

    /// The coefficients of a pair of bodies with their own coefficients: the minimum
    /// restitution and the geometric mean of the frictions.
    #[inline]
    pub fn for_pair(a: &Self, b: &Self) -> Self {
        Self {
            restitution: a.restitution.min(b.restitution),
            friction: (a.friction * b.friction).sqrt(),
        }
    }

    /// The same friction with another restitution (what the guards of
    /// [`crate::guard`] decide).
    ///
    /// # Errors
    /// `restitution` if not in `[0, 1]`.
    pub fn with_restitution(&self, restitution: T) -> Result<Self, InvalidValue> {
        Self::new(restitution, self.friction)
    }

    /// The restitution `e`.
    #[inline]
    pub fn restitution(&self) -> T {
        self.restitution
    }

    /// The friction coefficient `μ`.
    #[inline]
    pub fn friction(&self) -> T {
        self.friction
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_field() {
        assert_eq!(
            Coefficients::new(1.5_f64, 0.0).unwrap_err().to_string(),
            "restitution: must be in [0, 1], got 1.5"
        );
        assert_eq!(
            Coefficients::new(0.5_f64, -0.1).unwrap_err().field,
            "friction"
        );
        assert_eq!(
            Coefficients::new(f64::NAN, 0.1).unwrap_err().field,
            "restitution"
        );
        assert!(Coefficients::new(0.0_f32, 0.0).is_ok());
        assert!(Coefficients::new(1.0_f32, 1e3).is_ok());
    }

    #[test]
    fn pairs_take_the_minimum_restitution_and_the_geometric_mean_friction() {
        let a = Coefficients::new(0.9_f64, 0.4).unwrap();
        let b = Coefficients::new(0.5_f64, 0.1).unwrap();
        let p = Coefficients::for_pair(&a, &b);
        assert_eq!(p.restitution(), 0.5);
        assert!((p.friction() - 0.2).abs() < 1e-16);
        let ice = Coefficients::frictionless(1.0_f64).unwrap();
        assert_eq!(Coefficients::for_pair(&a, &ice).friction(), 0.0);
        assert_eq!(Coefficients::for_pair(&a, &a), a);
    }
}
