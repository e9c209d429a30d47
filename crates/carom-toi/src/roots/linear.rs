//! The linear sphere gap `P(t) = |u + w t|² − r² = a t² + 2 h t + c` (`a = |w|²`,
//! `h = u·w`, `c = |u|² − r²`, `Δ = h² − a c`), decided by filtered arithmetic: plain
//! floating point with a rigorous error bound, and double-double only where the bound
//! cannot prove a sign or the accuracy of the root.
//!
//! This is the inner loop of the event-driven engine (every collision predicts about two
//! dozen pairs, most of them receding or missing), so the common cases must be cheap:
//!
//! | pair | work |
//! |---|---|
//! | receding (`h` certainly `> 0`) | one dot product and its magnitude, in the input precision: no square root, no FMA |
//! | missing (`Δ` certainly `< 0`) | three dot products, in the input precision: no square root |
//! | hitting, root proven to the budget | plain coefficients and bounds, one square root, one division |
//! | root not proven (near touching, glancing) | `h` and `c` in double-double, `Δ` recomputed from them |
//! | still not proven (near grazing, far away) | `a` and `Δ = h² − a c` in double-double too |
//!
//! A pair is only ever decided on a proven sign, so the answer is that of exact
//! arithmetic on the given `u`, `w`, `r`, up to the double-double evaluation's own
//! resolution: about `u²` times the magnitudes of the terms, far below the rounding of the
//! inputs themselves. The root is within `β + 3u` of exact, `β` the caller's budget
//! (`ball_ball`: `12u` in `f64`, a sixteenth of `f32`'s unit roundoff for `f32` output),
//! and within about `6u` when `Δ` is computed in double-double.
//!
//! # Error bounds
//!
//! `u` is the unit roundoff (`ε/2`), `γ_n = n u / (1 − n u)`, hats are computed values,
//! `fl(x ∘ y) = (x ∘ y)(1 + δ)` with `|δ| <= u`. Recursive summation of `n` products has
//! `|fl(Σ xᵢyᵢ) − Σ xᵢyᵢ| <= γ_n Σ |xᵢyᵢ|` (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, §3.1). Bounds are evaluated in floating point from computed magnitudes,
//! which are at least `1 − γ_k` of the exact ones after `k` operations; each coefficient
//! below is rounded up by at least one `u` (or the bound multiplied by `1 + 16u`), which
//! covers that, every second-order term, and the one rounding of the comparison in which
//! the bound is used. `T::MIN_POSITIVE` is added to every bound: it covers the absolute
//! error of products that underflow (at most half the smallest subnormal each), so the
//! filter stays rigorous for tiny inputs, which simply fall back.
//!
//! * **Quick test** ([`recedes_or_misses`], in the input precision, from the centres,
//!   velocities and radii). The differences `û = fl(c₂ − c₁)`, `ŵ = fl(v₂ − v₁)`,
//!   `R̂ = fl(r₁ + r₂)` are within `u` (relative, per component) of the exact ones.
//!   *Rate*: `|h − fl(û·ŵ)| <= (2u + u² + γ_D (1 + 2u)) A`, `A = Σ|ûᵢŵᵢ|`, bounded by
//!   `(D + 3) u Â`; `ĥ > (D + 3) u Â` proves a receding pair. *Miss*: with `s = |u|²`,
//!   `q = R²`, the exact `Δ` moves by at most `u a (8.8 s + 4.3 q)` under the rounding of
//!   the differences (using `A² <= s a`) and its plain evaluation errs by at most
//!   `u a (17.9 s + 7.3 q)` (the terms of `E_Δ` below, each bounded through `A² <= s a`
//!   and `|c| <= s + q`); `Δ̂ < −32 u â (ŝ + q̂)` proves `Δ < 0`, a miss (`Δ < 0` also
//!   implies `c > 0`: apart, and never touching).
//! * **Rate** (`f64`, on the exact differences). `|ĥ − h| <= γ_D Σ|uᵢ wᵢ|`, bounded by
//!   `E_h = (D + 1) u fl(Σ|uᵢwᵢ|)`; `|ĥ| <= E_h` falls back.
//! * **Gap.** `ŝ = fl(Σ uᵢ²)`, `q̂ = fl(r²)`, `ĉ = fl(ŝ − q̂)`:
//!   `|ĉ − c| <= γ_D s + u q + u |ŝ − q̂|`, bounded by `E_c = (D + 1) u ŝ + 2 u (q̂ + |ĉ|)`.
//!   Touching means `c <= τ = 2u q̂` (the centre distance rounds to `r`; `τ` is exact,
//!   a power of two times `q̂`); `|ĉ − τ| <= E_c` falls back.
//! * **Discriminant.** `Δ̂ = fl(fl(ĥ²) − fl(â ĉ))` with `â = fl(Σ wᵢ²)`:
//!   `|fl(ĥ²) − h²| <= E_h (2|ĥ| + E_h) + u ĥ²` and
//!   `|fl(â ĉ) − a c| <= |â − a| |c| + â |ĉ − c| + u â |ĉ| <= â ((D + 1) u |ĉ| + E_c)` to
//!   first order; the subtraction adds `u |Δ̂|`. So
//!   `E_Δ = (E_h (2|ĥ| + E_h) + â E_c + u (ĥ² + (D + 1) â |ĉ| + |Δ̂|)) (1 + 16u)`, and
//!   `|Δ̂| <= E_Δ` falls back. Far away (`|u| ≫ r`) `h² ≈ a c` are both of size
//!   `|u|² |w|²`: a graze by `1e-9` at a distance of `1e6` is inside the bound and is
//!   decided in double-double, where `Δ` is accurate to about `u² |u|² |w|² ≈ 1e-20 |w|²`
//!   against the `2e-9 |w|²` at stake.
//! * **Root.** `t = c / d` with `d = −h + √Δ` (both terms non-negative for a closing pair:
//!   no cancellation). `|√Δ̂ − √Δ| <= E_Δ / √Δ̂`, so with `σ̂ = fl(√Δ̂)`,
//!   `d̂ = fl(σ̂ − ĥ)`, `t̂ = fl(ĉ / d̂)`:
//!   `|t̂ − t| / t <= E_c / ĉ + (E_h + E_Δ / σ̂) / d̂ + 3u + O(u²)`. The root is accepted
//!   when the first two terms are within the budget `β`, checked without a division as
//!   `E_c d̂ σ̂ + ĉ (E_h σ̂ + E_Δ) <= β ĉ d̂ σ̂`.
//! * **Sharpened** `h` and `c` (Dot2 in double-double, rounded once): within
//!   `u |x| + γ_n² Σ|terms|` of exact (`n = D`, `D + 1`); `Δ̂` and `E_Δ` are recomputed
//!   from them with the formula above. Near touching `E_c / ĉ` dominates the plain bound;
//!   for a closing pair near touching `Δ ≈ h²` and `E_h` dominates `E_Δ`: both go.
//! * **Exact discriminant**: `a` by Dot2 as well and `Δ = h² − a c` from the three
//!   double-doubles, rounded once; the root is then within about `6u`.
//!
//! The bound on the plain root is a worst case, proportional to the conditioning of the
//! root: a nearly grazing hit (`σ ≪ d`) needs `Δ` to more digits than plain arithmetic
//! proves however the coefficients are rounded.

