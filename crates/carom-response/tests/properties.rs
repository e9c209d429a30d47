//! Property tests over random masses, radii, positions, velocities, spins, restitution
//! and friction, in 2D and 3D: momentum and angular momentum are conserved to 1e-12
//! relative, kinetic energy never increases (computed from masses and radii here, not
//! from the response's own bookkeeping), Newton's law holds along the normal, and a
//! receding pair is never touched. Without friction, `central_impulse` gives `resolve`'s
//! velocities to rounding.

use crate::common;

use carom_response::{
    Angular, Body, Coefficients, Contact, Friction, Outcome, Space, central_impulse, resolve,
};
use common::{TestBall, angular};
use nalgebra::{Const, Matrix3, SVector, Vector1, Vector2, Vector3};
use proptest::prelude::*;

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn vec2(r: f64) -> impl Strategy<Value = Vector2<f64>> {
    (-r..r, -r..r).prop_map(|(x, y)| Vector2::new(x, y))
}

fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

/// Two touching balls: `b` at distance `ρ_a + ρ_b` from `a` along `direction`.
fn touching<const D: usize>(
    masses: (f64, f64),
    radii: (f64, f64),
    center: SVector<f64, D>,
    direction: SVector<f64, D>,
    velocities: (SVector<f64, D>, SVector<f64, D>),
    spins: (Angular<f64, D>, Angular<f64, D>),
) -> (TestBall<D>, TestBall<D>)
where
    Const<D>: Space<f64, D>,
{
    let n = direction.normalize();
    let mut a = TestBall::new(masses.0, radii.0, center, velocities.0);
    let mut b = TestBall::new(
        masses.1,
        radii.1,
        center + n * (radii.0 + radii.1),
        velocities.1,
    );
    a.spin = spins.0;
    b.spin = spins.1;
    (a, b)
}

/// Checks every conservation law of one ball–ball collision.
fn check_ball_pair<const D: usize>(
    a: &TestBall<D>,
    b: &TestBall<D>,
    e: f64,
    mu: f64,
) -> Result<(), TestCaseError>
where
    Const<D>: Space<f64, D>,
{
    let contact = a.contact(b);
    let r = resolve(
        &a.body(),
        &b.body(),
        &contact,
        &Coefficients::new(e, mu).unwrap(),
    );
    let (a2, b2) = (
        a.moving(r.velocity[0], r.angular_velocity[0]),
        b.moving(r.velocity[1], r.angular_velocity[1]),
    );

    let v_n = (b.velocity
        + <Const<D> as Space<f64, D>>::angular_cross(&b.spin, &contact.offset_b())
        - a.velocity
        - <Const<D> as Space<f64, D>>::angular_cross(&a.spin, &contact.offset_a()))
    .dot(&contact.normal());
    if mu == 0.0 {
        // The smooth-ball shortcut: no impulse exactly when `resolve` applies none, and
        // otherwise the same velocities to rounding.
        let central = central_impulse(
            (1.0 / a.mass, &a.velocity),
            (1.0 / b.mass, &b.velocity),
            &contact.normal(),
            e,
        );
        prop_assert_eq!(central.is_some(), r.applied(), "{:?}", r.outcome);
        if let Some([va, vb]) = central {
            let scale = a.velocity.norm() + b.velocity.norm();
            prop_assert!(
                (va - r.velocity[0]).norm() <= 1e-13 * scale,
                "{va} vs {}",
                r.velocity[0]
            );
            prop_assert!(
                (vb - r.velocity[1]).norm() <= 1e-13 * scale,
                "{vb} vs {}",
                r.velocity[1]
            );
        }
    }
    if v_n > 0.0 {
        prop_assert_eq!(r.outcome, Outcome::Receding);
        prop_assert_eq!(r.velocity, [a.velocity, b.velocity]);
        return Ok(());
    }
    prop_assert!(r.applied() || v_n == 0.0);

    // Linear momentum, relative to the momenta involved.
    let scale_p = a.momentum().norm() + b.momentum().norm() + r.impulse.norm();
    let dp = (a2.momentum() + b2.momentum()) - (a.momentum() + b.momentum());
    prop_assert!(
        dp.norm() <= 1e-12 * scale_p,
        "momentum drift {} of {}",
        dp.norm(),
        scale_p
    );

    // Angular momentum about a fixed point away from the contact (the origin).
    let o = SVector::<f64, D>::zeros();
    let l_before = a.angular_momentum_about(&o) + b.angular_momentum_about(&o);
    let l_after = a2.angular_momentum_about(&o) + b2.angular_momentum_about(&o);
    let scale_l = [a, b, &a2, &b2]
        .iter()
        .map(|x| {
            x.center.norm() * x.momentum().norm()
                + x.inertia() * angular::<D>(&x.spin).iter().map(|w| w.abs()).sum::<f64>()
        })
        .sum::<f64>();
    for (x, y) in angular::<D>(&l_before).iter().zip(angular::<D>(&l_after)) {
        prop_assert!(
            (x - y).abs() <= 1e-12 * scale_l,
            "angular momentum {x} -> {y} (scale {scale_l})"
        );
    }

    // Energy never increases; the report agrees with the independent computation.
    let (ke, ke2) = (
        a.kinetic_energy() + b.kinetic_energy(),
        a2.kinetic_energy() + b2.kinetic_energy(),
    );
    prop_assert!(ke2 <= ke * (1.0 + 1e-12), "energy {ke} -> {ke2}");
    prop_assert!(r.kinetic_energy_change <= 1e-12 * ke);
    prop_assert!((r.kinetic_energy_change - (ke2 - ke)).abs() <= 1e-11 * ke);
    prop_assert!((r.contact_energy_change - r.kinetic_energy_change).abs() <= 1e-11 * ke);

    // Newton's law along the normal (balls: friction does not change normal velocities).
    let v_n_after = (b2.velocity
        + <Const<D> as Space<f64, D>>::angular_cross(&b2.spin, &contact.offset_b())
        - a2.velocity
        - <Const<D> as Space<f64, D>>::angular_cross(&a2.spin, &contact.offset_a()))
    .dot(&contact.normal());
    let speed_scale = [a, b, &a2, &b2]
        .iter()
        .map(|x| {
            x.velocity.norm()
                + x.radius * angular::<D>(&x.spin).iter().map(|w| w.abs()).sum::<f64>()
        })
        .sum::<f64>();
    prop_assert!(
        (v_n_after + e * v_n).abs() <= 1e-12 * speed_scale,
        "v_n {v_n} -> {v_n_after}, e = {e}"
    );
    Ok(())
}

