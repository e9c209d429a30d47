//! The gap between a moving point and a sphere: `g(t) = |u(t)| − r` with
//! `u(t) = u₀ + w t + A t²` (`A` is half the relative acceleration).
//!
//! This one function is every round contact: two balls (`u` = centre 2 − centre 1,
//! `r` = sum of radii), a ball against a box corner (`u` = centre − corner), and against
//! a box edge in 3D (`u` = the centre's offset from the edge line, the edge's own axis
//! zeroed). Its sign is that of `P(t) = |u(t)|² − r²`.
//!
//! **Linear motion** (`A = 0`): `P(t) = a t² + 2 h t + c` with `a = |w|²`, `h = u₀·w`,
//! `c = |u₀|² − r²`, a [`Quadratic`] whose descending root is the cancellation-free
//! `t = c / (−h + √Δ)`, `Δ = h² − a c`. Its coefficients come from [`LinearSphere`], in
//! `f64`: plain arithmetic where a rigorous error bound proves them to `8 u`, double-double
//! otherwise (a gap of `10⁻¹²` survives in `c`, and a graze by `10⁻⁹` at a distance of
//! `10⁶` in `Δ`, although `h² ≈ a c ≈ 10¹²` there).
//!
//! **Constant relative acceleration** (`A ≠ 0`): `P` is a quartic
//! `|A|² t⁴ + 2 A·w t³ + (|w|² + 2 A·u₀) t² + 2 u₀·w t + c`. Its critical points are the
//! roots of the cubic `P'`, isolated between the (closed-form) roots of the quadratic
//! `P''` and refined by ITP; between them `g` is monotone, and the first descent is
//! bracketed and refined (see [`first_descent_monotone`]). The search stops at
//! Fujiwara's bound on the roots, `2 max(|c₃/c₄|, |c₂/c₄|^½, |c₁/c₄|^⅓, |c₀/2c₄|^¼)`,
//! beyond which `P > 0`. The gap itself is evaluated as `|u(t)| − r` from the motion,
//! not from the expanded coefficients, so the bracketing is as accurate as the geometry.

use carom_math::{Real, Vector};

use super::{Descent, LinearSphere, Quadratic, first_descent_monotone, itp};

/// `g(t) = |u₀ + w t + A t²| − r`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SphereGap<T: Real, const D: usize> {
    u0: Vector<T, D>,
    w: Vector<T, D>,
    half_acceleration: Vector<T, D>,
    radius: T,
}

impl<T: Real, const D: usize> SphereGap<T, D> {
    /// The gap of the offset `u0 + w t + half_acceleration t²` to a sphere of `radius`.
    #[inline]
    pub(crate) fn new(
        u0: Vector<T, D>,
        w: Vector<T, D>,
        half_acceleration: Vector<T, D>,
        radius: T,
    ) -> Self {
        Self {
            u0,
            w,
            half_acceleration,
            radius,
        }
    }

    /// The offset `u(t)`.
    #[inline]
    pub(crate) fn offset(&self, t: T) -> Vector<T, D> {
        self.u0 + (self.w + self.half_acceleration * t) * t
    }

    /// The gap `|u(t)| − r`.
    #[inline]
    pub(crate) fn gap(&self, t: T) -> T {
        self.offset(t).norm() - self.radius
    }

    /// `true` if the sphere is touched or entered at `t = 0` and the gap closes (see
    /// [`closing`](super::closing)); `d/dt |u|²/2 = u·w` and `d²/dt² |u|²/2 = |w|² + 2 u·A`.
    pub(crate) fn closing_at_start(&self) -> bool {
        let gap0 = self.u0.norm() - self.radius;
        let curvature = self.w.norm_squared() + self.u0.dot(&self.half_acceleration) * T::lit(2.0);
        super::closing(gap0, self.u0.dot(&self.w), curvature)
    }

    /// The first descent on `[lo, hi]` (`hi` may be `+∞`); `None` if a value overflowed.
    pub(crate) fn first_descent(&self, lo: T, hi: T, armed: bool) -> Option<Descent<T>> {
        if self.is_linear() {
            self.linear_first_descent(lo, hi, armed)
        } else {
            self.quartic_first_descent(lo, hi, armed)
        }
    }

    /// `true` if the relative acceleration is zero.
    #[inline]
    pub(crate) fn is_linear(&self) -> bool {
        self.half_acceleration.iter().all(|&x| x == T::zero())
    }

    /// The first descent of the linear gap, solved in `f64` whatever `T` is (exact
    /// products for `f32`) with coefficients accurate to `8u` in `f64`, or to a sixteenth
    /// of `f32`'s unit roundoff for `f32`; `None` on overflow.
    fn linear_first_descent(&self, lo: T, hi: T, armed: bool) -> Option<Descent<T>> {
        let wide = |v: &Vector<T, D>| v.map(T::to_f64);
        let budget = (4.0 * f64::EPSILON).max(T::EPSILON.to_f64() / 32.0);
        let gap = LinearSphere::new(wide(&self.u0), wide(&self.w), self.radius.to_f64());
        Some(
            match gap
                .quadratic(budget)?
                .first_descent(lo.to_f64(), hi.to_f64(), armed)
            {
                Descent::At(s) => Descent::At(T::lit(s)),
                Descent::Clear { armed } => Descent::Clear { armed },
            },
        )
    }

