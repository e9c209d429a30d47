//! Property tests of the force laws against their textbook forms, in 2D and 3D, over
//! wide ranges of values (speeds up to 1e6 m/s, coordinates up to 1e6 m).

use carom_integrate::{
    AnchorSpring, BallState, Bodies, ForceField, Gravity, Integrator, LinearDrag, Magnus,
    QuadraticDrag, SpinDamping, Spring, Stepper, TimeStep,
};
use nalgebra::{Vector1, Vector2, Vector3};
use proptest::prelude::*;

fn vector3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

fn ball3(
    x: Vector3<f64>,
    v: Vector3<f64>,
    w: Vector3<f64>,
    inverse_mass: f64,
) -> BallState<f64, 3> {
    BallState {
        position: x,
        velocity: v,
        spin: w,
        inverse_mass,
        time: 0.0,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn magnus_is_s_over_m_omega_cross_v_and_does_no_work(
        v in vector3(1e6), w in vector3(1e3), s in 0.0..1e-3, inverse_mass in 1e-3..1e3,
    ) {
        let a = Magnus::new(s).unwrap().acceleration(&ball3(Vector3::zeros(), v, w, inverse_mass)).linear;
        let expected = w.cross(&v) * (s * inverse_mass);
        prop_assert!((a - expected).norm() <= 1e-15 * expected.norm() + f64::MIN_POSITIVE);
        prop_assert!(a.dot(&v).abs() <= 1e-14 * a.norm() * v.norm() + f64::MIN_POSITIVE);
    }

    #[test]
    fn magnus_in_2d_is_the_3d_force_in_the_plane(
        vx in -1e3..1e3_f64, vy in -1e3..1e3_f64, wz in -1e3..1e3_f64, s in 0.0..1e-3,
    ) {
        let flat = BallState {
            position: Vector2::zeros(),
            velocity: Vector2::new(vx, vy),
            spin: Vector1::new(wz),
            inverse_mass: 2.0,
            time: 0.0,
        };
        let a2 = Magnus::new(s).unwrap().acceleration(&flat).linear;
        let a3 = Magnus::new(s).unwrap()
            .acceleration(&ball3(Vector3::zeros(), Vector3::new(vx, vy, 0.0), Vector3::new(0.0, 0.0, wz), 2.0))
            .linear;
        prop_assert_eq!(a3.z, 0.0);
        prop_assert!((a2 - a3.xy()).norm() <= 1e-15 * a3.norm());
    }

    #[test]
    fn drags_point_against_the_velocity_with_the_textbook_magnitude(
        v in vector3(1e6), b in 0.0..10.0, c in 0.0..1e-2, inverse_mass in 1e-3..1e3,
    ) {
        let state = ball3(Vector3::zeros(), v, Vector3::zeros(), inverse_mass);
        let lin = LinearDrag::new(b).unwrap().acceleration(&state).linear;
        let quad = QuadraticDrag::new(c).unwrap().acceleration(&state).linear;
        prop_assert!((lin + v * (b * inverse_mass)).norm() <= 1e-15 * lin.norm() + f64::MIN_POSITIVE);
        let expected = v * (-c * inverse_mass * v.norm());
        prop_assert!((quad - expected).norm() <= 1e-15 * expected.norm() + f64::MIN_POSITIVE);
        prop_assert!(lin.dot(&v) <= 0.0 && quad.dot(&v) <= 0.0);
    }

    #[test]
    fn spring_force_matches_the_textbook_form(
        d in vector3(1e3), u in vector3(1e3), k in 0.0..1e4, c in 0.0..10.0, rest in 0.0..10.0,
    ) {
        prop_assume!(d.norm() > 1e-6);
        let spring = Spring::new(k, c, rest).unwrap();
        let n = d.normalize();
        let textbook = -n * (k * (d.norm() - rest)) - n * (c * u.dot(&n));
        let scale = k * (d.norm() + rest) + c * u.norm();
        prop_assert!((spring.force(&d, &u) - textbook).norm() <= 1e-13 * scale);
        // Through the anchored field: F / m.
        let field = AnchorSpring::new(Vector3::new(1e6, -1e6, 0.0), spring).unwrap();
        let x = Vector3::new(1e6, -1e6, 0.0) + d;
        let a = field.acceleration(&ball3(x, u, Vector3::zeros(), 0.5)).linear;
        // The offset x − anchor is recomputed far from the origin: allow its rounding.
        prop_assert!((a - textbook * 0.5).norm() <= 1e-13 * scale + k * 1e6 * f64::EPSILON);
    }

    #[test]
    fn chunked_stepping_is_bit_identical_for_any_chunk_length(chunk in 1_usize..40, steps in 1_usize..20) {
        let field = (
            Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap(),
            QuadraticDrag::new(3.8e-4).unwrap(),
            Magnus::new(4e-6).unwrap(),
            SpinDamping::new(0.3).unwrap(),
        );
        let stepper = Stepper::new(Integrator::Rk4, field).unwrap();
        let n = 37;
        let init = |i: usize| (i as f64 * 0.77).sin();
        let x0: Vec<_> = (0..n).map(|i| Vector3::new(init(i), init(i + 1), init(i + 2))).collect();
        let v0: Vec<_> = (0..n).map(|i| Vector3::new(9.0 * init(i + 3), 2.0, 30.0 * init(i))).collect();
        let w0: Vec<_> = (0..n).map(|i| Vector3::new(100.0 * init(i + 5), 0.0, 50.0)).collect();
        let m: Vec<f64> = (0..n).map(|i| 1.0 / (0.0027 * (1.0 + i as f64))).collect();
        let dt = TimeStep::new(1e-3).unwrap();
        let (mut x1, mut v1, mut w1) = (x0.clone(), v0.clone(), w0.clone());
        let (mut x2, mut v2, mut w2) = (x0, v0, w0);
        for s in 0..steps {
            let t = s as f64 * dt.get();
            let mut whole = Bodies::new(&mut x1, &mut v1, &m).unwrap().with_spins(&mut w1).unwrap();
            stepper.step(&mut whole, t, dt);
            for mut part in Bodies::new(&mut x2, &mut v2, &m).unwrap().with_spins(&mut w2).unwrap().chunks(chunk) {
                stepper.step(&mut part, t, dt);
            }
        }
        prop_assert_eq!((x1, v1, w1), (x2, v2, w2));
    }
}
