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
//! | receding (`h` certainly `> 0`), missing (`Δ` certainly `< 0`) or meeting after the horizon | three dot products and a magnitude, in the input precision, without a branch: no square root, no FMA |
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
//! * **Quick test** ([`certainly_clear`], in the input precision, from the centres,
//!   velocities and radii). The differences `û = fl(c₂ − c₁)`, `ŵ = fl(v₂ − v₁)`,
//!   `R̂ = fl(r₁ + r₂)` are within `u` (relative, per component) of the exact ones.
//!   *Rate*: `|h − fl(û·ŵ)| <= (2u + u² + γ_D (1 + 2u)) A`, `A = Σ|ûᵢŵᵢ|`, bounded by
//!   `(D + 3) u Â`; `ĥ > (D + 3) u Â` proves a receding pair. *Miss*: with `s = |u|²`,
//!   `q = R²`, the exact `Δ` moves by at most `u a (8.8 s + 4.3 q)` under the rounding of
//!   the differences (using `A² <= s a`) and its plain evaluation errs by at most
//!   `u a (17.9 s + 7.3 q)` (the terms of `E_Δ` below, each bounded through `A² <= s a`
//!   and `|c| <= s + q`); `Δ̂ < −32 u â (ŝ + q̂)` proves `Δ < 0`, a miss (`Δ < 0` also
//!   implies `c > 0`: apart, and never touching). *Horizon*: `P(t) >= c + 2 h t`, so
//!   `c + 2 h H > 0` (with `h < 0`, which makes `c > 0` too) proves no contact on
//!   `[0, H]`. The rounded differences move `s` by at most `(D + 3) u ŝ` (as `h`), `q̂` is
//!   within `4u q̂`, and the sums and products add `u` of each term, so the computed
//!   `ĉ + 2 ĥ H` is within `(D + 5) u (ŝ + q̂ + 2 H Â)` of exact to first order;
//!   `ĉ + 2ĥH > 32 u (ŝ + q̂ + 2 H Â)` proves it. A pair predicted against the best time
//!   found so far leaves here without a square root when it would meet later.
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

/// `true` if two balls whose relative position is `u`, relative velocity `w` and radius
/// sum `r` (each possibly rounded: `û = fl(c₂ − c₁)`, and so on), with time running in the
/// direction of `sign = ±1`, certainly recede, certainly miss, or certainly meet only
/// after `horizon` (search time, `+∞` for none): the cheap test callers make inline, in
/// the input precision, before anything else (module docs, "Quick test"). Without a
/// branch: see the comment inside.
#[inline]
pub(crate) fn certainly_clear<T: Real, const D: usize>(
    u: &Vector<T, D>,
    w: &Vector<T, D>,
    r: T,
    sign: T,
    horizon: T,
) -> bool {
    let unit = unit::<T>();
    let mut h = u[0] * w[0];
    let mut magnitude = h.abs();
    for i in 1..D {
        let p = u[i] * w[i];
        h += p;
        magnitude += p.abs();
    }
    let h = h * sign;
    // Each proof below is a margin `fl(x − y)`, positive exactly when `x > y` (a
    // difference of two distinct finite floats never rounds to zero and keeps its sign;
    // `∞ − ∞` is NaN, which proves nothing), and the pair is clear when the largest is
    // positive. `larger` passes over a NaN second argument: `later` is NaN for an
    // infinite horizon and a receding pair. A NaN from overflow elsewhere loses a proof
    // (the pair goes on to the exact test), never makes a wrong one.
    //
    // Computed without a branch: each proof goes either way often (about half of an
    // engine's partners recede) and waits on the partner's data, usually a cache miss, so
    // a branch on one is mispredicted often and discards the reads of the partners after
    // it. One comparison, not three joined by `|`, feeds the caller's branch: the
    // compiler splits a branch on an `or` of comparisons into one branch for each, or
    // not, depending on the code around it. Computing all three for a receding pair costs
    // a dozen products. Measured on the 3D gas (docs/event-engine.md, fortieth session).
    //
    // Receding: `h > (D + 3) u Σ|uᵢwᵢ|` (the bound is positive, so this proves `h > 0`).
    let receding = h - (magnitude * (T::from_count(D + 3) * unit) + T::MIN_POSITIVE);
    let (a, s) = (w.norm_squared(), u.norm_squared());
    let q = r * r;
    let c = s - q;
    let disc = h * h - a * c;
    // Missing: `Δ < −32 u a (s + q)`.
    let missing = -(a * (s + q) * (T::lit(32.0) * unit) + T::MIN_POSITIVE) - disc;
    // Beyond the horizon `H`: `P(t) = c + 2 h t + a t² >= c + 2 h t`, a line, positive
    // on all of `[0, H]` when positive at `0` and at `H`, and `c + 2hH > 0` with `h < 0`
    // implies `c > 0`. (An infinite `H` gives −∞ or NaN here: never positive.)
    let reach = horizon * (h + h);
    let later = (c + reach)
        - ((s + q + horizon * (magnitude + magnitude)) * (T::lit(32.0) * unit) + T::MIN_POSITIVE);
    larger(larger(receding, missing), later) > T::zero()
}

