//! Coulomb friction against closed forms: a sliding ball hitting the floor sticks (rolls
//! off) or slides, gains spin of the right sign, and spin turns into velocity (ping pong).
//!
//! The independent oracle: friction and the normal force both act at the contact point,
//! so a ball's angular momentum about the contact point, `I ω + m (c − x) × v`, is the
//! same before and after a collision with a static floor. With the rolling condition
//! `v_x + ω r = 0` this gives `v_x' = v_x / (1 + I/(m r²))`: `2/3 v_x` for a disk and
//! `5/7 v_x` for a solid sphere.

use crate::common;

use carom_response::{Body, Coefficients, Contact, Friction, Outcome, resolve};
use common::{TestBall, angular, assert_close};
use nalgebra::{Vector1, Vector2, Vector3};

const MASS: f64 = 0.0027;
const RADIUS: f64 = 0.02;

fn floor_2d() -> Contact<f64, 2> {
    Contact::ball_surface(RADIUS, &Vector2::new(0.0, -1.0), &Vector2::zeros()).unwrap()
}

fn bounce_2d(v: Vector2<f64>, spin: f64, e: f64, mu: f64) -> carom_response::Response<f64, 2> {
    let ball = Body::ball(MASS, RADIUS, v, Vector1::new(spin)).unwrap();
    resolve(
        &ball,
        &Body::fixed(),
        &floor_2d(),
        &Coefficients::new(e, mu).unwrap(),
    )
}

/// The ball's angular momentum about the contact point below it (2D: z component).
fn angular_momentum_about_contact(v: Vector2<f64>, spin: f64) -> f64 {
    // (c − x) = (0, r): (0, r) × m v = −m r v_x.
    0.5 * MASS * RADIUS * RADIUS * spin - MASS * RADIUS * v.x
}

#[test]
fn a_sliding_disk_with_enough_friction_rolls_off_at_two_thirds_its_speed() {
    let (vx, vy, e) = (3.0, -2.0, 0.8);
    let r = bounce_2d(Vector2::new(vx, vy), 0.0, e, 1.0);
    assert_eq!(r.outcome, Outcome::Applied(Friction::Sticking));
    assert!((r.velocity[0].x - 2.0 / 3.0 * vx).abs() < 1e-14);
    assert!((r.velocity[0].y - e * -vy).abs() < 1e-14);
    // Rolling to the right is a clockwise (negative) spin: v_x + ω r = 0.
    let spin = r.angular_velocity[0].x;
    assert!(spin < 0.0);
    assert!((r.velocity[0].x + spin * RADIUS).abs() < 1e-13);
    let l = angular_momentum_about_contact(r.velocity[0], spin);
    assert!((l - angular_momentum_about_contact(Vector2::new(vx, vy), 0.0)).abs() < 1e-18);
}

#[test]
fn a_sliding_disk_with_little_friction_slides_with_the_impulse_capped_at_mu_jn() {
    let (vx, vy, e, mu) = (3.0, -2.0, 0.8, 0.1);
    let r = bounce_2d(Vector2::new(vx, vy), 0.0, e, mu);
    assert_eq!(r.outcome, Outcome::Applied(Friction::Sliding));
    let j_n = MASS * (1.0 + e) * -vy;
    assert!((r.normal_impulse - j_n).abs() < 1e-17);
    assert!((r.tangential_impulse.norm() - mu * j_n).abs() < 1e-17);
    // The floor pushes the ball back (−x) and spins it clockwise.
    assert!((r.velocity[0].x - (vx - mu * (1.0 + e) * -vy)).abs() < 1e-14);
    let spin = r.angular_velocity[0].x;
    assert!((spin - -2.0 * mu * (1.0 + e) * -vy / RADIUS).abs() < 1e-12);
    // Still sliding: the contact point moves forward after the bounce.
    assert!(r.velocity[0].x + spin * RADIUS > 0.0);
    let l = angular_momentum_about_contact(r.velocity[0], spin);
    assert!((l - angular_momentum_about_contact(Vector2::new(vx, vy), 0.0)).abs() < 1e-18);
}

#[test]
fn the_sticking_sliding_transition_is_at_mu_star_and_continuous() {
    // Disk: sticking needs |F*| = m |v_x| / 3 ≤ μ m (1 + e) |v_y|.
    let (vx, vy, e) = (3.0, -2.0, 0.5);
    let mu_star = vx / (3.0 * (1.0 + e) * -vy);
    let above = bounce_2d(Vector2::new(vx, vy), 0.0, e, mu_star * (1.0 + 1e-9));
    let below = bounce_2d(Vector2::new(vx, vy), 0.0, e, mu_star * (1.0 - 1e-9));
    assert_eq!(above.outcome, Outcome::Applied(Friction::Sticking));
    assert_eq!(below.outcome, Outcome::Applied(Friction::Sliding));
    assert_close(
        above.velocity[0].as_slice(),
        below.velocity[0].as_slice(),
        1e-8,
        "v",
    );
    assert!((above.angular_velocity[0].x - below.angular_velocity[0].x).abs() < 1e-6);
}

