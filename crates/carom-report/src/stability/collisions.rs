//! Extreme collisions in both engines (and rapier2d for reference where the issue asks):
//! mass ratios to 1e6, speeds to 1e6 m/s, coordinates at 1e7, grazing and touching
//! contacts, coincident centres, restitution 0 and 1, inelastic collapse, Zeno bouncing.
//!
//! The stepped engine runs semi-implicit Euler at 1/60 s (a game's step) throughout, so
//! fast balls travel far more than their size in a step; references are the closed forms
//! of [`crate::reference`].

use carom_integrate::Integrator;
use carom_sim::scene::{BallSpec, Scene, World};
use carom_sim::scenes::classic;
use carom_sim::{BallStates, Counters, observe};
use nalgebra::Vector2;

use super::row;
use crate::engines::{self, Method};
use crate::model::StabilityRow;
use crate::reference::{self, FreeBall, Motion};

/// The step of the stepped engine in these cases.
const DT: f64 = 1.0 / 60.0;

/// carom's two engines as these cases run them.
const CAROM: [Method; 2] = [
    Method::Event,
    Method::Stepped(Integrator::SemiImplicitEuler, DT),
];

/// What a run ends with.
struct Outcome {
    pos: Vec<Vector2<f64>>,
    vel: Vec<Vector2<f64>>,
    counters: Option<Counters>,
}

impl Outcome {
    fn from_states(s: &BallStates<f64, 2>, counters: Counters) -> Self {
        Self {
            pos: s.pos.clone(),
            vel: s.vel.clone(),
            counters: Some(counters),
        }
    }

    /// Largest position and velocity errors against `expected`.
    fn errors(&self, expected: &[Motion]) -> (f64, f64) {
        let worst = |a: &[Vector2<f64>], b: &dyn Fn(&Motion) -> Vector2<f64>| {
            a.iter()
                .zip(expected)
                .map(|(x, m)| (x - b(m)).norm())
                .fold(0.0, f64::max)
        };
        (worst(&self.pos, &|m| m.pos), worst(&self.vel, &|m| m.vel))
    }
}

/// A carom engine's state after `t`, or why it failed.
fn carom(scene: &Scene<f64, 2>, method: Method, t: f64) -> Result<Outcome, String> {
    let mut sim = engines::build(scene, method).map_err(|e| e.to_string())?;
    sim.advance_to(t, &mut ()).map_err(|e| e.to_string())?;
    Ok(Outcome::from_states(
        &engines::states(sim.as_ref()),
        sim.counters(),
    ))
}

/// rapier2d's state after the whole steps of `t`.
#[cfg(feature = "rapier")]
fn rapier(scene: &Scene<f64, 2>, t: f64) -> Result<Outcome, String> {
    let mut peer = crate::peer::rapier::RapierScene::new(scene, DT).map_err(|e| e.to_string())?;
    for _ in 0..(t / DT).round() as usize {
        peer.step();
    }
    let (pos, vel) = (0..scene.balls.len())
        .map(|i| {
            (
                Vector2::from(peer.position(i)),
                Vector2::from(peer.velocity(i)),
            )
        })
        .unzip();
    Ok(Outcome {
        pos,
        vel,
        counters: None,
    })
}

/// The engines of a case: carom's two, and rapier2d when `with_rapier` (and the feature).
fn runs(
    scene: &Scene<f64, 2>,
    t: f64,
    with_rapier: bool,
) -> Vec<(String, Result<Outcome, String>)> {
    CAROM
        .iter()
        .map(|&m| (engine_name(m), carom(scene, m, t)))
        .chain(if with_rapier {
            reference_runs(scene, t)
        } else {
            Vec::new()
        })
        .collect()
}

/// rapier2d's run for reference, when the feature is on (none without it).
fn reference_runs(scene: &Scene<f64, 2>, t: f64) -> Vec<(String, Result<Outcome, String>)> {
    #[cfg(feature = "rapier")]
    return vec![("rapier2d (reference)".to_owned(), rapier(scene, t))];
    #[cfg(not(feature = "rapier"))]
    {
        let _ = (scene, t);
        Vec::new()
    }
}

fn engine_name(m: Method) -> String {
    match m {
        Method::Event => "event engine".to_owned(),
        Method::Stepped(i, dt) => format!("stepped engine ({i}, dt {dt:.4} s)"),
    }
}

fn free(b: &BallSpec<f64, 2>) -> FreeBall {
    FreeBall {
        pos: b.pos,
        vel: b.vel,
        radius: b.radius,
        mass: b.mass,
    }
}

