//! Broad-phase benchmarks: carom's sweep-and-prune, k-d tree and grids against parry's
//! BVH, on the shared scenes of `carom_broad::scenes`.
//!
//! One measured frame is `update` + `pairs` (or `par_update` + `par_pairs` on a pool of
//! 2 threads):
//! everything a stepped engine pays per step. One-shot frames alternate between two
//! unrelated scenes; coherent frames alternate between a scene and the same scene with
//! every ball moved by 1 % of its radius. Throughput is in balls, so criterion's
//! "elements/s" is the inverse of the ns per ball.
//!
//! * `cargo bench --bench broad`: criterion, N = 1e3 … 1e5, uniform at packing fraction
//!   0.1 and clustered, 2D and 3D, one-shot and coherent, 1 and 2 threads (≈ 10 min).
//! * `CAROM_BENCH_FULL=1`: adds fraction 0.5, radii log-uniform in `[1e-3, 1]` and
//!   N = 1e6 (long: sweep-and-prune needs seconds per frame at 1e6 in 3D).
//! * `CAROM_BENCH_DISTS=uniform0.1,uniform0.5,clustered,mixed`: these scenes instead.
//! * `CAROM_BENCH_SIZES=1000,1000000`: these ball counts instead.
//! * `CAROM_BENCH_FILTER=3D`: table mode runs only the cases whose label
//!   ("3D uniform0.1 1000000 coherent") contains the text.
//! * `CAROM_BENCH_TABLE=1`: instead of criterion, prints the markdown table of
//!   docs/broad-phase.md (median of repeated frames: ns per ball, pairs per second,
//!   2-thread speedup) and the 10,000-random-boxes figure. Single-thread figures are
//!   time on CPU (Linux), so that other processes on a shared machine inflate them
//!   less; 2-thread figures are the time on CPU of the busier pool thread (what the
//!   frame takes on two otherwise idle cores: sequential parts and stolen work
//!   included), with the wall-clock time beside them.
//! * `CAROM_BENCH_ORDER=sorted`: balls numbered in a spatial order instead of the
//!   generators' random one (see [`sort_spatially`]).
//! * `CAROM_BENCH_PROFILE=phase/case/frames`: a fixed number of frames of one case, for
//!   `valgrind --tool=callgrind` or `perf record` (see [`profile`]).
//!
//! parry's BVH (f32, glam) is built with `Bvh::from_leaves(Binned)` one-shot and
//! updated with `insert_or_update_partially` + `refit` when coherent, then traversed
//! against itself (`traverse_bvtt_single_tree`); it reports box pairs, unsorted, while
//! carom's rows include the exact ball test and the sorted output. The broad phases and
//! the peer are built as `carom report` builds them (`carom_report::broad::make_phase`,
//! `carom_report::peer::parry`).

use std::hint::black_box;
use std::time::{Duration, Instant};

use carom::broad::scenes::Scene;
use carom::broad::{Pair, ParallelBroadPhase, Volumes};
use carom_report::broad::{Peer, make_phase};
use carom_report::peer::parry::{ParryBvh2, ParryBvh3};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

/// A scene distribution of the benchmark matrix.
#[derive(Clone, Copy, Debug)]
enum Distribution {
    /// Uniform at a packing fraction.
    Uniform(f64),
    /// 16 clumps, packing fraction 0.1 over the whole domain.
    Clustered,
    /// Radii log-uniform in [1e-3, 1], uniform at packing fraction 0.1.
    Mixed,
}

impl Distribution {
    fn name(self) -> String {
        match self {
            Self::Uniform(f) => format!("uniform{f}"),
            Self::Clustered => "clustered".to_owned(),
            Self::Mixed => "mixed-radii".to_owned(),
        }
    }

    fn scene<const D: usize>(self, n: usize, seed: u64) -> Scene<f64, D> {
        match self {
            Self::Uniform(f) => Scene::uniform(n, 0.5, f, 0.0, seed),
            Self::Clustered => Scene::clustered(n, 0.5, 0.1, 16, seed),
            Self::Mixed => Scene::mixed(n, 1e-3, 1.0, 0.1, seed),
        }
    }
}

/// The two frames a benchmark alternates between.
struct Frames<const D: usize> {
    frames: [Scene<f64, D>; 2],
}