#[test]
fn a_sliding_sphere_rolls_off_at_five_sevenths_in_3d_whatever_the_direction() {
    let v = Vector3::new(2.0, -1.5, -4.0);
    let ball = Body::ball(MASS, RADIUS, v, Vector3::zeros()).unwrap();
    let floor = Contact::ball_surface(RADIUS, &-Vector3::z(), &Vector3::zeros()).unwrap();
    let r = resolve(
        &ball,
        &Body::fixed(),
        &floor,
        &Coefficients::new(0.9, 2.0).unwrap(),
    );
    assert_eq!(r.outcome, Outcome::Applied(Friction::Sticking));
    let expected = Vector3::new(v.x * 5.0 / 7.0, v.y * 5.0 / 7.0, 0.9 * 4.0);
    assert_close(r.velocity[0].as_slice(), expected.as_slice(), 1e-14, "v");
    // Rolling: the contact point (offset −r ẑ) does not move tangentially.
    let w = r.angular_velocity[0];
    let contact_velocity = r.velocity[0] + w.cross(&(-Vector3::z() * RADIUS));
    assert!(contact_velocity.x.abs() < 1e-13 && contact_velocity.y.abs() < 1e-13);
    // The spin axis is horizontal and perpendicular to the motion: ω ∥ ẑ × v.
    assert!(w.z.abs() < 1e-12);
    assert!(w.dot(&Vector3::new(v.x, v.y, 0.0)).abs() < 1e-10);
}

#[test]
fn topspin_turns_into_forward_speed_on_the_bounce() {
    // A ping-pong ball dropping straight down with topspin for a rightward flight
    // (clockwise, negative): its bottom slides backward, so the table pushes it forward.
    let r = bounce_2d(Vector2::new(0.0, -3.0), -200.0, 0.9, 0.3);
    assert!(r.velocity[0].x > 0.0);
    assert!(r.angular_velocity[0].x > -200.0); // spin reduced in magnitude
    // Backspin kicks it backward.
    let r = bounce_2d(Vector2::new(0.0, -3.0), 200.0, 0.9, 0.3);
    assert!(r.velocity[0].x < 0.0);
}

#[test]
fn friction_between_spinning_balls_opposes_their_slip_and_keeps_momenta() {
    let mut a = TestBall::<3>::new(1.0, 0.5, Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0));
    let mut b = TestBall::<3>::new(
        2.0,
        0.25,
        Vector3::new(0.75, 0.0, 0.0),
        Vector3::new(-1.0, 0.0, 0.0),
    );
    a.spin = Vector3::new(0.0, 0.0, 10.0); // its contact point (+x side) moves +y
    b.spin = Vector3::new(0.0, 3.0, 0.0); // its contact point (−x side) moves +z
    let contact = a.contact(&b);
    let slip_before = {
        let va = a.velocity + a.spin.cross(&contact.offset_a());
        let vb = b.velocity + b.spin.cross(&contact.offset_b());
        vb - va
    };
    for mu in [0.05, 5.0] {
        let r = resolve(
            &a.body(),
            &b.body(),
            &contact,
            &Coefficients::new(0.7, mu).unwrap(),
        );
        // The friction impulse on b opposes b's slip relative to a (balls: exactly).
        let t = r.tangential_impulse;
        let slip_t = slip_before - contact.normal() * contact.normal().dot(&slip_before);
        assert!((t.normalize() + slip_t.normalize()).norm() < 1e-12);
        let (a2, b2) = (
            a.moving(r.velocity[0], r.angular_velocity[0]),
            b.moving(r.velocity[1], r.angular_velocity[1]),
        );
        let x = a.center + contact.offset_a();
        assert_close(
            (a2.momentum() + b2.momentum()).as_slice(),
            (a.momentum() + b.momentum()).as_slice(),
            1e-14,
            "p",
        );
        assert_close(
            &angular::<3>(&(a2.angular_momentum_about(&x) + b2.angular_momentum_about(&x))),
            &angular::<3>(&(a.angular_momentum_about(&x) + b.angular_momentum_about(&x))),
            1e-14,
            "L",
        );
        assert!(
            a2.kinetic_energy() + b2.kinetic_energy() < a.kinetic_energy() + b.kinetic_energy()
        );
        if mu > 1.0 {
            assert_eq!(r.outcome, Outcome::Applied(Friction::Sticking));
            let va = a2.velocity + a2.spin.cross(&contact.offset_a());
            let vb = b2.velocity + b2.spin.cross(&contact.offset_b());
            let slip = vb - va;
            let n = contact.normal();
            assert!((slip - n * n.dot(&slip)).norm() < 1e-13);
        } else {
            assert_eq!(r.outcome, Outcome::Applied(Friction::Sliding));
        }
    }
}