use carom_math::{Real, Vector};

use super::Quadratic;
use super::exact::{DoubleDouble, two_product, two_square};

/// The outcome of a linear sphere-gap query from time 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LinearContact<T> {
    /// No contact: receding, missing, tangent, or beyond the horizon.
    Clear,
    /// Touching or overlapping at time 0 and closing.
    Immediate,
    /// First contact at this time (`> 0`).
    At(T),
    /// An intermediate value overflowed.
    Overflow,
}

/// `true` if two balls (centres `c₁`, `c₂`, velocities `v₁`, `v₂`, radii `r₁`, `r₂`,
/// time running in the direction of `sign = ±1`) certainly recede or certainly miss:
/// the cheap test callers make inline, in the input precision, before anything else
/// (module docs, "Quick test").
#[inline]
pub(crate) fn recedes_or_misses<T: Real, const D: usize>(
    (c1, c2): (&Vector<T, D>, &Vector<T, D>),
    (v1, v2): (&Vector<T, D>, &Vector<T, D>),
    (r1, r2): (T, T),
    sign: T,
) -> bool {
    let unit = unit::<T>();
    let (u0, w0) = (c2[0] - c1[0], v2[0] - v1[0]);
    let mut h = u0 * w0;
    let mut magnitude = h.abs();
    let (mut a, mut s) = (w0 * w0, u0 * u0);
    for i in 1..D {
        let (u, w) = (c2[i] - c1[i], v2[i] - v1[i]);
        let p = u * w;
        h += p;
        magnitude += p.abs();
        a += w * w;
        s += u * u;
    }
    if h * sign > magnitude * (T::from_count(D + 3) * unit) + T::MIN_POSITIVE {
        return true;
    }
    let r = r1 + r2;
    let q = r * r;
    let disc = h * h - a * (s - q);
    disc < -(a * (s + q) * (T::lit(32.0) * unit) + T::MIN_POSITIVE)
}

