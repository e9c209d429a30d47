//! [`Stepper`]: an integrator bound to a force field, advancing independent balls.
//!
//! Every ball is advanced on its own (all stages of a ball, then the next ball), reading
//! and writing only its own entries. Stepping any partition of the balls, in any order or
//! on any number of threads, therefore gives the same bits as stepping them all at once.
//! Nothing is allocated.

use carom_math::{InvalidValue, Real, Space, Vector, ensure_positive};
use nalgebra::Const;

use crate::scheme::{self, ExplicitEuler, Phase, Rk4, SemiImplicitEuler, VelocityVerlet};
use crate::state::Arrays;
use crate::{Angular, Bodies, ClosedForm, ForceField, Integrator};

/// A validated time step: finite and `> 0`.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct TimeStep<T: Real>(T);

impl<T: Real> TimeStep<T> {
    /// The step `dt`.
    ///
    /// # Errors
    /// `dt` if not finite or not `> 0`.
    pub fn new(dt: T) -> Result<Self, InvalidValue> {
        Ok(Self(ensure_positive("dt", dt)?))
    }

    /// The step in seconds.
    #[inline]
    pub fn get(self) -> T {
        self.0
    }
}

/// An integrator that cannot be used with what it was given.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("integrator `{integrator}` does not apply here: {reason}")]
pub struct Unsupported {
    /// The integrator asked for.
    pub integrator: Integrator,
    /// Why it does not apply.
    pub reason: &'static str,
}

/// An integrator bound to a force field.
///
/// Built by [`Stepper::new`], which checks that the exact integrator gets a field with a
/// closed form.
#[derive(Clone, Debug)]
pub struct Stepper<T: Real, const D: usize, F> {
    plan: Plan<T, D>,
    field: F,
}

/// The integrator, with the closed form the exact one steps by.
#[derive(Clone, Copy, Debug)]
enum Plan<T: Real, const D: usize> {
    ExplicitEuler,
    SemiImplicitEuler,
    VelocityVerlet,
    Rk4,
    Exact(ClosedForm<T, D>),
}

impl<T: Real, const D: usize, F: ForceField<T, D>> Stepper<T, D, F>
where
    Const<D>: Space<T, D>,
{
    /// `integrator` in `field`.
    ///
    /// # Errors
    /// [`Unsupported`] for [`Integrator::Exact`] when the field has no closed form
    /// (anything beyond gravity, linear drag and spin damping).
    pub fn new(integrator: Integrator, field: F) -> Result<Self, Unsupported> {
        let plan = match integrator {
            Integrator::ExplicitEuler => Plan::ExplicitEuler,
            Integrator::SemiImplicitEuler => Plan::SemiImplicitEuler,
            Integrator::VelocityVerlet => Plan::VelocityVerlet,
            Integrator::Rk4 => Plan::Rk4,
            Integrator::Exact => Plan::Exact(field.closed_form().ok_or(Unsupported {
                integrator,
                reason: "the force field has no closed-form solution \
                         (only gravity, linear drag and spin damping have one)",
            })?),
        };
        Ok(Self { plan, field })
    }

    /// The integrator.
    #[inline]
    pub fn integrator(&self) -> Integrator {
        match self.plan {
            Plan::ExplicitEuler => Integrator::ExplicitEuler,
            Plan::SemiImplicitEuler => Integrator::SemiImplicitEuler,
            Plan::VelocityVerlet => Integrator::VelocityVerlet,
            Plan::Rk4 => Integrator::Rk4,
            Plan::Exact(_) => Integrator::Exact,
        }
    }

    /// The force field.
    #[inline]
    pub fn field(&self) -> &F {
        &self.field
    }

    /// Advances every ball from time `t` to `t + dt`.
    pub fn step(&self, bodies: &mut Bodies<'_, T, D>, t: T, dt: TimeStep<T>) {
        self.step_arrays(bodies.arrays(), t, dt.get());
    }

    /// Advances one ball from time `t` to `t + dt` (the same arithmetic as
    /// [`Stepper::step`] does for each ball).
    pub fn step_ball(
        &self,
        position: &mut Vector<T, D>,
        velocity: &mut Vector<T, D>,
        spin: &mut Angular<T, D>,
        inverse_mass: T,
        t: T,
        dt: TimeStep<T>,
    ) {
        let arrays = Arrays {
            positions: core::slice::from_mut(position),
            velocities: core::slice::from_mut(velocity),
            inverse_masses: core::slice::from_ref(&inverse_mass),
            spins: Some(core::slice::from_mut(spin)),
        };
        self.step_arrays(arrays, t, dt.get());
    }

    /// [`Stepper::step`] on arrays of equal length.
    pub(crate) fn step_arrays(&self, arrays: Arrays<'_, T, D>, t: T, h: T) {
        let field = &self.field;
        macro_rules! run {
            ($scheme:ty) => {
                update_each(arrays, |y, m| {
                    scheme::step_ball::<$scheme, T, D, F>(field, y, m, t, h)
                })
            };
        }
        match &self.plan {
            Plan::ExplicitEuler => run!(ExplicitEuler),
            Plan::SemiImplicitEuler => run!(SemiImplicitEuler),
            Plan::VelocityVerlet => run!(VelocityVerlet),
            Plan::Rk4 => run!(Rk4),
            Plan::Exact(cf) => {
                let spin_decay = cf.spin_decay(h);
                update_each(arrays, |y, m| advance_exact(cf, spin_decay, &y, m, h));
            }
        }
    }
}

