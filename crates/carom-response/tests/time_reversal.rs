//! Time reversal: with `e = 1` and no friction, colliding, reversing every velocity,
//! colliding again and reversing again gives back the original motion.
//!
//! Mathematically exact: the reversed pair approaches with the same normal velocity and
//! receives the same impulse. In floating point the second impulse is computed from the
//! rounded velocities after the first, so the round trip is exact only to rounding: the
//! tests allow 16 ulps of the largest speed involved, componentwise, and show bit
//! identity where every intermediate is a dyadic rational (equal masses, head on).
//! With `e < 1` or friction there is no reversal: the reversed pair loses energy again.

use crate::common;

use carom_response::{Angular, Body, Coefficients, Contact, Response, Space, resolve};
use common::angular;
use nalgebra::{Const, Matrix3, SVector, Vector1, Vector2, Vector3};
use proptest::prelude::*;

/// The linear and angular velocity of each body of a pair.
type Motions<const D: usize> = [(SVector<f64, D>, Angular<f64, D>); 2];

/// The allowed round-trip error in units of `ε ×` the speed scale.
const ULPS: f64 = 16.0;

fn reversed<const D: usize>(body: &Body<f64, D>, r: &Response<f64, D>, which: usize) -> Body<f64, D>
where
    Const<D>: Space<f64, D>,
{
    body.with_velocities(-r.velocity[which], -r.angular_velocity[which])
}

/// Forward, reverse, forward, reverse: returns the final velocities of both bodies and
/// the speed scale of the round trip (the largest linear speed, or angular speed times
/// `lever`, before, between and after: rounding errors are relative to it).
fn round_trip<const D: usize>(
    a: &Body<f64, D>,
    b: &Body<f64, D>,
    contact: &Contact<f64, D>,
    coefficients: &Coefficients<f64>,
) -> (Motions<D>, f64)
where
    Const<D>: Space<f64, D>,
{
    let forward = resolve(a, b, contact, coefficients);
    let (a1, b1) = (reversed(a, &forward, 0), reversed(b, &forward, 1));
    let back = resolve(&a1, &b1, contact, coefficients);
    assert!(back.applied(), "the reversed pair must approach again");
    let levers = [contact.offset_a().norm(), contact.offset_b().norm()];
    let mut scale = 0.0f64;
    for response_velocities in [
        [
            (a.velocity(), a.angular_velocity()),
            (b.velocity(), b.angular_velocity()),
        ],
        [
            (forward.velocity[0], forward.angular_velocity[0]),
            (forward.velocity[1], forward.angular_velocity[1]),
        ],
    ] {
        for ((v, w), lever) in response_velocities.iter().zip(levers) {
            scale = scale.max(v.amax());
            for x in angular::<D>(w) {
                scale = scale.max(x.abs() * lever);
            }
        }
    }
    (
        [
            (-back.velocity[0], -back.angular_velocity[0]),
            (-back.velocity[1], -back.angular_velocity[1]),
        ],
        scale,
    )
}

/// The largest deviation from the original velocities (angular ones times `levers`).
fn max_error<const D: usize>(
    bodies: [&Body<f64, D>; 2],
    levers: [f64; 2],
    result: &Motions<D>,
) -> f64
where
    Const<D>: Space<f64, D>,
{
    let mut error = 0.0f64;
    for ((body, (v, w)), lever) in bodies.iter().zip(result).zip(levers) {
        error = error.max((v - body.velocity()).amax());
        for (x, y) in angular::<D>(w)
            .iter()
            .zip(angular::<D>(&body.angular_velocity()))
        {
            error = error.max((x - y).abs() * lever);
        }
    }
    error
}

#[test]
fn equal_masses_head_on_reverse_bit_for_bit() {
    let a = Body::<f64, 2>::ball(1.0, 0.5, Vector2::new(1.5, 0.25), Vector1::zeros()).unwrap();
    let b = Body::<f64, 2>::ball(1.0, 0.5, Vector2::new(-0.75, 2.0), Vector1::zeros()).unwrap();
    let contact = Contact::new(
        Vector2::x(),
        Vector2::new(0.5, 0.0),
        Vector2::new(-0.5, 0.0),
    )
    .unwrap();
    let (result, _) = round_trip(&a, &b, &contact, &Coefficients::elastic());
    assert_eq!(result[0].0, a.velocity());
    assert_eq!(result[1].0, b.velocity());
}