/// The closed form of a two-ball scene at `t`.
fn pair_reference(s: &Scene<f64, 2>, t: f64) -> [Motion; 2] {
    reference::free_pair(
        &free(&s.balls[0]),
        &free(&s.balls[1]),
        s.pair_restitution(0, 1),
        t,
    )
}

/// The bounds rapier2d rows are held to: a step-based `f32` engine with speculative
/// contacts resolves a collision up to a step early (position off by up to the closing
/// speed × 1/60 s, here at most 0.2 m) and rounds velocities to `f32` (a relative 1e-5
/// of speeds of a few m/s).
const RAPIER_BOUNDS: (f64, f64) = (0.2, 1e-5);

/// Rows comparing every engine's end state with `expected`: pass when the position error
/// is at most `pos_tol` and the velocity error at most `vel_tol` (carom), or within
/// [`RAPIER_BOUNDS`] (rapier2d).
fn compare_rows(
    case: &str,
    scene: &Scene<f64, 2>,
    t: f64,
    expected: &[Motion],
    carom_bounds: (f64, f64),
    with_rapier: bool,
) -> Vec<StabilityRow> {
    runs(scene, t, with_rapier)
        .into_iter()
        .map(|(engine, outcome)| match outcome {
            Ok(o) => {
                let (pos_tol, vel_tol) = if engine.starts_with("rapier2d") {
                    RAPIER_BOUNDS
                } else {
                    carom_bounds
                };
                let (ep, ev) = o.errors(expected);
                row(
                    format!("{case}, {engine}"),
                    ep <= pos_tol && ev <= vel_tol,
                    format!(
                        "position error {ep:.1e} m (bound {pos_tol:.0e}), velocity error {ev:.1e} m/s (bound {vel_tol:.0e})"
                    ),
                )
            }
            Err(why) => row(format!("{case}, {engine}"), false, format!("failed: {why}")),
        })
        .collect()
}

/// The rows of every collision case.
pub(super) fn rows() -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    rows.extend(mass_ratios());
    rows.extend(speeds());
    rows.extend(far_from_origin());
    rows.extend(grazing());
    rows.extend(touching_chain());
    rows.push(coincident_centres());
    rows.extend(restitution_extremes());
    rows.extend(inelastic_collapse());
    rows.extend(zeno());
    rows
}

fn mass_ratios() -> Vec<StabilityRow> {
    [1e3, 1e6]
        .into_iter()
        .flat_map(|ratio| {
            // A heavy ball at 1 m/s hits a light one at rest: it leaves at 2R/(R+1).
            let s = classic::head_on(ratio, 1.0, 1.0, 0.0, 1.0);
            let t = 2.0;
            compare_rows(
                &format!("mass ratio {ratio:.0e}, elastic head-on"),
                &s,
                t,
                &pair_reference(&s, t),
                (1e-12, 1e-12),
                true,
            )
        })
        .collect()
}

fn speeds() -> Vec<StabilityRow> {
    let speed = 1e6;
    // One step of 1/60 s: 16,667 m of flight, about 11,000 wall bounces in the step.
    let r = 0.1;
    let vel = Vector2::new(speed, 0.37 * speed);
    let s = classic::elastic_box(vec![BallSpec::new(Vector2::new(0.2, -0.3), vel, r, 1.0)]);
    let t = DT;
    let (x, vx) = reference::between_walls(0.2, vel.x, -1.0, 1.0, r, t);
    let (y, vy) = reference::between_walls(-0.3, vel.y, -1.0, 1.0, r, t);
    let mut rows = Vec::new();
    for (engine, outcome) in runs(&s, t, true) {
        let case = format!("speed 1e6 m/s in a 2 m box for 1/60 s, {engine}: no tunnelling");
        rows.push(match outcome {
            Ok(o) => {
                let inside = o.pos[0].x.abs() <= 1.0 - r + 1e-9 && o.pos[0].y.abs() <= 1.0 - r + 1e-9;
                let err = (o.pos[0] - Vector2::new(x, y)).norm();
                let verr = (o.vel[0] - Vector2::new(vx, vy)).norm();
                // rapier2d is held to staying inside only (no tunnelling).
                let exact_enough = engine.starts_with("rapier2d") || err <= 1e-6;
                row(
                    case,
                    inside && exact_enough,
                    format!(
                        "inside the box: {inside}; position error {err:.1e} m (bound 1e-6 for carom) after {:.0} m of flight, velocity error {verr:.1e} m/s",
                        vel.norm() * t
                    ),
                )
            }
            Err(why) => row(case, false, format!("failed: {why}")),
        });
    }
    let s = classic::head_on(1.0, 1.0, speed, -speed, 1.0);
    let t = 3.0 * DT;
    let expected = pair_reference(&s, t);
    for (engine, outcome) in runs(&s, t, true) {
        let case = format!("speed ±1e6 m/s head-on, {engine}: no tunnelling");
        rows.push(match outcome {
            Ok(o) => {
                let (ep, ev) = o.errors(&expected);
                let apart = o.pos[0].x < o.pos[1].x;
                let exact_enough = engine.starts_with("rapier2d") || ep <= 1e-6;
                row(
                    case,
                    apart && exact_enough,
                    format!(
                        "bounced back: {apart}; position error {ep:.1e} m (bound 1e-6 for carom), velocity error {ev:.1e} m/s"
                    ),
                )
            }
            Err(why) => row(case, false, format!("failed: {why}")),
        });
    }
    rows
}

