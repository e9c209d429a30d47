//! `f32` against `f64`, 1 against 2 threads (bit-identical), and bad input rejected with
//! the field named.

use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::observe;
use carom_sim::scene::Scene;
use carom_sim::scenes::classic;
use carom_sim::scenes::gas::{GasParams, gas};
use nalgebra::{Const, Vector2};

use super::{Sizes, row};
use crate::engines::{self, BuildError, Method};
use crate::model::StabilityRow;

/// The stepped engine as these cases run it.
const STEPPED: Method = Method::Stepped(Integrator::SemiImplicitEuler, 1.0 / 60.0);

/// The rows of every robustness case.
pub(super) fn rows(sizes: &Sizes) -> Vec<StabilityRow> {
    let mut rows = precision(sizes);
    rows.push(threads(sizes));
    rows.extend(bad_input());
    rows
}

/// Relative energy change of `scene` over `t` seconds in `method`.
fn energy_drift<T: Real>(scene: &Scene<T, 2>, method: Method, t: f64) -> Result<f64, String>
where
    Const<2>: Space<T, 2>,
{
    let mut sim = engines::build(scene, method).map_err(|e| e.to_string())?;
    let e0 = observe::energy(scene, &engines::states(sim.as_ref())).to_f64();
    sim.advance_to(T::lit(t), &mut ())
        .map_err(|e| e.to_string())?;
    let e1 = observe::energy(scene, &engines::states(sim.as_ref())).to_f64();
    Ok((e1 - e0) / e0)
}

fn precision(sizes: &Sizes) -> Vec<StabilityRow> {
    let mut rows = Vec::new();
    // A head-on pair: f32 must agree with f64 to a few f32 ulps.
    let s64 = classic::head_on(1.0, 3.0, 2.0, -1.0, 0.7);
    let s32 = s64.cast::<f32>().expect("the pair fits f32");
    for m in [Method::Event, STEPPED] {
        let case = format!("f32 against f64, head-on 1:3, {}", m.name());
        let run = || -> Result<f64, String> {
            let mut a = engines::build(&s64, m).map_err(|e| e.to_string())?;
            let mut b = engines::build(&s32, m).map_err(|e| e.to_string())?;
            a.advance_to(2.0, &mut ()).map_err(|e| e.to_string())?;
            b.advance_to(2.0, &mut ()).map_err(|e| e.to_string())?;
            let (x, y) = (engines::states(a.as_ref()), engines::states(b.as_ref()));
            Ok(x.vel
                .iter()
                .zip(&y.vel)
                .map(|(u, w)| (u - w.map(f64::from)).norm() / u.norm())
                .fold(0.0, f64::max))
        };
        rows.push(match run() {
            Ok(d) => row(
                case,
                d <= 1e-6,
                format!(
                    "largest relative velocity difference {d:.1e} (bound 1e-6; f32 ε = 1.2e-7)"
                ),
            ),
            Err(why) => row(case, false, format!("failed: {why}")),
        });
    }
    // An elastic gas: energy drift in each precision.
    let g64 = gas::<2>(&GasParams {
        n: sizes.precision_gas,
        fraction: 0.3,
        ..GasParams::default()
    })
    .expect("a valid gas");
    let g32 = g64.cast::<f32>().expect("the gas fits f32");
    let t = sizes.precision_seconds;
    for m in [Method::Event, STEPPED] {
        let case = format!(
            "f32 against f64, elastic gas of {} for {t} s, {}: energy kept to each precision",
            sizes.precision_gas,
            m.name()
        );
        rows.push(match (energy_drift(&g64, m, t), energy_drift(&g32, m, t)) {
            (Ok(d64), Ok(d32)) => row(
                case,
                d64.abs() <= 1e-12 && d32.abs() <= 1e-4,
                format!("energy drift f64 {d64:.1e} (bound 1e-12), f32 {d32:.1e} (bound 1e-4)"),
            ),
            (Err(why), _) | (_, Err(why)) => row(case, false, format!("failed: {why}")),
        });
    }
    rows
}

