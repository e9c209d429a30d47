//! Closed-form references: what the accuracy sections and the cross-validation tests
//! measure every engine against.
//!
//! Each function is the textbook solution written out here on its own, in `f64`, without
//! calling carom's own closed forms (carom-toi's times of impact, carom-integrate's
//! `exact` module, carom-response's impulses), so a shared mistake cannot hide: the
//! references are independent oracles.

use nalgebra::Vector2;

/// A point's position and velocity at some time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Position (m).
    pub pos: Vector2<f64>,
    /// Velocity (m/s).
    pub vel: Vector2<f64>,
}

/// One ball of a [`free_pair`]: its start, radius and mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeBall {
    /// Position at time 0.
    pub pos: Vector2<f64>,
    /// Velocity at time 0.
    pub vel: Vector2<f64>,
    /// Radius.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
}

/// When two balls moving in straight lines first touch, if they ever do.
///
/// With `d = p₁ − p₀`, `u = v₁ − v₀` and `R = r₀ + r₁`, contact is `|d + u τ| = R`:
/// `a τ² + 2 b τ + c = 0` with `a = |u|²`, `b = d·u`, `c = |d|² − R²`. The balls approach
/// when `b < 0`; the earlier root is `τ = (−b − √(b² − ac)) / a`, computed as
/// `c / (−b + √(b² − ac))` (the product of the roots is `c/a`), which has no cancellation
/// for grazing contacts (`b² ≈ ac`) or slow closings (`a → 0`).
pub fn contact_time(a: &FreeBall, b: &FreeBall) -> Option<f64> {
    let d = b.pos - a.pos;
    let u = b.vel - a.vel;
    let reach = a.radius + b.radius;
    let (qa, qb, qc) = (
        u.norm_squared(),
        d.dot(&u),
        d.norm_squared() - reach * reach,
    );
    let disc = qb * qb - qa * qc;
    if qb >= 0.0 || disc < 0.0 {
        return None;
    }
    Some((qc / (-qb + disc.sqrt())).max(0.0))
}

/// Two free balls (no border, no forces) at time `t`: straight flight, at most one
/// collision with restitution `e` and no friction, straight flight again.
///
/// At contact the unit normal is `n = (p₁ − p₀)/R`, the normal closing speed
/// `w = (v₁ − v₀)·n < 0`, and the impulse on ball 1 is `J n` with
/// `J = −(1 + e) w / (1/m₀ + 1/m₁)` (ball 0 gets `−J n`): momentum is kept and the normal
/// relative velocity becomes `−e w`.
pub fn free_pair(a: &FreeBall, b: &FreeBall, e: f64, t: f64) -> [Motion; 2] {
    let fly = |x: &FreeBall, s: f64| Motion {
        pos: x.pos + x.vel * s,
        vel: x.vel,
    };
    match contact_time(a, b) {
        Some(tc) if tc <= t => {
            let (pa, pb) = (a.pos + a.vel * tc, b.pos + b.vel * tc);
            let n = (pb - pa).normalize();
            let w = (b.vel - a.vel).dot(&n);
            let j = -(1.0 + e) * w / (1.0 / a.mass + 1.0 / b.mass);
            let (va, vb) = (a.vel - n * (j / a.mass), b.vel + n * (j / b.mass));
            let s = t - tc;
            [
                Motion {
                    pos: pa + va * s,
                    vel: va,
                },
                Motion {
                    pos: pb + vb * s,
                    vel: vb,
                },
            ]
        }
        _ => [fly(a, t), fly(b, t)],
    }
}

