//! Test helpers: balls with positions (which the response itself never needs) and the
//! conserved quantities computed from masses and radii, independently of the impulse
//! code's own energy bookkeeping.

use carom_response::{Angular, Body, Contact, Space};
use nalgebra::{Const, SVector};

/// A ball with everything a test needs: mass, radius, centre, velocity, spin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TestBall<const D: usize>
where
    Const<D>: Space<f64, D>,
{
    pub(crate) mass: f64,
    pub(crate) radius: f64,
    pub(crate) center: SVector<f64, D>,
    pub(crate) velocity: SVector<f64, D>,
    pub(crate) spin: Angular<f64, D>,
}

impl<const D: usize> TestBall<D>
where
    Const<D>: Space<f64, D>,
{
    pub(crate) fn new(
        mass: f64,
        radius: f64,
        center: SVector<f64, D>,
        velocity: SVector<f64, D>,
    ) -> Self {
        Self {
            mass,
            radius,
            center,
            velocity,
            spin: <Const<D> as Space<f64, D>>::angular_zero(),
        }
    }

    pub(crate) fn body(&self) -> Body<f64, D> {
        Body::ball(self.mass, self.radius, self.velocity, self.spin).unwrap()
    }

    /// The moment of inertia, from the disk / solid-sphere formulas.
    pub(crate) fn inertia(&self) -> f64 {
        let factor = if D == 2 { 0.5 } else { 0.4 };
        factor * self.mass * self.radius * self.radius
    }

    pub(crate) fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.velocity.norm_squared()
            + 0.5
                * self.inertia()
                * <Const<D> as Space<f64, D>>::angular_dot(&self.spin, &self.spin)
    }

    pub(crate) fn momentum(&self) -> SVector<f64, D> {
        self.velocity * self.mass
    }

    /// `m (c − o) × v + I ω` about the fixed point `o`.
    pub(crate) fn angular_momentum_about(&self, origin: &SVector<f64, D>) -> Angular<f64, D> {
        <Const<D> as Space<f64, D>>::cross(&(self.center - origin), &self.momentum())
            + self.spin * self.inertia()
    }

    /// The ball after a collision gave it `velocity` and `spin`.
    pub(crate) fn moving(&self, velocity: SVector<f64, D>, spin: Angular<f64, D>) -> Self {
        Self {
            velocity,
            spin,
            ..*self
        }
    }

    /// The contact with another ball (normal from `self` to `other`).
    pub(crate) fn contact(&self, other: &Self) -> Contact<f64, D> {
        Contact::between_balls(&self.center, self.radius, &other.center, other.radius).unwrap()
    }
}

/// The angular components as a slice, for comparisons.
pub(crate) fn angular<const D: usize>(w: &Angular<f64, D>) -> Vec<f64>
where
    Const<D>: Space<f64, D>,
{
    <Const<D> as Space<f64, D>>::angular_as_slice(w).to_vec()
}

/// `|a − b| ≤ tol` componentwise, with a message.
pub(crate) fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= tol,
            "{what}[{i}]: {x} vs {y} (tolerance {tol})"
        );
    }
}
