//! Throughput probe of the event engine on a hard-sphere gas (development tool).
use std::time::Instant;

use carom_sim::plan::{BroadChoice, Plan};
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::{BallStates, EngineKind, EventEngine, Simulation};
use carom_toi::Direction;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(32000, |s| s.parse().unwrap());
    let phi: f64 = args.get(2).map_or(0.45, |s| s.parse().unwrap());
    let dim: usize = args.get(3).map_or(3, |s| s.parse().unwrap());
    let t: f64 = args.get(4).map_or(1.0, |s| s.parse().unwrap());
    let p = GasParams {
        n,
        fraction: phi,
        periodic: true,
        ..GasParams::default()
    };
    let plan = Plan {
        engine: EngineKind::Event,
        reason: "",
        integrator: None,
        dt: None,
        broad: BroadChoice::Auto,
    };
    macro_rules! go { ($d:literal) => {{
        let scene = gas::<$d>(&p).unwrap();
        let start = Instant::now();
        let mut sim = EventEngine::new(&scene, &plan, Direction::Forward).unwrap();
        let setup = start.elapsed().as_secs_f64();
        let mut st = BallStates::default();
        sim.states(&mut st);
        let e0 = carom_sim::observe::energy(&scene, &st);
        let start = Instant::now();
        sim.advance_to(t, &mut ()).unwrap();
        let wall = start.elapsed().as_secs_f64();
        sim.states(&mut st);
        let e1 = carom_sim::observe::energy(&scene, &st);
        let c = sim.counters().ball_ball;
        let b = scene.world.border.unwrap().border;
        let mut worst = f64::INFINITY;
        if n <= 8000 { for i in 0..n { for j in i+1..n {
            let d = b.minimum_image(&(st.pos[j] - st.pos[i])).norm() - 1.0;
            worst = worst.min(d);
        }}}
        println!("min gap {worst:.3e}");
        println!("{}D n={n} phi={phi}: setup {setup:.3}s, {c} collisions in {wall:.3}s = {:.3} M/s, dE/E = {:.2e}", $d, c as f64 / wall / 1e6, (e1-e0)/e0);
    }}}
    if dim == 3 { go!(3) } else { go!(2) }
}