fn threads(sizes: &Sizes) -> StabilityRow {
    let s = gas::<2>(&GasParams {
        n: sizes.threads_gas,
        fraction: 0.3,
        ..GasParams::default()
    })
    .expect("a valid gas");
    let t = sizes.threads_steps as f64 / 60.0;
    let hash_on = |threads: usize| -> Result<(u64, u64), String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        pool.install(|| {
            let mut sim = engines::build(&s, STEPPED).map_err(|e| e.to_string())?;
            sim.advance_to(t, &mut ()).map_err(|e| e.to_string())?;
            Ok((
                observe::state_hash(&engines::states(sim.as_ref())),
                sim.counters().ball_ball,
            ))
        })
    };
    let case = format!(
        "1 against 2 threads, stepped engine, gas of {} for {} steps: bit-identical",
        sizes.threads_gas, sizes.threads_steps
    );
    match (hash_on(1), hash_on(2)) {
        (Ok((h1, c1)), Ok((h2, c2))) => row(
            case,
            h1 == h2 && c1 == c2,
            format!("state hash {h1:016x} on 1 thread, {h2:016x} on 2 ({c1} and {c2} collisions)"),
        ),
        (Err(why), _) | (_, Err(why)) => row(case, false, format!("failed: {why}")),
    }
}

/// A bad scene (or option) and the field its error must name.
struct Bad {
    what: &'static str,
    field: &'static str,
    scene: Scene<f64, 2>,
    method: Method,
}

fn bad_input() -> Vec<StabilityRow> {
    let base = || classic::ball_drop::<2>(1.0, 0.5);
    let mut cases = Vec::new();
    let mut push = |what, field, edit: &dyn Fn(&mut Scene<f64, 2>), method| {
        let mut scene = base();
        edit(&mut scene);
        cases.push(Bad {
            what,
            field,
            scene,
            method,
        });
    };
    push(
        "NaN position",
        "balls[0].pos[1]",
        &|s| s.balls[0].pos.y = f64::NAN,
        Method::Event,
    );
    push(
        "infinite velocity",
        "balls[0].vel[0]",
        &|s| s.balls[0].vel.x = f64::INFINITY,
        STEPPED,
    );
    push(
        "negative radius",
        "balls[0].radius",
        &|s| s.balls[0].radius = -0.1,
        Method::Event,
    );
    push(
        "zero mass",
        "balls[0].mass",
        &|s| s.balls[0].mass = 0.0,
        STEPPED,
    );
    push(
        "restitution 1.5",
        "world.restitution",
        &|s| s.world.restitution = 1.5,
        Method::Event,
    );
    push(
        "wall restitution −0.1",
        "world.border.restitution",
        &|s| {
            if let Some(b) = s.world.border.as_mut() {
                b.restitution = -0.1;
            }
        },
        STEPPED,
    );
    push(
        "negative drag",
        "world.drag",
        &|s| s.world.drag = -1.0,
        STEPPED,
    );
    push(
        "ball outside the border",
        "balls[0].pos",
        &|s| s.balls[0].pos = Vector2::new(5.0, 1.0),
        Method::Event,
    );
    push(
        "zero step",
        "--dt",
        &|_| {},
        Method::Stepped(Integrator::SemiImplicitEuler, 0.0),
    );
    let mut rows: Vec<StabilityRow> = cases
        .iter()
        .map(|c| {
            let case = format!("bad input rejected: {} ({})", c.what, c.method.name());
            match engines::build(&c.scene, c.method) {
                Err(BuildError::Scene(e)) => row(case, e.field == c.field, e.to_string()),
                Err(BuildError::Plan(e)) => row(case, e.0.starts_with(c.field), e.to_string()),
                Ok(_) => row(case, false, "accepted"),
            }
        })
        .collect();
    // f64 values beyond f32's range are refused when the scene is cast, not rounded to inf.
    let mut huge = base();
    huge.balls[0].vel.x = 1e39;
    let case = "bad input rejected: 1e39 m/s cast to f32";
    rows.push(match huge.cast::<f32>() {
        Err(e) => row(case, e.field == "balls[0].vel[0]", e.to_string()),
        Ok(_) => row(case, false, "accepted (rounded to infinity)"),
    });
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_input_rows_name_the_field() {
        for r in bad_input() {
            assert!(r.pass, "{}: {}", r.case, r.figure);
        }
    }
}