impl<const D: usize> Frames<D> {
    fn new(dist: Distribution, n: usize, coherent: bool) -> Self {
        let mut a = dist.scene::<D>(n, 1);
        if sorted_order() {
            sort_spatially(&mut a);
        }
        let b = if coherent {
            let mut b = a.clone();
            b.step(0.01);
            b
        } else {
            dist.scene::<D>(n, 2)
        };
        Self { frames: [a, b] }
    }
}

/// `CAROM_BENCH_ORDER=sorted`: the balls are numbered in a spatial order (rows of cells
/// a diameter wide, as an engine that sorts its bodies now and then would have them)
/// instead of the generators' random order, so that memory is read in the order space
/// is visited.
fn sorted_order() -> bool {
    std::env::var("CAROM_BENCH_ORDER").is_ok_and(|o| o == "sorted")
}

/// Renumbers the balls of `scene` by their cell (a diameter wide), last axis slowest.
fn sort_spatially<const D: usize>(scene: &mut Scene<f64, D>) {
    let width = 2.0 * scene.radii.iter().copied().fold(0.0, f64::max).max(1e-300);
    let cell = |c: &carom::broad::Vector<f64, D>| -> [i64; D] {
        core::array::from_fn(|k| (c[D - 1 - k] / width).floor() as i64)
    };
    let mut order: Vec<usize> = (0..scene.centers.len()).collect();
    order.sort_by_key(|&i| cell(&scene.centers[i]));
    scene.centers = order.iter().map(|&i| scene.centers[i]).collect();
    scene.radii = order.iter().map(|&i| scene.radii[i]).collect();
}

/// The broad phases measured, by name.
const PHASES: [&str; 5] = carom_report::broad::METHODS;

/// One frame of a carom broad phase; returns the pair count.
fn frame<const D: usize>(
    phase: &mut dyn ParallelBroadPhase<f64, D>,
    volumes: Volumes<'_, f64, D>,
    pool: Option<&rayon::ThreadPool>,
    out: &mut Vec<Pair>,
) -> usize {
    match pool {
        None => {
            phase.update(volumes);
            phase.pairs(out);
        }
        Some(pool) => pool.install(|| {
            phase.par_update(volumes);
            phase.par_pairs(out);
        }),
    }
    out.len()
}

fn full() -> bool {
    std::env::var_os("CAROM_BENCH_FULL").is_some()
}

fn sizes() -> Vec<usize> {
    if let Ok(list) = std::env::var("CAROM_BENCH_SIZES") {
        return list
            .split(',')
            .filter_map(|x| x.trim().parse().ok())
            .collect();
    }
    if full() {
        vec![1_000, 10_000, 100_000, 1_000_000]
    } else {
        vec![1_000, 10_000, 100_000]
    }
}

fn distributions() -> Vec<Distribution> {
    if let Ok(list) = std::env::var("CAROM_BENCH_DISTS") {
        return list
            .split(',')
            .filter_map(|d| match d.trim() {
                "uniform0.1" => Some(Distribution::Uniform(0.1)),
                "uniform0.5" => Some(Distribution::Uniform(0.5)),
                "clustered" => Some(Distribution::Clustered),
                "mixed" => Some(Distribution::Mixed),
                _ => None,
            })
            .collect();
    }
    if full() {
        vec![
            Distribution::Uniform(0.1),
            Distribution::Uniform(0.5),
            Distribution::Clustered,
            Distribution::Mixed,
        ]
    } else {
        vec![Distribution::Uniform(0.1), Distribution::Clustered]
    }
}

