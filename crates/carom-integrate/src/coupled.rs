//! [`CoupledStepper`]: an integrator for balls joined by springs, where each stage needs
//! every ball's stage state before any ball can take the next stage.
//!
//! One step runs stage by stage: the spring forces at the current stage states are
//! accumulated in link order ([`SpringNetwork`]), then every ball takes its stage update
//! (the same [`scheme`](crate::scheme) code as [`Stepper`]'s, with the spring
//! acceleration `F/m` added to the field's). The stage states, the per-ball carry and the
//! force buffer live in a caller-owned [`Scratch`], which grows to the largest ball count
//! it has seen and is reused: stepping allocates nothing after the first step.
//!
//! With an empty network the result is bit for bit [`Stepper::step`]'s.

use carom_math::{InvalidValue, Real, Space, Vector};
use nalgebra::Const;

use crate::scheme::{Carry, ExplicitEuler, Phase, Rk4, Scheme, SemiImplicitEuler, VelocityVerlet};
use crate::state::Arrays;
use crate::stepper::update_each;
use crate::{
    Angular, Bodies, ForceField, Integrator, SpringNetwork, Stepper, TimeStep, Unsupported,
};

/// Reusable buffers for [`CoupledStepper::step`]. Create one per engine (or per thread)
/// and pass it to every step.
#[derive(Clone, Debug)]
pub struct Scratch<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    stages: Vec<Phase<T, D>>,
    carries: Vec<Carry<T, D>>,
    forces: Vec<Vector<T, D>>,
}

impl<T: Real, const D: usize> Scratch<T, D>
where
    Const<D>: Space<T, D>,
{
    /// Empty buffers; the first step sizes them.
    pub fn new() -> Self {
        Self {
            stages: Vec::new(),
            carries: Vec::new(),
            forces: Vec::new(),
        }
    }

    /// Buffers already sized for `balls` balls.
    pub fn with_capacity(balls: usize) -> Self {
        let mut scratch = Self::new();
        scratch.resize(balls);
        scratch
    }

    /// Sizes the buffers for `n` balls (allocating only when `n` exceeds every size seen).
    fn resize(&mut self, n: usize) {
        let blank = Phase {
            x: Vector::zeros(),
            v: Vector::zeros(),
            w: <Const<D> as Space<T, D>>::angular_zero(),
        };
        self.stages.resize(n, blank);
        self.carries.resize(n, Carry::new(blank));
        self.forces.resize(n, Vector::zeros());
    }
}

impl<T: Real, const D: usize> Default for Scratch<T, D>
where
    Const<D>: Space<T, D>,
{
    fn default() -> Self {
        Self::new()
    }
}

/// An integrator bound to a force field and a spring network.
#[derive(Clone, Debug)]
pub struct CoupledStepper<T: Real, const D: usize, F> {
    stepper: Stepper<T, D, F>,
    network: SpringNetwork<T, D>,
}

impl<T: Real, const D: usize, F: ForceField<T, D>> CoupledStepper<T, D, F>
where
    Const<D>: Space<T, D>,
{
    /// `stepper`'s integrator and field, plus the springs of `network`.
    ///
    /// # Errors
    /// [`Unsupported`] for the exact integrator with a non-empty network (springs have no
    /// closed form here).
    pub fn new(
        stepper: Stepper<T, D, F>,
        network: SpringNetwork<T, D>,
    ) -> Result<Self, Unsupported> {
        if stepper.integrator() == Integrator::Exact && !network.is_empty() {
            return Err(Unsupported {
                integrator: Integrator::Exact,
                reason: "springs between balls have no closed-form solution",
            });
        }
        Ok(Self { stepper, network })
    }

    /// The integrator and force field.
    #[inline]
    pub fn stepper(&self) -> &Stepper<T, D, F> {
        &self.stepper
    }

    /// The springs.
    #[inline]
    pub fn network(&self) -> &SpringNetwork<T, D> {
        &self.network
    }

    /// Advances every ball from time `t` to `t + dt`, using `scratch` for the stage states.
    ///
    /// # Errors
    /// `bodies.len` if there are fewer balls than the network's links refer to (nothing is
    /// changed then).
    pub fn step(
        &self,
        bodies: &mut Bodies<'_, T, D>,
        t: T,
        dt: TimeStep<T>,
        scratch: &mut Scratch<T, D>,
    ) -> Result<(), InvalidValue> {
        self.network.ensure_balls("bodies.len", bodies.len())?;
        let h = dt.get();
        let run = match self.stepper.integrator() {
            Integrator::ExplicitEuler => run_staged::<ExplicitEuler, T, D, F>,
            Integrator::SemiImplicitEuler => run_staged::<SemiImplicitEuler, T, D, F>,
            Integrator::VelocityVerlet => run_staged::<VelocityVerlet, T, D, F>,
            Integrator::Rk4 => run_staged::<Rk4, T, D, F>,
            // `new` admits the exact integrator only without springs.
            Integrator::Exact => {
                self.stepper.step(bodies, t, dt);
                return Ok(());
            }
        };
        run(
            self.stepper.field(),
            &self.network,
            bodies.arrays(),
            t,
            h,
            scratch,
        );
        Ok(())
    }
}

/// One step of scheme `S`, stage by stage over all balls.
fn run_staged<S: Scheme, T: Real, const D: usize, F: ForceField<T, D>>(
    field: &F,
    network: &SpringNetwork<T, D>,
    arrays: Arrays<'_, T, D>,
    t: T,
    h: T,
    scratch: &mut Scratch<T, D>,
) where
    Const<D>: Space<T, D>,
{
    let Arrays {
        positions,
        velocities,
        inverse_masses,
        spins,
    } = arrays;
    scratch.resize(positions.len());
    let Scratch {
        stages,
        carries,
        forces,
    } = scratch;
    let zero_spin = <Const<D> as Space<T, D>>::angular_zero();
    let spins_in: &[Angular<T, D>] = spins.as_deref().unwrap_or(&[]);
    for (i, ((stage, carry), (x, v))) in stages
        .iter_mut()
        .zip(carries.iter_mut())
        .zip(positions.iter().zip(velocities.iter()))
        .enumerate()
    {
        *stage = Phase {
            x: *x,
            v: *v,
            w: spins_in.get(i).copied().unwrap_or(zero_spin),
        };
        *carry = Carry::new(*stage);
    }
    for (i, &c) in S::STAGE_TIMES.iter().enumerate() {
        let time = t + h * T::lit(c);
        network.write_forces(|b| (stages[b].x, stages[b].v), forces);
        for (((stage, carry), force), &m) in stages
            .iter_mut()
            .zip(carries.iter_mut())
            .zip(forces.iter())
            .zip(inverse_masses)
        {
            let mut acceleration = field.acceleration(&stage.ball(m, time));
            acceleration.linear += force * m;
            *stage = S::advance(i, carry, stage, &stage.rate(acceleration), h);
        }
    }
    let mut finished = stages.iter();
    let arrays = Arrays {
        positions,
        velocities,
        inverse_masses,
        spins,
    };
    update_each(arrays, |y, _| finished.next().copied().unwrap_or(y));
}
