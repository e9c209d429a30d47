//! Stick collisions: fused clusters against hand computations and conservation laws,
//! cluster–wall impulses at the contact point.

use crate::common;

use carom_response::{Body, Coefficients, Contact, Outcome, RigidCluster, resolve};
use common::{TestBall, assert_close};
use nalgebra::{Matrix3, Rotation2, Rotation3, Vector1, Vector2, Vector3};
use proptest::prelude::*;

#[test]
fn two_disks_fuse_as_computed_by_hand() {
    // A: 1 kg, r 0.5, at the origin moving (2, 0). B: 3 kg, r 0.5, at (0.6, 0.8), at rest.
    let a = RigidCluster::ball(
        1.0,
        0.5,
        Vector2::zeros(),
        Vector2::new(2.0, 0.0),
        Vector1::zeros(),
    )
    .unwrap();
    let b = RigidCluster::ball(
        3.0,
        0.5,
        Vector2::new(0.6, 0.8),
        Vector2::zeros(),
        Vector1::zeros(),
    )
    .unwrap();
    let f = a.fuse(&b).unwrap();
    // By hand: M = 4, c = (3/4)(0.6, 0.8) = (0.45, 0.6), v = (2, 0)/4 = (0.5, 0).
    assert_eq!(f.cluster.mass(), 4.0);
    assert_close(f.cluster.center().as_slice(), &[0.45, 0.6], 1e-15, "c");
    assert_close(f.cluster.velocity().as_slice(), &[0.5, 0.0], 1e-15, "v");
    // d_A = (−0.45, −0.6), d_B = (0.15, 0.2).
    // I = ½·1·0.25 + ½·3·0.25 + 1·0.5625 + 3·0.0625 = 1.25 (point masses alone: 0.75).
    assert!((f.cluster.world_inertia() - 1.25).abs() < 1e-15);
    // L = 1·(d_A × (1.5, 0)) + 3·(d_B × (−0.5, 0)) = 0.9 + 0.3 = 1.2; ω = 1.2/1.25 = 0.96.
    assert!((f.cluster.angular_momentum().x - 1.2).abs() < 1e-15);
    assert!((f.cluster.angular_velocity().x - 0.96).abs() < 1e-15);
    // KE: 2 before; ½·4·0.25 + ½·1.25·0.96² = 1.076 after.
    assert!((f.kinetic_energy_change - (1.076 - 2.0)).abs() < 1e-15);
    assert!((f.cluster.kinetic_energy() - 1.076).abs() < 1e-15);
    // Member maps: the old centres sit at d_A and d_B in the new body frame.
    assert_close(
        f.members_a.apply(&Vector2::zeros()).as_slice(),
        &[-0.45, -0.6],
        1e-15,
        "A",
    );
    assert_close(
        f.members_b.apply(&Vector2::zeros()).as_slice(),
        &[0.15, 0.2],
        1e-15,
        "B",
    );
}