/// A ball dropped from rest, bouncing on a floor with restitution `e` under gravity `g`
/// (magnitude): the height of its bottom above the floor and its vertical velocity at
/// time `t`.
///
/// The fall from height `h` lasts `t₀ = √(2h/g)` and lands at `v₀ = √(2gh)`; the `k`-th
/// rebound leaves at `eᵏ v₀` and flies `2 eᵏ v₀ / g`. The flights sum to the Zeno time
/// `t₀ + 2 e v₀ / (g (1 − e))`, after which the ball rests on the floor.
pub fn bouncing_ball(h: f64, e: f64, g: f64, t: f64) -> (f64, f64) {
    let v0 = (2.0 * g * h).sqrt();
    let t0 = (2.0 * h / g).sqrt();
    if t <= t0 {
        return (h - 0.5 * g * t * t, -g * t);
    }
    let (mut start, mut speed) = (t0, e * v0);
    loop {
        let flight = 2.0 * speed / g;
        if speed <= 0.0 || flight <= 0.0 {
            return (0.0, 0.0);
        }
        if t <= start + flight {
            let s = t - start;
            return (speed * s - 0.5 * g * s * s, speed - g * s);
        }
        start += flight;
        speed *= e;
    }
}

/// The apex heights `h e^(2k)`, `k = 1..=count`, of a ball dropped from `h` bouncing with
/// restitution `e`: each rebound keeps `e²` of the energy.
pub fn bounce_apexes(h: f64, e: f64, count: usize) -> Vec<f64> {
    (1..=count).map(|k| h * e.powi(2 * k as i32)).collect()
}

/// A projectile under gravity `g` and linear drag `−b v` on mass `m`, at time `t`.
///
/// `dv/dt = g − k v` with `k = b/m` has the terminal velocity `v∞ = g/k` and the solution
/// `v(t) = v∞ + (v₀ − v∞) e^(−kt)`, `x(t) = x₀ + v∞ t + (v₀ − v∞)(1 − e^(−kt))/k`
/// (for `k` well above rounding; the report's problems use `k ≥ 0.1`).
pub fn projectile_linear_drag(
    pos: Vector2<f64>,
    vel: Vector2<f64>,
    g: Vector2<f64>,
    k: f64,
    t: f64,
) -> Motion {
    let terminal = g / k;
    let decay = (-k * t).exp();
    Motion {
        pos: pos + terminal * t + (vel - terminal) * ((1.0 - decay) / k),
        vel: terminal + (vel - terminal) * decay,
    }
}

/// The damped oscillator `ẍ = −ω² x − 2ζω ẋ` (underdamped, `ζ < 1`) from `(x₀, v₀)`: the
/// displacement and velocity at time `t`.
///
/// With `ω_d = ω √(1 − ζ²)`:
/// `x(t) = e^(−ζωt) (x₀ cos ω_d t + (v₀ + ζω x₀)/ω_d · sin ω_d t)`, and `ẋ` its derivative
/// `e^(−ζωt) (v₀ cos ω_d t − (ω x₀ + ζ v₀) ω/ω_d · sin ω_d t)`.
pub fn damped_oscillator(x0: f64, v0: f64, omega: f64, zeta: f64, t: f64) -> (f64, f64) {
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let decay = (-zeta * omega * t).exp();
    let (s, c) = (wd * t).sin_cos();
    let x = decay * (x0 * c + (v0 + zeta * omega * x0) / wd * s);
    let v = decay * (v0 * c - (omega * x0 + zeta * v0) * omega / wd * s);
    (x, v)
}

/// A ball's centre moving along one axis between two elastic walls at `lo` and `hi`
/// (the ball's radius `r` already counted: the centre lives in `[lo + r, hi − r]`), from
/// `x0` at speed `v`: position and velocity at time `t`.
///
/// Unfolding the reflections, the centre moves freely on a line of period `2L`,
/// `L = hi − lo − 2r`: the free coordinate `s = x₀ − (lo + r) + v t` modulo `2L` is the
/// position on the way out (`s ≤ L`) or `2L − s` on the way back.
pub fn between_walls(x0: f64, v: f64, lo: f64, hi: f64, r: f64, t: f64) -> (f64, f64) {
    let span = hi - lo - 2.0 * r;
    let s = (x0 - (lo + r) + v * t).rem_euclid(2.0 * span);
    if s <= span {
        (lo + r + s, v)
    } else {
        (lo + r + 2.0 * span - s, -v)
    }
}

