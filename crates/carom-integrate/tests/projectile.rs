//! Projectile motion under constant gravity: every scheme's error against the closed
//! form, derived and measured.
//!
//! With `vₙ = v₀ + n h g` (exact for every scheme, since `g` is constant):
//!
//! * explicit Euler sums the old velocities, `xₙ = x₀ + h Σ_{j<n} v_j
//!   = x₀ + v₀ t + g h² n(n−1)/2 = x(t) − g h t / 2`;
//! * semi-implicit Euler sums the new ones, `xₙ = x₀ + v₀ t + g h² n(n+1)/2
//!   = x(t) + g h t / 2`;
//! * Verlet and RK4 integrate a quadratic exactly, and the exact integrator is the
//!   closed form: error zero.
//!
//! With gravity pointing down, `g = (0, −|g|)`, explicit Euler's ball is *higher* than
//! the true one by `|g| h t / 2` and semi-implicit Euler's *lower* by as much (the issue's
//! "+g h t/2 (explicit) and −g h t/2 (semi-implicit)", with `g` the magnitude and the
//! error in height). The errors are polynomial, so the comparison is to rounding: the
//! tolerance is a bound on the rounding of `n` additions, and each test also checks that
//! the predicted error is far above that bound.

use crate::common;

use carom_integrate::{Gravity, Integrator, Real, Space, Stepper, Vector, exact};
use common::{OneBall, wide};
use nalgebra::{Const, Vector2, Vector3};

/// Runs `steps` steps of `h` and returns `(computed − closed form, rounding bound)` for
/// the position, in `f64`.
fn position_error<T: Real, const D: usize>(
    integrator: Integrator,
    x0: Vector<T, D>,
    v0: Vector<T, D>,
    g: Vector<T, D>,
    h: T,
    steps: usize,
) -> (Vector<f64, D>, f64)
where
    Const<D>: Space<T, D>,
{
    let stepper = Stepper::new(integrator, Gravity::new(g).unwrap()).unwrap();
    let mut ball = OneBall::new(x0, v0);
    ball.run(&stepper, h, steps, |_, _| {});
    // The closed form in f64 from the same (rounded) inputs.
    let t = h.to_f64() * steps as f64;
    let truth = exact::ballistic(&wide(&x0), &wide(&v0), &wide(&g), t).position;
    let scale = wide(&x0).amax() + wide(&v0).amax() * t + wide(&g).amax() * t * t;
    let rounding = 4.0 * steps as f64 * T::EPSILON.to_f64() * scale;
    (wide(&ball.x) - truth, rounding)
}

fn check<T: Real, const D: usize>(
    x0: Vector<T, D>,
    v0: Vector<T, D>,
    g: Vector<T, D>,
    h: T,
    steps: usize,
) where
    Const<D>: Space<T, D>,
{
    let t = h.to_f64() * steps as f64;
    let half_ght = wide(&g) * (h.to_f64() * t / 2.0);
    for (integrator, predicted) in [
        (Integrator::ExplicitEuler, -half_ght),
        (Integrator::SemiImplicitEuler, half_ght),
        (Integrator::VelocityVerlet, Vector::zeros()),
        (Integrator::Rk4, Vector::zeros()),
        (Integrator::Exact, Vector::zeros()),
    ] {
        let (error, rounding) = position_error(integrator, x0, v0, g, h, steps);
        assert!(
            (error - predicted).amax() <= rounding,
            "{integrator}: error {error:?}, predicted {predicted:?}, rounding bound {rounding:e}"
        );
        assert!(
            half_ght.amax() > 100.0 * rounding,
            "the prediction must stand out of rounding"
        );
    }
}

#[test]
fn explicit_euler_is_high_by_g_h_t_over_2_and_semi_implicit_low_by_as_much_in_2d() {
    let g = Vector2::new(0.0, -9.81);
    check::<f64, 2>(
        Vector2::new(0.0, 1.0),
        Vector2::new(3.0, 4.0),
        g,
        1.0 / 240.0,
        480,
    );
    check::<f64, 2>(Vector2::new(0.0, 1.0), Vector2::new(3.0, 4.0), g, 0.05, 40);
    // Far from the origin and fast.
    check::<f64, 2>(
        Vector2::new(1e6, -1e6),
        Vector2::new(1e3, 2e3),
        g,
        1e-3,
        1_000,
    );
    check::<f32, 2>(
        Vector2::new(0.0, 1.0),
        Vector2::new(3.0, 4.0),
        Vector2::new(0.0, -9.81),
        0.05,
        40,
    );
}

#[test]
fn the_same_errors_hold_per_component_in_3d() {
    let g = Vector3::new(0.5, -0.25, -9.81);
    check::<f64, 3>(
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::new(-2.0, 1.0, 5.0),
        g,
        1.0 / 120.0,
        360,
    );
    check::<f32, 3>(
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::new(-2.0, 1.0, 5.0),
        Vector3::new(0.5, -0.25, -9.81),
        1.0 / 64.0,
        64,
    );
}

#[test]
fn the_sign_matches_the_issue_in_height() {
    // The statement of the issue, literally: with |g| = 9.81 downwards, after t = 1 s at
    // h = 0.01 explicit Euler is 9.81 · 0.01 · 1 / 2 = 0.04905 m too high, semi-implicit
    // Euler as much too low.
    let g = Vector2::new(0.0, -9.81);
    let (explicit, _) = position_error(
        Integrator::ExplicitEuler,
        Vector2::zeros(),
        Vector2::new(1.0, 5.0),
        g,
        0.01,
        100,
    );
    let (semi, _) = position_error(
        Integrator::SemiImplicitEuler,
        Vector2::zeros(),
        Vector2::new(1.0, 5.0),
        g,
        0.01,
        100,
    );
    assert!((explicit.y - 0.04905).abs() < 1e-12, "{}", explicit.y);
    assert!((semi.y + 0.04905).abs() < 1e-12, "{}", semi.y);
    assert!(explicit.x.abs() < 1e-13 && semi.x.abs() < 1e-13);
}
