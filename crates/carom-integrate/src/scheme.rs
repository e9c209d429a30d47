//! The four time-stepping schemes, written once as stage updates of one ball.
//!
//! Each ball is the ODE `y = (x, v, ω)`, `y' = f(t, y) = (v, a(t, y), α(t, y))`. A scheme
//! with `s` stages evaluates `f` at `s` stage states `Y₀ = yₙ, Y₁, …` and builds each next
//! stage state (and finally `yₙ₊₁`) from the rates seen so far. [`Scheme::advance`] is
//! that update for one ball: given stage `i`'s state and rate it returns stage `i+1`'s
//! state, or `yₙ₊₁` after the last stage; [`Carry`] keeps what the later stages need.
//!
//! Written this way, the same update serves both steppers: the independent one runs all
//! stages of a ball before moving to the next ball (everything stays in registers), the
//! coupled one runs one stage for all balls, evaluates the springs between them, then the
//! next stage. Both therefore compute the same arithmetic for the same rates.

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::{Acceleration, Angular, BallState, ForceField};

/// A ball's ODE state `(x, v, ω)`, or a rate `(dx/dt, dv/dt, dω/dt)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Phase<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) x: Vector<T, D>,
    pub(crate) v: Vector<T, D>,
    pub(crate) w: Angular<T, D>,
}

impl<T: Real, const D: usize> Phase<T, D>
where
    Const<D>: Space<T, D>,
{
    /// `self + h · rate`.
    #[inline]
    fn plus(&self, h: T, rate: &Self) -> Self {
        Self {
            x: self.x + rate.x * h,
            v: self.v + rate.v * h,
            w: self.w + rate.w * h,
        }
    }

    /// The rate at this state: `(v, a, α)`.
    #[inline]
    pub(crate) fn rate(&self, acceleration: Acceleration<T, D>) -> Self {
        Self {
            x: self.v,
            v: acceleration.linear,
            w: acceleration.angular,
        }
    }

    /// The state as a force field sees it.
    #[inline]
    pub(crate) fn ball(&self, inverse_mass: T, time: T) -> BallState<T, D> {
        BallState {
            position: self.x,
            velocity: self.v,
            spin: self.w,
            inverse_mass,
            time,
        }
    }
}

/// What a step remembers between its stages: the state it started from and a rate
/// (Verlet: the first acceleration; RK4: the weighted sum of the rates so far).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Carry<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    start: Phase<T, D>,
    rate: Phase<T, D>,
}

impl<T: Real, const D: usize> Carry<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    pub(crate) fn new(start: Phase<T, D>) -> Self {
        Self { start, rate: start }
    }
}

/// One time-stepping scheme as a sequence of stage updates.
pub(crate) trait Scheme {
    /// Where each stage evaluates the field, as fractions `cᵢ` of the step (one entry
    /// per evaluation).
    const STAGE_TIMES: &'static [f64];

    /// Stage `stage`'s update: from the stage state `y` and its `rate`, the next stage
    /// state, or the new state after the last stage.
    fn advance<T: Real, const D: usize>(
        stage: usize,
        carry: &mut Carry<T, D>,
        y: &Phase<T, D>,
        rate: &Phase<T, D>,
        h: T,
    ) -> Phase<T, D>
    where
        Const<D>: Space<T, D>;
}

/// `xₙ₊₁ = xₙ + h vₙ`, `vₙ₊₁ = vₙ + h aₙ` (and `ω` likewise): one forward-Euler step of
/// the whole state, so the position moves with the old velocity.
pub(crate) struct ExplicitEuler;

impl Scheme for ExplicitEuler {
    const STAGE_TIMES: &'static [f64] = &[0.0];

    #[inline]
    fn advance<T: Real, const D: usize>(
        _: usize,
        _: &mut Carry<T, D>,
        y: &Phase<T, D>,
        rate: &Phase<T, D>,
        h: T,
    ) -> Phase<T, D>
    where
        Const<D>: Space<T, D>,
    {
        y.plus(h, rate)
    }
}

/// `vₙ₊₁ = vₙ + h aₙ`, then `xₙ₊₁ = xₙ + h vₙ₊₁`: the position moves with the new velocity.
pub(crate) struct SemiImplicitEuler;

impl Scheme for SemiImplicitEuler {
    const STAGE_TIMES: &'static [f64] = &[0.0];

