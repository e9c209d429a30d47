//! Conservative advancement with rigorous steps, then bracketed refinement.
//!
//! A cluster query has many *components*: one per (cluster ball, obstacle) pair, each
//! with a signed gap `gₖ(s)` (distance between surfaces). No closed form exists once the
//! cluster spins, so the search advances in steps that provably skip no contact:
//!
//! * **First order.** If every point involved moves at most at speed `Bₖ` over
//!   `[s, s + τ]`, then `|ġₖ| <= Bₖ` and `gₖ` cannot reach 0 before `τ = gₖ/Bₖ`. With
//!   `B = |v_com| + |ω| reach` this is the bound PhET lacks: a purely spinning cluster
//!   (`v_com = 0`) still has `B > 0` and is stepped towards the wall, never through it.
//!   Bounds that depend on the interval (gravity) are made consistent in two passes:
//!   `τ₀ = g/B(s, s)`, then `τ₁ = g/B(s, s + τ₀) <= τ₀`, which is safe because `B` does
//!   not decrease with the interval.
//! * **Second order.** If also `|g̈ₖ| <= Kₖ`, then `gₖ(s + τ) >= gₖ + ġₖ τ − Kₖ τ²/2`,
//!   positive up to that parabola's first root: a longer safe step when the component
//!   recedes or moves tangentially (a graze no longer crawls), and a Newton-like step
//!   near a transversal contact. The step is the larger of the two safe steps, the
//!   smallest over the components.
//!
//! The search stops at a component that is within the tolerance `δ` and closing. The
//! upper parabola `gₖ + ġₖ τ + Kₖ τ²/2` then gives a time where `gₖ < 0` is certain;
//! with the last safe time this brackets the first contact, which ITP refines until the
//! bracket's width is `δ / B` (so the gap is known to `δ`) or machine precision. The
//! returned time is the bracket's end where every gap is still `>= 0`.
//!
//! Components that start in contact (gap `<= 0`) and are not closing are *unarmed*:
//! they cannot collide again before they separate by more than `δ`. Their steps are
//! limited so that their gap cannot exceed `2δ` within one step, so a separation and a
//! return are never both hidden between two samples unless the separation stays within
//! `2δ`.
//!
//! Guarantee: no contact of an armed component is skipped (up to the rounding of the
//! gap evaluations); the contact found is located to `δ` in distance.

use carom_math::{InvalidValue, Problem, Real, Vector, ensure_positive};

/// The tolerances of conservative advancement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdvanceOptions<T: Real> {
    tolerance: T,
    max_steps: usize,
}

impl<T: Real> AdvanceOptions<T> {
    /// The default step budget.
    pub const DEFAULT_MAX_STEPS: usize = 10_000;

    /// An absolute distance `tolerance > 0` (contacts are located to this distance, and
    /// a component that started in contact must separate by more than it before it can
    /// collide again) and a step budget (`>= 1`) after which the query reports
    /// [`Status::NotConverged`](crate::Status::NotConverged).
    ///
    /// # Errors
    /// `tolerance` if not finite or not `> 0`; `max_steps` if zero.
    pub fn new(tolerance: T, max_steps: usize) -> Result<Self, InvalidValue> {
        ensure_positive("tolerance", tolerance)?;
        if max_steps == 0 {
            return Err(InvalidValue::new("max_steps", Problem::NotPositive(0.0)));
        }
        Ok(Self {
            tolerance,
            max_steps,
        })
    }

    /// A tolerance of `10⁻¹²` times the scene scale (for `f32`, `64 ε ≈ 7.6·10⁻⁶` times
    /// it: rounding allows no better), and the default step budget. A natural scale is
    /// the cluster's bounding radius; with coordinates far from the origin, use at least
    /// `|x| ε / 10⁻¹²` so that the tolerance stays above the rounding of positions.
    ///
    /// # Errors
    /// `scale` if not finite or not `> 0`.
    pub fn relative_to(scale: T) -> Result<Self, InvalidValue> {
        let scale = ensure_positive("scale", scale)?;
        let relative = T::lit(1e-12).max(T::lit(64.0) * T::EPSILON);
        Self::new(relative * scale, Self::DEFAULT_MAX_STEPS)
    }

    /// The distance tolerance.
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// The step budget.
    pub fn max_steps(&self) -> usize {
        self.max_steps
    }
}

/// The most components one query may have: 64 cluster balls against 64.
pub(crate) const MAX_COMPONENTS: usize = 64 * 64;

/// The gap and its rate of one component at one time.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sample<T> {
    pub(crate) gap: T,
    pub(crate) rate: T,
}

/// Bounds on the rate of change of one component's gap over an interval.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bounds<T> {
    /// `|ġ| <=` this.
    pub(crate) speed: T,
    /// `|g̈| <=` this while the gap stays `>= 0`.
    pub(crate) curvature_apart: T,
    /// `|g̈| <=` this whatever the gap (`+∞` if unknown).
    pub(crate) curvature_any: T,
}

