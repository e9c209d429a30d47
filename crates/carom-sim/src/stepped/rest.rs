//! Balls held by several supports at once: the exact projection of a chord onto every
//! support constraint of the moment.
//!
//! A resting correction stops a ball's chord from closing on one support. Done one
//! support at a time, a ball held by two (a ball in a hollow between two others, in a
//! corner) is projected alternately: each projection leaves it sliding along the last
//! surface, which can point upwards (the ball climbs out of the hollow and gains energy
//! step after step). So the constraints of all the supports a ball touches at the same
//! instant (within a millionth of the step) are kept together ([`RestSet`]), and each
//! new one re-solves the projection of the ball's chord **as it was before the first
//! correction of that instant**, `u₀`:
//!
//! ```text
//! minimise |u − u₀|²   subject to   aₘ·u >= bₘ  for every support m
//! ```
//!
//! with `aₘ` the unit normal from support `m` towards the ball and `bₘ` the support's own
//! velocity along it. The optimum is `u = u₀ + Σ λₘ aₘ` with `λ >= 0` on a set of active
//! constraints (the KKT conditions); with at most [`MAX_SUPPORTS`] constraints the active
//! set is found by trying every subset of at most `D` of them, solving its small Gram
//! system and keeping the feasible one closest to `u₀`. Under gravity a ball in a hollow
//! between two supports at rest gets `u = 0` in one correction.

use carom_math::{Real, Vector};

/// The most supports one ball keeps at one instant (more are dropped, oldest first).
pub(crate) const MAX_SUPPORTS: usize = 6;

/// What holds a ball: a border wall (axis and side), a box, or another ball.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Support {
    /// A wall of the border, by the contact normal (its axis and sign).
    Wall(usize, bool),
    /// Box `k`.
    Box(u32),
    /// Ball `j`.
    Ball(u32),
}

/// A support a ball touches: what it is, the unit normal from the ball into it, and
/// its velocity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Touch<T: Real, const D: usize> {
    /// The support.
    pub(crate) support: Support,
    /// Unit normal from the ball into the support.
    pub(crate) normal: Vector<T, D>,
    /// The support's velocity (its chord, for a ball).
    pub(crate) velocity: Vector<T, D>,
}

/// The support constraints of one ball at one instant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RestSet<T: Real, const D: usize> {
    /// The in-step time of the instant.
    time: T,
    /// The chord before the first correction of the instant.
    reference: Vector<T, D>,
    supports: [(Support, Vector<T, D>, T); MAX_SUPPORTS],
    count: usize,
}

impl<T: Real, const D: usize> RestSet<T, D> {
    /// An empty set at time `time` for a ball whose chord is `chord`.
    pub(crate) fn new(time: T, chord: Vector<T, D>) -> Self {
        Self {
            time,
            reference: chord,
            supports: [(Support::Ball(0), Vector::zeros(), T::zero()); MAX_SUPPORTS],
            count: 0,
        }
    }

    /// Whether this set is for the instant `time`, within `tolerance`: contacts met within
    /// rounding of each other (a ball settling into a hollow whose two gaps differ by an
    /// ulp) belong to one instant.
    pub(crate) fn is_at(&self, time: T, tolerance: T) -> bool {
        (self.time - time).abs() <= tolerance
    }

    /// The number of supports.
    pub(crate) fn len(&self) -> usize {
        self.count
    }

    /// Adds (or replaces) `support` with normal `a` (unit, from the support towards the
    /// ball) moving at `b` along it.
    pub(crate) fn add(&mut self, support: Support, a: Vector<T, D>, b: T) {
        let entry = (support, a, b);
        if let Some(slot) = self.supports[..self.count]
            .iter_mut()
            .find(|(s, _, _)| *s == support)
        {
            *slot = entry;
        } else if self.count < MAX_SUPPORTS {
            self.supports[self.count] = entry;
            self.count += 1;
        } else {
            self.supports.copy_within(1.., 0);
            self.supports[MAX_SUPPORTS - 1] = entry;
        }
    }