/// Brute force only where it finishes in reasonable time; `CAROM_BENCH_PHASES=sap,grid`
/// restricts the phases.
fn runs(name: &str, n: usize) -> bool {
    let chosen =
        std::env::var("CAROM_BENCH_PHASES").map_or(true, |list| list.split(',').any(|p| p == name));
    chosen && (name != "brute" || n <= 1_000)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

// ---------------------------------------------------------------------------------
// criterion

fn bench_dim<const D: usize>(c: &mut Criterion, peer: &mut dyn FnMut() -> Box<dyn Peer<D>>) {
    let two = pool(2);
    for dist in distributions() {
        for &n in &sizes() {
            for coherent in [false, true] {
                let mode = if coherent { "coherent" } else { "oneshot" };
                let frames = Frames::<D>::new(dist, n, coherent);
                let mut group = c.benchmark_group(format!("broad/{D}d/{}/{mode}", dist.name()));
                group.throughput(Throughput::Elements(n as u64));
                group.sample_size(10);
                group.warm_up_time(Duration::from_millis(300));
                group.measurement_time(Duration::from_millis(if n >= 1_000_000 {
                    8000
                } else {
                    1200
                }));
                let mut out = Vec::new();
                for name in PHASES.into_iter().filter(|p| runs(p, n)) {
                    for threads in [1, 2] {
                        if threads == 2 && name == "brute" {
                            continue;
                        }
                        let mut phase = make_phase::<D>(name, coherent);
                        let p = (threads == 2).then_some(&two);
                        let mut k = 0usize;
                        group.bench_function(
                            BenchmarkId::new(format!("{name}/{threads}t"), n),
                            |b| {
                                b.iter(|| {
                                    k += 1;
                                    black_box(frame(
                                        phase.as_mut(),
                                        frames.frames[k % 2].balls(),
                                        p,
                                        &mut out,
                                    ))
                                });
                            },
                        );
                    }
                }
                let mut parry = peer();
                let mut k = 0usize;
                group.bench_function(BenchmarkId::new("parry-bvh/1t", n), |b| {
                    b.iter(|| {
                        k += 1;
                        black_box(parry.frame(&frames.frames[k % 2], coherent))
                    });
                });
                group.finish();
            }
        }
    }
}

fn bench_random_boxes(c: &mut Criterion) {
    let a = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 1);
    let b = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 2);
    let mut group = c.benchmark_group("broad/terdiman-10k-random-boxes");
    group.throughput(Throughput::Elements(10_000));
    let mut out = Vec::new();
    for name in ["sap", "grid", "kd"] {
        let mut phase = make_phase::<3>(name, false);
        let mut k = 0usize;
        group.bench_function(name, |bench| {
            bench.iter(|| {
                k += 1;
                let s = if k.is_multiple_of(2) { &a } else { &b };
                black_box(frame(phase.as_mut(), s.aabbs(), None, &mut out))
            });
        });
    }
    group.finish();
}

fn criterion_benches(c: &mut Criterion) {
    if let Ok(spec) = std::env::var("CAROM_BENCH_PROFILE") {
        profile(&spec);
        return;
    }
    if std::env::var_os("CAROM_BENCH_TABLE").is_some() {
        print_table();
        return;
    }
    bench_random_boxes(c);
    bench_dim::<2>(c, &mut || Box::new(ParryBvh2::default()));
    bench_dim::<3>(c, &mut || Box::new(ParryBvh3::default()));
}

// ---------------------------------------------------------------------------------
// table mode

/// The time this thread has spent on a CPU (Linux: `/proc/thread-self/schedstat`), so
/// that single-thread figures exclude the time other processes held the cores.
fn on_cpu() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(Duration::from_nanos(
        text.split_whitespace().next()?.parse().ok()?,
    ))
}

/// The median duration of one call of `f`, over at least 5 samples (~0.5 s in all):
/// each sample times a batch of calls lasting at least 25 ms (120 ms on the per-thread CPU
/// clock, which ticks in steps of a few ms on some kernels), on CPU when `cpu` is set
/// and the platform reports it (the per-thread clock ticks too coarsely for one short
/// call), wall-clock otherwise.
fn median_time(cpu: bool, mut f: impl FnMut(usize)) -> Duration {
    let clock = || if cpu { on_cpu() } else { None };
    let t = Instant::now();
    f(0);
    f(1);
    let per_call = t.elapsed() / 2;
    let target = if cpu {
        Duration::from_millis(120)
    } else {
        Duration::from_millis(25)
    };
    let batch = (target.as_nanos() / per_call.as_nanos().max(1)).clamp(1, 100_000) as usize;
    let mut times = Vec::new();
    let start = Instant::now();
    let mut k = 0;
    while times.len() < 5 || (start.elapsed() < Duration::from_millis(500) && times.len() < 100) {
        let (t, c) = (Instant::now(), clock());
        for _ in 0..batch {
            f(k);
            k += 1;
        }
        let total = match (c, clock()) {
            (Some(a), Some(b)) => b.saturating_sub(a),
            _ => t.elapsed(),
        };
        times.push(total / batch as u32);
    }
    times.sort();
    times[times.len() / 2]
}