/// A set of gap components that advance together.
pub(crate) trait Components<T: Real, const D: usize> {
    /// What is computed once per time (the bodies' states).
    type State;
    /// The number of components (`<= MAX_COMPONENTS`).
    fn count(&self) -> usize;
    /// The bodies at search time `s`.
    fn state(&self, s: T) -> Self::State;
    /// Component `k`'s gap and rate in `state`.
    fn sample(&self, state: &Self::State, k: usize) -> Sample<T>;
    /// Component `k`'s bounds over the search times between `s0` and `s1`.
    fn bounds(&self, k: usize, s0: T, s1: T) -> Bounds<T>;
    /// `true` if component `k` provably never touches after search time `s` (so an
    /// unbounded search can stop): its reference points move apart without acceleration
    /// and are farther apart than the balls can reach.
    fn separating_for_good(&self, state: &Self::State, k: usize, s: T) -> bool;
    /// Component `k`'s unit normal (first body to second) and contact point in `state`.
    fn contact(&self, state: &Self::State, k: usize) -> (Vector<T, D>, Vector<T, D>);
}

/// The outcome of an advancement.
pub(crate) enum Advance<T> {
    /// Component `k` is in contact and closing at time 0.
    Immediate(usize),
    /// Component `k` makes contact at search time `s`.
    At(T, usize),
    /// No contact within the horizon.
    Clear,
    /// The step budget ran out (or a value overflowed); no contact before `s`.
    NotConverged(T),
}

/// A fixed-size bit set over component indices (no allocation).
struct Armed([u64; MAX_COMPONENTS / 64]);

impl Armed {
    fn get(&self, k: usize) -> bool {
        self.0[k / 64] >> (k % 64) & 1 == 1
    }
    fn set(&mut self, k: usize) {
        self.0[k / 64] |= 1 << (k % 64);
    }
}

/// The largest `τ` with `g + ġ τ − K τ²/2 >= 0` for `g > 0` (the lower parabola's first
/// root), written without cancellation; `+∞` if it never reaches 0.
fn lower_parabola_root<T: Real>(g: T, rate: T, k: T) -> T {
    if !k.finite() {
        return T::zero();
    }
    if k == T::zero() {
        return if rate < T::zero() {
            g / -rate
        } else {
            T::INFINITY
        };
    }
    let root = (rate * rate + T::lit(2.0) * k * g).sqrt();
    if rate < T::zero() {
        T::lit(2.0) * g / (root - rate)
    } else {
        (rate + root) / k
    }
}

/// The first `τ` with `g + ġ τ + K τ²/2 = level` for `g < level` (the upper parabola),
/// `+∞` if it never gets there.
fn upper_parabola_root<T: Real>(g: T, rate: T, k: T, level: T) -> T {
    lower_parabola_root(level - g, -rate, k)
}

/// Conservative advancement of `set` from search time 0 to `horizon`.
pub(crate) fn advance<T: Real, const D: usize, C: Components<T, D>>(
    set: &C,
    horizon: T,
    options: &AdvanceOptions<T>,
) -> Advance<T> {
    let n = set.count().min(MAX_COMPONENTS);
    let delta = options.tolerance;
    let mut armed = Armed([0; MAX_COMPONENTS / 64]);
    let mut state = set.state(T::zero());
    // Time 0: contact and closing is immediate; the deepest such component is reported.
    let mut deepest: Option<(T, usize)> = None;
    for k in 0..n {
        let x = set.sample(&state, k);
        if x.gap > T::zero() {
            armed.set(k);
        } else if x.rate < T::zero() && deepest.is_none_or(|(g, _)| x.gap < g) {
            deepest = Some((x.gap, k));
        }
    }
    if let Some((_, k)) = deepest {
        return Advance::Immediate(k);
    }
    let (mut s, mut previous) = (T::zero(), T::zero());
    for _ in 0..options.max_steps {
        let mut step = T::INFINITY;
        let mut closest: Option<(Sample<T>, usize)> = None;
        let mut all_separating = true;
        for k in 0..n {
            let x = set.sample(&state, k);
            if !(x.gap.finite() && x.rate.finite()) {
                return Advance::NotConverged(previous);
            }
            if armed.get(k) && x.gap <= T::zero() {
                // Rounding let a safe step land on or past the contact.
                return refine(set, &armed, n, previous, s, delta);
            }
            if !armed.get(k) && x.gap > delta {
                armed.set(k);
            }
            if armed.get(k)
                && x.gap <= delta
                && x.rate < T::zero()
                && closest.is_none_or(|(c, _)| x.gap < c.gap)
            {
                closest = Some((x, k));
            }
            step = step.min(safe_step(set, k, s, x, armed.get(k), delta));
            all_separating = all_separating && set.separating_for_good(&state, k, s);
        }
        if let Some((x, k)) = closest {
            // Within δ and closing: the upper parabola says when the gap is surely < 0.
            let b = set.bounds(k, s, s + T::lit(4.0) * x.gap / -x.rate);
            let certain = upper_parabola_root(x.gap, x.rate, b.curvature_apart, T::zero());
            let probe = s + if certain.finite() {
                certain
            } else {
                T::lit(2.0) * x.gap / -x.rate
            };
            let probe = probe.min(horizon);
            if probe > s && armed_minimum(set, &armed, n, &set.state(probe)).0 < T::zero() {
                return refine(set, &armed, n, s, probe, delta);
            }
        }
        if all_separating || step == T::INFINITY || s + step > horizon {
            return Advance::Clear;
        }
        let next = s + step;
        if next <= s {
            return Advance::NotConverged(s);
        }
        previous = s;
        s = next;
        state = set.state(s);
    }
    Advance::NotConverged(s)
}