    #[inline]
    fn advance<T: Real, const D: usize>(
        _: usize,
        _: &mut Carry<T, D>,
        y: &Phase<T, D>,
        rate: &Phase<T, D>,
        h: T,
    ) -> Phase<T, D>
    where
        Const<D>: Space<T, D>,
    {
        let v = y.v + rate.v * h;
        Phase {
            x: y.x + v * h,
            v,
            w: y.w + rate.w * h,
        }
    }
}

/// Velocity Verlet. Stage 0 (at `tₙ`, `aₙ = a(xₙ, vₙ)`):
/// `xₙ₊₁ = xₙ + h (vₙ + (h/2) aₙ)` and the predicted `ṽ = vₙ + h aₙ`, `ω̃ = ωₙ + h αₙ`.
/// Stage 1 (at `tₙ + h`, `aₙ₊₁ = a(xₙ₊₁, ṽ)`): `vₙ₊₁ = vₙ + (h/2)(aₙ + aₙ₊₁)`, and `ω`
/// likewise. For `a(x)` alone this is the textbook (symplectic, time-reversible) scheme;
/// with velocity dependence it is still second order: it differs from Heun's method only
/// in evaluating the corrector at `xₙ₊₁` instead of `xₙ + h vₙ`, an `O(h²)` shift of an
/// argument that enters multiplied by `h/2`.
pub(crate) struct VelocityVerlet;

impl Scheme for VelocityVerlet {
    const STAGE_TIMES: &'static [f64] = &[0.0, 1.0];

    #[inline]
    fn advance<T: Real, const D: usize>(
        stage: usize,
        carry: &mut Carry<T, D>,
        y: &Phase<T, D>,
        rate: &Phase<T, D>,
        h: T,
    ) -> Phase<T, D>
    where
        Const<D>: Space<T, D>,
    {
        let half_h = h * T::lit(0.5);
        if stage == 0 {
            carry.rate = *rate;
            Phase {
                x: y.x + (y.v + rate.v * half_h) * h,
                v: y.v + rate.v * h,
                w: y.w + rate.w * h,
            }
        } else {
            let start = &carry.start;
            Phase {
                x: y.x,
                v: start.v + (carry.rate.v + rate.v) * half_h,
                w: start.w + (carry.rate.w + rate.w) * half_h,
            }
        }
    }
}

/// The classical Runge–Kutta method: `K₀ = f(yₙ)`, `K₁ = f(yₙ + (h/2) K₀)`,
/// `K₂ = f(yₙ + (h/2) K₁)`, `K₃ = f(yₙ + h K₂)` at `tₙ, tₙ + h/2, tₙ + h/2, tₙ + h`, and
/// `yₙ₊₁ = yₙ + (h/6)(K₀ + 2K₁ + 2K₂ + K₃)`.
pub(crate) struct Rk4;

impl Scheme for Rk4 {
    const STAGE_TIMES: &'static [f64] = &[0.0, 0.5, 0.5, 1.0];

    #[inline]
    fn advance<T: Real, const D: usize>(
        stage: usize,
        carry: &mut Carry<T, D>,
        _: &Phase<T, D>,
        rate: &Phase<T, D>,
        h: T,
    ) -> Phase<T, D>
    where
        Const<D>: Space<T, D>,
    {
        let two = T::lit(2.0);
        let half_h = h * T::lit(0.5);
        match stage {
            0 => {
                carry.rate = *rate;
                carry.start.plus(half_h, rate)
            }
            1 => {
                carry.rate = carry.rate.plus(two, rate);
                carry.start.plus(half_h, rate)
            }
            2 => {
                carry.rate = carry.rate.plus(two, rate);
                carry.start.plus(h, rate)
            }
            _ => {
                let sum = carry.rate.plus(T::one(), rate);
                carry.start.plus(h / T::lit(6.0), &sum)
            }
        }
    }
}

/// One step of one ball in a field: all stages in a row.
#[inline]
pub(crate) fn step_ball<S: Scheme, T: Real, const D: usize, F: ForceField<T, D> + ?Sized>(
    field: &F,
    y: Phase<T, D>,
    inverse_mass: T,
    t: T,
    h: T,
) -> Phase<T, D>
where
    Const<D>: Space<T, D>,
{
    let mut carry = Carry::new(y);
    let mut stage = y;
    for (i, &c) in S::STAGE_TIMES.iter().enumerate() {
        let time = t + h * T::lit(c);
        let acceleration = field.acceleration(&stage.ball(inverse_mass, time));
        stage = S::advance(i, &mut carry, &stage, &stage.rate(acceleration), h);
    }
    stage
}