/// The unit roundoff `u = ε/2`.
#[inline]
fn unit<T: Real>() -> T {
    T::EPSILON * T::lit(0.5)
}

/// Relative error, in `u`, up to which [`LinearSphere::quadratic`] keeps a coefficient
/// without sharpening it.
const COEFFICIENT_BUDGET: f64 = 8.0;

/// A computed value and a bound on its error.
#[derive(Clone, Copy, Debug)]
struct Bounded<T> {
    value: T,
    err: T,
}

impl<T: Real> Bounded<T> {
    /// `true` if the error bound proves the value within `budget` (relative).
    #[inline]
    fn within(self, budget: T) -> bool {
        self.err <= budget * self.value.abs()
    }
}

/// The coefficients with their bounds, and the magnitudes the sharpened bounds need.
#[derive(Clone, Copy, Debug)]
struct Coefficients<T> {
    h: Bounded<T>,
    a: T,
    c: Bounded<T>,
    disc: Bounded<T>,
    /// `fl(Σ|uᵢwᵢ|)`.
    rate_magnitude: T,
    /// `ŝ + q̂`.
    gap_magnitude: T,
    /// `τ`: the largest `c` that counts as touching.
    touch: T,
}

/// `P(t) = |u + w t|² − r²` for linear relative motion.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearSphere<T: Real, const D: usize> {
    u: Vector<T, D>,
    w: Vector<T, D>,
    r: T,
}

impl<T: Real, const D: usize> LinearSphere<T, D> {
    /// The gap of the offset `u + w t` to a sphere of radius `r`.
    #[inline]
    pub(crate) fn new(u: Vector<T, D>, w: Vector<T, D>, r: T) -> Self {
        Self { u, w, r }
    }

    /// The offset `u + w s`.
    #[inline]
    pub(crate) fn offset(&self, s: T) -> Vector<T, D> {
        self.u + self.w * s
    }

    /// The relative velocity `w`.
    #[inline]
    pub(crate) fn velocity(&self) -> &Vector<T, D> {
        &self.w
    }

    /// The radius `r`.
    #[inline]
    pub(crate) fn radius(&self) -> T {
        self.r
    }

    /// The plain coefficients and their bounds (module docs).
    #[inline]
    fn plain(&self) -> Coefficients<T> {
        let unit = unit::<T>();
        let (u, w) = (&self.u, &self.w);
        let mut h = u[0] * w[0];
        let mut rate_magnitude = h.abs();
        let (mut a, mut s) = (w[0] * w[0], u[0] * u[0]);
        for i in 1..D {
            let p = u[i] * w[i];
            h += p;
            rate_magnitude += p.abs();
            a += w[i] * w[i];
            s += u[i] * u[i];
        }
        let q = self.r * self.r;
        let c = s - q;
        let h = Bounded {
            value: h,
            err: rate_magnitude * (T::from_count(D + 1) * unit) + T::MIN_POSITIVE,
        };
        let c = Bounded {
            value: c,
            err: s * (T::from_count(D + 1) * unit)
                + (q + c.abs()) * (unit + unit)
                + T::MIN_POSITIVE,
        };
        Coefficients {
            h,
            a,
            c,
            disc: discriminant::<T, D>(h, a, c),
            rate_magnitude,
            gap_magnitude: s + q,
            touch: q * (unit + unit),
        }
    }

