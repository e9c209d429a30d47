//! The integration schemes by name: [`Integrator`], its command-line names and what
//! theory says about each (order, evaluations per step, stability on the oscillator).
//!
//! ## Stability on the undamped oscillator `ẍ = −ω² x`
//!
//! One step of size `h` multiplies `(x, v)` by a matrix `M(ωh)`; the scheme is stable
//! when the powers of `M` stay bounded. With `E = (v² + ω² x²)/2`:
//!
//! * **Explicit Euler** `x' = x + h v`, `v' = v − h ω² x`:
//!   `E' = ((v − hω²x)² + ω²(x + hv)²)/2 = (1 + ω²h²) E` — the cross terms cancel, so the
//!   energy grows by exactly `1 + ω²h²` every step, at any `h`. Never stable.
//! * **Semi-implicit Euler** `v' = v − hω²x`, `x' = x + h v'` and **velocity Verlet**
//!   `x' = x + hv − h²ω²x/2`, `v' = v − hω²(x + x')/2`: `det M = 1` (both are
//!   symplectic) and `tr M = 2 − ω²h²`, so the eigenvalues `λ` solve
//!   `λ² − (2 − ω²h²) λ + 1 = 0`. For `ωh < 2` they are a conjugate pair on the unit
//!   circle (bounded; a modified energy is conserved); for `ωh > 2` they are real with
//!   product 1, and the larger grows like `|λ|ⁿ`. Stable for `ωh < 2`.
//! * **RK4** multiplies by `R(iωh)` with `R(z) = 1 + z + z²/2 + z³/6 + z⁴/24`, and
//!   `|R(iy)|² = 1 − y⁶/72 + y⁸/576`, which is `≤ 1` exactly when `y ≤ 2√2`. Stable for
//!   `ωh ≤ 2√2` (with a slight energy loss below the limit).
//! * **Exact** has no truncation error and no step limit.
//!
//! ## Stability on linear drag `v̇ = −k v`
//!
//! With `z = −k h`, one step multiplies `v` by a polynomial `P(z)`; the scheme is stable
//! while `|P(z)| <= 1`, beyond which a light ball under drag speeds up step after step
//! instead of slowing down (a ball of 1 mg under `drag = 0.2` has `k = 2·10⁵ /s`):
//!
//! * **Explicit and semi-implicit Euler** `v' = v − h k v`: `P = 1 + z`, stable for
//!   `k h <= 2` (the position update does not feed back into the velocity).
//! * **Velocity Verlet** (the velocity from the rates at both ends, the end one at the
//!   predicted `v + h a`): `P = 1 + z + z²/2`, also stable for `k h <= 2`.
//! * **RK4**: `P = R(z)` above, stable for `k h <= 2.7852935634…`, where `R(z)`
//!   (positive on the whole real axis) comes back to 1.
//! * **Exact** follows `e^{−k h}`: no limit.

use core::fmt;
use core::str::FromStr;

/// An integration scheme. The [`FromStr`] and [`Display`](fmt::Display) forms are the
/// names `carom run --integrator` takes: `explicit-euler`, `semi-implicit-euler`,
/// `verlet`, `rk4`, `exact`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// `x += h v; v += h a(x, v)`: position with the old velocity. First order; gains
    /// energy on every undamped oscillator. A baseline, not a choice.
    ExplicitEuler,
    /// `v += h a(x, v); x += h v`: position with the new velocity (the scheme of the
    /// ping-pong paper; symplectic Euler). First order, one evaluation per step, stable
    /// for `ωh < 2`, energy bounded over long runs.
    SemiImplicitEuler,
    /// Velocity Verlet: `x += h v + h² a/2`, then `v += h (a + a')/2` with `a'` at the new
    /// position. Second order, two evaluations per step (the stepper does not cache the
    /// last one: collisions change velocities between steps), stable for `ωh < 2`.
    /// Velocity-dependent forces see the predicted velocity `v + h a` at the new
    /// position, which keeps second order (the scheme is then Heun's method in
    /// velocity); it is symplectic only for position-dependent forces.
    VelocityVerlet,
    /// The classical fourth-order Runge–Kutta method: four evaluations per step, stable
    /// for `ωh ≤ 2√2`, not symplectic (it loses a little energy every step).
    Rk4,
    /// The closed form of gravity plus linear drag plus spin damping ([`exact`](crate::exact)):
    /// exact to rounding at any step, for fields that have one.
    Exact,
}

impl Integrator {
    /// Every integrator, in the order of the documentation.
    pub const ALL: [Integrator; 5] = [
        Integrator::ExplicitEuler,
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
        Integrator::Exact,
    ];

