//! Section 3, engine throughput: the stepped engine against rapier2d on the same gas, and
//! the event-driven engine's collisions per second in 2D and 3D.
//!
//! **Stepped engine.** The elastic gas of [`carom_sim::scenes::gas`] (packing fraction
//! 0.1, radius 0.5, thermal speed 1 m/s, restitution 1, no gravity) in a box, stepped at
//! `dt = 1/60` (the scene of `benches/stepped.rs`): carom with the semi-implicit Euler
//! integrator and its automatic broad phase in `f64`, rapier2d 0.36 through
//! [`crate::peer::rapier`] (`f32`, CCD on, exact restitution 1, friction 0). Both start
//! from the same state on a rayon pool of the given size, and their steps alternate, each
//! timed alone, so both see the same load of a shared machine. A row's `ms_per_step` is
//! the median step; its `energy_drift` the relative change of kinetic energy over the
//! whole run (300 steps = 5 s of simulated time in the quick and full reports).
//!
//! **Event-driven engine.** Hard discs (2D, area fraction 0.3) and hard spheres (3D,
//! packing fraction 0.45) in a periodic box, unit diameter and thermal speed (the scenes
//! of `benches/event.rs`). The gas first relaxes from its lattice start; then each sample
//! advances it by a span of about 0.2 s of wall-clock time, and the row holds the median of
//! the samples' collisions per second (ball–ball collisions, from the engine's counters)
//! and the relative energy change from the start to the end. The engine runs on one core.

use carom_integrate::Integrator;
use carom_math::Space;
use carom_sim::plan::{BroadChoice, EngineChoice, Plan, RunOptions, plan};
use carom_sim::scene::Scene;
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, EventEngine, Simulation, observe};
use carom_toi::Direction;
use nalgebra::Const;

use crate::error::ReportError;
use crate::model::ThroughputRow;
use crate::timing::{Sampling, median, timed};

/// The stepped gas's step (s).
pub const GAS_DT: f64 = 1.0 / 60.0;

/// The stepped gas's scene name in the rows.
pub const STEPPED_SCENE: &str = "gas2d-phi0.1";

/// The 2D event-driven scene's name in the rows.
pub const EVENT_2D_SCENE: &str = "discs2d-phi0.3-periodic";

/// The 3D event-driven scene's name in the rows.
pub const EVENT_3D_SCENE: &str = "spheres3d-phi0.45-periodic";

/// Engine names of the rows.
pub mod engine {
    /// carom's time-stepped engine.
    pub const STEPPED: &str = "carom-stepped";
    /// carom's event-driven engine.
    pub const EVENT: &str = "carom-event";
    /// rapier2d 0.36.
    pub const RAPIER: &str = "rapier2d";
}

/// The stepped engines' gas of `n` balls (module docs).
///
/// # Errors
/// `n = 0`.
pub fn stepped_gas(n: usize) -> Result<Scene<f64, 2>, ReportError> {
    gas::<2>(&GasParams {
        n,
        ..GasParams::default()
    })
    .map_err(ReportError::case(STEPPED_SCENE))
}

/// One engine stepping the gas.
trait Stepper {
    /// The engine's name in the rows.
    fn engine(&self) -> &'static str;
    /// One step of [`GAS_DT`].
    fn step(&mut self) -> Result<(), ReportError>;
    /// The balls' kinetic energy.
    fn energy(&self) -> f64;
}

/// carom's stepped engine on the gas.
struct CaromStepped<'a> {
    scene: &'a Scene<f64, 2>,
    sim: SteppedEngine<f64, 2>,
    steps: u32,
}

impl<'a> CaromStepped<'a> {
    fn new(scene: &'a Scene<f64, 2>) -> Result<Self, ReportError> {
        let options = RunOptions {
            engine: EngineChoice::Stepped,
            integrator: Some(Integrator::SemiImplicitEuler),
            dt: Some(GAS_DT),
            ..RunOptions::default()
        };
        let case = ReportError::case(STEPPED_SCENE);
        let p = plan(scene, &options).map_err(case)?;
        let sim = SteppedEngine::new(scene, &p, Direction::Forward)
            .map_err(ReportError::case(STEPPED_SCENE))?;
        Ok(Self {
            scene,
            sim,
            steps: 0,
        })
    }
}

impl Stepper for CaromStepped<'_> {
    fn engine(&self) -> &'static str {
        engine::STEPPED
    }

    fn step(&mut self) -> Result<(), ReportError> {
        self.steps += 1;
        self.sim
            .advance_to(f64::from(self.steps) * GAS_DT, &mut ())
            .map_err(ReportError::case(STEPPED_SCENE))
    }

    fn energy(&self) -> f64 {
        let mut states = BallStates::default();
        self.sim.states(&mut states);
        observe::energy(self.scene, &states)
    }
}

#[cfg(feature = "rapier")]
impl Stepper for crate::peer::rapier::RapierScene {
    fn engine(&self) -> &'static str {
        engine::RAPIER
    }

    fn step(&mut self) -> Result<(), ReportError> {
        crate::peer::rapier::RapierScene::step(self);
        Ok(())
    }

    fn energy(&self) -> f64 {
        self.kinetic_energy()
    }
}

/// A rayon pool of `threads` threads.
pub(crate) fn pool(threads: usize) -> Result<rayon::ThreadPool, ReportError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(ReportError::case("thread pool"))
}

