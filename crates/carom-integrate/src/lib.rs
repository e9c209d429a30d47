//! Integrators and force fields for balls, over struct-of-arrays state.
//!
//! * **Integrators** ([`Integrator`]): explicit Euler, semi-implicit Euler (velocity
//!   first, then position with the new velocity), velocity Verlet, classical RK4, and the
//!   exact closed form of gravity plus linear drag ([`exact`]). The module documentation
//!   of [`integrator`] derives each one's stability on the undamped oscillator: explicit
//!   Euler gains a factor `1 + ω²h²` of energy every step at any step size;
//!   semi-implicit Euler and Verlet are stable for `ωh < 2`; RK4 for `ωh ≤ 2√2`.
//! * **Force fields** ([`ForceField`]): [`Gravity`], [`LinearDrag`], [`QuadraticDrag`],
//!   the [`Magnus`] force `S ω × v` with [`SpinDamping`], and damped Hooke springs to a
//!   fixed point ([`AnchorSpring`]). Compose them with tuples, or at run time with a
//!   `Vec<`[`Field`]`>`; implement the trait for your own.
//! * **Steppers**: [`Stepper`] binds an integrator to a field and advances independent
//!   balls in place through a [`Bodies`] view of the engine's arrays (positions,
//!   velocities, inverse masses, optional spins). Each ball is advanced on its own, so
//!   chunks stepped on any number of threads give identical bits; nothing is allocated.
//!   [`CoupledStepper`] adds springs between balls ([`SpringNetwork`]), evaluated stage by
//!   stage with a caller-owned [`Scratch`] and accumulated in link order.
//!
//! Everything is generic over the scalar (`f32`, `f64`) and the dimension (2, 3); the
//! [`d2`] and [`d3`] modules name the concrete types. Fields and steps are validated
//! values (`Result<_, InvalidValue>` naming the field); stepping takes them as they are
//! and never panics.
//!
//! ```
//! use carom_integrate::{Bodies, Gravity, Integrator, LinearDrag, Stepper, TimeStep};
//! use nalgebra::Vector2;
//!
//! let field = (Gravity::new(Vector2::new(0.0, -9.81))?, LinearDrag::new(0.01)?);
//! let stepper = Stepper::new("semi-implicit-euler".parse::<Integrator>()?, field)?;
//! let mut positions = vec![Vector2::new(0.0, 1.0); 100];
//! let mut velocities = vec![Vector2::new(2.0, 3.0); 100];
//! let inverse_masses = vec![1.0 / 0.0027; 100];
//! let dt = TimeStep::new(1.0 / 240.0)?;
//! let mut t = 0.0;
//! for _ in 0..240 {
//!     let mut bodies = Bodies::new(&mut positions, &mut velocities, &inverse_masses)?;
//!     stepper.step(&mut bodies, t, dt);
//!     t += dt.get();
//! }
//! assert!(positions[0].y < 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod coupled;
pub mod exact;
mod field;
mod fields;
pub mod integrator;
mod network;
mod scheme;
mod state;
mod stepper;

pub use carom_math::{InvalidValue, Problem, Real, Space, Vector};
pub use coupled::{CoupledStepper, Scratch};
pub use exact::PointState;
pub use field::{ClosedForm, ForceField};
pub use fields::{
    AnchorSpring, Field, Gravity, LinearDrag, Magnus, QuadraticDrag, SpinDamping, Spring,
};
pub use integrator::{Integrator, UnknownIntegrator};
pub use network::{Attachment, Link, SpringNetwork};
pub use state::{Acceleration, Angular, BallState, Bodies, Chunks};
pub use stepper::{Stepper, TimeStep, Unsupported};

/// The 2D types, `f64` unless a scalar is given (`d2::Gravity<f32>`).
pub mod d2 {
    /// A spin: the z component of the angular velocity.
    pub type Spin<T = f64> = crate::Angular<T, 2>;
    /// One ball as a field sees it.
    pub type BallState<T = f64> = crate::BallState<T, 2>;
    /// Many balls, struct of arrays.
    pub type Bodies<'a, T = f64> = crate::Bodies<'a, T, 2>;
    /// Uniform gravity.
    pub type Gravity<T = f64> = crate::Gravity<T, 2>;
    /// Springs from every ball to a fixed point.
    pub type AnchorSpring<T = f64> = crate::AnchorSpring<T, 2>;
    /// Any built-in field.
    pub type Field<T = f64> = crate::Field<T, 2>;
    /// Springs between balls.
    pub type SpringNetwork<T = f64> = crate::SpringNetwork<T, 2>;
    /// Scratch buffers of the coupled stepper.
    pub type Scratch<T = f64> = crate::Scratch<T, 2>;
    /// An integrator bound to a field.
    pub type Stepper<F, T = f64> = crate::Stepper<T, 2, F>;
    /// An integrator bound to a field and springs.
    pub type CoupledStepper<F, T = f64> = crate::CoupledStepper<T, 2, F>;
}

/// The 3D types, `f64` unless a scalar is given (`d3::Gravity<f32>`).
pub mod d3 {
    /// A spin: the angular velocity vector.
    pub type Spin<T = f64> = crate::Angular<T, 3>;
    /// One ball as a field sees it.
    pub type BallState<T = f64> = crate::BallState<T, 3>;
    /// Many balls, struct of arrays.
    pub type Bodies<'a, T = f64> = crate::Bodies<'a, T, 3>;
    /// Uniform gravity.
    pub type Gravity<T = f64> = crate::Gravity<T, 3>;
    /// Springs from every ball to a fixed point.
    pub type AnchorSpring<T = f64> = crate::AnchorSpring<T, 3>;
    /// Any built-in field.
    pub type Field<T = f64> = crate::Field<T, 3>;
    /// Springs between balls.
    pub type SpringNetwork<T = f64> = crate::SpringNetwork<T, 3>;
    /// Scratch buffers of the coupled stepper.
    pub type Scratch<T = f64> = crate::Scratch<T, 3>;
    /// An integrator bound to a field.
    pub type Stepper<F, T = f64> = crate::Stepper<T, 3, F>;
    /// An integrator bound to a field and springs.
    pub type CoupledStepper<F, T = f64> = crate::CoupledStepper<T, 3, F>;
}