/// Newton's cradle (`carom_sim::scenes::classic::newtons_cradle(n, 1.0)`: the striker
/// 0.5 m left of a touching row of `n` balls, coming in at 1 m/s) at time `t >= 0.5`:
/// the textbook answer for equal elastic balls. The striker stops touching the row (its
/// centre at −0.2), the row stays at rest, and the last ball leaves at 1 m/s from the
/// instant the striker arrives (0.5 s).
pub fn newtons_cradle(n: usize, t: f64) -> Vec<Motion> {
    let mut motions: Vec<Motion> = (0..=n)
        .map(|k| Motion {
            pos: Vector2::new(if k == 0 { -0.2 } else { 0.2 * (k - 1) as f64 }, 0.0),
            vel: Vector2::zeros(),
        })
        .collect();
    motions[n].pos.x += t - 0.5;
    motions[n].vel.x = 1.0;
    motions
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(x: f64, y: f64, vx: f64, vy: f64, mass: f64) -> FreeBall {
        FreeBall {
            pos: Vector2::new(x, y),
            vel: Vector2::new(vx, vy),
            radius: 0.1,
            mass,
        }
    }

    #[test]
    fn newtons_cradle_keeps_the_scene_layout_and_the_striker_momentum() {
        let n = 4;
        let scene = carom_sim::scenes::classic::newtons_cradle(n, 1.0);
        let m = newtons_cradle(n, 2.0);
        assert_eq!(m.len(), scene.balls.len());
        // The row's resting balls stay where the scene puts them.
        for (motion, ball) in m.iter().zip(&scene.balls).take(n).skip(1) {
            assert_eq!(motion.pos, ball.pos);
        }
        // The striker's momentum ends in the last ball, which left 1.5 s ago.
        let p: f64 = m.iter().map(|b| b.vel.x).sum();
        assert_eq!(p, scene.balls[0].vel.x);
        assert_eq!(m[n].pos.x, scene.balls[n].pos.x + 1.5);
        // The striker stops touching the first ball of the row.
        assert_eq!(m[1].pos.x - m[0].pos.x, 0.2);
    }

    #[test]
    fn a_head_on_pair_keeps_momentum_and_restitution() {
        // Textbook 1D: v₀' = (m₀v₀ + m₁v₁ + m₁ e (v₁ − v₀)) / (m₀ + m₁).
        let (m0, m1, v0, v1, e) = (1.0, 3.0, 2.0, -1.0, 0.6);
        let [a, b] = free_pair(
            &ball(-1.0, 0.0, v0, 0.0, m0),
            &ball(1.0, 0.0, v1, 0.0, m1),
            e,
            2.0,
        );
        let expected0 = (m0 * v0 + m1 * v1 + m1 * e * (v1 - v0)) / (m0 + m1);
        let expected1 = (m0 * v0 + m1 * v1 + m0 * e * (v0 - v1)) / (m0 + m1);
        assert!((a.vel.x - expected0).abs() < 1e-15);
        assert!((b.vel.x - expected1).abs() < 1e-15);
        // Contact after 1.8 m of closing at 3 m/s: t = 0.6.
        let tc = contact_time(&ball(-1.0, 0.0, v0, 0.0, m0), &ball(1.0, 0.0, v1, 0.0, m1)).unwrap();
        assert!((tc - 0.6).abs() < 1e-15);
        assert!((a.pos.x - (-1.0 + v0 * 0.6 + expected0 * 1.4)).abs() < 1e-14);
    }

    #[test]
    fn an_oblique_equal_mass_elastic_collision_leaves_at_right_angles() {
        let [a, b] = free_pair(
            &ball(-1.0, 0.05, 1.0, 0.0, 1.0),
            &ball(0.0, 0.0, 0.0, 0.0, 1.0),
            1.0,
            3.0,
        );
        assert!(a.vel.dot(&b.vel).abs() < 1e-15);
        assert!((a.vel.norm_squared() + b.vel.norm_squared() - 1.0).abs() < 1e-15);
        // A miss by a hair: no collision.
        let c = contact_time(
            &ball(-1.0, 0.2 + 1e-12, 1.0, 0.0, 1.0),
            &ball(0.0, 0.0, 0.0, 0.0, 1.0),
        );
        assert_eq!(c, None);
    }

    #[test]
    fn the_bouncing_ball_is_continuous_and_reaches_its_apexes() {
        let (h, e, g) = (1.0_f64, 0.8, 9.81);
        let v0 = (2.0 * g * h).sqrt();
        let t0 = (2.0 * h / g).sqrt();
        // First apex: t₀ + e v₀ / g.
        let (y, v) = bouncing_ball(h, e, g, t0 + e * v0 / g);
        assert!((y - h * e * e).abs() < 1e-14 && v.abs() < 1e-14);
        // Continuous across the second bounce.
        let t2 = t0 + 2.0 * e * v0 / g;
        let (below, _) = bouncing_ball(h, e, g, t2 - 1e-9);
        let (above, _) = bouncing_ball(h, e, g, t2 + 1e-9);
        assert!(below.abs() < 1e-7 && above.abs() < 1e-7);
        assert_eq!(bouncing_ball(h, e, g, 100.0), (0.0, 0.0));
        assert_eq!(bounce_apexes(1.0, 0.5, 2), vec![0.25, 0.0625]);
    }

    #[test]
    fn the_drag_and_oscillator_solutions_solve_their_equations() {
        // Central differences of the solutions against the right-hand sides.
        let (g, k) = (Vector2::new(0.0, -9.81), 0.7);
        let (x0, v0) = (Vector2::new(1.0, 2.0), Vector2::new(3.0, 4.0));
        let eps = 1e-5;
        for t in [0.0, 0.3, 2.0] {
            let m = projectile_linear_drag(x0, v0, g, k, t);
            let (lo, hi) = (
                projectile_linear_drag(x0, v0, g, k, t - eps),
                projectile_linear_drag(x0, v0, g, k, t + eps),
            );
            assert!(((hi.pos - lo.pos) / (2.0 * eps) - m.vel).norm() < 1e-8);
            assert!(((hi.vel - lo.vel) / (2.0 * eps) - (g - m.vel * k)).norm() < 1e-7);
        }
        let (omega, zeta) = (30.0, 0.2);
        for t in [0.0, 0.05, 0.4] {
            let (x, v) = damped_oscillator(0.5, -1.0, omega, zeta, t);
            let (xl, vl) = damped_oscillator(0.5, -1.0, omega, zeta, t - eps);
            let (xh, vh) = damped_oscillator(0.5, -1.0, omega, zeta, t + eps);
            assert!(((xh - xl) / (2.0 * eps) - v).abs() < 1e-6);
            let a = -omega * omega * x - 2.0 * zeta * omega * v;
            assert!(((vh - vl) / (2.0 * eps) - a).abs() < 1e-3 * a.abs().max(1.0));
        }
        assert_eq!(damped_oscillator(0.5, -1.0, omega, zeta, 0.0), (0.5, -1.0));
    }

    #[test]
    fn reflections_between_walls_fold_the_free_line() {
        // Walls at 0 and 2, radius 0.5: the centre lives in [0.5, 1.5], L = 1.
        assert_eq!(between_walls(1.0, 1.0, 0.0, 2.0, 0.5, 0.25), (1.25, 1.0));
        let (x, v) = between_walls(1.0, 1.0, 0.0, 2.0, 0.5, 0.75);
        assert!((x - 1.25).abs() < 1e-15 && v == -1.0);
        let (x, v) = between_walls(1.0, 1.0, 0.0, 2.0, 0.5, 2.0);
        assert!((x - 1.0).abs() < 1e-15 && v == 1.0);
        let (x, v) = between_walls(1.0, -1.0, 0.0, 2.0, 0.5, 0.75);
        assert!((x - 0.75).abs() < 1e-15 && v == 1.0);
    }
}
