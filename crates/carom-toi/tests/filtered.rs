//! `ball_ball` and `relative_contact_time` at the boundaries of their filtered
//! arithmetic, against exact integer arithmetic: grazes far away, nearly touching pairs
//! and tangential motions whose discriminant, gap or rate is within the plain error bound
//! of zero, so that the double-double fallback decides them; through the public API, in
//! f64 and f32, forward and backward, at coordinates far from the origin.
//! `relative_contact_time` must take every decision `ball_ball` takes; with a reach of
//! zero its time is as accurate as `ball_ball`'s, and with the event engine's reach (four
//! roundings of the largest coordinate) it may also differ by a move of the relative
//! position within that reach.
//!
//! Inputs are integers (below `2^29` in f64, `2^24` in f32), so every coefficient of
//! `|u + w t|² − R²` is an exact `i128`; the reference root is computed in f64 from the
//! exact integers (within about `4u`).

use carom_geometry::Ball;
use carom_toi::{Direction, Kinematics, Real, Status, Window, ball_ball, relative_contact_time};
use nalgebra::Vector3;
use proptest::prelude::*;

/// The exact coefficients `h = u·w`, `a = |w|²`, `c = |u|² − R²`, `Δ = h² − a c`.
#[derive(Debug)]
struct Exact {
    h: i128,
    a: i128,
    c: i128,
    disc: i128,
}

fn dot(x: [i64; 3], y: [i64; 3]) -> i128 {
    x.iter()
        .zip(y)
        .map(|(&a, b)| i128::from(a) * i128::from(b))
        .sum()
}

fn exact(u: [i64; 3], w: [i64; 3], r: i64) -> Exact {
    let (h, a) = (dot(u, w), dot(w, w));
    let c = dot(u, u) - i128::from(r) * i128::from(r);
    Exact {
        h,
        a,
        c,
        disc: h * h - a * c,
    }
}

/// The expected status and (forward) time: touching is `c <= 2u fl(R²)` in f64 (the
/// centre distance rounds to `R`).
fn reference(e: &Exact, r: i64) -> (Status, f64) {
    let touch = (r as f64 * r as f64) * f64::EPSILON;
    if e.h >= 0 {
        (Status::NoHit, f64::INFINITY)
    } else if (e.c as f64) <= touch {
        (Status::AlreadyTouching, 0.0)
    } else if e.disc <= 0 {
        (Status::NoHit, f64::INFINITY)
    } else {
        let t = e.c as f64 / ((e.disc as f64).sqrt() - e.h as f64);
        (Status::Hit, t)
    }
}

/// Runs `ball_ball` for ball 1 at `offset` at rest and ball 2 at `offset + u` moving at
/// `w` (backward: at `−w`, so the forward answer applies), radii splitting `R`, and
/// checks it against the exact reference: status, time within `tolerance · t`, and a unit
/// normal along the offset at contact; and `relative_contact_time` on the same pair (see the
/// module docs).
fn check<T: Real>(
    u: [i64; 3],
    w: [i64; 3],
    r: i64,
    offset: [i64; 3],
    backward: bool,
    tolerance: f64,
) -> Result<(), TestCaseError> {
    let v = |x: [i64; 3]| Vector3::from(x.map(|c| T::lit(c as f64)));
    let lit = |x: i64| T::lit(x as f64);
    let c2 = [0, 1, 2].map(|i| offset[i] + u[i]);
    let b1 = Ball::new(v(offset), lit(r / 2)).unwrap();
    let b2 = Ball::new(v(c2), lit(r - r / 2)).unwrap();
    let (window, velocity) = if backward {
        (Window::unbounded(Direction::Backward), w.map(|x| -x))
    } else {
        (Window::unbounded(Direction::Forward), w)
    };
    let toi = ball_ball(
        &b1,
        &Kinematics::at_rest(),
        &b2,
        &Kinematics::linear(v(velocity)).unwrap(),
        &window,
    );
    let e = exact(u, w, r);
    let (status, t_ref) = reference(&e, r);
    prop_assert_eq!(toi.status, status, "{:?}", e);
    let sign = if backward { -1.0 } else { 1.0 };
    let t = toi.time.to_f64() * sign;
    match status {
        Status::Hit => {
            prop_assert!(
                (t - t_ref).abs() <= tolerance * t_ref,
                "{t} vs {t_ref}: {e:?}"
            );
            let n = toi.normal.map(T::to_f64);
            prop_assert!((n.norm() - 1.0).abs() <= 4.0 * T::EPSILON.to_f64());
            // Along the exact offset at the reference time.
            let at =
                Vector3::from(u.map(|x| x as f64)) + Vector3::from(w.map(|x| x as f64)) * t_ref;
            prop_assert!((n - at / at.norm()).norm() <= 1e-6, "{n} vs {at}");
        }
        Status::AlreadyTouching => prop_assert_eq!(toi.time, T::zero()),
        _ => prop_assert!(toi.time.to_f64().is_infinite()),
    }
    let offset = b2.center() - b1.center();
    let coordinate = b1.center().amax().max(b2.center().amax()).to_f64();
    let speed = (e.a as f64).sqrt();
    for reach in [0.0, 2.0 * T::EPSILON.to_f64() * coordinate] {
        let time = relative_contact_time(
            &offset,
            &v(velocity),
            b1.radius() + b2.radius(),
            &window,
            T::lit(reach),
        );
        prop_assert_eq!(time.is_some(), toi.is_hit(), "{:?}", e);
        if let Some(time) = time {
            let t = time.to_f64() * sign;
            prop_assert!(
                (t - t_ref).abs() * speed <= reach + tolerance * t_ref * speed,
                "{t} vs {t_ref}, moving {} against a reach of {reach}: {e:?}",
                (t - t_ref).abs() * speed
            );
        }
    }
    Ok(())
}