/// One exact step of one ball, given the step's spin factor `e^{−λ h}`.
#[inline]
pub(crate) fn advance_exact<T: Real, const D: usize>(
    closed_form: &ClosedForm<T, D>,
    spin_decay: T,
    y: &Phase<T, D>,
    inverse_mass: T,
    h: T,
) -> Phase<T, D>
where
    Const<D>: Space<T, D>,
{
    let (moved, w) =
        closed_form.advance_with_spin_decay(spin_decay, &y.x, &y.v, &y.w, inverse_mass, h);
    Phase {
        x: moved.position,
        v: moved.velocity,
        w,
    }
}

/// Replaces each ball's state `y` by `update(y, inverse_mass)`, in order. Balls without a
/// spin slice are updated with a zero spin, and their new spin is dropped.
#[inline]
pub(crate) fn update_each<T: Real, const D: usize>(
    arrays: Arrays<'_, T, D>,
    mut update: impl FnMut(Phase<T, D>, T) -> Phase<T, D>,
) where
    Const<D>: Space<T, D>,
{
    let Arrays {
        positions,
        velocities,
        inverse_masses,
        spins,
    } = arrays;
    let balls = positions.iter_mut().zip(velocities).zip(inverse_masses);
    if let Some(spins) = spins {
        for (((x, v), &m), w) in balls.zip(spins) {
            let y = update(
                Phase {
                    x: *x,
                    v: *v,
                    w: *w,
                },
                m,
            );
            (*x, *v, *w) = (y.x, y.v, y.w);
        }
    } else {
        let w = <Const<D> as Space<T, D>>::angular_zero();
        for ((x, v), &m) in balls {
            let y = update(Phase { x: *x, v: *v, w }, m);
            (*x, *v) = (y.x, y.v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Gravity, LinearDrag, QuadraticDrag};
    use nalgebra::{Vector1, Vector2};

    #[test]
    fn time_steps_must_be_positive_and_finite() {
        assert_eq!(TimeStep::new(0.0_f64).unwrap_err().field, "dt");
        assert!(TimeStep::new(-1e-3_f32).is_err());
        assert!(TimeStep::new(f64::NAN).is_err());
        assert_eq!(TimeStep::new(1e-3).unwrap().get(), 1e-3);
    }

    #[test]
    fn exact_needs_a_closed_form_and_says_so() {
        let g = Gravity::new(Vector2::new(0.0, -9.81)).unwrap();
        let quad = QuadraticDrag::new(0.1).unwrap();
        let e = Stepper::new(Integrator::Exact, (g, quad)).unwrap_err();
        assert_eq!(e.integrator, Integrator::Exact);
        assert!(
            e.to_string()
                .starts_with("integrator `exact` does not apply here")
        );
        assert!(Stepper::new(Integrator::Exact, (g, LinearDrag::new(0.1).unwrap())).is_ok());
        assert!(Stepper::new(Integrator::Rk4, (g, quad)).is_ok());
    }

    #[test]
    fn step_ball_is_the_same_arithmetic_as_step() {
        let field = (
            Gravity::new(Vector2::new(0.0, -9.81)).unwrap(),
            QuadraticDrag::new(0.3).unwrap(),
        );
        let dt = TimeStep::new(0.01).unwrap();
        for integrator in [Integrator::ExplicitEuler, Integrator::Rk4] {
            let stepper = Stepper::new(integrator, field).unwrap();
            let mut p = [Vector2::new(1.0, 2.0)];
            let mut v = [Vector2::new(3.0, -1.0)];
            let mut w = [Vector1::new(0.0)];
            let mut bodies = Bodies::new(&mut p, &mut v, &[2.0]).unwrap();
            stepper.step(&mut bodies, 0.0, dt);
            let (mut x1, mut v1) = (Vector2::new(1.0, 2.0), Vector2::new(3.0, -1.0));
            stepper.step_ball(&mut x1, &mut v1, &mut w[0], 2.0, 0.0, dt);
            assert_eq!((p[0], v[0]), (x1, v1));
        }
    }
}