proptest! {
    #[test]
    fn ball_pairs_in_2d_conserve_momenta_and_never_gain_energy(
        ma in log_uniform(1e-3, 1e3), mb in log_uniform(1e-3, 1e3),
        ra in 0.01..1.0f64, rb in 0.01..1.0f64,
        center in vec2(1e3), direction in vec2(1.0).prop_filter("non-zero", |d| d.norm() > 1e-3),
        va in vec2(10.0), vb in vec2(10.0), wa in -50.0..50.0f64, wb in -50.0..50.0f64,
        e in 0.0..=1.0f64, mu in prop_oneof![Just(0.0), 0.0..2.0f64],
    ) {
        let (a, b) = touching::<2>((ma, mb), (ra, rb), center, direction, (va, vb), (Vector1::new(wa), Vector1::new(wb)));
        check_ball_pair(&a, &b, e, mu)?;
    }

    #[test]
    fn ball_pairs_in_3d_conserve_momenta_and_never_gain_energy(
        ma in log_uniform(1e-3, 1e3), mb in log_uniform(1e-3, 1e3),
        ra in 0.01..1.0f64, rb in 0.01..1.0f64,
        center in vec3(1e3), direction in vec3(1.0).prop_filter("non-zero", |d| d.norm() > 1e-3),
        va in vec3(10.0), vb in vec3(10.0), wa in vec3(50.0), wb in vec3(50.0),
        e in 0.0..=1.0f64, mu in prop_oneof![Just(0.0), 0.0..2.0f64],
    ) {
        let (a, b) = touching::<3>((ma, mb), (ra, rb), center, direction, (va, vb), (wa, wb));
        check_ball_pair(&a, &b, e, mu)?;
    }

    /// General rigid bodies (clusters): random symmetric positive definite inertia,
    /// contact point anywhere, normal in any direction. Here `K` couples normal and
    /// tangential directions and friction is the approximate model of the docs; energy
    /// and momenta must still hold.
    #[test]
    fn rigid_bodies_in_3d_conserve_momenta_and_never_gain_energy(
        ma in log_uniform(1e-2, 1e2), mb in log_uniform(1e-2, 1e2),
        ia in prop::array::uniform9(-1.0..1.0f64), ib in prop::array::uniform9(-1.0..1.0f64),
        x in vec3(10.0), ra in vec3(1.0), rb in vec3(1.0),
        normal in vec3(1.0).prop_filter("non-zero", |d| d.norm() > 1e-3),
        va in vec3(10.0), vb in vec3(10.0), wa in vec3(10.0), wb in vec3(10.0),
        e in 0.0..=1.0f64, mu in prop_oneof![Just(0.0), 0.0..3.0f64],
    ) {
        // I = A Aᵀ + 0.05 𝟙 (symmetric positive definite).
        let spd = |m: [f64; 9], mass: f64| {
            let a = Matrix3::from_row_slice(&m);
            (a * a.transpose() + Matrix3::identity() * 0.05) * mass
        };
        let (inertia_a, inertia_b) = (spd(ia, ma), spd(ib, mb));
        let a = Body::dynamic(ma, inertia_a, va, wa).unwrap();
        let b = Body::dynamic(mb, inertia_b, vb, wb).unwrap();
        let contact = Contact::new(normal, ra, rb).unwrap();
        let r = resolve(&a, &b, &contact, &Coefficients::new(e, mu).unwrap());
        let (ca, cb) = (x - ra, x - rb);
        let ke = |m: f64, i: &Matrix3<f64>, v: &Vector3<f64>, w: &Vector3<f64>| 0.5 * m * v.norm_squared() + 0.5 * w.dot(&(i * w));
        let before = ke(ma, &inertia_a, &va, &wa) + ke(mb, &inertia_b, &vb, &wb);
        let after = ke(ma, &inertia_a, &r.velocity[0], &r.angular_velocity[0]) + ke(mb, &inertia_b, &r.velocity[1], &r.angular_velocity[1]);
        prop_assert!(after <= before * (1.0 + 1e-12), "energy {before} -> {after}");
        prop_assert!(r.contact_energy_change <= 1e-12 * before);
        prop_assert!((r.kinetic_energy_change - (after - before)).abs() <= 1e-11 * before);
        let p = |v0: &Vector3<f64>, v1: &Vector3<f64>| v0 * ma + v1 * mb;
        let scale_p = (va * ma).norm() + (vb * mb).norm() + r.impulse.norm();
        prop_assert!((p(&r.velocity[0], &r.velocity[1]) - p(&va, &vb)).norm() <= 1e-12 * scale_p);
        let l = |v0: &Vector3<f64>, v1: &Vector3<f64>, w0: &Vector3<f64>, w1: &Vector3<f64>| {
            ca.cross(&(v0 * ma)) + inertia_a * w0 + cb.cross(&(v1 * mb)) + inertia_b * w1
        };
        let scale_l = ca.norm() * scale_p + cb.norm() * scale_p + (inertia_a * wa).norm() + (inertia_b * wb).norm()
            + (inertia_a * r.angular_velocity[0]).norm() + (inertia_b * r.angular_velocity[1]).norm();
        let dl = l(&r.velocity[0], &r.velocity[1], &r.angular_velocity[0], &r.angular_velocity[1]) - l(&va, &vb, &wa, &wb);
        prop_assert!(dl.norm() <= 1e-12 * scale_l, "angular momentum drift {} of {}", dl.norm(), scale_l);
        let n = contact.normal();
        let rel = |v0: &Vector3<f64>, v1: &Vector3<f64>, w0: &Vector3<f64>, w1: &Vector3<f64>| {
            v1 + w1.cross(&rb) - v0 - w0.cross(&ra)
        };
        let after = rel(&r.velocity[0], &r.velocity[1], &r.angular_velocity[0], &r.angular_velocity[1]);
        let speed = va.norm() + vb.norm() + (wa.norm() + wb.norm()) * 2.0 + r.velocity.iter().map(Vector3::norm).sum::<f64>()
            + r.angular_velocity.iter().map(|w| w.norm() * 2.0).sum::<f64>();
        if mu == 0.0 && r.applied() {
            prop_assert!((after.dot(&n) + e * r.normal_velocity).abs() <= 1e-12 * speed);
        }
        // Sticking: the tangential solve (two conjugate-gradient steps for an anisotropic
        // K_tt) leaves no tangential slip.
        if r.outcome == Outcome::Applied(Friction::Sticking) {
            let slip = after - n * n.dot(&after);
            prop_assert!(slip.norm() <= 1e-11 * speed, "slip {} after sticking", slip.norm());
        }
    }

    /// A ball hit by a moving, spinning paddle: the paddle does work, but in the contact
    /// frame the collision only dissipates, and the ball's normal velocity relative to
    /// the paddle point obeys Newton's law.
    #[test]
    fn paddle_hits_dissipate_in_the_contact_frame(
        m in log_uniform(1e-3, 1e1), radius in 0.01..0.1f64,
        u in vec3(20.0), spin in vec3(20.0), v in vec3(20.0), w in vec3(100.0),
        normal in vec3(1.0).prop_filter("non-zero", |d| d.norm() > 1e-3), offset in vec3(0.5),
        e in 0.0..=1.0f64, mu in 0.0..1.0f64,
    ) {
        let paddle = Body::kinematic(u, spin).unwrap();
        let ball = Body::ball(m, radius, v, w).unwrap();
        let n = normal.normalize();
        let contact = Contact::new(n, offset, -n * radius).unwrap();
        let r = resolve(&paddle, &ball, &contact, &Coefficients::new(e, mu).unwrap());
        prop_assert_eq!(r.velocity[0], u);
        let scale = 0.5 * m * (v.norm() + u.norm() + (spin.norm() + w.norm()) * 0.6).powi(2);
        prop_assert!(r.contact_energy_change <= 1e-12 * scale);
        if r.applied() {
            let point = |b: &Body<f64, 3>, off: &Vector3<f64>| b.point_velocity(off);
            let after = point(&r.body_b(&ball), &contact.offset_b()) - point(&paddle, &contact.offset_a());
            prop_assert!((after.dot(&n) + e * r.normal_velocity).abs() <= 1e-12 * scale.sqrt() / m.sqrt() * 4.0);
        }
    }
}