const U64: f64 = f64::EPSILON / 2.0;
const U32: f64 = f32::EPSILON as f64 / 2.0;

/// A graze far away: `u = s w + p`, the radius the miss distance (about `|p|`) rounded and
/// moved by `δ`.
fn graze(w: [i64; 3], s: i64, p: [i64; 3], delta: i64) -> Option<([i64; 3], [i64; 3], i64)> {
    let u = [0, 1, 2].map(|i| s * w[i] + p[i]);
    let e = exact(u, w, 0);
    if e.h >= 0 || e.a == 0 {
        return None;
    }
    // With R = 0, Δ = h² − a |u|² = −|u ∧ w|² (Lagrange): the miss distance is √(−Δ/a).
    let miss = ((-e.disc) as f64 / e.a as f64).sqrt();
    Some((u, w, (miss.round() as i64 + delta).max(2)))
}

/// Nearly touching: `u = (R, x, y)` permuted, so `c = x² + y²` (or `c < 0` with `R + 1`).
fn near_touch(r: i64, x: i64, y: i64, perm: usize, inside: bool) -> ([i64; 3], i64) {
    let mut u = [r, x, y];
    u.rotate_left(perm);
    (u, if inside { r + 1 } else { r })
}

/// `w` with `u·w < 0`.
fn closing(u: [i64; 3], w: [i64; 3]) -> [i64; 3] {
    if dot(u, w) > 0 { w.map(|x| -x) } else { w }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn grazes_far_away_f64(
        w in prop::array::uniform3(-(1i64 << 20)..(1 << 20)), s in -(1i64 << 8)..0,
        p in prop::array::uniform3(-(1i64 << 12)..(1 << 12)), delta in -8i64..=8,
        offset in prop::array::uniform3(-(1i64 << 20)..(1 << 20)), backward in any::<bool>(),
    ) {
        let Some((u, w, r)) = graze(w, s, p, delta) else { return Ok(()) };
        // Shifted far from the origin: the differences stay exact (below 2^53).
        let far = offset.map(|x| x << 20);
        check::<f64>(u, w, r, far, backward, 20.0 * U64)?;
    }

    #[test]
    fn grazes_far_away_f32(
        w in prop::array::uniform3(-(1i64 << 10)..(1 << 10)), s in -(1i64 << 6)..0,
        p in prop::array::uniform3(-(1i64 << 6)..(1 << 6)), delta in -4i64..=4,
        backward in any::<bool>(),
    ) {
        let Some((u, w, r)) = graze(w, s, p, delta) else { return Ok(()) };
        // Inputs below 2^24 are exact in f32; the root is rounded once to f32.
        check::<f32>(u, w, r, [0; 3], backward, 1.1 * U32)?;
    }

    #[test]
    fn nearly_touching_f64(
        r in (1i64 << 28)..(1 << 29), x in 0i64..32, y in 0i64..32, w in prop::array::uniform3(-(1i64 << 29)..(1 << 29)),
        perm in 0usize..3, inside in any::<bool>(), backward in any::<bool>(),
    ) {
        let (u, r) = near_touch(r, x, y, perm, inside);
        check::<f64>(u, closing(u, w), r, [0; 3], backward, 20.0 * U64)?;
    }

    #[test]
    fn nearly_touching_f32(
        r in (1i64 << 22)..(1 << 23), x in 0i64..32, y in 0i64..32, w in prop::array::uniform3(-(1i64 << 23)..(1 << 23)),
        perm in 0usize..3, inside in any::<bool>(),
    ) {
        let (u, r) = near_touch(r, x, y, perm, inside);
        check::<f32>(u, closing(u, w), r, [0; 3], false, 1.1 * U32)?;
    }

    /// `u = (a, b, 1)`, `w = (−k b, k a, z)`: `u·w = z`, touching or not.
    #[test]
    fn tangential_f64(
        a in (1i64 << 25)..(1 << 28), b in (1i64 << 25)..(1 << 28), k in 1i64..16,
        z in -8i64..=8, r_offset in -2i64..3, backward in any::<bool>(),
    ) {
        let (u, w) = ([a, -b, 1], [k * b, k * a, z]);
        let distance = ((a * a + b * b + 1) as f64).sqrt() as i64;
        check::<f64>(u, w, distance + r_offset, [0; 3], backward, 20.0 * U64)?;
    }
}

#[test]
fn the_filter_boundaries_are_reached() {
    // Passing at a distance of exactly 5 from 2^28 away: Δ = |w|² (R² − 25) is inside the
    // plain bound (h² = 2^96), so the double-double path decides: a hit for R = 6, a miss
    // for R = 4, and R = 5 is a tangency (not a collision).
    let w = [1 << 20, 0, 0];
    for (r, hit) in [(6, true), (4, false), (5, false)] {
        let u = [-(1 << 28), 3, 4];
        let e = exact(u, w, r);
        assert_eq!(e.disc > 0, hit);
        let toi = ball_ball(
            &Ball::new(Vector3::zeros(), r as f64 / 2.0).unwrap(),
            &Kinematics::at_rest(),
            &Ball::new(Vector3::from(u.map(|x| x as f64)), r as f64 / 2.0).unwrap(),
            &Kinematics::linear(Vector3::from(w.map(|x| x as f64))).unwrap(),
            &Window::unbounded(Direction::Forward),
        );
        assert_eq!(toi.is_hit(), hit, "R = {r}");
    }
}
