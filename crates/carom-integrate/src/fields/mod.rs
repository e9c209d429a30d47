//! The built-in force fields, and [`Field`], their run-time union.
//!
//! Each field is a small validated value implementing [`ForceField`]. Compose them
//! statically with a tuple (`(gravity, drag, magnus)`) when the set is known at compile
//! time, or at run time with a `Vec<Field>` (what a scene loader builds); both add the
//! parts in the order given.

mod drag;
mod gravity;
mod magnus;
mod spring;

pub use drag::{LinearDrag, QuadraticDrag};
pub use gravity::Gravity;
pub use magnus::{Magnus, SpinDamping};
pub use spring::{AnchorSpring, Spring};

use carom_math::{Real, Space};
use nalgebra::Const;

use crate::{Acceleration, BallState, ClosedForm, ForceField};

/// Any built-in field, for compositions chosen at run time (`Vec<Field<T, D>>` is a
/// [`ForceField`]: the sum of its entries).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Field<T: Real, const D: usize> {
    /// Uniform gravity.
    Gravity(Gravity<T, D>),
    /// Linear drag `−b v`.
    LinearDrag(LinearDrag<T>),
    /// Quadratic drag `−c |v| v`.
    QuadraticDrag(QuadraticDrag<T>),
    /// The Magnus force `S ω × v`.
    Magnus(Magnus<T>),
    /// Spin damping `dω/dt = −λ ω`.
    SpinDamping(SpinDamping<T>),
    /// A damped spring from every ball to a fixed anchor.
    AnchorSpring(AnchorSpring<T, D>),
}

impl<T: Real, const D: usize> ForceField<T, D> for Field<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        match self {
            Field::Gravity(f) => f.acceleration(ball),
            Field::LinearDrag(f) => f.acceleration(ball),
            Field::QuadraticDrag(f) => f.acceleration(ball),
            Field::Magnus(f) => f.acceleration(ball),
            Field::SpinDamping(f) => f.acceleration(ball),
            Field::AnchorSpring(f) => f.acceleration(ball),
        }
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        match self {
            Field::Gravity(f) => f.closed_form(),
            Field::LinearDrag(f) => ForceField::<T, D>::closed_form(f),
            Field::QuadraticDrag(f) => ForceField::<T, D>::closed_form(f),
            Field::Magnus(f) => ForceField::<T, D>::closed_form(f),
            Field::SpinDamping(f) => ForceField::<T, D>::closed_form(f),
            Field::AnchorSpring(f) => f.closed_form(),
        }
    }
}

macro_rules! impl_from_field {
    ($($variant:ident($ty:ty)),*) => {
        $(impl<T: Real, const D: usize> From<$ty> for Field<T, D> {
            fn from(f: $ty) -> Self {
                Field::$variant(f)
            }
        })*
    };
}

impl_from_field!(
    Gravity(Gravity<T, D>),
    LinearDrag(LinearDrag<T>),
    QuadraticDrag(QuadraticDrag<T>),
    Magnus(Magnus<T>),
    SpinDamping(SpinDamping<T>),
    AnchorSpring(AnchorSpring<T, D>)
);
