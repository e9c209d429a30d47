//! Reproducible random scenes for tests, benchmarks and reports.
//!
//! The generators are deterministic functions of their arguments and a seed (a
//! SplitMix64 stream, no dependency), so a benchmark, a test and `carom report` that ask
//! for the same scene get the same balls on every machine.
//!
//! * [`Scene::uniform`]: equal balls, uniform in a cube sized for a packing fraction
//!   (the total ball area or volume over the domain's; balls may overlap).
//! * [`Scene::clustered`]: equal balls in `clusters` dense clumps (uniform in a ball of
//!   a tenth of the domain's width around uniform cluster centres).
//! * [`Scene::mixed`]: radii log-uniform in `[r_min, r_max]`, uniform positions.
//! * [`Scene::boxes`]: random boxes as in Terdiman's box-pruning test.
//! * [`Scene::step`]: one coherent frame: every ball moves by a fixed fraction of its
//!   radius in a random direction.

use carom_geometry::{Aabb, Border};
use carom_math::{Real, Vector};

use crate::{Balls, Volumes};

/// SplitMix64 (Steele, Lea and Flood 2014): a tiny, fast, well-mixed 64-bit generator.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)` (53 random bits).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A standard normal variate (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.next_f64();
        let v = self.next_f64();
        (-2.0 * u.ln()).sqrt() * (core::f64::consts::TAU * v).cos()
    }

    /// A uniformly random unit vector in `D` dimensions.
    pub fn direction<const D: usize>(&mut self) -> [f64; D] {
        loop {
            let v: [f64; D] = core::array::from_fn(|_| self.normal());
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 1e-12 {
                return v.map(|x| x / n);
            }
        }
    }
}

/// The content of the unit ball in `D` dimensions (`D` = 1, 2 or 3; higher by recurrence).
fn unit_ball(d: usize) -> f64 {
    match d {
        0 => 1.0,
        1 => 2.0,
        _ => core::f64::consts::TAU / d as f64 * unit_ball(d - 2),
    }
}

/// Balls (or boxes) in a cubic domain.
#[derive(Clone, Debug)]
pub struct Scene<T: Real, const D: usize> {
    /// Ball centres.
    pub centers: Vec<Vector<T, D>>,
    /// Ball radii.
    pub radii: Vec<T>,
    /// The boxes of [`Scene::boxes`] (empty for ball scenes).
    pub boxes: Vec<Aabb<T, D>>,
    /// The domain `[0, side]^D` the scene was generated in.
    pub domain: Border<T, D>,
    rng: SplitMix64,
}

impl<T: Real, const D: usize> Scene<T, D> {
    fn with_domain(side: f64, offset: f64, seed: u64) -> Self {
        let lo = Vector::<T, D>::repeat(T::lit(offset));
        let hi = Vector::<T, D>::repeat(T::lit(offset + side.max(1e-300)));
        Self {
            centers: Vec::new(),
            radii: Vec::new(),
            boxes: Vec::new(),
            domain: Border::new(lo, hi).unwrap_or_else(|_| {
                Border::new(Vector::zeros(), Vector::repeat(T::one())).expect("unit box")
            }),
            rng: SplitMix64::new(seed),
        }
    }

    /// The side of a cube holding `n` balls of mean content `content` at `fraction`.
    fn side(n: usize, content: f64, fraction: f64) -> f64 {
        (n as f64 * content / fraction.max(1e-12)).powf(1.0 / D as f64)
    }

    fn uniform_point(&mut self, side: f64, offset: f64) -> Vector<T, D> {
        Vector::<T, D>::from_fn(|_, _| T::lit(offset + self.rng.range(0.0, side)))
    }

    /// `n` balls of radius `radius` uniform in a cube sized for packing `fraction`,
    /// the cube starting at `offset` on every axis (`1e6` for far-from-origin scenes).
    pub fn uniform(n: usize, radius: f64, fraction: f64, offset: f64, seed: u64) -> Self {
        let side = Self::side(n, unit_ball(D) * radius.powf(D as f64), fraction);
        let mut s = Self::with_domain(side, offset, seed);
        for _ in 0..n {
            let c = s.uniform_point(side, offset);
            s.centers.push(c);
            s.radii.push(T::lit(radius));
        }
        s
    }

