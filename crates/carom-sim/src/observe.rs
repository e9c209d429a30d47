//! What drivers measure on a running simulation: energy, momentum, a state hash.
//!
//! Energy is kinetic (translation plus each ball's own spin, `½ I ω²` with the disk or
//! solid-sphere inertia) plus gravitational potential `−m g·x`. For a stuck cluster the
//! sum over its balls of translation and own spin is exactly the cluster's rigid-body
//! kinetic energy (the cross terms vanish about the centre of mass), so one formula
//! serves every engine. The state hash is FNV-1a over the bit patterns of every
//! position and velocity: equal hashes mean bit-identical states (determinism tests).

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::engine::BallStates;
use crate::scene::Scene;

/// Kinetic plus gravitational potential energy of the balls.
///
/// Computed in `f64` whatever `T` is, and rounded to `T` once: in `f32` the potential
/// terms of a scene far from the origin are large and cancel, and each addition in
/// `f32` rounds to the last place of a running sum that holds them, which can be all
/// of the rest (test below: 0 J for 0.01 J). In `f64` it is the plain sum.
pub fn energy<T: Real, const D: usize>(scene: &Scene<T, D>, states: &BallStates<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    let inertia = <Const<D> as Space<T, D>>::ball_inertia_factor().to_f64();
    let g = scene.world.gravity.map(T::to_f64);
    let mut e = 0.0_f64;
    for (k, b) in scene.balls.iter().enumerate() {
        let (m, r) = (b.mass.to_f64(), b.radius.to_f64());
        let spin = &states.spin[k];
        let rotation =
            inertia * m * r * r * <Const<D> as Space<T, D>>::angular_dot(spin, spin).to_f64();
        let (v, x) = (states.vel[k].map(T::to_f64), states.pos[k].map(T::to_f64));
        e += 0.5 * m * v.norm_squared() + 0.5 * rotation - m * g.dot(&x);
    }
    T::lit(e)
}

/// Total linear momentum `Σ m v`.
pub fn momentum<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    states: &BallStates<T, D>,
) -> Vector<T, D>
where
    Const<D>: Space<T, D>,
{
    scene
        .balls
        .iter()
        .zip(&states.vel)
        .fold(Vector::zeros(), |p, (b, v)| p + v * b.mass)
}

/// FNV-1a over the bits of every position and velocity, in ball order.
pub fn state_hash<T: Real, const D: usize>(states: &BallStates<T, D>) -> u64
where
    Const<D>: Space<T, D>,
{
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in states.pos.iter().chain(&states.vel) {
        for x in v.iter() {
            for byte in x.to_f64().to_bits().to_le_bytes() {
                h = (h ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::classic;
    use nalgebra::{Vector1, Vector2};

    #[test]
    fn energy_counts_translation_spin_and_height() {
        let mut s = classic::head_on(2.0, 1.0, 3.0, 0.0, 1.0);
        s.world.gravity = Vector2::new(0.0, -10.0);
        let states = BallStates {
            pos: vec![Vector2::new(0.0, 1.0), Vector2::new(1.0, 0.0)],
            vel: vec![Vector2::new(3.0, 0.0), Vector2::zeros()],
            spin: vec![Vector1::new(0.0), Vector1::new(10.0)],
        };
        // ½·2·9 + 2·10·1 + ½·(½·1·0.1²)·100 = 9 + 20 + 0.25
        assert!((energy(&s, &states) - 29.25).abs() < 1e-12);
        assert_eq!(momentum(&s, &states), Vector2::new(6.0, 0.0));
        let mut moved = states.clone();
        moved.pos[1].x = f64::from_bits(moved.pos[1].x.to_bits() + 1);
        assert_ne!(
            state_hash(&states),
            state_hash(&moved),
            "one ulp changes the hash"
        );
    }

    /// Two 1 kg balls 5e4 m above and below the origin in `f32`: their potential terms
    /// (±490,500 J, a last place of 0.03 J) cancel, and the energy is the kinetic 0.01 J,
    /// to `f32`'s rounding of that (a sum in `f32` gave 0).
    #[test]
    fn energy_in_f32_far_from_the_origin_keeps_the_small_terms() {
        let mut s = classic::head_on(1.0, 1.0, 0.1, 0.0, 0.0)
            .cast::<f32>()
            .unwrap();
        s.world.gravity = Vector2::new(0.0, -9.81);
        let states = BallStates {
            pos: vec![Vector2::new(0.0, 5e4), Vector2::new(0.0, -5e4)],
            vel: vec![Vector2::new(0.1, 0.0), Vector2::new(-0.1, 0.0)],
            spin: vec![Vector1::new(0.0); 2],
        };
        let expected = 0.5 * 1.0 * 0.1_f64.powi(2) * 2.0;
        let e = f64::from(energy(&s, &states));
        assert!(
            (e - expected).abs() <= 2.0 * f64::from(f32::EPSILON) * expected,
            "{e} J, expected {expected} J"
        );
    }
}