    /// The command-line name (`explicit-euler`, `semi-implicit-euler`, `verlet`, `rk4`,
    /// `exact`).
    pub const fn name(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit-euler",
            Integrator::SemiImplicitEuler => "semi-implicit-euler",
            Integrator::VelocityVerlet => "verlet",
            Integrator::Rk4 => "rk4",
            Integrator::Exact => "exact",
        }
    }

    /// The order of the global error (`error = O(hᵖ)`); `None` for the exact integrator,
    /// which has no truncation error.
    pub const fn order(self) -> Option<u32> {
        match self {
            Integrator::ExplicitEuler | Integrator::SemiImplicitEuler => Some(1),
            Integrator::VelocityVerlet => Some(2),
            Integrator::Rk4 => Some(4),
            Integrator::Exact => None,
        }
    }

    /// How a step shows a constant acceleration `a` in its mean velocity: the step from
    /// `(x₀, v₀)` is `x₁ = x₀ + h (v₀ + w a h)`, `v₁ = v₀ + a h` with this weight `w` —
    /// `0` for explicit Euler (the position moves with the old velocity), `1` for
    /// semi-implicit Euler (with the new one), `½` for Verlet, RK4 and the exact
    /// integrator (exact for constant acceleration). So a force held constant over a step
    /// changes the step's chord `(x₁ − x₀)/h` by `w` times what it adds to the end
    /// velocity: the time-stepped engine turns a correction of a chord into the end
    /// velocity of the constant contact force that makes it (`w > 0`), and corrects
    /// explicit Euler's chords with impulses instead (`w = 0`: no force within the step
    /// moves them). Under linear drag the relation depends on the drag over the step:
    /// see [`Self::end_per_chord`].
    pub const fn chord_weight(self) -> f64 {
        match self {
            Integrator::ExplicitEuler => 0.0,
            Integrator::SemiImplicitEuler => 1.0,
            Integrator::VelocityVerlet | Integrator::Rk4 | Integrator::Exact => 0.5,
        }
    }

    /// Force-field evaluations per ball per step.
    pub const fn evaluations_per_step(self) -> usize {
        match self {
            Integrator::ExplicitEuler | Integrator::SemiImplicitEuler => 1,
            Integrator::VelocityVerlet => 2,
            Integrator::Rk4 => 4,
            Integrator::Exact => 0,
        }
    }

    /// The largest `ωh` at which the undamped oscillator `ẍ = −ω² x` stays bounded (see
    /// the [module documentation](self)): `0` for explicit Euler (never), `2` for
    /// semi-implicit Euler and Verlet, `2√2` for RK4, infinity for the exact integrator.
    pub fn oscillator_stability_limit(self) -> f64 {
        match self {
            Integrator::ExplicitEuler => 0.0,
            Integrator::SemiImplicitEuler | Integrator::VelocityVerlet => 2.0,
            Integrator::Rk4 => 2.0 * core::f64::consts::SQRT_2,
            Integrator::Exact => f64::INFINITY,
        }
    }
}

impl Integrator {
    /// The largest `k h` at which linear drag `v̇ = −k v` still decays (see the
    /// [module documentation](self)): `2` for the Euler schemes and Verlet, the real root
    /// of `R(z) = 1` for RK4 (2.785…), infinity for the exact integrator.
    pub fn decay_stability_limit(self) -> f64 {
        match self {
            Integrator::ExplicitEuler
            | Integrator::SemiImplicitEuler
            | Integrator::VelocityVerlet => 2.0,
            Integrator::Rk4 => 2.785_293_563_405_282,
            Integrator::Exact => f64::INFINITY,
        }
    }
}

