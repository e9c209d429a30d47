//! Helpers shared by the integration tests: running a stepper for many steps, the
//! oscillator field, and fitting convergence orders.

use carom_integrate::{
    AnchorSpring, Angular, Bodies, ForceField, Real, Space, Spring, Stepper, TimeStep, Vector,
};
use nalgebra::Const;

/// One ball's state, for stepping it alone.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OneBall<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) x: Vector<T, D>,
    pub(crate) v: Vector<T, D>,
    pub(crate) spin: Angular<T, D>,
    pub(crate) inverse_mass: T,
}

impl<T: Real, const D: usize> OneBall<T, D>
where
    Const<D>: Space<T, D>,
{
    /// A ball of unit mass without spin.
    pub(crate) fn new(x: Vector<T, D>, v: Vector<T, D>) -> Self {
        Self {
            x,
            v,
            spin: <Const<D> as Space<T, D>>::angular_zero(),
            inverse_mass: T::one(),
        }
    }

    /// Advances `steps` times by `dt` from time 0, calling `observe(n, self)` after every
    /// step.
    pub(crate) fn run<F: ForceField<T, D>>(
        &mut self,
        stepper: &Stepper<T, D, F>,
        dt: T,
        steps: usize,
        mut observe: impl FnMut(usize, &Self),
    ) {
        let step = TimeStep::new(dt).unwrap();
        for n in 0..steps {
            let t = T::from_count(n) * dt;
            stepper.step_ball(
                &mut self.x,
                &mut self.v,
                &mut self.spin,
                self.inverse_mass,
                t,
                step,
            );
            observe(n + 1, self);
        }
    }
}

/// Steps whole arrays `steps` times.
pub(crate) fn run_bodies<T: Real, const D: usize, F: ForceField<T, D>>(
    stepper: &Stepper<T, D, F>,
    bodies: &mut Bodies<'_, T, D>,
    dt: T,
    steps: usize,
) where
    Const<D>: Space<T, D>,
{
    let step = TimeStep::new(dt).unwrap();
    for n in 0..steps {
        stepper.step(bodies, T::from_count(n) * dt, step);
    }
}

/// The undamped oscillator `ẍ = −ω² x` for a ball of unit mass: a spring of stiffness
/// `ω²`, rest length 0, anchored at the origin.
pub(crate) fn oscillator<T: Real, const D: usize>(omega: T) -> AnchorSpring<T, D> {
    let spring = Spring::new(omega * omega, T::zero(), T::zero()).unwrap();
    AnchorSpring::new(Vector::zeros(), spring).unwrap()
}

/// A vector's components in `f64` (exact), for measuring in the higher precision.
pub(crate) fn wide<T: Real, const D: usize>(x: &Vector<T, D>) -> Vector<f64, D> {
    x.map(Real::to_f64)
}

/// The oscillator's energy per unit mass `(|v|² + k |x|²)/2`, computed in `f64`.
pub(crate) fn oscillator_energy<T: Real, const D: usize>(
    k: T,
    x: &Vector<T, D>,
    v: &Vector<T, D>,
) -> f64 {
    0.5 * (wide(v).norm_squared() + k.to_f64() * wide(x).norm_squared())
}

/// The least-squares slope of `ln error` against `ln h`: the measured order.
pub(crate) fn fitted_order(steps: &[f64], errors: &[f64]) -> f64 {
    let xs: Vec<f64> = steps.iter().map(|h| h.ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}