/// The larger of `a` and `b`, and `a` when `b` is NaN. `max`, which passes over a NaN in
/// either, cost the 3D gas 2 % more instructions (callgrind, `event_throughput 4000 0.45
/// 3 1 1`: 1,718.8 against 1,681.5 million). A NaN `a` gives `a`, which proves nothing:
/// the caller's proof is then lost, never wrong.
#[inline]
fn larger<T: Real>(a: T, b: T) -> T {
    if b > a { b } else { a }
}

/// The unit roundoff `u = ε/2`.
#[inline]
fn unit<T: Real>() -> T {
    T::EPSILON * T::lit(0.5)
}

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
            disc: bounded_discriminant::<T, D>(h, a, c),
            rate_magnitude,
            gap_magnitude: s + q,
            touch: q * (unit + unit),
        }
    }

    /// The first contact from time 0 up to `hi` (`+∞` allowed), cheapest case first
    /// (module docs). `budget` is the error allowed for a root computed without the
    /// double-double discriminant.
    #[inline]
    pub(crate) fn first_contact(&self, hi: T, budget: Budget<T>) -> LinearContact<T> {
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
                match accurate_root(h, c, disc, p.a, budget) {
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
    fn sharpened_contact(
        &self,
        plain: &Coefficients<T>,
        hi: T,
        budget: Budget<T>,
    ) -> LinearContact<T> {
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
            && let Ok(t) = accurate_root(sharp.h, sharp.c, disc, sharp.a, budget)
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
            disc: bounded_discriminant::<T, D>(h, plain.a, c),
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

    /// `a t² + 2 h t + c` with every coefficient within `budget` (relative) of exact:
    /// plain where the bounds prove it, sharpened otherwise (the double-double `Δ` is
    /// within about `u`); `None` on overflow.
    pub(crate) fn quadratic(&self, budget: T) -> Option<Quadratic<T>> {
        let p = self.plain();
        if !p.disc.err.finite() {
            return None;
        }
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
fn bounded_discriminant<T: Real, const D: usize>(h: Bounded<T>, a: T, c: Bounded<T>) -> Bounded<T> {
    let unit = unit::<T>();
    let hh = h.value * h.value;
    let disc = hh - a * c.value;
    let err = ((h.err * (h.value.abs() * T::lit(2.0) + h.err) + a * c.err)
        + (hh + a * c.value.abs() * T::from_count(D + 1) + disc.abs()) * unit)
        * (T::one() + T::lit(16.0) * unit)
        + T::MIN_POSITIVE;
    Bounded { value: disc, err }
}

/// The error a root may have when it is computed without the double-double
/// discriminant: a relative error (besides the final `3u`), or a distance.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Budget<T> {
    /// The relative error allowed.
    pub(crate) relative: T,
    /// A distance: the root is also accepted when its error moves the relative position
    /// `u + w t` by at most this much (`0`: the relative error alone decides).
    pub(crate) reach: T,
}

/// The root `c / (−h + √Δ)` of a certain hit (`h < 0`, `c > 0`, `Δ > 0` proven) if the
/// bounds prove it within the budget (plus `3u`) of exact (module docs); otherwise a lower
/// bound on it, computed on demand.
///
/// The relative error of the root is at most `ρ = bound / scale` (plus `3u`). Within the
/// budget's reach means `ρ t |w| <= reach`: squared, without a square root,
/// `(bound · t)² · a <= (reach · scale)²` (`a = |w|²`; all terms are non-negative, and an
/// overflow to `∞` only refuses).
#[inline]
fn accurate_root<T: Real>(
    h: Bounded<T>,
    c: Bounded<T>,
    disc: Bounded<T>,
    a: T,
    budget: Budget<T>,
) -> Result<T, impl Fn() -> T> {
    let sigma = disc.value.sqrt();
    let d = sigma - h.value;
    let scale = c.value * d * sigma;
    let bound = c.err * d * sigma + c.value * (h.err * sigma + disc.err);
    let t = c.value / d;
    let moved = bound * t;
    let reach = budget.reach * scale;
    if bound <= budget.relative * scale
        || (budget.reach > T::zero() && moved * moved * a <= reach * reach)
    {
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

#[cfg(test)]
mod tests {
    //! The bounds and decisions against exact integer arithmetic: integer-valued inputs
    //! (below `2^30`) make every coefficient an exact `i128` (`Δ` below `2^124`), while
    //! their products exceed 53 bits, so the plain evaluation does round.

    use super::*;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    const U: f64 = f64::EPSILON / 2.0;

    /// The exact coefficients of `|u + w t|² − r²` for integer inputs.
    #[derive(Debug)]
    struct Exact {
        h: i128,
        a: i128,
        c: i128,
        disc: i128,
    }

    fn exact(u: [i64; 3], w: [i64; 3], r: i64) -> Exact {
        let dot = |x: [i64; 3], y: [i64; 3]| -> i128 {
            x.iter()
                .zip(y)
                .map(|(&a, b)| i128::from(a) * i128::from(b))
                .sum()
        };
        let (h, a) = (dot(u, w), dot(w, w));
        let c = dot(u, u) - i128::from(r) * i128::from(r);
        Exact {
            h,
            a,
            c,
            disc: h * h - a * c,
        }
    }

    fn sphere(u: [i64; 3], w: [i64; 3], r: i64) -> LinearSphere<f64, 3> {
        let f = |x: [i64; 3]| Vector3::from(x.map(|v| v as f64));
        LinearSphere::new(f(u), f(w), r as f64)
    }

    /// `|computed − exact| <= bound`; every computed value is an integer here (sums and
    /// products of integers round to integers).
    fn within(computed: f64, exact: i128, bound: f64) -> bool {
        assert_eq!(computed.fract(), 0.0);
        ((computed as i128) - exact).unsigned_abs() as f64 <= bound
    }

    /// The reference answer: status from the exact signs, root in f64 from the exact
    /// integers (within about `4u`).
    fn reference(e: &Exact, r: i64) -> LinearContact<f64> {
        let touch = (r as f64 * r as f64) * (2.0 * U);
        if e.h >= 0 {
            LinearContact::Clear
        } else if (e.c as f64) <= touch {
            LinearContact::Immediate
        } else if e.disc <= 0 {
            LinearContact::Clear
        } else {
            LinearContact::At(e.c as f64 / ((e.disc as f64).sqrt() - e.h as f64))
        }
    }

    /// `first_contact` agrees with the reference, the root within `16u` (the guarantee)
    /// plus the reference's own `4u`.
    fn agrees(u: [i64; 3], w: [i64; 3], r: i64, budget: f64) -> Result<(), TestCaseError> {
        let e = exact(u, w, r);
        let exact_only = Budget {
            relative: budget,
            reach: 0.0,
        };
        let got = sphere(u, w, r).first_contact(f64::INFINITY, exact_only);
        match (got, reference(&e, r)) {
            (LinearContact::At(t), LinearContact::At(t_ref)) => {
                prop_assert!(
                    (t - t_ref).abs() <= 20.0 * U * t_ref,
                    "{t} vs {t_ref} {e:?}"
                );
            }
            (got, want) => prop_assert_eq!(got, want, "{:?}", e),
        }
        Ok(())
    }

    fn int3() -> impl Strategy<Value = [i64; 3]> {
        prop::array::uniform3(-(1i64 << 29)..(1i64 << 29))
    }

    /// `u` and `w` with `u·w < 0` (closing), from any pair.
    fn closing(u: [i64; 3], w: [i64; 3]) -> ([i64; 3], [i64; 3]) {
        if exact(u, w, 0).h > 0 {
            (u, w.map(|x| -x))
        } else {
            (u, w)
        }
    }

    /// The margins' non-finite cases (module comment in `certainly_clear`): an infinite
    /// horizon makes `later` NaN for a receding pair, which must not hide the rate's
    /// proof; products that overflow make margins NaN or infinite, which must never prove
    /// a closing pair clear.
    #[test]
    fn quick_test_with_an_infinite_horizon_and_overflowing_products() {
        let v = |x: f64| Vector3::new(x, 0.0, 0.0);
        let clear = |u: f64, w: f64, horizon: f64| certainly_clear(&v(u), &v(w), 1.0, 1.0, horizon);
        // Receding, ahead by 3: clear for any horizon.
        assert!(clear(3.0, 1.0, f64::INFINITY));
        assert!(clear(3.0, 1.0, 0.5));
        // Closing, meeting at 2: clear only for a horizon before 2.
        assert!(!clear(3.0, -1.0, f64::INFINITY));
        assert!(!clear(3.0, -1.0, 10.0));
        assert!(clear(3.0, -1.0, 1.0));
        // Missing sideways: clear for any horizon.
        let sideways = certainly_clear(
            &Vector3::new(0.0, 3.0, 0.0),
            &v(-1.0),
            1.0,
            1.0,
            f64::INFINITY,
        );
        assert!(sideways);
        // Far apart and fast, meeting at about 1: `h`, `a`, `s` and `c` overflow, and
        // the margins are infinite or NaN. The pair is never proven clear before it meets.
        for horizon in [f64::INFINITY, 2.0, 1.0] {
            assert!(!clear(1e200, -1e200, horizon), "closing, horizon {horizon}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The plain and sharpened bounds of the module docs hold.
        #[test]
        fn bounds_hold(u in int3(), w in int3(), r in 1i64..(1 << 29)) {
            let e = exact(u, w, r);
            let s = sphere(u, w, r);
            let p = s.plain();
            prop_assert!(within(p.h.value, e.h, p.h.err), "h {p:?} {e:?}");
            prop_assert!(within(p.c.value, e.c, p.c.err), "c {p:?} {e:?}");
            prop_assert!(within(p.disc.value, e.disc, p.disc.err), "disc {p:?} {e:?}");
            let (dd_h, dd_c, sharp) = s.sharpen(&p);
            prop_assert!(within(sharp.h.value, e.h, sharp.h.err));
            prop_assert!(within(sharp.c.value, e.c, sharp.c.err));
            prop_assert!(within(sharp.disc.value, e.disc, sharp.disc.err));
            // The double-double discriminant: one rounding plus u² of the terms.
            let disc = s.exact_discriminant(dd_h, dd_c);
            let terms = (e.h * e.h) as f64 + (e.a as f64) * (e.c.abs() as f64);
            prop_assert!(within(disc, e.disc, U * (e.disc.abs() as f64) * 1.01 + 64.0 * U * U * terms));
        }

        /// The quick test only ever claims a certain recession or miss, also in f32 where
        /// the differences of the inputs round.
        #[test]
        fn quick_test_is_never_wrong(
            c1 in int3(), c2 in int3(), v1 in int3(), v2 in int3(),
            r1 in 1i64..(1 << 28), r2 in 1i64..(1 << 28), backward in any::<bool>(),
        ) {
            let sign = if backward { -1 } else { 1 };
            let d = |x: [i64; 3], y: [i64; 3]| [0, 1, 2].map(|i| y[i] - x[i]);
            // f32 inputs: round each to f32 and take the exact integer it became.
            let f = |x: [i64; 3]| x.map(|v| v as f32 as i64);
            let (c1f, c2f, v1f, v2f) = (f(c1), f(c2), f(v1), f(v2));
            let (r1f, r2f) = (r1 as f32 as i64, r2 as f32 as i64);
            let e = exact(d(c1f, c2f), d(v1f, v2f).map(|x| x * sign), r1f + r2f);
            let v3 = |x: [i64; 3]| Vector3::from(x.map(|v| v as f32));
            if certainly_clear(&(v3(c2f) - v3(c1f)), &(v3(v2f) - v3(v1f)), r1f as f32 + r2f as f32, sign as f32, f32::INFINITY) {
                prop_assert!(e.h > 0 || e.disc < 0, "{e:?}");
            }
            let e = exact(d(c1, c2), d(v1, v2).map(|x| x * sign), r1 + r2);
            let v3 = |x: [i64; 3]| Vector3::from(x.map(|v| v as f64));
            if certainly_clear(&(v3(c2) - v3(c1)), &(v3(v2) - v3(v1)), r1 as f64 + r2 as f64, sign as f64, f64::INFINITY) {
                prop_assert!(e.h > 0 || e.disc < 0, "{e:?}");
            }
        }

        /// The horizon part of the quick test never drops a contact at or before the
        /// horizon: closing pairs placed at random offsets (so that the differences of
        /// the inputs round in f32), with the horizon within `2^-k` of the first contact,
        /// before or after it. The reference decides exactly, in integers: no contact on
        /// `[0, H]` iff `P(H) > 0` and `H` comes before the vertex `−h/a`.
        #[test]
        fn quick_test_never_drops_a_contact_before_the_horizon(
            u in prop::array::uniform3(-(1i64 << 20)..(1 << 20)),
            w in prop::array::uniform3(-(1i64 << 20)..(1 << 20)),
            r in 1i64..(1 << 20), k in 1i32..52, later in any::<bool>(),
            offset in int3(), drift in int3(), near in any::<bool>(), gap in 1i64..64,
        ) {
            const SCALE: i128 = 1 << 20;
            // `near`: almost touching and closing head-on, where the contact is where the
            // line `c + 2ht` crosses zero (`a t²` below the rounding of `c`).
            let (u, w) = if near {
                let r = r.max(1 << 10);
                ([r + gap, u[1] >> 12, u[2] >> 12], [-(w[0].abs() >> 4) - 1, w[1] >> 14, w[2] >> 14])
            } else {
                closing(u, w)
            };
            let r = if near { r.max(1 << 10) } else { r };
            let add = |x: [i64; 3], y: [i64; 3]| [0, 1, 2].map(|i| x[i] + y[i]);
            let d = |x: [i64; 3], y: [i64; 3]| [0, 1, 2].map(|i| y[i] - x[i]);
            let (c1, c2, v1, v2) = (offset, add(offset, u), drift, add(drift, w));
            let f = |x: [i64; 3]| x.map(|v| v as f32 as i64);
            let (r1, r2) = (r / 2 + 1, r - r / 2);
            let cases = [
                (d(f(c1), f(c2)), d(f(v1), f(v2)), (r1 as f32 as i64, r2 as f32 as i64), true),
                (u, w, (r1, r2), false),
            ];
            for (u, w, (r1, r2), single) in cases {
                let e = exact(u, w, r1 + r2);
                if e.a == 0 || e.h >= 0 || e.c <= 0 || e.disc <= 0 {
                    continue;
                }
                let t1 = e.c as f64 / (-(e.h as f64) + (e.disc as f64).sqrt());
                if t1 > 1e6 {
                    continue;
                }
                let moved = t1 * (1.0 + if later { 1.0 } else { -1.0 } * 2f64.powi(-k));
                // The horizon as a multiple of 2^-20, exact in f32 and f64 here.
                let n = (moved * SCALE as f64).round().max(0.0) as i128;
                let horizon = n as f64 / SCALE as f64;
                let p_at_horizon = e.c * SCALE * SCALE + 2 * e.h * n * SCALE + e.a * n * n;
                let clear = p_at_horizon > 0 && e.a * n + e.h * SCALE < 0;
                let claimed = if single {
                    let v = |x: [i64; 3]| Vector3::from(x.map(|v| v as f32));
                    certainly_clear(
                        &(v(f(c2)) - v(f(c1))),
                        &(v(f(v2)) - v(f(v1))),
                        r1 as f32 + r2 as f32,
                        1.0,
                        horizon as f32,
                    )
                } else {
                    let v = |x: [i64; 3]| Vector3::from(x.map(|v| v as f64));
                    certainly_clear(&(v(c2) - v(c1)), &(v(v2) - v(v1)), r1 as f64 + r2 as f64, 1.0, horizon)
                };
                prop_assert!(!claimed || clear, "f32 {single}: {e:?} H = {horizon} t1 = {t1}");
            }
        }

        /// The quick test near its boundaries: grazes far away and tangential motions
        /// (as below), placed at random offsets so that the differences of the inputs
        /// round, in f32 and f64.
        #[test]
        fn quick_test_is_never_wrong_near_its_boundaries(
            w in prop::array::uniform3(-(1i64 << 20)..(1 << 20)), s in -(1i64 << 8)..0,
            p in prop::array::uniform3(-(1i64 << 12)..(1 << 12)), delta in -8i64..=8,
            k in 1i64..16, z in -8i64..=8, tangential in any::<bool>(),
            offset in int3(), drift in int3(),
        ) {
            let (u, w, r) = if tangential {
                let (a, b) = (w[0] << 8, w[1] << 8);
                let r = ((a * a + b * b + 1) as f64).sqrt() as i64 + delta.signum();
                ([a, b, 1], [-k * b, k * a, z], r.max(2))
            } else {
                let u = [0, 1, 2].map(|i| s * w[i] + p[i]);
                let e = exact(u, w, 0);
                prop_assume!(e.a > 0);
                let miss = ((-e.disc) as f64 / e.a as f64).sqrt();
                (u, w, (miss.round() as i64 + delta).max(2))
            };
            let add = |x: [i64; 3], y: [i64; 3]| [0, 1, 2].map(|i| x[i] + y[i]);
            let (c1, c2, v1, v2) = (offset, add(offset, u), drift, add(drift, w));
            for sign in [1, -1] {
                // f32: every input rounds to f32; the reference takes the rounded values.
                let f = |x: [i64; 3]| x.map(|v| v as f32 as i64);
                let d = |x: [i64; 3], y: [i64; 3]| [0, 1, 2].map(|i| y[i] - x[i]);
                let (r1, r2) = ((r / 2) as f32 as i64, (r - r / 2) as f32 as i64);
                let e = exact(d(f(c1), f(c2)), d(f(v1), f(v2)).map(|x| x * sign), r1 + r2);
                let v3 = |x: [i64; 3]| Vector3::from(x.map(|v| v as f32));
                if certainly_clear(&(v3(c2) - v3(c1)), &(v3(v2) - v3(v1)), r1 as f32 + r2 as f32, sign as f32, f32::INFINITY) {
                    prop_assert!(e.h > 0 || e.disc < 0, "f32 {e:?}");
                }
                let e = exact(u, w.map(|x| x * sign), r);
                let v3 = |x: [i64; 3]| Vector3::from(x.map(|v| v as f64));
                let (r1, r2) = ((r / 2) as f64, (r - r / 2) as f64);
                if certainly_clear(&(v3(c2) - v3(c1)), &(v3(v2) - v3(v1)), r1 + r2, sign as f64, f64::INFINITY) {
                    prop_assert!(e.h > 0 || e.disc < 0, "f64 {e:?}");
                }
            }
        }

        /// Random pairs: mostly decided and solved by the plain values.
        #[test]
        fn random_pairs_match_exact_arithmetic(u in int3(), w in int3(), r in 1i64..(1 << 29)) {
            agrees(u, w, r, 12.0 * U)?;
        }

        /// A graze far away: `u = s w + p` (`s` up to `−2⁸`, `p` small), so the miss
        /// distance is about `|p|` while `|u| ≈ |s| |w|` is up to `2²⁴` times larger; the
        /// radius is the miss distance rounded, moved by `δ`. `Δ = |w|² r² − |u ∧ w|²`
        /// is then within a few `|w|² r` of zero while `h² ≈ a c ≈ |u|² |w|²`: inside the
        /// plain bound for small `δ` (decided in double-double), outside for large ones.
        #[test]
        fn grazes_far_away_match_exact_arithmetic(
            w in prop::array::uniform3(-(1i64 << 20)..(1 << 20)), s in -(1i64 << 8)..0,
            p in prop::array::uniform3(-(1i64 << 12)..(1 << 12)), delta in -8i64..=8,
        ) {
            let u = [0, 1, 2].map(|i| s * w[i] + p[i]);
            let e = exact(u, w, 0);
            prop_assume!(e.h < 0 && e.a > 0);
            // With r = 0, Δ = h² − a |u|² = −|u ∧ w|²: the miss distance is √(−Δ/a).
            let miss = ((-e.disc) as f64 / e.a as f64).sqrt();
            let r = (miss.round() as i64 + delta).max(1);
            agrees(u, w, r, 12.0 * U)?;
            // Forcing the double-double root changes nothing but accuracy.
            agrees(u, w, r, 0.0)?;
        }

        /// Nearly touching: `u = (r, x, y)` (permuted, signs flipped) with `x² + y²` up to
        /// 1024, so `c` is between 0 and 1024 against `r² ≈ 2⁵⁸`: touching (`c <= 2u r²`,
        /// about 64), or apart by less than the plain bound.
        #[test]
        fn near_touching_matches_exact_arithmetic(
            r in (1i64 << 28)..(1 << 29), x in 0i64..32, y in 0i64..32, w in int3(),
            perm in 0usize..3, signs in prop::array::uniform3(any::<bool>()), inside in any::<bool>(),
        ) {
            let mut u = [r, x, y];
            u.rotate_left(perm);
            for (v, s) in u.iter_mut().zip(signs) {
                if s { *v = -*v; }
            }
            let (u, w) = closing(u, w);
            let r = if inside { r + 1 } else { r };
            agrees(u, w, r, 12.0 * U)?;
        }

        /// Tangential motion: `u = (a, b, 1)`, `w = (−k b, k a, z)`, so `u·w = z`, a few
        /// units against `Σ|uᵢwᵢ| ≈ 2⁵⁹`: the sign of the rate is beyond the plain bound
        /// and decides touching pairs (closing or resting).
        #[test]
        fn tangential_motion_matches_exact_arithmetic(
            a in (1i64 << 25)..(1 << 29), b in (1i64 << 25)..(1 << 29), k in 1i64..16,
            z in -8i64..=8, r_offset in -2i64..3, flip in any::<bool>(),
        ) {
            let a = if flip { -a } else { a };
            let (u, w) = ([a, b, 1], [-k * b, k * a, z]);
            let distance = ((a * a + b * b + 1) as f64).sqrt() as i64;
            agrees(u, w, distance + r_offset, 12.0 * U)?;
        }
    }
}