    /// The first contact from time 0 up to `hi` (`+∞` allowed), cheapest case first
    /// (module docs). `budget` is the relative error allowed for a root computed without
    /// the double-double discriminant.
    #[inline]
    pub(crate) fn first_contact(&self, hi: T, budget: T) -> LinearContact<T> {
        let p = self.plain();
        let (h, c, disc) = (p.h, p.c, p.disc);
        if h.value > h.err {
            return LinearContact::Clear; // receding
        }
        if !disc.err.finite() {
            return LinearContact::Overflow;
        }
        if disc.value < -disc.err {
            // A certain miss: `Δ < 0` also implies `c > 0` (apart), whatever the rate.
            return LinearContact::Clear;
        }
        if h.value < -h.err {
            if c.value <= p.touch - c.err {
                return LinearContact::Immediate; // touching or overlapping, and closing
            }
            if c.value > p.touch + c.err && disc.value > disc.err {
                // A certain hit: the plain root if the bound proves it ...
                match accurate_root(h, c, disc, budget) {
                    Ok(t) => return contact_before(t, hi),
                    // ... or the root certainly beyond the horizon ...
                    Err(t_min) if hi.finite() && t_min() > hi => return LinearContact::Clear,
                    Err(_) => {}
                }
            }
        }
        // ... otherwise sharpen (also when a sign is not proven).
        self.sharpened_contact(&p, hi, budget)
    }

    /// [`first_contact`](Self::first_contact) with `h` and `c` in double-double, and then
    /// `Δ` if needed; out of line.
    #[inline(never)]
    fn sharpened_contact(&self, plain: &Coefficients<T>, hi: T, budget: T) -> LinearContact<T> {
        let (dd_h, dd_c, sharp) = self.sharpen(plain);
        if sharp.h.value >= T::zero() {
            return LinearContact::Clear;
        }
        if sharp.c.value <= sharp.touch {
            return LinearContact::Immediate;
        }
        let disc = sharp.disc;
        if disc.value < -disc.err {
            return LinearContact::Clear;
        }
        if disc.value > disc.err
            && let Ok(t) = accurate_root(sharp.h, sharp.c, disc, budget)
        {
            return contact_before(t, hi);
        }
        let disc = self.exact_discriminant(dd_h, dd_c);
        if disc <= T::zero() {
            LinearContact::Clear
        } else {
            contact_before(sharp.c.value / (disc.sqrt() - sharp.h.value), hi)
        }
    }

    /// `h` and `c` by Dot2, and `Δ̂`, `E_Δ` recomputed from them (module docs). Called
    /// only once the plain coefficients are finite, so no split overflows.
    fn sharpen(
        &self,
        plain: &Coefficients<T>,
    ) -> (DoubleDouble<T>, DoubleDouble<T>, Coefficients<T>) {
        let unit = unit::<T>();
        let (u, w) = (&self.u, &self.w);
        let mut dd_h = DoubleDouble::from_product(two_product(u[0], w[0]));
        let (q, q_err) = two_square(self.r);
        let mut dd_c = DoubleDouble::from_product((-q, -q_err));
        for i in 0..D {
            if i > 0 {
                dd_h = dd_h.add_product(two_product(u[i], w[i]));
            }
            dd_c = dd_c.add_product(two_square(u[i]));
        }
        let (dd_h, dd_c) = (dd_h.finish(), dd_c.finish());
        // Dot2: |res − x| <= u |x| + γ_n² Σ|terms|, so `(u |res| + (n + 1)² u² M)(1 + 4u)`.
        let dot2 = |res: T, n: usize, magnitude: T| {
            let gamma = T::from_count(n + 1) * unit;
            (res.abs() * unit + magnitude * gamma * gamma) * (T::one() + T::lit(4.0) * unit)
                + T::MIN_POSITIVE
        };
        let h = Bounded {
            value: dd_h.value(),
            err: dot2(dd_h.value(), D, plain.rate_magnitude),
        };
        let c = Bounded {
            value: dd_c.value(),
            err: dot2(dd_c.value(), D + 1, plain.gap_magnitude),
        };
        let sharp = Coefficients {
            h,
            c,
            disc: discriminant::<T, D>(h, plain.a, c),
            ..*plain
        };
        (dd_h, dd_c, sharp)
    }