    /// `n` balls of radius `radius` in `clusters` clumps, the domain sized for `fraction`.
    pub fn clustered(n: usize, radius: f64, fraction: f64, clusters: usize, seed: u64) -> Self {
        let side = Self::side(n, unit_ball(D) * radius.powf(D as f64), fraction);
        let mut s = Self::with_domain(side, 0.0, seed);
        let hubs: Vec<Vector<T, D>> = (0..clusters.max(1))
            .map(|_| s.uniform_point(side, 0.0))
            .collect();
        let spread = 0.1 * side;
        for i in 0..n {
            let hub = hubs[i % hubs.len()];
            let dir = s.rng.direction::<D>();
            let dist = spread * s.rng.next_f64().powf(1.0 / D as f64);
            s.centers
                .push(hub + Vector::<T, D>::from_fn(|k, _| T::lit(dir[k] * dist)));
            s.radii.push(T::lit(radius));
        }
        s
    }

    /// `n` balls with radii log-uniform in `[r_min, r_max]`, uniform in a cube sized for
    /// `fraction`.
    pub fn mixed(n: usize, r_min: f64, r_max: f64, fraction: f64, seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed ^ 0x5EED);
        let (a, b) = (r_min.ln(), r_max.ln());
        let radii: Vec<f64> = (0..n).map(|_| rng.range(a, b).exp()).collect();
        let content = radii
            .iter()
            .map(|r| unit_ball(D) * r.powf(D as f64))
            .sum::<f64>()
            / n.max(1) as f64;
        let side = Self::side(n, content, fraction);
        let mut s = Self::with_domain(side, 0.0, seed);
        for r in radii {
            let c = s.uniform_point(side, 0.0);
            s.centers.push(c);
            s.radii.push(T::lit(r));
        }
        s
    }

    /// `n` random boxes as in Terdiman's box-pruning test: centres uniform in
    /// `[−spread/2, spread/2]^D`, half extents uniform in `[0, max_half_extent)` per
    /// axis (his figures use spread 2000 and half extents up to 20). The radii are the
    /// boxes' half diagonals.
    pub fn boxes(n: usize, spread: f64, max_half_extent: f64, seed: u64) -> Self {
        let mut s = Self::with_domain(spread, -0.5 * spread, seed);
        for _ in 0..n {
            let c = s.uniform_point(spread, -0.5 * spread);
            let half = Vector::<T, D>::from_fn(|_, _| T::lit(s.rng.range(0.0, max_half_extent)));
            let b = Aabb::from_center_half_extents(c, half)
                .unwrap_or_else(|_| Aabb::new_unchecked(c, c));
            s.centers.push(c);
            s.radii.push(half.norm());
            s.boxes.push(b);
        }
        s
    }

    /// Moves every ball by `fraction × radius` in a random direction (one coherent
    /// frame; `0.01` is the benchmarks' 1 %). Boxes move with their centres.
    pub fn step(&mut self, fraction: f64) {
        for i in 0..self.centers.len() {
            let dir = self.rng.direction::<D>();
            let d = fraction * self.radii[i].to_f64();
            let offset = Vector::<T, D>::from_fn(|k, _| T::lit(dir[k] * d));
            self.centers[i] += offset;
            if let Some(b) = self.boxes.get_mut(i) {
                *b = b.translated(&offset);
            }
        }
    }

    /// The balls as broad-phase input.
    pub fn balls(&self) -> Volumes<'_, T, D> {
        Volumes::Balls(Balls::new_unchecked(&self.centers, &self.radii))
    }

    /// The boxes as broad-phase input ([`Scene::boxes`] scenes; empty otherwise).
    pub fn aabbs(&self) -> Volumes<'_, T, D> {
        Volumes::Boxes(&self.boxes)
    }

    /// The number of balls.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// `true` if the scene is empty.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_scenes_have_the_requested_packing_fraction() {
        let s = Scene::<f64, 3>::uniform(1000, 0.5, 0.1, 0.0, 1);
        let side = s.domain.extents()[0];
        let fraction = 1000.0 * 4.0 / 3.0 * core::f64::consts::PI * 0.125 / side.powi(3);
        assert!((fraction - 0.1).abs() < 1e-12);
        assert!(
            s.centers
                .iter()
                .all(|c| c.iter().all(|&x| (0.0..side).contains(&x)))
        );
    }

    #[test]
    fn scenes_are_reproducible_and_steps_move_by_the_fraction() {
        let a = Scene::<f32, 2>::clustered(100, 0.5, 0.3, 4, 7);
        let mut b = Scene::<f32, 2>::clustered(100, 0.5, 0.3, 4, 7);
        assert_eq!(a.centers, b.centers);
        b.step(0.01);
        for (p, q) in a.centers.iter().zip(&b.centers) {
            assert!(((p - q).norm() - 0.005).abs() < 1e-5);
        }
    }
}
