//! The force field the stepped engine integrates: the scene's gravity and linear drag,
//! as seen in the direction the run goes.
//!
//! The engine always steps its own time `s` forward. A backward run (`carom run --until
//! -T`) simulates the time-reversed motion `y(s) = x(−s)`: velocities are negated once at
//! the start (and again when reported), and every force is rewritten for the reversed
//! system. With `ẏ = −v` and `ÿ = a(x, v) = a(y, −ẏ)`:
//!
//! * gravity `a = g` does not depend on the velocity and is unchanged;
//! * linear drag `a = −(b/m) v` becomes `a = +(b/m) ẏ`: going back in time a ball under drag
//!   speeds up exponentially (by `e^{(b/m) T}` over a span `T`), because forward in time
//!   it slowed down from that speed. Drag is dissipative, so this reversed motion is
//!   unstable: any rounding or integration error grows at the same rate, and a backward
//!   run does not retrace a forward run with drag the way an elastic run without drag
//!   does. It is the exact backward continuation of the equations of motion, no more.
//!
//! Both parts are carom-integrate's own fields ([`Gravity`], [`LinearDrag`]); the field
//! keeps the closed form (gravity plus signed linear drag), so the `exact` integrator
//! applies forward and backward.

use carom_integrate::{Acceleration, BallState, ClosedForm, ForceField, Gravity, LinearDrag};
use carom_math::{Real, Space, Vector};
use nalgebra::Const;

/// Gravity and linear drag, reversed for backward runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WorldForces<T: Real, const D: usize> {
    gravity: Option<Gravity<T, D>>,
    drag: Option<LinearDrag<T>>,
    reversed: bool,
}

impl<T: Real, const D: usize> WorldForces<T, D> {
    /// The field of a scene with `gravity` and linear `drag` (validated, finite, drag
    /// `>= 0`); zero parts are left out. `reversed` for a backward run.
    pub(crate) fn new(gravity: Vector<T, D>, drag: T, reversed: bool) -> Self {
        Self {
            gravity: if gravity == Vector::<T, D>::zeros() {
                None
            } else {
                Gravity::new(gravity).ok()
            },
            drag: if drag > T::zero() {
                LinearDrag::new(drag).ok()
            } else {
                None
            },
            reversed,
        }
    }

    /// The names of the parts, for the pipeline.
    pub(crate) fn names(&self) -> impl Iterator<Item = &'static str> {
        let drag = match (self.drag.is_some(), self.reversed) {
            (false, _) => None,
            (true, false) => Some("linear-drag"),
            (true, true) => Some("linear-drag (reversed: backward run)"),
        };
        self.gravity.map(|_| "gravity").into_iter().chain(drag)
    }

    /// The gravity vector (zero if none).
    pub(crate) fn gravity(&self) -> Vector<T, D> {
        self.gravity.map_or_else(Vector::zeros, |g| g.g())
    }
}

impl<T: Real, const D: usize> ForceField<T, D> for WorldForces<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        let mut a = Acceleration::zero();
        if let Some(g) = &self.gravity {
            a += g.acceleration(ball);
        }
        if let Some(drag) = &self.drag {
            let d = drag.acceleration(ball);
            if self.reversed {
                a.linear -= d.linear;
            } else {
                a += d;
            }
        }
        a
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        let b = self.drag.map_or_else(T::zero, |d| d.coefficient());
        Some(ClosedForm {
            gravity: self.gravity(),
            linear_drag: if self.reversed { -b } else { b },
            spin_damping: T::zero(),
        })
    }
}