fn far_from_origin() -> Vec<StabilityRow> {
    let mut s = classic::head_on(1.0, 2.0, 1.0, -1.0, 0.8);
    let shift = Vector2::new(1e7, -1e7);
    for b in &mut s.balls {
        b.pos += shift;
    }
    let t = 2.0;
    // Positions at 1e7 m have an ulp of 1.9e-9 m: the bound is a few dozen ulps.
    compare_rows(
        "head-on at 1e7 m from the origin",
        &s,
        t,
        &pair_reference(&s, t),
        (1e-7, 1e-9),
        true,
    )
}

/// The bound of the grazing cases. At an offset of `2r (1 − 1e-9)` the contact normal's
/// component along the motion is `√(2e-9) ≈ 4.5e-5`, so rounding of the contact point
/// (1e-16) is amplified about `1/4.5e-5`: errors of a few 1e-12 are rounding here.
const GRAZING_BOUND: f64 = 1e-10;

fn grazing() -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    for (label, factor, hits) in [("1 − 1e-9", 1.0 - 1e-9, 1), ("1 + 1e-9", 1.0 + 1e-9, 0)] {
        let mut s = classic::head_on(1.0, 1.0, 1.0, 0.0, 1.0);
        s.balls[0].pos.y = 0.2 * factor;
        let t = 3.0;
        let expected = pair_reference(&s, t);
        for m in CAROM {
            let case = format!(
                "grazing at offset 2r·({label}), {}: {}",
                engine_name(m),
                if hits == 1 {
                    "one collision"
                } else {
                    "no collision"
                }
            );
            rows.push(match carom(&s, m, t) {
                Ok(o) => {
                    let count = o.counters.map_or(0, |c| c.ball_ball);
                    let (ep, ev) = o.errors(&expected);
                    row(
                        case,
                        count == hits && ep <= GRAZING_BOUND && ev <= GRAZING_BOUND,
                        format!(
                            "{count} collision(s); position error {ep:.1e} m, velocity error {ev:.1e} m/s (bounds {GRAZING_BOUND:.0e}: the normal is ill-conditioned at grazing)"
                        ),
                    )
                }
                Err(why) => row(case, false, format!("failed: {why}")),
            });
        }
    }
    rows
}

fn touching_chain() -> Vec<StabilityRow> {
    // Newton's cradle of 10 touching balls: the last leaves at v, the rest end at rest.
    let n = 10;
    let s = classic::newtons_cradle(n, 1.0);
    let t = 2.0;
    let expected = reference::newtons_cradle(n, t);
    compare_rows(
        "touching chain (Newton's cradle of 10)",
        &s,
        t,
        &expected,
        (1e-12, 1e-12),
        true,
    )
}

fn coincident_centres() -> StabilityRow {
    let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
    s.balls[1].pos = s.balls[0].pos;
    let outcomes: Vec<String> = CAROM
        .iter()
        .map(|&m| match engines::build(&s, m) {
            Err(engines::BuildError::Scene(e)) if e.field == "balls[1].pos" => {
                format!("{}: rejected, {e}", engine_name(m))
            }
            Err(e) => format!(
                "{}: rejected without naming balls[1].pos: {e}",
                engine_name(m)
            ),
            Ok(_) => format!("{}: accepted", engine_name(m)),
        })
        .collect();
    let pass = outcomes.iter().all(|o| o.contains(": rejected, "));
    row(
        "coincident centres: rejected at validation, naming the field (both engines)",
        pass,
        outcomes.join("; "),
    )
}