    /// The chord closest to the reference that closes on no support, or `None` if no
    /// active set solves it (numerically degenerate normals).
    pub(crate) fn project(&self) -> Option<Vector<T, D>> {
        let m = self.count;
        let u0 = self.reference;
        let slack = T::lit(64.0) * T::EPSILON;
        let feasible = |u: &Vector<T, D>| {
            self.supports[..m]
                .iter()
                .all(|(_, a, b)| a.dot(u) >= *b - slack * (u.norm() + b.abs() + u0.norm()))
        };
        if feasible(&u0) {
            return Some(u0);
        }
        let mut best: Option<(T, Vector<T, D>)> = None;
        for subset in 1u32..(1 << m) {
            let size = subset.count_ones() as usize;
            if size > D {
                continue;
            }
            let mut idx = [0usize; 3];
            let mut k = 0;
            for bit in 0..m {
                if subset & (1 << bit) != 0 {
                    idx[k] = bit;
                    k += 1;
                }
            }
            let Some(u) = self.solve_active(&idx[..size], &u0) else {
                continue;
            };
            if !feasible(&u) {
                continue;
            }
            let d = (u - u0).norm_squared();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, u));
            }
        }
        best.map(|(_, u)| u)
    }

    /// `u = u₀ + Σ λₖ aₖ` with `aₖ·u = bₖ` on the active set `idx` and every `λₖ >= 0`.
    fn solve_active(&self, idx: &[usize], u0: &Vector<T, D>) -> Option<Vector<T, D>> {
        let n = idx.len();
        // The Gram system G λ = r, G = [aᵢ·aⱼ], r = bᵢ − aᵢ·u₀ (n <= 3), by Gaussian
        // elimination with partial pivoting.
        let mut g = [[T::zero(); 4]; 3];
        for (row, &i) in idx.iter().enumerate() {
            let (_, ai, bi) = self.supports[i];
            for (col, &j) in idx.iter().enumerate() {
                g[row][col] = ai.dot(&self.supports[j].1);
            }
            g[row][n] = bi - ai.dot(u0);
        }
        for col in 0..n {
            let pivot = (col..n).max_by(|&p, &q| {
                g[p][col]
                    .abs()
                    .partial_cmp(&g[q][col].abs())
                    .unwrap_or(core::cmp::Ordering::Equal)
            })?;
            if g[pivot][col].abs() <= T::lit(1e-9) {
                return None;
            }
            g.swap(col, pivot);
            let pivot_row = g[col];
            for row in &mut g[col + 1..n] {
                let f = row[col] / pivot_row[col];
                for (x, p) in row[col..=n].iter_mut().zip(&pivot_row[col..=n]) {
                    *x -= f * *p;
                }
            }
        }
        let mut lambda = [T::zero(); 3];
        for row in (0..n).rev() {
            let mut v = g[row][n];
            for c in row + 1..n {
                v -= g[row][c] * lambda[c];
            }
            lambda[row] = v / g[row][row];
        }
        if lambda[..n].iter().any(|&l| l < T::zero() || !l.finite()) {
            return None;
        }
        Some(
            idx.iter()
                .zip(&lambda)
                .fold(*u0, |u, (&i, &l)| u + self.supports[i].1 * l),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn a_ball_in_a_hollow_stops() {
        // Supports below-left and below-right at 30° from the vertical.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let mut set = RestSet::new(0.0, Vector2::new(0.0, -1.0));
        set.add(Support::Ball(0), Vector2::new(s, c), 0.0);
        set.add(Support::Ball(1), Vector2::new(-s, c), 0.0);
        assert!(set.project().unwrap().norm() < 1e-15);
    }

    #[test]
    fn one_support_removes_the_normal_part_and_the_floor_keeps_sliding() {
        let mut set = RestSet::new(0.0, Vector3::new(2.0, -1.0, 0.5));
        set.add(Support::Wall(1, false), Vector3::new(0.0, 1.0, 0.0), 0.0);
        assert_eq!(set.project().unwrap(), Vector3::new(2.0, 0.0, 0.5));
        // Adding a wall the ball moves away from changes nothing.
        set.add(Support::Wall(0, true), Vector3::new(1.0, 0.0, 0.0), -5.0);
        assert_eq!(set.project().unwrap(), Vector3::new(2.0, 0.0, 0.5));
    }

    #[test]
    fn a_corner_stops_both_components_and_a_moving_support_carries_the_ball() {
        let mut set = RestSet::new(0.0, Vector2::new(-3.0, -1.0));
        set.add(Support::Wall(1, false), Vector2::new(0.0, 1.0), 0.0);
        set.add(Support::Wall(0, false), Vector2::new(1.0, 0.0), 0.0);
        assert_eq!(set.project().unwrap(), Vector2::zeros());
        // A floor rising at 2: the ball rises with it.
        set.add(Support::Wall(1, false), Vector2::new(0.0, 1.0), 2.0);
        assert_eq!(set.project().unwrap(), Vector2::new(0.0, 2.0));
    }

    #[test]
    fn the_projection_is_the_nearest_feasible_point_against_sampling() {
        // Three supports in 3D; compare with the best of many feasible candidates.
        let normals = [
            Vector3::new(0.3, 0.9, 0.1).normalize(),
            Vector3::new(-0.5, 0.8, 0.2).normalize(),
            Vector3::new(0.1, 0.7, -0.7).normalize(),
        ];
        let u0 = Vector3::new(0.4, -2.0, 0.3);
        let mut set = RestSet::new(0.0, u0);
        for (k, a) in normals.iter().enumerate() {
            set.add(Support::Ball(k as u32), *a, 0.0);
        }
        let u = set.project().unwrap();
        assert!(normals.iter().all(|a| a.dot(&u) >= -1e-12));
        let d = (u - u0).norm();
        let mut seed = 7_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..20_000 {
            let v = Vector3::new(next(), next(), next());
            if normals.iter().all(|a| a.dot(&v) >= 0.0) {
                assert!((v - u0).norm() >= d - 1e-12);
            }
        }
    }
}
