//! Hooke springs with damping: the force law ([`Spring`]) and the field that ties every
//! ball to one fixed point ([`AnchorSpring`]), the undamped oscillator of the stability
//! tests when the rest length and damping are zero.
//!
//! For an end at offset `d` from the other end, moving at relative velocity `u`, with
//! unit direction `n = d / |d|`:
//!
//! ```text
//! F = −k (|d| − L) n − c (u · n) n
//!   = −k d + (k L − c (u · n)) n
//! ```
//!
//! The second form is how it is computed: with `L = 0` and `c = 0` it is exactly the
//! linear force `−k d` (no rounding from normalising), which the oscillator tests rely
//! on. At `|d| = 0` the direction is undefined: the elastic part `−k d` is zero there
//! and the rest (the push of a spring of positive rest length, the damping along the
//! axis) is taken as zero too, the unstable equilibrium of a compressed spring.

use carom_math::{InvalidValue, Real, Space, Vector, ensure_finite_vector, ensure_non_negative};
use nalgebra::Const;

use crate::{Acceleration, BallState, ClosedForm, ForceField};

/// The parameters of a damped Hooke spring: stiffness `k`, damping `c`, rest length `L`.
///
/// Invariant (checked by [`Spring::new`]): all three finite and `>= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring<T: Real> {
    stiffness: T,
    damping: T,
    rest_length: T,
}

impl<T: Real> Spring<T> {
    /// A spring of `stiffness` `k` (N/m), `damping` `c` (N·s/m) and `rest_length` `L` (m).
    ///
    /// # Errors
    /// `stiffness`, `damping` or `rest_length` if not finite or negative.
    pub fn new(stiffness: T, damping: T, rest_length: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            stiffness: ensure_non_negative("stiffness", stiffness)?,
            damping: ensure_non_negative("damping", damping)?,
            rest_length: ensure_non_negative("rest_length", rest_length)?,
        })
    }

    /// The stiffness `k`.
    #[inline]
    pub fn stiffness(&self) -> T {
        self.stiffness
    }

    /// The damping `c`.
    #[inline]
    pub fn damping(&self) -> T {
        self.damping
    }

    /// The rest length `L`.
    #[inline]
    pub fn rest_length(&self) -> T {
        self.rest_length
    }

    /// The force on the end at `offset` `d` from the other end, moving at
    /// `relative_velocity` `u` with respect to it (the other end feels the opposite).
    #[inline]
    pub fn force<const D: usize>(
        &self,
        offset: &Vector<T, D>,
        relative_velocity: &Vector<T, D>,
    ) -> Vector<T, D> {
        let elastic = offset * -self.stiffness;
        let length = offset.norm();
        if length > T::zero() {
            let n = offset / length;
            let along =
                self.stiffness * self.rest_length - self.damping * relative_velocity.dot(&n);
            elastic + n * along
        } else {
            elastic
        }
    }

    /// The elastic energy `k (|d| − L)² / 2` stored at `offset` `d`.
    #[inline]
    pub fn potential_energy<const D: usize>(&self, offset: &Vector<T, D>) -> T {
        let stretch = offset.norm() - self.rest_length;
        T::lit(0.5) * self.stiffness * stretch * stretch
    }
}

/// A spring from every ball to one fixed `anchor`: `F = spring.force(x − anchor, v)`.
///
/// With rest length 0 and no damping, `dv/dt = −(k/m)(x − anchor)`: the harmonic
/// oscillator of angular frequency `ω = sqrt(k/m)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnchorSpring<T: Real, const D: usize> {
    anchor: Vector<T, D>,
    spring: Spring<T>,
}

impl<T: Real, const D: usize> AnchorSpring<T, D> {
    /// Springs of parameters `spring` from every ball to `anchor`.
    ///
    /// # Errors
    /// `anchor[i]` if a component is not finite.
    pub fn new(anchor: Vector<T, D>, spring: Spring<T>) -> Result<Self, InvalidValue> {
        Ok(Self {
            anchor: ensure_finite_vector("anchor", &anchor)?,
            spring,
        })
    }

    /// The fixed end.
    #[inline]
    pub fn anchor(&self) -> Vector<T, D> {
        self.anchor
    }

    /// The spring parameters.
    #[inline]
    pub fn spring(&self) -> Spring<T> {
        self.spring
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for AnchorSpring<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        let force = self
            .spring
            .force(&(ball.position - self.anchor), &ball.velocity);
        Acceleration::linear(force * ball.inverse_mass)
    }

    /// Free flight when the spring has neither stiffness nor damping; otherwise none.
    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        (self.spring.stiffness == T::zero() && self.spring.damping == T::zero())
            .then(ClosedForm::free)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn zero_rest_length_and_damping_give_exactly_minus_k_d() {
        let s = Spring::new(3.0, 0.0, 0.0).unwrap();
        let d = Vector3::new(0.1, -0.7, 1e-3);
        assert_eq!(s.force(&d, &Vector3::new(5.0, 6.0, 7.0)), d * -3.0);
    }

    #[test]
    fn the_force_matches_the_textbook_formula() {
        let s = Spring::new(2.0, 0.5, 1.0).unwrap();
        let d = Vector2::<f64>::new(3.0, 4.0); // |d| = 5, n = (0.6, 0.8), stretch 4
        let u = Vector2::new(1.0, -2.0); // u · n = −1
        // −k (|d| − L) n − c (u · n) n = −8 n + 0.5 n = −7.5 n.
        let expected = Vector2::new(-4.5, -6.0);
        assert!((s.force(&d, &u) - expected).norm() < 1e-14);
        assert_eq!(s.potential_energy(&d), 16.0);
        // Compressed below its rest length, it pushes outwards.
        let short = Vector2::new(0.3, 0.4);
        assert!(s.force(&short, &Vector2::zeros()).dot(&short) > 0.0);
    }

    #[test]
    fn coincident_ends_give_no_force_and_no_nan() {
        let s = Spring::new(2.0, 0.5, 1.0).unwrap();
        let f = s.force(&Vector3::zeros(), &Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(f, Vector3::zeros());
        // Offsets whose squared length underflows or overflows stay finite.
        assert!(
            s.force(&Vector3::new(1e-200, 0.0, 0.0), &Vector3::zeros())
                .iter()
                .all(|c: &f64| c.is_finite())
        );
        assert!(
            s.force(&Vector3::new(1e200, 1e200, 0.0), &Vector3::zeros())
                .iter()
                .all(|c: &f64| c.is_finite())
        );
    }

    #[test]
    fn parameters_and_anchor_are_validated() {
        assert_eq!(Spring::new(-1.0, 0.0, 0.0).unwrap_err().field, "stiffness");
        assert_eq!(
            Spring::new(1.0, f64::NAN, 0.0).unwrap_err().field,
            "damping"
        );
        assert_eq!(
            Spring::new(1.0, 0.0, -0.5).unwrap_err().field,
            "rest_length"
        );
        let s = Spring::new(1.0, 0.0, 0.0).unwrap();
        assert_eq!(
            AnchorSpring::new(Vector2::new(0.0, f64::INFINITY), s)
                .unwrap_err()
                .field,
            "anchor[1]"
        );
        let slack =
            AnchorSpring::new(Vector2::new(1.0, 2.0), Spring::new(0.0, 0.0, 3.0).unwrap()).unwrap();
        assert_eq!(slack.closed_form(), Some(ClosedForm::free()));
        let taut = AnchorSpring::new(Vector2::new(1.0, 2.0), s).unwrap();
        assert_eq!(taut.closed_form(), None);
    }
}