    /// `Δ = h² − a c` from double-double `h`, `c` and `a = Σ wᵢ²` by Dot2, rounded once.
    fn exact_discriminant(&self, h: DoubleDouble<T>, c: DoubleDouble<T>) -> T {
        let w = &self.w;
        let mut a = DoubleDouble::from_product(two_square(w[0]));
        for x in w.iter().skip(1) {
            a = a.add_product(two_square(*x));
        }
        h.square_minus_product(a.finish(), c)
    }

    /// `a t² + 2 h t + c` with every coefficient within `8 u` of exact (plain where the
    /// bounds prove it, sharpened otherwise); `None` on overflow.
    pub(crate) fn quadratic(&self) -> Option<Quadratic<T>> {
        let p = self.plain();
        if !p.disc.err.finite() {
            return None;
        }
        let budget = T::lit(COEFFICIENT_BUDGET) * unit::<T>();
        if p.h.within(budget) && p.c.within(budget) && p.disc.within(budget) {
            return Some(Quadratic::with_discriminant(
                p.a,
                p.h.value,
                p.c.value,
                p.disc.value,
            ));
        }
        let (dd_h, dd_c, sharp) = self.sharpen(&p);
        let disc = if sharp.disc.within(budget) {
            sharp.disc.value
        } else {
            self.exact_discriminant(dd_h, dd_c)
        };
        Some(Quadratic::with_discriminant(
            p.a,
            sharp.h.value,
            sharp.c.value,
            disc,
        ))
    }
}

/// `Δ̂ = fl(ĥ² − â ĉ)` and its bound `E_Δ` (module docs).
#[inline]
fn discriminant<T: Real, const D: usize>(h: Bounded<T>, a: T, c: Bounded<T>) -> Bounded<T> {
    let unit = unit::<T>();
    let hh = h.value * h.value;
    let disc = hh - a * c.value;
    let err = ((h.err * (h.value.abs() * T::lit(2.0) + h.err) + a * c.err)
        + (hh + a * c.value.abs() * T::from_count(D + 1) + disc.abs()) * unit)
        * (T::one() + T::lit(16.0) * unit)
        + T::MIN_POSITIVE;
    Bounded { value: disc, err }
}

/// The root `c / (−h + √Δ)` of a certain hit (`h < 0`, `c > 0`, `Δ > 0` proven) if the
/// bounds prove it within `budget` (plus `3u`) of exact (module docs); otherwise a lower
/// bound on it, computed on demand.
#[inline]
fn accurate_root<T: Real>(
    h: Bounded<T>,
    c: Bounded<T>,
    disc: Bounded<T>,
    budget: T,
) -> Result<T, impl Fn() -> T> {
    let sigma = disc.value.sqrt();
    let d = sigma - h.value;
    let scale = c.value * d * sigma;
    let bound = c.err * d * sigma + c.value * (h.err * sigma + disc.err);
    let t = c.value / d;
    if bound <= budget * scale {
        Ok(t)
    } else {
        // t >= t̂ (1 − ρ) with ρ = bound / scale + 3u; twice that covers second order.
        Err(move || {
            let rho = bound / scale + T::lit(3.0) * unit::<T>();
            t * (T::one() - rho - rho)
        })
    }
}

/// A contact at `t` if it is within the horizon.
#[inline]
fn contact_before<T: Real>(t: T, hi: T) -> LinearContact<T> {
    if t <= hi {
        LinearContact::At(t)
    } else {
        LinearContact::Clear
    }
}
