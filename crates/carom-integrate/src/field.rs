//! The [`ForceField`] trait, its closed-form summary [`ClosedForm`], and composition:
//! `()` (no force), references, tuples (static composition) and slices or vectors of
//! fields (run-time composition, e.g. of [`Field`](crate::Field)).
//!
//! A field maps one ball's state to its acceleration. Fields that depend on other balls
//! (springs between balls) are not fields but a [`SpringNetwork`](crate::SpringNetwork),
//! which the coupled stepper evaluates for all balls at once.
//!
//! Compositions add their parts in the order written, so the sum (and its rounding) is
//! the same on every run and every thread.

use core::ops::Add;

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::{Acceleration, BallState};

/// A force field: the acceleration of one ball as a function of its own state
/// (position, velocity, spin, inverse mass) and the time.
///
/// Contract: the result is finite for finite input, and zero for a ball of infinite mass
/// (`inverse_mass == 0`), which no field moves. Implementations are pure: the same
/// input gives the same bits.
pub trait ForceField<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The linear and angular acceleration of `ball`.
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D>;

    /// The field as constant gravity plus linear drag plus spin damping, if it is exactly
    /// that: then the motion has a closed form and the exact integrator applies.
    /// `None` (the default) for anything else.
    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        None
    }
}

/// A field of the one family whose motion is known in closed form: constant gravity `g`,
/// linear drag `F = −b v` and spin damping `dω/dt = −λ ω`.
///
/// For a ball of inverse mass `w > 0` the velocity obeys `dv/dt = g − k v` with
/// `k = b·w` and the spin `dω/dt = −λ ω`; see [`exact`](crate::exact) for the solution.
/// A ball with `w = 0` moves at constant velocity and spin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm<T: Real, const D: usize> {
    /// Gravity `g` (an acceleration).
    pub gravity: Vector<T, D>,
    /// The linear drag coefficient `b` (force per velocity, `F = −b v`).
    pub linear_drag: T,
    /// The spin damping rate `λ` (per second).
    pub spin_damping: T,
}

impl<T: Real, const D: usize> ClosedForm<T, D> {
    /// No force at all: free flight.
    pub fn free() -> Self {
        Self {
            gravity: Vector::zeros(),
            linear_drag: T::zero(),
            spin_damping: T::zero(),
        }
    }
}

impl<T: Real, const D: usize> Add for ClosedForm<T, D> {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self {
            gravity: self.gravity + rhs.gravity,
            linear_drag: self.linear_drag + rhs.linear_drag,
            spin_damping: self.spin_damping + rhs.spin_damping,
        }
    }
}

/// No force: free flight.
impl<T: Real, const D: usize> ForceField<T, D> for ()
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, _: &BallState<T, D>) -> Acceleration<T, D> {
        Acceleration::zero()
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        Some(ClosedForm::free())
    }
}

impl<T: Real, const D: usize, F: ForceField<T, D> + ?Sized> ForceField<T, D> for &F
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        (**self).acceleration(ball)
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        (**self).closed_form()
    }
}

/// The sum of the fields, added in slice order.
impl<T: Real, const D: usize, F: ForceField<T, D>> ForceField<T, D> for [F]
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        let mut sum = Acceleration::zero();
        for field in self {
            sum += field.acceleration(ball);
        }
        sum
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        self.iter()
            .try_fold(ClosedForm::free(), |sum, f| Some(sum + f.closed_form()?))
    }
}

/// The sum of the fields, added in vector order.
impl<T: Real, const D: usize, F: ForceField<T, D>> ForceField<T, D> for Vec<F>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
        self.as_slice().acceleration(ball)
    }

    fn closed_form(&self) -> Option<ClosedForm<T, D>> {
        self.as_slice().closed_form()
    }
}

