//! Exact motion under constant gravity and linear drag, forward or backward in time.
//!
//! These are the closed forms the `exact` integrator steps with, and what an
//! event-driven engine uses to move a ball in flight to any instant.
//!
//! ## Derivation
//!
//! With `dv/dt = g − k v` (gravity `g`, drag rate `k = b/m`), variation of constants gives
//!
//! ```text
//! v(t) = e^{−kt} v₀ + ∫₀ᵗ e^{−k(t−s)} g ds = e^{−kt} v₀ + g (1 − e^{−kt}) / k
//! x(t) = x₀ + ∫₀ᵗ v(s) ds = x₀ + v₀ (1 − e^{−kt}) / k + g (kt − 1 + e^{−kt}) / k²
//! ```
//!
//! equal to the textbook `v = v∞ + (v₀ − v∞) e^{−kt}`, `x = x₀ + v∞ t + (v₀ − v∞)(1 −
//! e^{−kt}) / k` with the terminal velocity `v∞ = g/k`. Both textbook forms cancel
//! catastrophically when `kt` is small (and divide by zero at `k = 0`). Written with
//! `z = −kt` and the entire functions
//!
//! ```text
//! φ₁(z) = (e^z − 1) / z        = Σ zⁿ / (n+1)!  = 1 + z/2 + z²/6 + …
//! φ₂(z) = (e^z − 1 − z) / z²   = Σ zⁿ / (n+2)!  = 1/2 + z/6 + z²/24 + …
//! ```
//!
//! (the "phi functions" of exponential integrators) they become
//!
//! ```text
//! v(t) = e^z v₀ + g t φ₁(z)
//! x(t) = x₀ + t (v₀ φ₁(z) + g t φ₂(z))
//! ```
//!
//! which have no division by `k` and reduce to the ballistic `x₀ + t (v₀ + g t/2)`,
//! `v₀ + g t` at `k = 0` (bit for bit: `φ₁(0) = 1`, `φ₂(0) = 1/2` exactly).
//!
//! For `|z| ≤ 1/2`, `φ₂` is summed from its Taylor series (6, 9 or 14 terms for
//! `|z| ≤ 1/256, 1/16, 1/2`: the first omitted term is below `1e-19`, under `2⁻⁵³` of
//! `φ₂ ≥ 0.39`), then `φ₁ = 1 + z φ₂` and `e^z = 1 + z φ₁` (`|z φ₂| ≤ 0.33` and
//! `|z φ₁| ≤ 0.65`: nothing cancels). Otherwise `φ₁ = expm1(z)/z` and `φ₂ = (φ₁ − 1)/z`,
//! where `|φ₁ − 1| ≥ 0.2` so the subtraction loses at most a few bits. Typical steps
//! (`k h` well below 1/256) cost six fused multiply-adds and no transcendental call.
//! The formulas hold for any sign of `k` and `t`; going backward under drag (`kt < 0`)
//! the velocity grows like `e^{|kt|}` and overflows to infinity once
//! `|kt|` exceeds about 709 in `f64` (88 in `f32`), which is the physics, not rounding.

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::{Angular, ClosedForm};

/// A point's position and velocity at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointState<T: Real, const D: usize> {
    /// The position.
    pub position: Vector<T, D>,
    /// The velocity.
    pub velocity: Vector<T, D>,
}

/// Free fall under constant acceleration `g` for time `t` (any sign):
/// `x = x₀ + t (v₀ + g t/2)`, `v = v₀ + g t`.
#[inline]
pub fn ballistic<T: Real, const D: usize>(
    x0: &Vector<T, D>,
    v0: &Vector<T, D>,
    g: &Vector<T, D>,
    t: T,
) -> PointState<T, D> {
    let half_t = t * T::lit(0.5);
    PointState {
        position: x0 + (v0 + g * half_t) * t,
        velocity: v0 + g * t,
    }
}

/// Motion under constant acceleration `g` and linear drag of rate `k` (`dv/dt = g − k v`;
/// `k = b/m` for a drag force `−b v`) for time `t` (any sign). At `k = 0` the result is
/// [`ballistic`]'s, bit for bit; see the [module documentation](self) for the derivation.
#[inline]
pub fn linear_drag<T: Real, const D: usize>(
    x0: &Vector<T, D>,
    v0: &Vector<T, D>,
    g: &Vector<T, D>,
    k: T,
    t: T,
) -> PointState<T, D> {
    let Decay { exp, phi1, phi2 } = Decay::new(-k * t);
    PointState {
        position: x0 + (v0 * phi1 + g * (t * phi2)) * t,
        velocity: v0 * exp + g * (t * phi1),
    }
}