/// The safe step of component `k` from time `s`, the larger of the first- and
/// second-order bounds (module docs), evaluated with interval-consistent bounds.
fn safe_step<T: Real, const D: usize, C: Components<T, D>>(
    set: &C,
    k: usize,
    s: T,
    x: Sample<T>,
    armed: bool,
    delta: T,
) -> T {
    let step_with = |b: Bounds<T>| {
        if armed {
            let first = if b.speed > T::zero() {
                x.gap / b.speed
            } else {
                T::INFINITY
            };
            first.max(lower_parabola_root(x.gap, x.rate, b.curvature_apart))
        } else {
            let room = T::lit(2.0) * delta - x.gap;
            let first = if b.speed > T::zero() {
                room / b.speed
            } else {
                T::INFINITY
            };
            first.max(upper_parabola_root(
                x.gap,
                x.rate,
                b.curvature_any,
                T::lit(2.0) * delta,
            ))
        }
    };
    let optimistic = step_with(set.bounds(k, s, s));
    if optimistic == T::INFINITY {
        // Bounds that do not grow with the interval: the step stands.
        let far = set.bounds(k, s, T::MAX);
        return step_with(far);
    }
    step_with(set.bounds(k, s, s + optimistic)).min(optimistic)
}

/// The smallest gap over the armed components at `state`, and its component.
fn armed_minimum<T: Real, const D: usize, C: Components<T, D>>(
    set: &C,
    armed: &Armed,
    n: usize,
    state: &C::State,
) -> (T, usize) {
    let mut best = (T::INFINITY, 0);
    for k in (0..n).filter(|&k| armed.get(k)) {
        let g = set.sample(state, k).gap;
        if g < best.0 || crate::roots::is_nan(g) {
            best = (g, k);
        }
    }
    best
}

/// Narrows `[lo, hi]`, where the armed minimum gap is `> 0` at `lo` and `<= 0` at `hi`,
/// to width `δ / B` (or machine precision) with ITP.
fn refine<T: Real, const D: usize, C: Components<T, D>>(
    set: &C,
    armed: &Armed,
    n: usize,
    lo: T,
    hi: T,
    delta: T,
) -> Advance<T> {
    let at = |s: T| armed_minimum(set, armed, n, &set.state(s));
    let (g_lo, _) = at(lo);
    let (g_hi, k_hi) = at(hi);
    if g_hi == T::zero() || g_lo <= T::zero() || crate::roots::is_nan(g_lo) {
        return Advance::At(if g_hi == T::zero() { hi } else { lo }, k_hi);
    }
    if crate::roots::is_nan(g_hi) {
        return Advance::NotConverged(lo);
    }
    let speed = (0..n)
        .filter(|&k| armed.get(k))
        .map(|k| set.bounds(k, lo, hi).speed)
        .fold(T::zero(), T::max);
    let tol = if speed > T::zero() {
        delta / speed
    } else {
        T::zero()
    };
    let (apart, touching) = crate::roots::itp(|s| at(s).0, lo, hi, g_lo, g_hi, tol);
    Advance::At(apart, at(touching).1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parabola_roots_are_the_safe_steps() {
        // g = 1, ġ = −1, K = 0: reaches 0 at τ = 1.
        assert_eq!(lower_parabola_root(1.0, -1.0, 0.0), 1.0);
        // g = 1, ġ = 0, K = 2: 1 − τ² = 0 at τ = 1.
        assert_eq!(lower_parabola_root(1.0, 0.0, 2.0), 1.0);
        // Unknown curvature: no second-order step.
        assert_eq!(lower_parabola_root(1.0, 5.0, f64::INFINITY), 0.0);
        // Receding without curvature: never.
        assert_eq!(lower_parabola_root(1.0, 1.0, 0.0), f64::INFINITY);
        // Upper: from g = −1 rising at 1 with K = 0 to level 1 takes τ = 2.
        assert_eq!(upper_parabola_root(-1.0, 1.0, 0.0, 1.0), 2.0);
    }

    #[test]
    fn options_are_validated() {
        assert_eq!(
            AdvanceOptions::new(0.0_f64, 10).unwrap_err().field,
            "tolerance"
        );
        assert_eq!(
            AdvanceOptions::new(1e-9_f64, 0).unwrap_err().field,
            "max_steps"
        );
        let o = AdvanceOptions::<f32>::relative_to(2.0).unwrap();
        assert!(o.tolerance() > 1e-5 && o.tolerance() < 2e-5);
    }
}