impl Integrator {
    /// What a constant acceleration held over a step adds to the end velocity per what it
    /// adds to the chord `(x₁ − x₀)/h`, against linear drag `v̇ = a − k v` with
    /// `decay = k h` (negative in a backward run, whose drag is reversed): `1/w` without
    /// drag ([`Self::chord_weight`]), `None` for explicit Euler (`w = 0`: no force within
    /// the step moves its chord). The time-stepped engine solves its contact forces as
    /// chord changes and gives each body's end velocity this many times its chord's.
    ///
    /// Each scheme's step is linear in `a` and in the start state, so the acceleration's
    /// part is the step from rest with gravity `a` and drag `k` (`x = k h`):
    ///
    /// * **Semi-implicit Euler** `v₁ = a h`, `x₁ = h v₁`: chord `a h`, end `a h`, so `1`
    ///   at any drag (the drag acts on the start velocity, zero here).
    /// * **Velocity Verlet** `x₁ = a h²/2`, predicted `ṽ = a h`,
    ///   `v₁ = (h/2)(a + a − k a h)`: chord `a h/2`, end `a h (1 − x/2)`, so `2 − x`.
    /// * **RK4** on the linear system `y = (x, v)`, `ẏ = A y + b` with
    ///   `A = [[0, 1], [0, −k]]`, `b = (0, a)`: from rest
    ///   `y₁ = h Σⱼ₌₀³ (hA)ʲ b/(j+1)!`, and `Ab = (a, −ka)`, `A²b = (−ka, k²a)`,
    ///   `A³b = (k²a, −k³a)`: chord `a h (1/2 − x/6 + x²/24)`, end
    ///   `a h (1 − x/2 + x²/6 − x³/24)`.
    /// * **Exact** `v(t) = (a/k)(1 − e^{−kt})`: end `a h (1 − e^{−x})/x`, chord
    ///   `a h (x − 1 + e^{−x})/x²`, so `x (1 − e^{−x})/(x − 1 + e^{−x})`. Below
    ///   `|x| = 1e-3` the difference `x − (1 − e^{−x})` cancels, and the ratio of the
    ///   series `(1 − x/2 + x²/6 − x³/24)/(1/2 − x/6 + x²/24 − x³/120)` is used instead
    ///   (its truncation is `O(x⁴)`, below 1e-12).
    pub fn end_per_chord(self, decay: f64) -> Option<f64> {
        let x = decay;
        // The end's series to x³, RK4's end and the exact end's truncation alike.
        let end = 1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0;
        let chord = 0.5 - x / 6.0 + x * x / 24.0;
        match self {
            Integrator::ExplicitEuler => None,
            Integrator::SemiImplicitEuler => Some(1.0),
            Integrator::VelocityVerlet => Some(2.0 - x),
            Integrator::Rk4 => Some(end / chord),
            Integrator::Exact if x.abs() < 1e-3 => Some(end / (chord - x * x * x / 120.0)),
            Integrator::Exact => {
                let lost = -(-x).exp_m1();
                Some(x * lost / (x - lost))
            }
        }
    }
}

impl Integrator {
    /// The largest `k h` at which one step under linear drag `v̇ = −k v` neither speeds a
    /// ball up nor turns it back: its end velocity and its chord `(x₁ − x₀)/h` keep the
    /// start velocity's direction and are no longer than it. The time-stepped engine
    /// refuses a longer step (`carom run --dt`).
    ///
    /// One step from `v₀` gives the end velocity `P(−x) v₀` (`x = k h`, see the
    /// [module documentation](self)) and the chord `C(−x) v₀`:
    ///
    /// * **Explicit Euler** `P = 1 − x`, `C = 1`; **semi-implicit Euler** `P = C = 1 − x`:
    ///   both turn the ball back beyond `x = 1`, though they stay bounded up to 2. A
    ///   fuzzed scene at `x = 1.88` with semi-implicit Euler: its light balls' chords ran
    ///   against their velocities, and the collisions between them pumped a 1,000 kg ball
    ///   to 3e19 m/s within a millisecond.
    /// * **Velocity Verlet** `P = 1 − x + x²/2` (positive), `C = 1 − x/2`: `2`, its
    ///   stability limit.
    /// * **RK4** `P = R(−x)` (positive), `C = (1 − R(−x))/x`: its stability limit.
    /// * **Exact**: no limit.
    pub fn drag_step_limit(self) -> f64 {
        match self {
            Integrator::ExplicitEuler | Integrator::SemiImplicitEuler => 1.0,
            other => other.decay_stability_limit(),
        }
    }
}

impl fmt::Display for Integrator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not one of the integrators' command-line names.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown integrator `{0}`: expected one of explicit-euler, semi-implicit-euler, verlet, rk4, exact"
)]
pub struct UnknownIntegrator(pub String);

impl FromStr for Integrator {
    type Err = UnknownIntegrator;