#[test]
fn two_spinning_spheres_fuse_keeping_both_momenta() {
    let mut a = TestBall::<3>::new(
        2.0,
        0.3,
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::new(1.0, -1.0, 0.5),
    );
    let mut b = TestBall::<3>::new(
        0.5,
        0.2,
        Vector3::new(1.3, 2.4, 3.0),
        Vector3::new(-2.0, 0.0, 1.0),
    );
    a.spin = Vector3::new(3.0, 0.0, -1.0);
    b.spin = Vector3::new(0.0, 5.0, 2.0);
    let cluster = |t: &TestBall<3>| {
        RigidCluster::ball(t.mass, t.radius, t.center, t.velocity, t.spin).unwrap()
    };
    let f = cluster(&a).fuse(&cluster(&b)).unwrap();
    // Inertia by hand: each sphere 2/5 m r² 𝟙 plus m (|d|² 𝟙 − d dᵀ) about the new centre.
    let c = (a.center * a.mass + b.center * b.mass) / (a.mass + b.mass);
    let steiner =
        |m: f64, d: Vector3<f64>| (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m;
    let expected = Matrix3::identity() * (0.4 * 2.0 * 0.09 + 0.4 * 0.5 * 0.04)
        + steiner(a.mass, a.center - c)
        + steiner(b.mass, b.center - c);
    assert_close(
        f.cluster.world_inertia().as_slice(),
        expected.as_slice(),
        1e-15,
        "I",
    );
    let o = Vector3::new(-5.0, 7.0, 1.0);
    let l_before = a.angular_momentum_about(&o) + b.angular_momentum_about(&o);
    assert_close(
        f.cluster.angular_momentum_about(&o).as_slice(),
        l_before.as_slice(),
        1e-13,
        "L",
    );
    assert_close(
        f.cluster.linear_momentum().as_slice(),
        (a.momentum() + b.momentum()).as_slice(),
        1e-15,
        "p",
    );
    let ke_before = a.kinetic_energy() + b.kinetic_energy();
    assert!((f.cluster.kinetic_energy() - ke_before - f.kinetic_energy_change).abs() < 1e-13);
    assert!(f.kinetic_energy_change < 0.0);
}

#[test]
fn fusion_is_associative() {
    let ball = |m: f64, c: Vector3<f64>, v: Vector3<f64>, w: Vector3<f64>| {
        RigidCluster::ball(m, 0.5, c, v, w).unwrap()
    };
    let a = ball(
        1.0,
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    );
    let b = ball(
        2.0,
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 3.0),
    );
    let c = ball(
        0.5,
        Vector3::new(1.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(2.0, 0.0, 0.0),
    );
    let left = a.fuse(&b).unwrap().cluster.fuse(&c).unwrap();
    let right = a.fuse(&b.fuse(&c).unwrap().cluster).unwrap();
    let (l, r) = (left.cluster, right.cluster);
    assert_close(l.center().as_slice(), r.center().as_slice(), 1e-15, "c");
    assert_close(l.velocity().as_slice(), r.velocity().as_slice(), 1e-15, "v");
    assert_close(
        l.world_inertia().as_slice(),
        r.world_inertia().as_slice(),
        1e-14,
        "I",
    );
    assert_close(
        l.angular_momentum().as_slice(),
        r.angular_momentum().as_slice(),
        1e-14,
        "L",
    );
    // The total energy lost does not depend on the order of fusion.
    let lost = |x: f64, y: f64| x + y;
    let first = a.fuse(&b).unwrap().kinetic_energy_change;
    let second = b.fuse(&c).unwrap().kinetic_energy_change;
    assert!(
        (lost(first, left.kinetic_energy_change) - lost(second, right.kinetic_energy_change)).abs()
            < 1e-14
    );
}

#[test]
fn a_tilted_dumbbell_hits_the_floor_with_the_rigid_body_impulse_at_its_contact_point() {
    // Two disks (1 kg, r 0.5) at (−0.3, 0.4) and (0.3, −0.4), falling at 2 m/s. The lower
    // one touches the floor y = −0.9 at x = (0.3, −0.9): offset r = (0.3, −0.9) from the
    // centre of mass (the origin), normal n = (0, −1) from the cluster into the floor.
    let disk = |c: Vector2<f64>| {
        RigidCluster::ball(1.0, 0.5, c, Vector2::new(0.0, -2.0), Vector1::zeros()).unwrap()
    };
    let cluster = disk(Vector2::new(-0.3, 0.4))
        .fuse(&disk(Vector2::new(0.3, -0.4)))
        .unwrap()
        .cluster;
    assert!((cluster.world_inertia() - 0.75).abs() < 1e-15); // 2·(⅛) + 2·(0.25)
    let r = Vector2::new(0.3, -0.9);
    let contact = Contact::new(Vector2::new(0.0, -1.0), r, Vector2::zeros()).unwrap();
    for e in [1.0, 0.4] {
        let response = resolve(
            &cluster.body(),
            &Body::fixed(),
            &contact,
            &Coefficients::frictionless(e).unwrap(),
        );
        // By hand: r × n = −0.3, n·K n = 1/2 + 0.09/0.75 = 0.62, v_n = −2.
        let j = (1.0 + e) * 2.0 / 0.62;
        assert!((response.normal_impulse - j).abs() < 1e-14);
        let after = cluster.with_impulse(&-response.impulse, &contact.offset_a());
        assert_close(
            after.velocity().as_slice(),
            &[0.0, -2.0 + j / 2.0],
            1e-14,
            "v",
        );
        assert!((after.angular_velocity().x - 0.3 * j / 0.75).abs() < 1e-14);
        assert_eq!(after.velocity(), response.velocity[0]);
        assert!((after.angular_velocity().x - response.angular_velocity[0].x).abs() < 1e-14);
        // The contact point rebounds at e times its approach speed.
        let point = after.velocity() + Vector2::new(-r.y, r.x) * after.angular_velocity().x;
        assert!((point.y - 2.0 * e).abs() < 1e-14);
        // Independent check: the impulse acts at x, so L about x is unchanged.
        let x = cluster.center() + r;
        assert!(
            (after.angular_momentum_about(&x).x - cluster.angular_momentum_about(&x).x).abs()
                < 1e-14
        );
        let lost = after.kinetic_energy() - cluster.kinetic_energy();
        assert!((lost - response.kinetic_energy_change).abs() < 1e-14);
        if e == 1.0 {
            assert!(lost.abs() < 1e-14);
        }
    }
}

#[test]
fn a_turned_3d_cluster_keeps_angular_momentum_while_its_spin_changes() {
    let body_inertia = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 4.0));
    let turned = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let cluster = RigidCluster::new(
        3.0,
        Vector3::zeros(),
        turned,
        body_inertia,
        Vector3::zeros(),
        Vector3::new(1.0, 2.0, 3.0),
    )
    .unwrap();
    assert_close(
        cluster.angular_velocity().as_slice(),
        &[1.0, 2.0, 3.0],
        1e-14,
        "ω",
    );
    let later = cluster.with_pose(
        Vector3::new(1.0, 0.0, 0.0),
        Rotation3::from_euler_angles(0.5, 0.1, -0.2),
    );
    assert_eq!(later.angular_momentum(), cluster.angular_momentum());
    // Same L, different orientation: ω = R I⁻¹ Rᵀ L changes (precession), energy ½ ω·L too.
    assert!((later.angular_velocity() - cluster.angular_velocity()).norm() > 0.1);
    // A wall hit at an off-centre point: angular momentum about the contact point is kept.
    let r = Vector3::new(0.4, -0.3, -0.8);
    let contact = Contact::new(-Vector3::z(), r, Vector3::zeros()).unwrap();
    let moving = RigidCluster::new(
        3.0,
        Vector3::zeros(),
        turned,
        body_inertia,
        Vector3::new(0.5, 0.0, -3.0),
        Vector3::new(1.0, 2.0, 3.0),
    )
    .unwrap();
    let response = resolve(
        &moving.body(),
        &Body::fixed(),
        &contact,
        &Coefficients::new(0.7, 0.4).unwrap(),
    );
    assert!(matches!(response.outcome, Outcome::Applied(_)));
    let after = moving.with_impulse(&-response.impulse, &r);
    let x = moving.center() + r;
    assert_close(
        after.angular_momentum_about(&x).as_slice(),
        moving.angular_momentum_about(&x).as_slice(),
        1e-13,
        "L about x",
    );
    assert!(after.kinetic_energy() <= moving.kinetic_energy());
    assert_close(
        after.angular_velocity().as_slice(),
        response.angular_velocity[0].as_slice(),
        1e-13,
        "ω",
    );
}