/// The stepped gas of `n` balls on `threads` threads for `steps` steps: one row per
/// engine (carom, and rapier2d with the `rapier` feature).
///
/// # Errors
/// A scene or run failure (a bug), or no thread pool.
pub fn stepped(n: usize, threads: usize, steps: usize) -> Result<Vec<ThroughputRow>, ReportError> {
    let scene = stepped_gas(n)?;
    pool(threads)?.install(|| {
        let mut engines: Vec<Box<dyn Stepper + '_>> = vec![Box::new(CaromStepped::new(&scene)?)];
        #[cfg(feature = "rapier")]
        engines.push(Box::new(
            crate::peer::rapier::RapierScene::new(&scene, GAS_DT)
                .map_err(ReportError::case(STEPPED_SCENE))?,
        ));
        let start: Vec<f64> = engines.iter().map(|e| e.energy()).collect();
        let mut times = vec![Vec::with_capacity(steps); engines.len()];
        for _ in 0..steps {
            for (e, t) in engines.iter_mut().zip(&mut times) {
                let (result, d) = timed(|| e.step());
                result?;
                t.push(d);
            }
        }
        Ok(engines
            .iter()
            .zip(&mut times)
            .zip(start)
            .map(|((e, t), e0)| ThroughputRow {
                scene: STEPPED_SCENE.to_owned(),
                engine: e.engine().to_owned(),
                n,
                threads,
                ms_per_step: Some(median(t).as_secs_f64() * 1e3),
                collisions_per_s: None,
                energy_drift: Some((e.energy() - e0) / e0),
            })
            .collect())
    })
}

/// The event-driven scene of `D` dimensions (area fraction 0.3 in 2D, packing fraction
/// 0.45 in 3D), with its row name.
fn event_scene<const D: usize>(n: usize) -> Result<(Scene<f64, D>, &'static str), ReportError> {
    let (fraction, name) = if D == 2 {
        (0.3, EVENT_2D_SCENE)
    } else {
        (0.45, EVENT_3D_SCENE)
    };
    let scene = gas::<D>(&GasParams {
        n,
        fraction,
        periodic: true,
        seed: 7,
        ..GasParams::default()
    })
    .map_err(ReportError::case(name))?;
    Ok((scene, name))
}

/// The event-driven engine's throughput on the `D`-dimensional gas of `n` balls: relax
/// for `relax` time units, then sample (module docs).
///
/// # Errors
/// A scene or run failure (a bug).
pub fn event<const D: usize>(
    n: usize,
    relax: f64,
    sampling: Sampling,
) -> Result<ThroughputRow, ReportError>
where
    Const<D>: Space<f64, D>,
{
    let (scene, name) = event_scene::<D>(n)?;
    let case = |e: &dyn std::fmt::Display| ReportError::Case {
        case: format!("{name} N={n}"),
        message: e.to_string(),
    };
    let event_plan = Plan::event(BroadChoice::Auto);
    let mut sim =
        EventEngine::new(&scene, &event_plan, Direction::Forward).map_err(|e| case(&e))?;
    let mut states = BallStates::default();
    sim.states(&mut states);
    let e0 = observe::energy(&scene, &states);
    let advance = |sim: &mut EventEngine<f64, D>, span: f64| {
        let (before, t) = (sim.counters().ball_ball, sim.time());
        let (result, d) = timed(|| sim.advance_to(t + span, &mut ()));
        result.map(|()| (sim.counters().ball_ball - before, d))
    };
    advance(&mut sim, relax).map_err(|e| case(&e))?;
    // Calibrate a span of about 0.2 s of wall-clock time from a short one.
    let mut span = 0.01;
    let per_sample = sampling.budget.as_secs_f64().clamp(0.02, 0.2);
    loop {
        let (_, d) = advance(&mut sim, span).map_err(|e| case(&e))?;
        if d.as_secs_f64() >= 0.02 {
            span *= per_sample / d.as_secs_f64();
            break;
        }
        span *= 4.0;
    }
    let mut rates = Vec::new();
    let start = std::time::Instant::now();
    while rates.len() < sampling.min_samples.max(1) || start.elapsed() < sampling.budget {
        let (collisions, d) = advance(&mut sim, span).map_err(|e| case(&e))?;
        rates.push(collisions as f64 / d.as_secs_f64());
    }
    rates.sort_unstable_by(f64::total_cmp);
    sim.states(&mut states);
    Ok(ThroughputRow {
        scene: name.to_owned(),
        engine: engine::EVENT.to_owned(),
        n,
        threads: 1,
        ms_per_step: None,
        collisions_per_s: Some(rates[rates.len() / 2]),
        energy_drift: Some((observe::energy(&scene, &states) - e0) / e0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_stepped_run_gives_a_row_per_engine_with_its_drift() {
        let rows = stepped(200, 1, 12).unwrap();
        let carom = &rows[0];
        assert_eq!(carom.engine, engine::STEPPED);
        assert_eq!((carom.n, carom.threads), (200, 1));
        assert!(carom.ms_per_step.unwrap() > 0.0);
        // The elastic gas keeps its energy to rounding (the stepped engine's tests).
        assert!(carom.energy_drift.unwrap().abs() < 1e-12, "{carom:?}");
        #[cfg(feature = "rapier")]
        {
            assert_eq!(rows.len(), 2);
            assert_eq!(rows[1].engine, engine::RAPIER);
            assert!(rows[1].energy_drift.unwrap().is_finite());
        }
    }

    #[test]
    fn an_event_run_counts_collisions_and_keeps_energy() {
        let sampling = Sampling {
            min_samples: 2,
            budget: Duration::ZERO,
        };
        for row in [
            event::<2>(400, 0.5, sampling).unwrap(),
            event::<3>(300, 0.5, sampling).unwrap(),
        ] {
            assert!(row.collisions_per_s.unwrap() > 0.0, "{row:?}");
            assert!(row.energy_drift.unwrap().abs() < 1e-10, "{row:?}");
            assert!(row.ms_per_step.is_none());
        }
    }
}