    /// Parses a command-line name exactly (case-sensitive, no aliases).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Integrator::ALL
            .into_iter()
            .find(|i| i.name() == s)
            .ok_or_else(|| UnknownIntegrator(s.to_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_the_cli_names() {
        let names: Vec<String> = Integrator::ALL.iter().map(ToString::to_string).collect();
        assert_eq!(
            names,
            [
                "explicit-euler",
                "semi-implicit-euler",
                "verlet",
                "rk4",
                "exact"
            ]
        );
        for i in Integrator::ALL {
            assert_eq!(i.to_string().parse::<Integrator>(), Ok(i));
        }
    }

    #[test]
    fn unknown_names_are_rejected_with_the_list_of_valid_ones() {
        let e = "RK4".parse::<Integrator>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown integrator `RK4`: expected one of explicit-euler, semi-implicit-euler, verlet, rk4, exact"
        );
        assert!("euler".parse::<Integrator>().is_err());
        assert!("".parse::<Integrator>().is_err());
    }

    #[test]
    fn the_end_per_chord_under_drag_is_what_each_scheme_does_with_a_constant_acceleration() {
        use crate::{Bodies, Gravity, LinearDrag, Stepper, TimeStep};
        use nalgebra::Vector2;
        // The acceleration's part of a step is the difference of two steps from the same
        // start, with and without it (each scheme is linear in it); drag rate k = b/m, a
        // ball of 1 kg.
        let (x0, v0, h) = (Vector2::new(0.3, 2.0), Vector2::new(1.5, -0.7), 0.01);
        let a = Vector2::new(0.0, -9.81);
        for integrator in Integrator::ALL {
            for decay in [0.0, 1e-7, 4e-4, 2e-3, 0.3, 1.0, 1.9, 45.0] {
                if decay > integrator.decay_stability_limit() {
                    continue;
                }
                let step = |g: Vector2<f64>| {
                    let drag = LinearDrag::new(decay / h).unwrap();
                    let field = (Gravity::new(g).unwrap(), drag);
                    let stepper = Stepper::new(integrator, field).unwrap();
                    let (mut x, mut v) = ([x0], [v0]);
                    let mut bodies = Bodies::new(&mut x, &mut v, &[1.0]).unwrap();
                    stepper.step(&mut bodies, 0.0, TimeStep::new(h).unwrap());
                    (x[0] / h, v[0])
                };
                let ((chord_a, end_a), (chord_0, end_0)) = (step(a), step(Vector2::zeros()));
                let (chord, end) = ((chord_a - chord_0).y, (end_a - end_0).y);
                match integrator.end_per_chord(decay) {
                    None => assert_eq!(chord, 0.0, "{integrator}: no chord"),
                    Some(ratio) => assert!(
                        (end / chord - ratio).abs() < 1e-9 * ratio.abs().max(1.0),
                        "{integrator}, k h = {decay}: {} stepped, {ratio} said",
                        end / chord
                    ),
                }
                if decay == 0.0 && integrator.chord_weight() > 0.0 {
                    let ratio = integrator.end_per_chord(0.0).unwrap();
                    assert_eq!(ratio, 1.0 / integrator.chord_weight(), "{integrator}");
                }
            }
        }
    }

    #[test]
    fn the_exact_end_per_chord_is_smooth_across_its_series_and_backward() {
        // Either side of the switch at |x| = 1e-3 the two forms agree, and a backward
        // run's reversed drag (x < 0) continues the same function, whose Taylor series
        // is 2 (1 − x/6 + x²/36 − x³/540 + O(x⁴)) (the O(x⁴) term measured at 50 digits:
        // about 3.1e-4 x⁴ for |x| <= 1/2).
        let f = |x: f64| Integrator::Exact.end_per_chord(x).unwrap();
        for x in [1e-3, -1e-3] {
            let (below, above) = (f(x * (1.0 - 1e-9)), f(x * (1.0 + 1e-9)));
            assert!((below - above).abs() < 1e-11, "{x}: {below} vs {above}");
        }
        for x in [-0.5, -1e-2, -1e-5, 1e-5, 1e-2] {
            let series = 2.0 * (1.0 - x / 6.0 + x * x / 36.0 - x * x * x / 540.0);
            assert!((f(x) - series).abs() < 4e-4 * x.powi(4) + 1e-14, "{x}");
        }
        assert!(f(-3.0) > 2.0 && f(30.0) < 1.1 && f(30.0) > 1.0);
    }

    #[test]
    fn the_chord_weight_is_what_each_scheme_does_with_a_constant_acceleration() {
        use crate::{Bodies, Gravity, Stepper, TimeStep};
        use nalgebra::Vector2;
        // One step under constant gravity from (x₀, v₀): (x₁ − x₀)/h − v₀ = w a h.
        let a = Vector2::new(0.0, -9.81);
        let (x0, v0, h) = (Vector2::new(0.3, 2.0), Vector2::new(1.5, 0.7), 0.01);
        for integrator in Integrator::ALL {
            let stepper = Stepper::new(integrator, Gravity::new(a).unwrap()).unwrap();
            let (mut x, mut v) = ([x0], [v0]);
            let mut bodies = Bodies::new(&mut x, &mut v, &[1.0]).unwrap();
            stepper.step(&mut bodies, 0.0, TimeStep::new(h).unwrap());
            let w = ((x[0] - x0) / h - v0).y / (a.y * h);
            assert!(
                (w - integrator.chord_weight()).abs() < 1e-12,
                "{integrator}: {w}"
            );
            assert!(
                ((v[0] - v0) - a * h).norm() < 1e-15,
                "{integrator}: v₁ = v₀ + a h"
            );
        }
    }

    #[test]
    fn drag_decays_just_below_each_schemes_limit_and_grows_just_above_it() {
        use crate::{Bodies, LinearDrag, Stepper, TimeStep};
        use nalgebra::Vector2;
        // The schemes themselves, stepped on v̇ = −(b/m) v: |v| after 200 steps.
        let (b, m) = (0.2, 1e-3);
        let k = b / m;
        let speed_after = |integrator: Integrator, kh: f64| {
            let stepper = Stepper::new(integrator, LinearDrag::new(b).unwrap()).unwrap();
            let (mut x, mut v) = ([Vector2::zeros()], [Vector2::new(1.0, 0.0)]);
            let inverse_masses = [1.0 / m];
            let mut bodies = Bodies::new(&mut x, &mut v, &inverse_masses).unwrap();
            for n in 0..200 {
                let h = TimeStep::new(kh / k).unwrap();
                stepper.step(&mut bodies, f64::from(n) * kh / k, h);
            }
            v[0].norm()
        };
        for integrator in Integrator::ALL {
            let limit = integrator.decay_stability_limit();
            if limit.is_infinite() {
                assert!(speed_after(integrator, 1e3) <= 1.0, "{integrator}");
                continue;
            }
            assert!(speed_after(integrator, 0.99 * limit) < 1.0, "{integrator}");
            assert!(speed_after(integrator, 1.01 * limit) > 1.0, "{integrator}");
        }
        // RK4 has no real root (R > 0 on the real axis): its limit is where R comes back to 1.
        let z = -Integrator::Rk4.decay_stability_limit();
        let r = 1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0;
        assert!((r - 1.0).abs() < 1e-12, "{r}");
    }

    #[test]
    fn below_the_drag_step_limit_a_step_neither_speeds_a_ball_up_nor_turns_it_back() {
        use crate::{Bodies, LinearDrag, Stepper, TimeStep};
        use nalgebra::Vector2;
        // One step of a 1 kg ball at 1 m/s under drag b = k: end velocity and chord.
        let step = |integrator: Integrator, kh: f64| {
            let stepper = Stepper::new(integrator, LinearDrag::new(kh).unwrap()).unwrap();
            let (mut x, mut v) = ([Vector2::zeros()], [Vector2::new(1.0, 0.0)]);
            let mut bodies = Bodies::new(&mut x, &mut v, &[1.0]).unwrap();
            stepper.step(&mut bodies, 0.0, TimeStep::new(1.0).unwrap());
            (v[0].x, x[0].x)
        };
        let faithful =
            |(v, chord): (f64, f64)| (0.0..=1.0).contains(&v) && (0.0..=1.0).contains(&chord);
        for integrator in Integrator::ALL {
            let limit = integrator.drag_step_limit();
            assert!(limit <= integrator.decay_stability_limit(), "{integrator}");
            if limit.is_infinite() {
                assert!(faithful(step(integrator, 1e3)), "{integrator}");
                continue;
            }
            for kh in [0.1, 0.5, 0.99 * limit] {
                assert!(faithful(step(integrator, kh)), "{integrator} at {kh}");
            }
            let beyond = step(integrator, 1.01 * limit);
            assert!(
                !faithful(beyond),
                "{integrator}: {beyond:?} beyond its limit"
            );
        }
    }

    #[test]
    fn rk4_limit_is_where_its_amplification_factor_reaches_one() {
        // |R(iy)|² = 1 − y⁶/72 + y⁸/576 from the complex polynomial itself.
        let r2 = |y: f64| {
            let re = 1.0 - y * y / 2.0 + y.powi(4) / 24.0;
            let im = y - y.powi(3) / 6.0;
            re * re + im * im
        };
        let y = Integrator::Rk4.oscillator_stability_limit();
        assert!((r2(y) - 1.0).abs() < 1e-14);
        assert!(r2(0.999 * y) < 1.0 && r2(1.001 * y) > 1.0);
    }
}
