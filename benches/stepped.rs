//! The time-stepped engine against rapier2d 0.36 on the same scene: an elastic gas of
//! `N` balls in a box (carom's `scenes::gas`, packing fraction 0.1, radius 0.5, thermal
//! speed 1 m/s per component), no gravity, `dt = 1/60`, one step per iteration.
//!
//! carom runs the semi-implicit Euler integrator and its automatic broad phase (a
//! uniform grid), in `f64`; rapier2d runs in `f32` with CCD on every ball, restitution
//! exactly 1 and friction 0, and its default integration parameters: the scene is built by
//! `carom_report::peer::rapier`, the peer of the report and of its tests. Both run on a
//! rayon pool of 1 and of 2 threads (rapier2d with its `parallel` feature).
//! `carom report` measures the same scene (section 3) with both engines' steps
//! interleaved.
//!
//! * `cargo bench --bench stepped`: criterion, N = 1e3 and 1e4 (and 1e5 with
//!   `CAROM_BENCH_FULL=1`), time per step.
//! * `CAROM_BENCH_TABLE=1 cargo bench --bench stepped`: prints the markdown table of
//!   docs/stepped.md instead: median milliseconds per step of both engines on 1 and 2
//!   threads, the ratio, the 2-thread speedups, and the relative energy drift of each
//!   over 5 s of simulated time (`CAROM_BENCH_SIZES=1000,10000,100000` to choose N),
//!   after the machine's own 2-thread speedups on loops that share no data
//!   (`carom_report::ceiling`), the ceilings the speedups are to be read against.

use std::hint::black_box;
use std::time::{Duration, Instant};

use carom_integrate::Integrator;
use carom_sim::plan::{EngineChoice, RunOptions, plan};
use carom_sim::scene::Scene;
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Simulation, observe};
use carom_toi::Direction;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

use carom_report::peer::rapier::RapierScene;

const DT: f64 = 1.0 / 60.0;

fn scene(n: usize) -> Scene<f64, 2> {
    gas::<2>(&GasParams {
        n,
        ..GasParams::default()
    })
    .expect("a valid gas")
}

/// rapier2d holding `s`.
fn rapier_scene(s: &Scene<f64, 2>) -> RapierScene {
    RapierScene::new(s, DT).expect("rapier2d holds an elastic gas in a box")
}

/// carom's stepped engine on `s`, stepping one grid step per call.
struct Carom {
    sim: SteppedEngine<f64, 2>,
    steps: u64,
}

impl Carom {
    fn new(s: &Scene<f64, 2>) -> Self {
        let options = RunOptions {
            engine: EngineChoice::Stepped,
            integrator: Some(Integrator::SemiImplicitEuler),
            dt: Some(DT),
            ..RunOptions::default()
        };
        let p = plan(s, &options).expect("a valid plan");
        Self {
            sim: SteppedEngine::new(s, &p, Direction::Forward).expect("a valid scene"),
            steps: 0,
        }
    }

    fn step(&mut self) {
        self.steps += 1;
        self.sim
            .advance_to(self.steps as f64 * DT, &mut ())
            .expect("the gas runs");
    }

    fn energy(&self, s: &Scene<f64, 2>) -> f64 {
        let mut st = BallStates::default();
        self.sim.states(&mut st);
        observe::energy(s, &st)
    }
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

fn sizes() -> Vec<usize> {
    if let Ok(list) = std::env::var("CAROM_BENCH_SIZES") {
        return list
            .split(',')
            .filter_map(|s| s.trim().parse().ok())
            .collect();
    }
    if std::env::var_os("CAROM_BENCH_FULL").is_some() {
        vec![1_000, 10_000, 100_000]
    } else {
        vec![1_000, 10_000]
    }
}

fn criterion_benches(c: &mut Criterion) {
    if std::env::var_os("CAROM_BENCH_TABLE").is_some() {
        print_table();
        return;
    }
    let mut group = c.benchmark_group("stepped/gas-2d");
    group.sample_size(20);
    for n in sizes() {
        let s = scene(n);
        group.throughput(Throughput::Elements(n as u64));
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut carom = pool.install(|| Carom::new(&s));
            group.bench_function(BenchmarkId::new(format!("carom {threads}t"), n), |b| {
                b.iter(|| pool.install(|| carom.step()));
            });
            let mut rapier = rapier_scene(&s);
            group.bench_function(BenchmarkId::new(format!("rapier2d {threads}t"), n), |b| {
                b.iter(|| pool.install(|| rapier.step()));
            });
        }
    }
    group.finish();
}

/// The median wall-clock time of one call of `f` over at least 7 calls and about 1 s.
fn median_step(mut f: impl FnMut()) -> Duration {
    f();
    let mut times = Vec::new();
    let start = Instant::now();
    while times.len() < 7 || (start.elapsed() < Duration::from_secs(1) && times.len() < 200) {
        let t = Instant::now();
        f();
        times.push(t.elapsed());
    }
    times.sort();
    times[times.len() / 2]
}

/// Relative energy change over 5 s of simulated time (300 steps), from a fresh start.
fn drifts(s: &Scene<f64, 2>) -> (f64, f64) {
    let mut carom = Carom::new(s);
    let e0 = carom.energy(s);
    for _ in 0..300 {
        carom.step();
    }
    let carom_drift = (carom.energy(s) - e0) / e0;
    let mut rapier = rapier_scene(s);
    let r0 = rapier.kinetic_energy();
    for _ in 0..300 {
        rapier.step();
    }
    (carom_drift, (rapier.kinetic_energy() - r0) / r0)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn print_table() {
    let (one, two) = (pool(1), pool(2));
    println!("{}", rapier_scene(&scene(10)).settings());
    let c = carom_report::ceiling::measure(&carom_report::ceiling::CeilingSizes::report())
        .expect("pools of 1 and 2 threads");
    println!(
        "this machine's own 2-thread speedups now (docs/benchmarks.md): {}",
        c.speedups()
    );
    println!(
        "| N | carom 1t (ms/step) | carom 2t | rapier2d 1t | rapier2d 2t | rapier2d / carom (1t) | carom 2t speedup | rapier2d 2t speedup | energy drift 5 s: carom | rapier2d |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for n in sizes() {
        let s = scene(n);
        let mut times = [Duration::ZERO; 4];
        for (k, p) in [&one, &two].into_iter().enumerate() {
            let mut carom = p.install(|| Carom::new(&s));
            times[k] = p.install(|| median_step(|| carom.step()));
            let mut rapier = rapier_scene(&s);
            times[2 + k] = p.install(|| median_step(|| rapier.step()));
            black_box(&carom.sim);
        }
        let (carom_drift, rapier_drift) = one.install(|| drifts(&s));
        println!(
            "| {n} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1}× | {:.2}× | {:.2}× | {carom_drift:.1e} | {rapier_drift:.1e} |",
            ms(times[0]),
            ms(times[1]),
            ms(times[2]),
            ms(times[3]),
            times[2].as_secs_f64() / times[0].as_secs_f64(),
            times[0].as_secs_f64() / times[1].as_secs_f64(),
            times[2].as_secs_f64() / times[3].as_secs_f64(),
        );
    }
}

criterion_group!(benches, criterion_benches);
criterion_main!(benches);