fn restitution_extremes() -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    for e in [0.0, 1.0] {
        let s = classic::head_on(1.0, 2.0, 1.5, -1.0, e);
        let t = 2.0;
        let expected = pair_reference(&s, t);
        // Kinetic energy lost: ½ μ (1 − e²) w², μ the reduced mass, w the closing speed.
        let mu = 2.0 / 3.0;
        let lost = 0.5 * mu * (1.0 - e * e) * 2.5 * 2.5;
        let e0 = 0.5 * 1.5 * 1.5 + 0.5 * 2.0;
        for m in CAROM {
            let case = format!("restitution {e}, head-on 1:2, {}", engine_name(m));
            rows.push(match carom(&s, m, t) {
                Ok(o) => {
                    let (_, ev) = o.errors(&expected);
                    let energy: f64 = o
                        .vel
                        .iter()
                        .zip(&s.balls)
                        .map(|(v, b)| 0.5 * b.mass * v.norm_squared())
                        .sum();
                    let eerr = (energy - (e0 - lost)).abs();
                    row(
                        case,
                        ev <= 1e-12 && eerr <= 1e-12,
                        format!(
                            "velocity error {ev:.1e} m/s, energy {energy:.6} J against {:.6} J (error {eerr:.1e}; bounds 1e-12)",
                            e0 - lost
                        ),
                    )
                }
                Err(why) => row(case, false, format!("failed: {why}")),
            });
        }
    }
    rows
}

fn inelastic_collapse() -> Vec<StabilityRow> {
    // Three balls on a line closing in with restitution 0.05, below the 1D collapse
    // threshold 7 − 4√3 ≈ 0.072: without a guard the collisions pile up without end.
    let e = 0.05;
    let s = Scene {
        name: Some("collapse".to_owned()),
        world: World {
            restitution: e,
            ..World::default()
        },
        balls: vec![
            BallSpec::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0), 0.1, 1.0),
            BallSpec::new(Vector2::new(0.21, 0.0), Vector2::zeros(), 0.1, 1.0),
            BallSpec::new(Vector2::new(0.42, 0.0), Vector2::new(-0.8, 0.0), 0.1, 1.0),
        ],
        boxes: Vec::new(),
    };
    let t = 1.0;
    let p0: Vector2<f64> = s.balls.iter().map(|b| b.vel * b.mass).sum();
    CAROM
        .iter()
        .map(|&m| {
            let case = format!(
                "inelastic collapse (3 balls, e = 0.05), {}: ends, keeps momentum, no overlap",
                engine_name(m)
            );
            match carom(&s, m, t) {
                Ok(o) => {
                    let p: Vector2<f64> = o.vel.iter().sum();
                    let perr = (p - p0).norm();
                    let overlap = (0..3)
                        .flat_map(|i| (i + 1..3).map(move |j| (i, j)))
                        .map(|(i, j)| 0.2 - (o.pos[j] - o.pos[i]).norm())
                        .fold(f64::NEG_INFINITY, f64::max);
                    let spread = (o.vel[2] - o.vel[0]).norm();
                    let count = o.counters.map_or(0, |c| c.ball_ball);
                    row(
                        case,
                        perr <= 1e-12 && overlap <= 1e-9,
                        format!(
                            "{count} collisions; momentum error {perr:.1e} (bound 1e-12), deepest overlap {:.1e} m (bound 1e-9), final velocity spread {spread:.1e} m/s",
                            overlap.max(0.0)
                        ),
                    )
                }
                Err(why) => row(case, false, format!("failed: {why}")),
            }
        })
        .collect()
}

fn zeno() -> Vec<StabilityRow> {
    let (h, e, g, r) = (1.0, 0.5, 9.81, 0.1);
    let s = classic::ball_drop::<2>(h, e);
    // The bounces sum to t₀ + 2 e v₀ / (g (1 − e)) = 1.355 s; after 10 s the ball rests.
    let t = 10.0;
    CAROM
        .iter()
        .map(|&m| {
            let case = format!(
                "Zeno bouncing (drop from 1 m, e = 0.5), {}: comes to rest on the floor",
                engine_name(m)
            );
            match carom(&s, m, t) {
                Ok(o) => {
                    let height = o.pos[0].y - r;
                    let speed = o.vel[0].norm();
                    let count = o.counters.map_or(0, |c| c.ball_border);
                    let st = BallStates {
                        pos: o.pos.clone(),
                        vel: o.vel.clone(),
                        spin: vec![nalgebra::Vector1::zeros()],
                    };
                    let energy = observe::energy(&s, &st) - s.balls[0].mass * g * r;
                    row(
                        case,
                        height.abs() <= 1e-9 && speed <= 1e-9 && energy.abs() <= 1e-8,
                        format!(
                            "{count} bounces reported; height {height:.1e} m, speed {speed:.1e} m/s (bounds 1e-9), energy above rest {energy:.1e} J"
                        ),
                    )
                }
                Err(why) => row(case, false, format!("failed: {why}")),
            }
        })
        .collect()
}