/// The time on CPU of the busiest thread of `pool`, and the wall-clock time, of one
/// call of `f` (medians as in [`median_time`]). The busiest thread's time is what a
/// frame would take on otherwise idle cores: it includes the sequential parts (which one
/// thread runs), and work stolen from a thread the system descheduled, but not the time
/// a thread waited for the other to be scheduled, which on a shared machine dominates
/// the wall clock.
fn median_pool_time(pool: &rayon::ThreadPool, mut f: impl FnMut(usize)) -> (Duration, Duration) {
    let cpu = || pool.broadcast(|_| on_cpu().unwrap_or_default());
    let t = Instant::now();
    f(0);
    f(1);
    let per_call = t.elapsed() / 2;
    let batch = (Duration::from_millis(120).as_nanos() / per_call.as_nanos().max(1))
        .clamp(1, 100_000) as usize;
    let (mut busiest, mut walls) = (Vec::new(), Vec::new());
    let start = Instant::now();
    let mut k = 0;
    while busiest.len() < 5 || (start.elapsed() < Duration::from_millis(500) && busiest.len() < 100)
    {
        let (t, before) = (Instant::now(), cpu());
        for _ in 0..batch {
            f(k);
            k += 1;
        }
        let after = cpu();
        walls.push(t.elapsed() / batch as u32);
        let most = after
            .iter()
            .zip(&before)
            .map(|(a, b)| a.saturating_sub(*b))
            .max()
            .unwrap_or_default();
        busiest.push(most / batch as u32);
    }
    busiest.sort();
    walls.sort();
    (busiest[busiest.len() / 2], walls[walls.len() / 2])
}

/// Prints one table row: `case` is "dim | scene | N | frames", `one` the frame time on
/// 1 thread (on CPU), `two` the busiest thread's time on CPU and the wall-clock time on
/// 2 threads.
fn row(
    case: &str,
    n: usize,
    name: &str,
    one: Duration,
    two: Option<(Duration, Duration)>,
    pairs: usize,
) {
    let ns = one.as_secs_f64() * 1e9 / n as f64;
    let mpairs = pairs as f64 / one.as_secs_f64() / 1e6;
    let (ns2, speedup, wall) = match two {
        Some((t, w)) => (
            format!("{:.1}", t.as_secs_f64() * 1e9 / n as f64),
            format!("{:.2}", one.as_secs_f64() / t.as_secs_f64()),
            format!("{:.1}", w.as_secs_f64() * 1e9 / n as f64),
        ),
        None => ("–".to_owned(), "–".to_owned(), "–".to_owned()),
    };
    println!(
        "| {case} | {name} | {ns:.1} | {ns2} | {speedup} | {wall} | {mpairs:.1} | {:.2} |",
        pairs as f64 / n as f64
    );
}

fn table_dim<const D: usize>(peer: &mut dyn FnMut() -> Box<dyn Peer<D>>) {
    let two = pool(2);
    for dist in distributions() {
        for &n in &sizes() {
            for coherent in [false, true] {
                let mode = if coherent { "coherent" } else { "one-shot" };
                let label = format!("{D}D {} {n} {mode}", dist.name());
                if !std::env::var("CAROM_BENCH_FILTER").is_ok_and(|f| label.contains(&f))
                    && std::env::var_os("CAROM_BENCH_FILTER").is_some()
                {
                    continue;
                }
                let frames = Frames::<D>::new(dist, n, coherent);
                let mut out = Vec::new();
                for name in PHASES.into_iter().filter(|p| runs(p, n)) {
                    let mut phase = make_phase::<D>(name, coherent);
                    let one = median_time(true, |k| {
                        frame(phase.as_mut(), frames.frames[k % 2].balls(), None, &mut out);
                    });
                    let two_t = (name != "brute").then(|| {
                        median_pool_time(&two, |k| {
                            frame(
                                phase.as_mut(),
                                frames.frames[k % 2].balls(),
                                Some(&two),
                                &mut out,
                            );
                        })
                    });
                    let pairs = frame(phase.as_mut(), frames.frames[0].balls(), None, &mut out);
                    row(
                        &format!("{D}D | {} | {n} | {mode}", dist.name()),
                        n,
                        name,
                        one,
                        two_t,
                        pairs,
                    );
                }
                let mut parry = peer();
                let one = median_time(true, |k| {
                    parry.frame(&frames.frames[k % 2], coherent);
                });
                // The pair column is always the first frame's.
                let pairs = parry.frame(&frames.frames[0], coherent);
                let case = format!("{D}D | {} | {n} | {mode}", dist.name());
                row(&case, n, "parry-bvh (f32, box pairs)", one, None, pairs);
            }
        }
    }
}