    fn quartic_first_descent(&self, lo: T, hi: T, armed: bool) -> Option<Descent<T>> {
        let (u, w, a, r) = (&self.u0, &self.w, &self.half_acceleration, self.radius);
        let two = T::lit(2.0);
        let dist = u.norm();
        let c = [
            (dist - r) * (dist + r),
            u.dot(w) * two,
            w.norm_squared() + a.dot(u) * two,
            a.dot(w) * two,
            a.norm_squared(),
        ];
        if c.iter().any(|x| !x.finite()) {
            return None;
        }
        if c[4] == T::zero() {
            // A underflowed in the squares: the motion is linear to working precision.
            return self.linear_first_descent(lo, hi, armed);
        }
        let bound = fujiwara_bound(&c);
        let end = hi.min(bound);
        if !end.finite() {
            return None;
        }
        if end <= lo {
            // Beyond every root P > 0: the gap is positive on all of [lo, hi].
            return Some(Descent::Clear {
                armed: armed || lo < hi,
            });
        }
        let (critical, n) = quartic_critical_points(&c, lo, end);
        let descent = first_descent_monotone(|t| self.gap(t), lo, end, &critical[..n], armed)?;
        Some(match descent {
            Descent::Clear { armed } => Descent::Clear {
                armed: armed || end < hi,
            },
            at @ Descent::At(_) => at,
        })
    }
}

/// Fujiwara's bound on the magnitude of every root of `Σ cₖ tᵏ` (`c₄ ≠ 0`).
fn fujiwara_bound<T: Real>(c: &[T; 5]) -> T {
    let lead = c[4].abs();
    let terms = [
        c[3].abs() / lead,
        (c[2].abs() / lead).sqrt(),
        (c[1].abs() / lead).cbrt(),
        (c[0].abs() / (lead * T::lit(2.0))).sqrt().sqrt(),
    ];
    terms.iter().fold(T::zero(), |m, &x| m.max(x)) * T::lit(2.0)
}

/// The roots of `P'(t) = 4c₄t³ + 3c₃t² + 2c₂t + c₁` in `(lo, hi)`, sorted: the points
/// between which the quartic `P` is monotone. `P'` is itself monotone between the roots
/// of `P'' = 12c₄t² + 6c₃t + 2c₂` (closed form), so each of its sign changes is bracketed.
fn quartic_critical_points<T: Real>(c: &[T; 5], lo: T, hi: T) -> ([T; 3], usize) {
    let derivative =
        |t: T| ((c[4] * T::lit(4.0) * t + c[3] * T::lit(3.0)) * t + c[2] * T::lit(2.0)) * t + c[1];
    let (inflections, m) =
        Quadratic::new(c[4] * T::lit(12.0), c[3] * T::lit(3.0), c[2] * T::lit(2.0)).roots();
    let mut out = [T::zero(); 3];
    let mut n = 0;
    let mut x0 = lo;
    let mut d0 = derivative(lo);
    let inside = inflections[..m]
        .iter()
        .copied()
        .filter(|&x| x > lo && x < hi);
    for x1 in inside.chain(core::iter::once(hi)) {
        let d1 = derivative(x1);
        if d0 * d1 < T::zero() && n < 3 {
            let (near, _) = itp(derivative, x0, x1, d0, d1, T::zero());
            out[n] = near;
            n += 1;
        } else if d1 == T::zero() && x1 < hi && n < 3 {
            out[n] = x1;
            n += 1;
        }
        x0 = x1;
        d0 = d1;
    }
    (out, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn linear_head_on_contact_is_gap_over_speed() {
        let s = SphereGap::new(
            Vector2::new(3.0, 0.0),
            Vector2::new(-2.0, 0.0),
            Vector2::zeros(),
            1.0,
        );
        assert_eq!(
            s.first_descent(0.0, f64::INFINITY, true),
            Some(Descent::At(1.0))
        );
    }

    #[test]
    fn quartic_finds_the_falling_contact() {
        // A point dropped from height 3 onto a unit sphere below it, g = 2: u = (0, 3 − t²).
        let s = SphereGap::new(
            Vector2::new(0.0, 3.0),
            Vector2::zeros(),
            Vector2::new(0.0, -1.0),
            1.0,
        );
        let Some(Descent::At(t)) = s.first_descent(0.0, 10.0, true) else {
            panic!("no contact")
        };
        assert!((t - 2f64.sqrt()).abs() < 1e-15, "{t}");
    }

    #[test]
    fn critical_points_of_a_quartic_with_three() {
        // P = (t² − 1)² = t⁴ − 2t² + 1: critical points −1, 0, 1.
        let (x, n) = quartic_critical_points::<f64>(&[1.0, 0.0, -2.0, 0.0, 1.0], -2.0, 2.0);
        assert_eq!(n, 3);
        assert!((x[0] + 1.0).abs() < 1e-15 && x[1].abs() < 1e-15 && (x[2] - 1.0).abs() < 1e-15);
    }
}
