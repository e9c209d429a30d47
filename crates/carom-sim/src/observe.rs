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
pub fn energy<T: Real, const D: usize>(scene: &Scene<T, D>, states: &BallStates<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    let half = T::lit(0.5);
    let inertia = <Const<D> as Space<T, D>>::ball_inertia_factor();
    let g = scene.world.gravity;
    let mut e = T::zero();
    for (k, b) in scene.balls.iter().enumerate() {
        let spin = &states.spin[k];
        let rotation = inertia
            * b.mass
            * b.radius
            * b.radius
            * <Const<D> as Space<T, D>>::angular_dot(spin, spin);
        e += half * b.mass * states.vel[k].norm_squared() + half * rotation
            - b.mass * g.dot(&states.pos[k]);
    }
    e
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
}