fn print_table() {
    println!(
        "| dim | scene | N | frames | broad phase | ns/ball 1t | ns/ball 2t | speedup | 2t wall ns/ball | Mpairs/s 1t | pairs/ball |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let a = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 1);
    let b = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 2);
    let mut out = Vec::new();
    for name in ["sap", "grid", "kd"].into_iter().filter(|p| runs(p, 0)) {
        let mut phase = make_phase::<3>(name, false);
        let one = median_time(true, |k| {
            let boxes = if k.is_multiple_of(2) {
                a.aabbs()
            } else {
                b.aabbs()
            };
            frame(phase.as_mut(), boxes, None, &mut out);
        });
        let pairs = frame(phase.as_mut(), a.aabbs(), None, &mut out);
        row(
            "3D | 10k random boxes (Terdiman) | 10000 | one-shot",
            10_000,
            name,
            one,
            None,
            pairs,
        );
    }
    table_dim::<2>(&mut || Box::new(ParryBvh2::default()));
    table_dim::<3>(&mut || Box::new(ParryBvh3::default()));
}

// ---------------------------------------------------------------------------------
// profile mode

/// Runs a fixed number of frames of one case, for instruction counts under
/// `valgrind --tool=callgrind` (or cachegrind): `CAROM_BENCH_PROFILE=phase/case/frames`,
/// the case being `boxes` (Terdiman's 10,000 random boxes) or `3D-uniform0.1-1000000-coherent`.
fn profile(spec: &str) {
    let parts: Vec<&str> = spec.split('/').collect();
    let [name, case, frames] = parts[..] else {
        panic!("CAROM_BENCH_PROFILE=phase/case/frames, e.g. sap/boxes/20");
    };
    let frames: usize = frames.parse().expect("frame count");
    let mut out = Vec::new();
    if case == "boxes" {
        let a = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 1);
        let b = Scene::<f64, 3>::boxes(10_000, 2000.0, 20.0, 2);
        let mut phase = make_phase::<3>(name, false);
        for k in 0..frames {
            let s = if k.is_multiple_of(2) { &a } else { &b };
            frame(phase.as_mut(), s.aabbs(), None, &mut out);
        }
        println!("{} pairs", out.len());
        return;
    }
    let fields: Vec<&str> = case.split('-').collect();
    let [dim, dist, n, mode] = fields[..] else {
        panic!("case: dim-scene-n-mode, e.g. 3D-uniform0.1-1000000-coherent");
    };
    let dist = match dist {
        "clustered" => Distribution::Clustered,
        "mixed" => Distribution::Mixed,
        d => Distribution::Uniform(d.trim_start_matches("uniform").parse().expect("fraction")),
    };
    let n: usize = n.parse().expect("ball count");
    let coherent = mode == "coherent";
    let threads = std::env::var("CAROM_BENCH_THREADS").map_or(1, |t| t.parse().unwrap_or(1));
    let p = pool(threads);
    let pool = (threads > 1).then_some(&p);
    macro_rules! run {
        ($d:literal) => {{
            let frames_of = Frames::<$d>::new(dist, n, coherent);
            let mut phase = make_phase::<$d>(name, coherent);
            for k in 0..frames {
                frame(
                    phase.as_mut(),
                    frames_of.frames[k % 2].balls(),
                    pool,
                    &mut out,
                );
            }
        }};
    }
    if dim == "2D" {
        run!(2);
    } else {
        run!(3);
    }
    println!("{} pairs", out.len());
}

criterion_group!(benches, criterion_benches);
criterion_main!(benches);
