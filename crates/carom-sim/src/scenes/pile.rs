//! Balls dropped in rows into a narrow box, where they land on each other and form a
//! pile under gravity with friction: the stepped engine's pile test
//! (`tests/stepped_resting.rs`) and its draws over many seeds
//! (`examples/pile_draws.rs`, `docs/stepped.md`, piles items 14 and 15).

use carom_geometry::Border;
use carom_math::{Real, Vector};

use crate::scene::{BallSpec, BorderSpec, Scene, World};

/// Gravity's magnitude (m/s²).
const G: f64 = 9.81;

/// The first state of the pile test's generator; draw `k` starts from this plus `k`.
const FIRST_STATE: u64 = 0x2545_f491_4f6c_dd1d;

/// `rows` rows of 16 balls of radius 0.25 m and 0.5 to 2 kg, 0.6 m apart in height from
/// 0.5 m up, with horizontal speeds up to 1 m/s, dropped into a box open to 30 m
/// (restitution 0.2 for balls and walls, friction 0.3), drawn from `draw` (0: the pile
/// test's own). In 2D the box is 10 m wide and a row is a line 0.625 m apart; in 3D it is
/// 2.5 m wide and deep, and a row is a square of 4 × 4 balls 0.6 m apart. Each ball's
/// place is jittered by up to 5 cm along each horizontal axis.
///
/// The numbers come from xorshift64 (Marsaglia's 13/7/17), the generator the pile test
/// was written with, so that draw 0 is its scene bit for bit.
pub fn dropped_rows<const D: usize>(rows: u32, draw: u64) -> Scene<f64, D> {
    let mut state = FIRST_STATE.wrapping_add(draw);
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1_u64 << 53) as f64
    };
    let width = if D == 2 { 10.0 } else { 2.5 };
    let mut balls = Vec::new();
    for row in 0..rows {
        for k in 0..16_u32 {
            let mut pos = Vector::<f64, D>::zeros();
            let mut vel = Vector::<f64, D>::zeros();
            if D == 2 {
                pos[0] = -4.7 + 0.625 * f64::from(k) + 0.1 * (uniform() - 0.5);
                vel[0] = 2.0 * uniform() - 1.0;
            } else {
                pos[0] = -0.9 + 0.6 * f64::from(k % 4) + 0.1 * (uniform() - 0.5);
                pos[2] = -0.9 + 0.6 * f64::from(k / 4) + 0.1 * (uniform() - 0.5);
                vel[0] = 2.0 * uniform() - 1.0;
                vel[2] = 2.0 * uniform() - 1.0;
            }
            pos[1] = 0.5 + 0.6 * f64::from(row);
            balls.push(BallSpec::new(pos, vel, 0.25, 0.5 + 1.5 * uniform()));
        }
    }
    let mut gravity = Vector::<f64, D>::zeros();
    gravity[1] = -G;
    let mut low = Vector::<f64, D>::repeat(-width / 2.0);
    let mut high = Vector::<f64, D>::repeat(width / 2.0);
    low[1] = 0.0;
    high[1] = 30.0;
    Scene {
        world: World {
            gravity,
            restitution: 0.2,
            friction: 0.3,
            border: Some(BorderSpec {
                border: Border::new(low, high).expect("a valid border"),
                restitution: 0.2,
                periodic: false,
            }),
            ..World::default()
        },
        balls,
        ..Scene::default()
    }
}

/// What the narrow phase lets `scene`'s pile gain in a step of `dt` (J): every ball
/// lifted by how far a contact closing slower than a millionth of `g dt` sinks in the
/// step, `M g · 1e-6 g dt²` (the pile test's energy bound).
pub fn allowance<T: Real, const D: usize>(scene: &Scene<T, D>, dt: f64) -> f64 {
    let g = scene.world.gravity.norm().to_f64();
    let weight: f64 = scene.balls.iter().map(|b| b.mass.to_f64() * g).sum();
    weight * (resting_speed(g, dt) * dt)
}

/// The speed below which the narrow phase takes a contact for resting under gravity
/// `g` with steps of `dt`: a millionth of `g dt`.
pub fn resting_speed(g: f64, dt: f64) -> f64 {
    1e-6 * g * dt
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether no two of `balls` overlap.
    fn apart<const D: usize>(balls: &[BallSpec<f64, D>]) -> bool {
        (0..balls.len()).all(|i| {
            (balls[i + 1..].iter())
                .all(|q| (balls[i].pos - q.pos).norm() > balls[i].radius + q.radius)
        })
    }

    #[test]
    fn draws_differ_and_repeat_and_keep_every_ball_apart() {
        let (a, b) = (dropped_rows::<2>(6, 0), dropped_rows::<2>(6, 1));
        assert_eq!(a.balls.len(), 96);
        assert_eq!(a, dropped_rows::<2>(6, 0));
        assert_ne!(a.balls[0].pos, b.balls[0].pos);
        assert!(apart(&a.balls) && apart(&b.balls));
        let c = dropped_rows::<3>(4, 2);
        assert_eq!(c.balls.len(), 64);
        assert!(apart(&c.balls));
    }
}