/// `e^z`, `φ₁(z)` and `φ₂(z)` for one `z = −kt`.
struct Decay<T> {
    exp: T,
    phi1: T,
    phi2: T,
}

/// `1/m!` for `m = 0..=16`.
const INV_FACTORIALS: [f64; 17] = {
    let mut table = [1.0; 17];
    let mut m = 1;
    while m < 17 {
        table[m] = table[m - 1] / m as f64;
        m += 1;
    }
    table
};

/// `φ₂(z) = Σ_{n<N} zⁿ/(n+2)!` by Horner's rule, highest term first.
#[inline]
fn phi2_series<T: Real, const N: usize>(z: T) -> T {
    let mut sum = T::zero();
    for n in (0..N).rev() {
        sum = sum * z + T::lit(INV_FACTORIALS[n + 2]);
    }
    sum
}

impl<T: Real> Decay<T> {
    #[inline]
    fn new(z: T) -> Self {
        let size = z.abs();
        if size <= T::lit(0.5) {
            let phi2 = if size <= T::lit(1.0 / 256.0) {
                phi2_series::<T, 6>(z)
            } else if size <= T::lit(1.0 / 16.0) {
                phi2_series::<T, 9>(z)
            } else {
                phi2_series::<T, 14>(z)
            };
            let phi1 = T::one() + z * phi2;
            Self {
                exp: T::one() + z * phi1,
                phi1,
                phi2,
            }
        } else {
            let phi1 = z.exp_m1() / z;
            Self {
                exp: z.exp(),
                phi1,
                phi2: (phi1 - T::one()) / z,
            }
        }
    }
}