#[test]
fn cluster_constructors_name_the_bad_field() {
    let bad = Matrix3::from_diagonal(&Vector3::new(1.0, 0.0, 1.0));
    let e = RigidCluster::new(
        1.0,
        Vector3::zeros(),
        Rotation3::identity(),
        bad,
        Vector3::zeros(),
        Vector3::zeros(),
    )
    .unwrap_err();
    assert_eq!(e.field, "inertia");
    let e = RigidCluster::<f64, 2>::new(
        1.0,
        Vector2::zeros(),
        Rotation2::new(f64::NAN),
        1.0,
        Vector2::zeros(),
        Vector1::zeros(),
    )
    .unwrap_err();
    assert_eq!(e.field, "orientation");
    let e = RigidCluster::<f64, 2>::ball(
        1.0,
        0.5,
        Vector2::new(f64::INFINITY, 0.0),
        Vector2::zeros(),
        Vector1::zeros(),
    )
    .unwrap_err();
    assert_eq!(e.field, "center[0]");
    let e = RigidCluster::<f32, 2>::ball(
        3e38,
        1.0,
        Vector2::zeros(),
        Vector2::zeros(),
        Vector1::zeros(),
    )
    .unwrap()
    .fuse(
        &RigidCluster::ball(
            3e38,
            1.0,
            Vector2::zeros(),
            Vector2::zeros(),
            Vector1::zeros(),
        )
        .unwrap(),
    )
    .unwrap_err();
    assert_eq!(e.field, "mass");
}