#[test]
fn inelastic_and_frictional_collisions_do_not_reverse() {
    let a = Body::<f64, 2>::ball(1.0, 0.5, Vector2::new(1.0, 1.0), Vector1::zeros()).unwrap();
    let b = Body::<f64, 2>::ball(2.0, 0.5, Vector2::new(-1.0, 0.0), Vector1::zeros()).unwrap();
    let contact = Contact::new(
        Vector2::x(),
        Vector2::new(0.5, 0.0),
        Vector2::new(-0.5, 0.0),
    )
    .unwrap();
    for coefficients in [
        Coefficients::frictionless(0.9).unwrap(),
        Coefficients::new(1.0, 0.5).unwrap(),
    ] {
        let (result, _) = round_trip(&a, &b, &contact, &coefficients);
        let error = max_error([&a, &b], [0.5, 0.5], &result);
        assert!(
            error > 1e-3,
            "a dissipative collision reversed (error {error})"
        );
    }
}

proptest! {
    #[test]
    fn elastic_ball_collisions_reverse_to_rounding(
        ma in 0.01..100.0f64, mb in 0.01..100.0f64, ra in 0.01..1.0f64, rb in 0.01..1.0f64,
        n in prop::array::uniform3(-1.0..1.0f64).prop_filter("non-zero", |d| d.iter().map(|x| x * x).sum::<f64>() > 1e-4),
        va in prop::array::uniform3(-10.0..10.0f64), vb in prop::array::uniform3(-10.0..10.0f64),
        wa in prop::array::uniform3(-10.0..10.0f64), wb in prop::array::uniform3(-10.0..10.0f64),
    ) {
        let n = Vector3::from(n).normalize();
        let (va, vb) = (Vector3::from(va), Vector3::from(vb));
        let v_n = (vb - va).dot(&n);
        // Reversing every velocity turns a receding pair into an approaching one; keep
        // the approach clear of rounding.
        prop_assume!(v_n.abs() > 1e-6 * (va.norm() + vb.norm()));
        let sign = if v_n > 0.0 { -1.0 } else { 1.0 };
        let a = Body::ball(ma, ra, va * sign, Vector3::from(wa) * sign).unwrap();
        let b = Body::ball(mb, rb, vb * sign, Vector3::from(wb) * sign).unwrap();
        let contact = Contact::new(n, n * ra, -n * rb).unwrap();
        let (result, scale) = round_trip(&a, &b, &contact, &Coefficients::elastic());
        let error = max_error([&a, &b], [ra, rb], &result);
        prop_assert!(error <= ULPS * f64::EPSILON * scale, "error {error} at scale {scale}");
    }

    /// Rigid bodies with coupled normal and tangential directions reverse too.
    #[test]
    fn elastic_rigid_body_collisions_reverse_to_rounding(
        masses in (0.1..10.0f64, 0.1..10.0f64),
        ia in prop::array::uniform9(-1.0..1.0f64),
        ra in prop::array::uniform2(-1.0..1.0f64), rb in prop::array::uniform2(-1.0..1.0f64),
        va in prop::array::uniform2(-10.0..10.0f64), vb in prop::array::uniform2(-10.0..10.0f64),
        w in (-10.0..10.0f64, -10.0..10.0f64), angle in 0.0..6.3f64,
    ) {
        let n = Vector2::new(angle.cos(), angle.sin());
        let inertia = {
            let m = Matrix3::from_row_slice(&ia);
            (m * m.transpose()).trace() + 0.05
        };
        let contact = Contact::new(n, Vector2::from(ra), Vector2::from(rb)).unwrap();
        let bodies = |sign: f64| {
            (
                Body::dynamic(masses.0, inertia, Vector2::from(va) * sign, Vector1::new(w.0 * sign)).unwrap(),
                Body::dynamic(masses.1, inertia * 2.0, Vector2::from(vb) * sign, Vector1::new(w.1 * sign)).unwrap(),
            )
        };
        // Reversing every velocity turns a receding pair into an approaching one.
        let (a, b) = bodies(1.0);
        let v_n = carom_response::normal_velocity(&a, &b, &contact);
        let (a, b) = if v_n > 0.0 { bodies(-1.0) } else { (a, b) };
        prop_assume!(v_n.abs() > 1e-6 * 40.0);
        let (result, scale) = round_trip(&a, &b, &contact, &Coefficients::elastic());
        let error = max_error([&a, &b], [contact.offset_a().norm(), contact.offset_b().norm()], &result);
        prop_assert!(error <= ULPS * f64::EPSILON * scale, "error {error} at scale {scale}");
    }
}
