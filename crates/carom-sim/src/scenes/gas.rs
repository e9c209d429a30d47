//! A gas: many equal balls in a box at a given area (2D) or volume (3D) fraction.
//!
//! Balls start on a simple cubic (square) lattice filling the box, with the sites left
//! empty chosen at random, each ball jittered randomly inside the slack its site leaves,
//! so no two overlap. Velocities are Gaussian with the total momentum removed and then
//! scaled so the kinetic energy is exactly `D/2 · N · kT` with `kT = mass · speed²`
//! (`speed` is the per-component thermal speed). The simple lattice holds at most
//! π/4 ≈ 0.785 (2D) or π/6 ≈ 0.524 (3D); denser requests are refused.

use carom_geometry::Border;
use carom_math::Vector;

use super::SplitMix64;
use crate::scene::{BallSpec, BorderSpec, Scene, SceneError, World};

/// How to build a gas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GasParams {
    /// Number of balls.
    pub n: usize,
    /// Area (2D) or volume (3D) fraction of the box the balls fill, in `(0, max)`.
    pub fraction: f64,
    /// Ball radius (m).
    pub radius: f64,
    /// Ball mass (kg).
    pub mass: f64,
    /// Thermal speed per component (m/s).
    pub speed: f64,
    /// Ball–ball and wall restitution.
    pub restitution: f64,
    /// Periodic box (wrap-around) instead of reflecting walls.
    pub periodic: bool,
    /// Random seed.
    pub seed: u64,
}

impl Default for GasParams {
    fn default() -> Self {
        Self {
            n: 1000,
            fraction: 0.1,
            radius: 0.5,
            mass: 1.0,
            speed: 1.0,
            restitution: 1.0,
            periodic: false,
            seed: 1,
        }
    }
}

/// The content of a ball of radius `r` in `D` dimensions (area in 2D).
fn ball_content<const D: usize>(r: f64) -> f64 {
    match D {
        2 => std::f64::consts::PI * r * r,
        3 => 4.0 / 3.0 * std::f64::consts::PI * r * r * r,
        _ => unreachable!("carom scenes are 2D or 3D"),
    }
}

/// The gas scene, centred on the origin.
///
/// # Errors
/// `n`, `fraction`, `radius`, `mass` or `speed` out of range, naming the parameter.
pub fn gas<const D: usize>(p: &GasParams) -> Result<Scene<f64, D>, SceneError> {
    if p.n == 0 {
        return Err(SceneError::new("n", "must be at least 1"));
    }
    for (name, v) in [("radius", p.radius), ("mass", p.mass)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(SceneError::new(name, format!("must be > 0, got {v}")));
        }
    }
    if !(p.speed.is_finite() && p.speed >= 0.0) {
        return Err(SceneError::new(
            "speed",
            format!("must be >= 0, got {}", p.speed),
        ));
    }
    // Sites per side k with k^D >= n; the box side L gives the requested fraction.
    if !p.fraction.is_finite() || p.fraction <= 0.0 {
        return Err(SceneError::new(
            "fraction",
            format!("must be > 0, got {}", p.fraction),
        ));
    }
    // Sites per side k with k^D >= n (the float root, corrected for rounding).
    let mut per_side = (p.n as f64).powf(1.0 / D as f64).ceil().max(1.0) as usize;
    while per_side.pow(D as u32) < p.n {
        per_side += 1;
    }
    while per_side > 1 && (per_side - 1).pow(D as u32) >= p.n {
        per_side -= 1;
    }
    let side = (p.n as f64 * ball_content::<D>(p.radius) / p.fraction).powf(1.0 / D as f64);
    let spacing = side / per_side as f64;
    if !side.is_finite() || spacing < 2.0 * p.radius {
        let max = (p.n as f64 * ball_content::<D>(p.radius))
            / (per_side as f64 * 2.0 * p.radius).powi(D as i32);
        return Err(SceneError::new(
            "fraction",
            format!(
                "must be in (0, {max:.4}] for {} balls on a simple lattice, got {}",
                p.n, p.fraction
            ),
        ));
    }
    let mut rng = SplitMix64::new(p.seed);
    // Choose which sites stay empty: a partial Fisher–Yates shuffle of the site indices.
    let sites = per_side.pow(D as u32);
    let mut order: Vec<usize> = (0..sites).collect();
    for i in 0..p.n.min(sites - 1) {
        let j = i + (rng.next_u64() % (sites - i) as u64) as usize;
        order.swap(i, j);
    }
    let mut used = order[..p.n].to_vec();
    used.sort_unstable();
    let slack = 0.5 * (spacing - 2.0 * p.radius);
    let half = 0.5 * side;
    let mut balls: Vec<BallSpec<f64, D>> = used
        .iter()
        .map(|&site| {
            let mut rest = site;
            let pos = Vector::<f64, D>::from_fn(|_, _| {
                let k = rest % per_side;
                rest /= per_side;
                -half + (k as f64 + 0.5) * spacing + slack * (2.0 * rng.next_f64() - 1.0)
            });
            let vel = Vector::<f64, D>::from_fn(|_, _| rng.normal());
            BallSpec::new(pos, vel, p.radius, p.mass)
        })
        .collect();
    thermalise(&mut balls, p.speed);
    let border = Border::new(Vector::repeat(-half), Vector::repeat(half))
        .map_err(|e| SceneError::from(e.within("box")))?;
    Ok(Scene {
        name: Some(format!("gas-{D}d-n{}-phi{}", p.n, p.fraction)),
        world: World {
            restitution: p.restitution,
            border: Some(BorderSpec {
                border,
                restitution: p.restitution,
                periodic: p.periodic,
            }),
            ..World::default()
        },
        balls,
        boxes: Vec::new(),
    })
}

