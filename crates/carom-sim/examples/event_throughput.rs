//! Collisions per second of the event-driven engine on a hard-sphere gas, with the energy
//! drift and (for up to 8,000 balls) the smallest gap between any two balls at the end.
//!
//! ```sh
//! cargo run --release -p carom-sim --example event_throughput -- [N] [FRACTION] [DIM] [TIME] [RELAX] [SEARCH]
//! cargo run --release -p carom-sim --example event_throughput -- 32000 0.45 3 1
//! cargo run --release -p carom-sim --example event_throughput -- 100000 0.3 2 2 2 lists
//! ```
//!
//! Defaults: N = 32,000, packing fraction 0.45, 3D, 1 time unit timed after 2 untimed
//! ones (unit-diameter spheres, unit thermal speed, periodic box). The gas starts on a
//! lattice; the untimed `RELAX` lets it reach equilibrium first, as `benches/event.rs`
//! does: a relaxed gas costs more per collision than the lattice start (its lists hold
//! more partners: contacts are more likely than in a uniform gas), so a run timed from
//! the start reports more collisions per second than the engine sustains. `SEARCH` is how
//! partners are found: `auto` (the engine's choice, default), `lists` (neighbour lists)
//! or `cells` (cell lists with crossing events). The criterion
//! bench `benches/event.rs` measures the same scenes with statistics; this example is
//! the quick look.

use std::time::Instant;

use carom_sim::plan::{BroadChoice, Plan};
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::{BallStates, EventEngine, PairSearch, Simulation};
use carom_toi::Direction;

fn arg<T: std::str::FromStr>(k: usize, default: T) -> T {
    std::env::args().nth(k).map_or(default, |s| {
        s.parse()
            .unwrap_or_else(|_| panic!("argument {k}: cannot parse `{s}`"))
    })
}

fn main() {
    let (n, fraction, dim, time, relax) = (
        arg(1, 32_000usize),
        arg(2, 0.45),
        arg(3, 3usize),
        arg(4, 1.0),
        arg(5, 2.0),
    );
    let search = match arg(6, "auto".to_owned()).as_str() {
        "auto" => PairSearch::Auto,
        "lists" => PairSearch::NeighbourLists,
        "cells" => PairSearch::CellLists,
        other => panic!("argument 6: `{other}` is not one of auto, lists, cells"),
    };
    let params = GasParams {
        n,
        fraction,
        periodic: true,
        ..GasParams::default()
    };
    let plan = Plan::event(BroadChoice::Auto);
    macro_rules! run {
        ($d:literal) => {{
            let scene = gas::<$d>(&params).unwrap_or_else(|e| panic!("{e}"));
            let start = Instant::now();
            let mut sim = EventEngine::with_pair_search(&scene, &plan, Direction::Forward, search)
                .expect("a valid gas");
            let setup = start.elapsed().as_secs_f64();
            let mut st = BallStates::default();
            sim.states(&mut st);
            let e0 = carom_sim::observe::energy(&scene, &st);
            sim.advance_to(relax, &mut ()).expect("the run completes");
            let before = sim.counters().ball_ball;
            let start = Instant::now();
            sim.advance_to(relax + time, &mut ()).expect("the run completes");
            let wall = start.elapsed().as_secs_f64();
            sim.states(&mut st);
            let e1 = carom_sim::observe::energy(&scene, &st);
            let collisions = sim.counters().ball_ball - before;
            println!(
                "{}D N = {n}, fraction {fraction} ({}): setup {setup:.3} s; after {relax} untimed time units, {collisions} collisions in {wall:.3} s = {:.3} M/s; energy drift {:.1e}",
                $d,
                sim.pipeline()[1],
                collisions as f64 / wall / 1e6,
                (e1 - e0) / e0
            );
            if n <= 8_000 {
                let border = scene.world.border.expect("a gas has a box").border;
                let mut gap = f64::INFINITY;
                for i in 0..n {
                    for j in i + 1..n {
                        gap = gap.min(border.minimum_image(&(st.pos[j] - st.pos[i])).norm() - 2.0 * params.radius);
                    }
                }
                println!("smallest gap between two balls: {gap:.3e}");
            }
        }};
    }
    match dim {
        2 => run!(2),
        3 => run!(3),
        d => panic!("DIM must be 2 or 3, got {d}"),
    }
}