impl<T: Real, const D: usize> ClosedForm<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The position, velocity and spin of a ball of `inverse_mass` after time `t` (any
    /// sign) in this field. A ball of infinite mass (`inverse_mass == 0`) keeps its
    /// velocity and spin.
    ///
    /// The spin decays as `ω(t) = e^{−λ t}ω₀` (there is no torque other than damping in
    /// this family).
    #[inline]
    pub fn advance(
        &self,
        position: &Vector<T, D>,
        velocity: &Vector<T, D>,
        spin: &Angular<T, D>,
        inverse_mass: T,
        t: T,
    ) -> (PointState<T, D>, Angular<T, D>) {
        self.advance_with_spin_decay(
            self.spin_decay(t),
            position,
            velocity,
            spin,
            inverse_mass,
            t,
        )
    }

    /// The spin factor `e^{−λ t}` of balls of finite mass, the same for all of them.
    #[inline]
    pub(crate) fn spin_decay(&self, t: T) -> T {
        if self.spin_damping == T::zero() {
            T::one()
        } else {
            (-self.spin_damping * t).exp()
        }
    }

    /// [`ClosedForm::advance`] with the spin factor `e^{−λ t}` computed by the caller
    /// (once per step for all balls).
    #[inline]
    pub(crate) fn advance_with_spin_decay(
        &self,
        spin_decay: T,
        position: &Vector<T, D>,
        velocity: &Vector<T, D>,
        spin: &Angular<T, D>,
        inverse_mass: T,
        t: T,
    ) -> (PointState<T, D>, Angular<T, D>) {
        if inverse_mass > T::zero() {
            let k = self.linear_drag * inverse_mass;
            let moved = linear_drag(position, velocity, &self.gravity, k, t);
            (moved, *spin * spin_decay)
        } else {
            let moved = PointState {
                position: position + velocity * t,
                velocity: *velocity,
            };
            (moved, *spin)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    /// φ₁ and φ₂ from their definitions, where they do not cancel badly.
    fn phis_direct(z: f64) -> (f64, f64) {
        let e = z.exp();
        ((e - 1.0) / z, (e - 1.0 - z) / (z * z))
    }

    #[test]
    fn phi_functions_match_their_definitions_on_both_branches() {
        for &z in &[
            -40.0, -3.0, -1.0, -0.75, -0.5000001, 0.5000001, 0.9, 2.0, 30.0,
        ] {
            let d = Decay::<f64>::new(z);
            let (p1, p2) = phis_direct(z);
            assert!((d.phi1 - p1).abs() <= 1e-14 * p1.abs(), "φ₁({z})");
            assert!((d.phi2 - p2).abs() <= 1e-13 * p2.abs(), "φ₂({z})");
            assert!((d.exp - z.exp()).abs() <= 1e-15 * z.exp(), "exp({z})");
        }
    }

    #[test]
    fn every_series_tier_is_accurate_at_its_widest() {
        // At each tier's largest |z| its sum must match the longest series the table
        // allows (15 terms, truncation below 1e-19 even at |z| = 1/2) to an ulp.
        for z in [
            1.0 / 256.0,
            -1.0 / 256.0,
            1.0 / 16.0,
            -1.0 / 16.0,
            0.5,
            -0.5,
        ] {
            let d = Decay::<f64>::new(z);
            let reference = phi2_series::<f64, 15>(z);
            assert!(
                (d.phi2 - reference).abs() <= f64::EPSILON * reference,
                "φ₂({z})"
            );
            // φ₁ against expm1(z)/z and e^z against exp, neither of which cancels.
            let p1 = z.exp_m1() / z;
            assert!((d.phi1 - p1).abs() <= 2.0 * f64::EPSILON, "φ₁({z})");
            assert!((d.exp - z.exp()).abs() <= 2.0 * f64::EPSILON, "exp({z})");
        }
        // And at |z| = 1/2 the definition of φ₂ loses only ~2 bits: compare directly.
        let (_, p2) = phis_direct(0.5);
        assert!((Decay::<f64>::new(0.5).phi2 - p2).abs() < 8.0 * f64::EPSILON);
    }

    #[test]
    fn the_series_branch_is_continuous_with_the_expm1_branch() {
        // At |z| = 1/2 both branches are accurate; they must agree to rounding.
        for &z in &[-0.5_f64, 0.5] {
            let series = Decay::<f64>::new(z);
            let above = Decay::<f64>::new(z * (1.0 + f64::EPSILON));
            assert!((series.phi1 - above.phi1).abs() < 1e-15, "φ₁ at {z}");
            assert!((series.phi2 - above.phi2).abs() < 4e-15, "φ₂ at {z}");
            assert!((series.exp - above.exp).abs() < 1e-15, "exp at {z}");
        }
    }

    #[test]
    fn tiny_z_gives_the_taylor_limits_where_the_definitions_cancel() {
        let d = Decay::<f64>::new(-1e-12);
        assert!((d.phi1 - (1.0 - 0.5e-12)).abs() < 1e-16);
        assert!((d.phi2 - (0.5 - 1e-12 / 6.0)).abs() < 1e-16);
        let (_, naive2) = phis_direct(-1e-12);
        assert!((naive2 - 0.5).abs() > 1e-6, "the naive form cancels here");
        let d0 = Decay::<f32>::new(0.0);
        assert_eq!((d0.exp, d0.phi1, d0.phi2), (1.0, 1.0, 0.5));
    }

    #[test]
    fn zero_drag_is_ballistic_bit_for_bit() {
        let x0 = Vector3::new(1.0, -2.0, 1e6);
        let v0 = Vector3::new(3.0, 0.1, -7.0);
        let g = Vector3::new(0.0, 0.0, -9.81);
        for &t in &[0.0, 1e-9, 0.37, -2.5, 1e3] {
            assert_eq!(
                linear_drag(&x0, &v0, &g, 0.0, t),
                ballistic(&x0, &v0, &g, t)
            );
        }
    }

    #[test]
    fn infinite_mass_moves_at_constant_velocity_and_spin() {
        let cf = ClosedForm {
            gravity: Vector2::new(0.0, -9.81),
            linear_drag: 0.5,
            spin_damping: 2.0,
        };
        let w = nalgebra::Vector1::new(3.0);
        let (p, s) = cf.advance(
            &Vector2::new(1.0, 1.0),
            &Vector2::new(2.0, 0.0),
            &w,
            0.0,
            0.5,
        );
        assert_eq!(p.position, Vector2::new(2.0, 1.0));
        assert_eq!(p.velocity, Vector2::new(2.0, 0.0));
        assert_eq!(s, w);
    }
}
