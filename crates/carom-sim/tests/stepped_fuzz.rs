//! A small robustness campaign in CI: the stepped engine on the 60 random scenes of seed
//! 1127 (`carom_sim::scenes::fuzz`), every integrator in `f64` and the two of the `f32`
//! campaign, checked at every sample against the invariants the engine promises. The
//! `stepped_fuzz` example runs the full campaign (2 s, with figures); this runs 0.5 s of
//! each scene.
//!
//! In `f64` no ball may sink into another ball or a box, or reach out of the border, by
//! more than 1e-8 m (the full campaign's largest is 2.0e-9 m; the defects earlier
//! campaigns found reached 1.1e-3 m), no state may be non-finite, and the
//! energy may not rise in a scene without a moving box. A run may end early only with
//! an error the engine names (a crushed ball, a cluster spinning too fast for the step,
//! a speed the periodic window cannot follow, an overflow) or a planner's refusal of a
//! step too long for the scene's drag. In `f32` the states must stay finite and the
//! errors named; how far `f32` runs sink is measured by the example, not bounded here
//! (docs/stepped.md: a ball far from the origin moving less than half a unit of its
//! coordinates per step does not move at all, and a moving box sinks into it).

use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::scene::{LoadedScene, Scene, parse_scene};
use carom_sim::scenes::fuzz::{Invariants, failure_kind, scene_text};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Simulation};
use carom_toi::Direction;
use nalgebra::Const;
use rayon::prelude::*;

const SEED: u64 = 1127;
const SCENES: usize = 60;
const DT: f64 = 0.01;
const UNTIL: f64 = 0.5;
/// The largest overlap or reach out of the border allowed in `f64` (m).
const F64_EXCURSION: f64 = 1e-8;
/// The largest energy rise allowed, over the scene's energy scale.
const ENERGY_RISE: f64 = 1e-9;

/// Runs scene `text` with `integrator` in `T` and checks every sample; returns a
/// description of the first broken promise.
fn check_run<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    integrator: Integrator,
    bounded: bool,
) -> Result<(), String>
where
    Const<D>: Space<T, D> + Space<f64, D>,
{
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(integrator),
        dt: Some(DT),
        broad: BroadChoice::Auto,
    };
    let p = match plan(scene, &options) {
        Ok(p) => p,
        Err(e) if failure_kind(&e.0) == Some("drag-refusal") => return Ok(()),
        Err(e) => return Err(format!("refused: {}", e.0)),
    };
    let mut sim = SteppedEngine::new(scene, &p, Direction::Forward).map_err(|e| e.to_string())?;
    let mut states = BallStates::default();
    sim.states(&mut states);
    let invariants = Invariants::new(scene, &states);
    for k in 1..=(UNTIL / DT).round() as u32 {
        let t = f64::from(k) * DT;
        if let Err(e) = sim.advance_to(T::lit(t), &mut ()) {
            // A run may end early only with an error the engine names.
            return if failure_kind(&e.message).is_some() {
                Ok(())
            } else {
                Err(format!("an unnamed error: {e}"))
            };
        }
        sim.states(&mut states);
        let sample = invariants.sample(scene, &states, t, DT);
        if !sample.finite {
            return Err(format!("a non-finite state at {t} s"));
        }
        if bounded && sample.worst() > F64_EXCURSION {
            return Err(format!("at {t} s: {sample:?}"));
        }
        if bounded && sample.energy_rise.is_some_and(|r| r > ENERGY_RISE) {
            return Err(format!("the energy rose at {t} s: {sample:?}"));
        }
    }
    Ok(())
}

/// Every run of the campaign in precision `f32` or not, with `integrators`; panics
/// listing every failed run.
fn campaign(f32: bool, integrators: &[Integrator]) {
    let runs: Vec<(usize, Integrator)> = (0..SCENES)
        .flat_map(|k| integrators.iter().map(move |&i| (k, i)))
        .collect();
    let failures: Vec<String> = runs
        .par_iter()
        .filter_map(|&(k, integrator)| {
            let loaded = parse_scene(&scene_text(SEED, k)).expect("the generator's scenes load");
            let result = match (loaded, f32) {
                (LoadedScene::D2(s), false) => check_run(&s, integrator, true),
                (LoadedScene::D3(s), false) => check_run(&s, integrator, true),
                // A scene that does not survive rounding to f32 is refused, as it must be.
                (LoadedScene::D2(s), true) => s
                    .cast::<f32>()
                    .map_or(Ok(()), |s| check_run(&s, integrator, false)),
                (LoadedScene::D3(s), true) => s
                    .cast::<f32>()
                    .map_or(Ok(()), |s| check_run(&s, integrator, false)),
            };
            result.err().map(|e| format!("s{k:02} {integrator}: {e}"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn random_scenes_in_f64_keep_every_promise_with_every_integrator() {
    campaign(false, &Integrator::ALL);
}

#[test]
fn random_scenes_in_f32_stay_finite_and_end_only_with_named_errors() {
    campaign(true, &[Integrator::SemiImplicitEuler, Integrator::Exact]);
}
