//! The pile test's drop (`tests/stepped_resting.rs`, `drop_rows_of_balls`) over many
//! draws of its generator: for each seed, 300 steps of rows of 16 balls dropped into a
//! box 10 m wide (restitution 0.2, friction 0.3, semi-implicit Euler unless `INTEGRATOR`
//! names another, `dt = 1/60`), the
//! steps whose energy rose beyond what the narrow phase's allowance lets the pile's
//! weight do, the largest such rise (in allowances and as a fraction of the energy),
//! the fastest ball at 4 s and the run's wall time.
//!
//! ```sh
//! cargo run --release -p carom-sim --example pile_draws -- [ROWS] [SEEDS] [FIRST] [DIM] [INTEGRATOR]
//! cargo run --release -p carom-sim --example pile_draws -- 6 18
//! cargo run --release -p carom-sim --example pile_draws -- 4 18 0 3 verlet
//! ```
//!
//! The scenes are `carom_sim::scenes::pile::dropped_rows` (seed 0 is the test's own
//! draw). `DIM` 3 drops the balls in square layers of 4×4 into a box 2.5 m wide instead
//! (64 balls for 4 layers), the 3D check of `docs/stepped.md`.

use std::time::Instant;

use carom_integrate::Integrator;
use carom_math::Space;
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::scenes::pile;
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Simulation, observe};
use carom_toi::Direction;
use nalgebra::Const;

fn arg<T: std::str::FromStr>(k: usize, default: T) -> T {
    std::env::args().nth(k).map_or(default, |s| {
        s.parse()
            .unwrap_or_else(|_| panic!("argument {k}: cannot parse `{s}`"))
    })
}

fn states<const D: usize>(sim: &dyn Simulation<f64, D>) -> BallStates<f64, D>
where
    Const<D>: Space<f64, D>,
{
    let mut st = BallStates::default();
    sim.states(&mut st);
    st
}

/// One draw: (steps above the allowance, largest rise in allowances, as a fraction of
/// the energy, fastest ball at 4 s, wall seconds).
fn draw<const D: usize>(rows: u32, seed: u64, integrator: Integrator) -> (usize, f64, f64, f64, f64)
where
    Const<D>: Space<f64, D>,
{
    let s = pile::dropped_rows::<D>(rows, seed);
    let dt = 1.0 / 60.0;
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(integrator),
        dt: Some(dt),
        broad: BroadChoice::Auto,
    };
    let p = plan(&s, &options).expect("a valid plan");
    let mut sim = SteppedEngine::new(&s, &p, Direction::Forward).expect("a valid scene");
    let allowance = pile::allowance(&s, dt);
    let mut before = observe::energy(&s, &states(&sim));
    let (mut above, mut worst, mut fraction, mut at_4) = (0, 0.0_f64, 0.0_f64, 0.0);
    let start = Instant::now();
    for k in 1..=300 {
        sim.advance_to(f64::from(k) * dt, &mut ())
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let st = states(&sim);
        let e = observe::energy(&s, &st);
        let rise = e - before;
        if rise > allowance {
            above += 1;
            if rise / allowance > worst {
                worst = rise / allowance;
                fraction = rise / before;
            }
        }
        if k == 240 {
            at_4 = st
                .vel
                .iter()
                .map(nalgebra::Matrix::norm)
                .fold(0.0, f64::max);
        }
        before = e;
    }
    (above, worst, fraction, at_4, start.elapsed().as_secs_f64())
}

fn main() {
    let (rows, seeds, first, dim, integrator) = (
        arg(1, 6_u32),
        arg(2, 18_u64),
        arg(3, 0_u64),
        arg(4, 2_usize),
        arg(5, Integrator::SemiImplicitEuler),
    );
    let mut times = Vec::new();
    let mut draws_above = 0;
    for k in first..first + seeds {
        let (above, worst, fraction, at_4, wall) = match dim {
            2 => draw::<2>(rows, k, integrator),
            3 => draw::<3>(rows, k, integrator),
            other => panic!("argument 4: dimension {other} is not 2 or 3"),
        };
        draws_above += usize::from(above > 0);
        times.push(wall);
        println!(
            "seed {k:>3}: {above:>3} steps above the allowance, largest {worst:>9.2}x ({fraction:.1e} of the energy); fastest at 4 s {at_4:.2e} m/s; {wall:.2} s"
        );
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{draws_above} of {seeds} draws above the allowance; median run {:.2} s",
        times[times.len() / 2]
    );
}