fn arb_cluster() -> impl Strategy<Value = RigidCluster<f64, 3>> {
    (
        0.1..10.0f64,
        prop::array::uniform3(-5.0..5.0f64),
        prop::array::uniform3(-3.2..3.2f64),
        prop::array::uniform9(-1.0..1.0f64),
        prop::array::uniform3(-5.0..5.0f64),
        prop::array::uniform3(-5.0..5.0f64),
    )
        .prop_map(|(m, c, angles, i, v, w)| {
            let a = Matrix3::from_row_slice(&i);
            let inertia = (a * a.transpose() + Matrix3::identity() * 0.05) * m;
            let orientation = Rotation3::from_euler_angles(angles[0], angles[1], angles[2]);
            RigidCluster::new(
                m,
                Vector3::from(c),
                orientation,
                inertia,
                Vector3::from(v),
                Vector3::from(w),
            )
            .unwrap()
        })
}

proptest! {
    #[test]
    fn fusion_keeps_momenta_and_member_positions_and_never_gains_energy(a in arb_cluster(), b in arb_cluster(), member in prop::array::uniform3(-1.0..1.0f64)) {
        let f = a.fuse(&b).unwrap();
        let p = a.linear_momentum() + b.linear_momentum();
        prop_assert!((f.cluster.linear_momentum() - p).norm() <= 1e-12 * (a.linear_momentum().norm() + b.linear_momentum().norm()));
        let o = Vector3::new(0.5, -1.0, 2.0);
        let l = a.angular_momentum_about(&o) + b.angular_momentum_about(&o);
        let scale = a.angular_momentum_about(&o).norm() + b.angular_momentum_about(&o).norm() + 20.0 * (a.linear_momentum().norm() + b.linear_momentum().norm());
        prop_assert!((f.cluster.angular_momentum_about(&o) - l).norm() <= 1e-12 * scale);
        let before = a.kinetic_energy() + b.kinetic_energy();
        prop_assert!(f.kinetic_energy_change <= 1e-12 * before);
        prop_assert!((f.cluster.kinetic_energy() - before - f.kinetic_energy_change).abs() <= 1e-11 * before);
        // A member's world position is unchanged by the fusion.
        let member = Vector3::from(member);
        for (part, map) in [(&a, &f.members_a), (&b, &f.members_b)] {
            let world_before = part.center() + part.orientation() * member;
            let world_after = f.cluster.center() + f.cluster.orientation() * map.apply(&member);
            prop_assert!((world_after - world_before).norm() <= 1e-13);
        }
    }
}