/// Removes the mean velocity and scales to `Σ ½ m v² = D/2 · N · m · speed²`.
fn thermalise<const D: usize>(balls: &mut [BallSpec<f64, D>], speed: f64) {
    let n = balls.len() as f64;
    let mean = balls.iter().map(|b| b.vel).sum::<Vector<f64, D>>() / n;
    for b in balls.iter_mut() {
        b.vel -= mean;
    }
    let sum_sq: f64 = balls.iter().map(|b| b.vel.norm_squared()).sum();
    let target = D as f64 * n * speed * speed;
    let scale = if sum_sq > 0.0 {
        (target / sum_sq).sqrt()
    } else {
        0.0
    };
    for b in balls.iter_mut() {
        b.vel *= scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_gap<const D: usize>(s: &Scene<f64, D>) -> f64 {
        let mut gap = f64::INFINITY;
        for i in 0..s.balls.len() {
            for j in i + 1..s.balls.len() {
                gap = gap.min(
                    (s.balls[i].pos - s.balls[j].pos).norm()
                        - s.balls[i].radius
                        - s.balls[j].radius,
                );
            }
        }
        gap
    }

    #[test]
    fn a_dense_3d_gas_has_the_requested_fraction_no_overlap_and_zero_momentum() {
        let p = GasParams {
            n: 500,
            fraction: 0.45,
            periodic: true,
            ..GasParams::default()
        };
        let s = gas::<3>(&p).unwrap();
        s.validate().unwrap();
        let b = s.world.border.unwrap().border;
        let fraction = 500.0 * ball_content::<3>(0.5) / b.extents().product();
        assert!((fraction - 0.45).abs() < 1e-12);
        assert!(min_gap(&s) >= 0.0);
        let p_total: Vector<f64, 3> = s.balls.iter().map(|b| b.vel * b.mass).sum();
        assert!(p_total.norm() < 1e-12);
        let ke: f64 = s
            .balls
            .iter()
            .map(|b| 0.5 * b.mass * b.vel.norm_squared())
            .sum();
        assert!((ke - 1.5 * 500.0).abs() < 1e-9);
    }

    #[test]
    fn the_same_seed_gives_the_same_gas_and_another_seed_another() {
        let p = GasParams {
            n: 300,
            fraction: 0.3,
            ..GasParams::default()
        };
        assert_eq!(gas::<2>(&p).unwrap(), gas::<2>(&p).unwrap());
        assert_ne!(
            gas::<2>(&p).unwrap(),
            gas::<2>(&GasParams { seed: 2, ..p }).unwrap()
        );
        assert!(min_gap(&gas::<2>(&p).unwrap()) >= 0.0);
    }

    #[test]
    fn impossible_fractions_are_refused_naming_the_parameter() {
        let e = gas::<3>(&GasParams {
            fraction: 0.6,
            ..GasParams::default()
        })
        .unwrap_err();
        assert_eq!(e.field, "fraction");
        assert_eq!(
            gas::<2>(&GasParams {
                n: 0,
                ..GasParams::default()
            })
            .unwrap_err()
            .field,
            "n"
        );
        assert_eq!(
            gas::<2>(&GasParams {
                fraction: -0.1,
                ..GasParams::default()
            })
            .unwrap_err()
            .field,
            "fraction"
        );
    }
}