/// Tuples of fields are their sum, added left to right.
macro_rules! impl_tuple_sum {
    ($first:ident $(, $rest:ident)*) => {
        impl<T: Real, const D: usize, $first: ForceField<T, D> $(, $rest: ForceField<T, D>)*>
            ForceField<T, D> for ($first, $($rest,)*)
        where
            Const<D>: Space<T, D>,
        {
            #[inline]
            #[allow(non_snake_case)]
            fn acceleration(&self, ball: &BallState<T, D>) -> Acceleration<T, D> {
                let ($first, $($rest,)*) = self;
                #[allow(unused_mut)]
                let mut sum = $first.acceleration(ball);
                $(sum += $rest.acceleration(ball);)*
                sum
            }

            #[allow(non_snake_case)]
            fn closed_form(&self) -> Option<ClosedForm<T, D>> {
                let ($first, $($rest,)*) = self;
                #[allow(unused_mut)]
                let mut sum = $first.closed_form()?;
                $(sum = sum + $rest.closed_form()?;)*
                Some(sum)
            }
        }
    };
}

impl_tuple_sum!(A);
impl_tuple_sum!(A, B);
impl_tuple_sum!(A, B, C);
impl_tuple_sum!(A, B, C, E);
impl_tuple_sum!(A, B, C, E, G);
impl_tuple_sum!(A, B, C, E, G, H);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Field, Gravity, LinearDrag, QuadraticDrag};
    use nalgebra::{Vector1, Vector2};

    fn ball(v: Vector2<f64>) -> BallState<f64, 2> {
        BallState {
            position: Vector2::new(1.0, 2.0),
            velocity: v,
            spin: Vector1::zeros(),
            inverse_mass: 0.5,
            time: 0.0,
        }
    }

    /// The linear acceleration through a generic bound (exercises the `&F` and `[F]` impls).
    fn through<F: ForceField<f64, 2>>(field: F, b: &BallState<f64, 2>) -> Vector2<f64> {
        field.acceleration(b).linear
    }

    #[test]
    fn compositions_add_their_parts_and_agree_with_each_other() {
        let g = Gravity::new(Vector2::new(0.0, -9.81)).unwrap();
        let lin = LinearDrag::new(0.3).unwrap();
        let quad = QuadraticDrag::new(0.1).unwrap();
        let b = ball(Vector2::new(3.0, 4.0));
        // The independent sum: g − (b/m) v − (c/m)|v| v with |v| = 5, 1/m = 0.5.
        let expected = Vector2::new(0.0, -9.81) - 0.15 * b.velocity - 0.05 * 5.0 * b.velocity;
        let tuple = (g, lin, quad).acceleration(&b).linear;
        let vec: Vec<Field<f64, 2>> = vec![g.into(), lin.into(), quad.into()];
        assert!((tuple - expected).norm() < 1e-14);
        assert_eq!(vec.acceleration(&b).linear, tuple);
        assert_eq!(through(&vec, &b), tuple);
        assert_eq!(through(vec.as_slice(), &b), tuple);
        assert_eq!(
            ForceField::<f64, 2>::acceleration(&(), &b),
            Acceleration::zero()
        );
    }

    #[test]
    fn closed_forms_compose_only_when_every_part_has_one() {
        let g = Gravity::new(Vector2::new(0.0, -9.81)).unwrap();
        let lin = LinearDrag::new(0.3).unwrap();
        let quad = QuadraticDrag::new(0.1).unwrap();
        let cf = (g, lin, lin).closed_form().unwrap();
        assert_eq!(cf.gravity, Vector2::new(0.0, -9.81));
        assert_eq!(cf.linear_drag, 0.6);
        assert!((g, quad).closed_form().is_none());
        let fields: Vec<Field<f64, 2>> = vec![g.into(), quad.into()];
        assert!(fields.closed_form().is_none());
        let empty: Vec<Field<f64, 2>> = Vec::new();
        assert_eq!(empty.closed_form(), Some(ClosedForm::free()));
    }
}
