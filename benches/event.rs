//! The event-driven engine's throughput: collisions per second on one core.
//!
//! Scenes (carom-sim's shared gas generator): 3D hard spheres in a periodic box at
//! packing fraction 0.45 (N = 32,000: the target, beside Smallenburg's EDMD,
//! measured at 0.78–0.80 M collisions/s on this project's current VM, docs/event-engine.md) and
//! 2D discs at area fraction 0.3
//! (N = 100,000). Each gas is first run for two time units so the lattice start has
//! relaxed; then each criterion iteration advances it by a fixed time span whose
//! collision count is measured beforehand (stable to about 1 % at these sizes), which
//! criterion turns into collisions per second.
//!
//! `CAROM_BENCH_QUICK=1` uses N = 4,000 and 10,000 for a fast check.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::time::Duration;

use carom::sim::plan::{BroadChoice, Plan};
use carom::sim::scenes::gas::{GasParams, gas};
use carom::sim::{EventEngine, Simulation};
use carom::toi::Direction;

fn plan() -> Plan {
    Plan::event(BroadChoice::Auto)
}

macro_rules! gas_bench {
    ($c:expr, $name:literal, $dim:literal, $n:expr, $phi:expr) => {{
        let p = GasParams {
            n: $n,
            fraction: $phi,
            periodic: true,
            seed: 7,
            ..GasParams::default()
        };
        let scene = gas::<$dim>(&p).expect("a valid gas");
        let mut sim = EventEngine::new(&scene, &plan(), Direction::Forward).expect("runs");
        sim.advance_to(2.0, &mut ()).expect("relaxes");
        // A span with about 100,000 collisions.
        let before = sim.counters().ball_ball;
        sim.advance_to(2.1, &mut ()).expect("runs");
        let per_tenth = (sim.counters().ball_ball - before).max(1);
        let span = 0.1 * 100_000.0 / per_tenth as f64;
        let mut t = sim.time();
        let before = sim.counters().ball_ball;
        sim.advance_to(t + span, &mut ()).expect("runs");
        let per_span = sim.counters().ball_ball - before;
        t = sim.time();
        let mut group = $c.benchmark_group($name);
        group.throughput(Throughput::Elements(per_span));
        group
            .sample_size(10)
            .measurement_time(Duration::from_secs(20));
        group.bench_function(BenchmarkId::from_parameter($n), |b| {
            b.iter(|| {
                t += span;
                sim.advance_to(t, &mut ()).expect("runs");
            });
        });
        group.finish();
    }};
}

fn event_engine(c: &mut Criterion) {
    let quick = std::env::var_os("CAROM_BENCH_QUICK").is_some();
    let (n3, n2) = if quick {
        (4_000, 10_000)
    } else {
        (32_000, 100_000)
    };
    gas_bench!(c, "event/3d-hard-spheres-phi0.45", 3, n3, 0.45);
    gas_bench!(c, "event/2d-discs-phi0.3", 2, n2, 0.3);
}

criterion_group!(benches, event_engine);
criterion_main!(benches);
