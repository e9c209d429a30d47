//! A reproducible robustness campaign for the time-stepped engine: random scenes run with
//! every integrator in `f64` and two in `f32`, each sample checked against the invariants
//! the engine promises, every failure sorted by kind.
//!
//! ```sh
//! cargo run --release -p carom-sim --example stepped_fuzz -- [--seed S] [--scenes N]
//!     [--until T] [--dt DT] [--every S] [--jobs J] [--timeout SECS] [--out DIR]
//!     [--compare OTHER_DIR/results.tsv]
//! ```
//!
//! Defaults: seed 1127, 60 scenes, `--until 2 --dt 0.01`, a sample every 0.01 s, 2 jobs,
//! 600 s per run, output in `stepped-fuzz-<seed>/`. The scenes are a deterministic
//! function of the seed (carom-broad's SplitMix64 stream), so the same seed gives the same
//! scenes on every machine and at every commit: two binaries are compared by running both
//! with one seed and passing the first one's `results.tsv` to the second as `--compare`,
//! which lists every run whose outcome or samples (a hash of every sample's bits) differ.
//!
//! **The scenes** are `carom_sim::scenes::fuzz::scene_text`'s (its docs list what they
//! mix). Each is written to `DIR/sNN.toml`, so one run is reproduced with `carom run
//! DIR/sNN.toml --engine stepped --until 2 --dt 0.01 --integrator ... --precision ...`.
//!
//! **The runs.** Every scene with each of the five integrators in `f64`, and with
//! semi-implicit Euler and the exact integrator in `f32`: 7 runs per scene. A run ends
//! as `completed`, or with what stopped it: `f32-refusal` (the scene does not survive
//! rounding to `f32`: the contract's `(in f32)` refusal), `drag-refusal` (the step is
//! too long for the scheme under the scene's drag: the planner names a step that works),
//! `refused` (another planning error), `crush`, `spin`, `moves-at`, `overflow` or `error`
//! (the engine's errors, sorted by their messages), `timeout` or `panic`.
//!
//! **The checks** are `carom_sim::scenes::fuzz::Invariants`', at every sample up to the
//! end (the last before an error: the state after one is for diagnosis only): finite
//! states, overlaps of balls and boxes, reach out of the border, energy rise. The largest
//! excursions are given in metres and in units of the precision's resolution at the
//! scene's largest coordinate (`ε · max|x|`).
//!
//! `DIR/results.tsv` holds one line per run; the summary (counts by outcome and
//! precision, the worst excursions, the energy rises) goes to standard output.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use carom_integrate::Integrator;
use carom_math::{Real, Space};
use carom_sim::observe::state_hash;
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::scene::{LoadedScene, Scene, parse_scene};
use carom_sim::scenes::fuzz::{Invariants, failure_kind, scene_text};
use carom_sim::stepped::SteppedEngine;
use carom_sim::{BallStates, Simulation};
use carom_toi::Direction;
use nalgebra::Const;

/// The campaign's settings, from the command line.
#[derive(Clone, Debug)]
struct Settings {
    seed: u64,
    scenes: usize,
    until: f64,
    dt: f64,
    every: f64,
    jobs: usize,
    timeout: Duration,
    out: PathBuf,
    compare: Option<PathBuf>,
}

impl Settings {
    fn from_args() -> Result<Self, String> {
        let mut s = Settings {
            seed: 1127,
            scenes: 60,
            until: 2.0,
            dt: 0.01,
            every: 0.01,
            jobs: 2,
            timeout: Duration::from_mins(10),
            out: PathBuf::new(),
            compare: None,
        };
        let mut args = std::env::args().skip(1);
        while let Some(flag) = args.next() {
            let value = args
                .next()
                .ok_or_else(|| format!("{flag}: needs a value"))?;
            let number = |what: &str| -> Result<f64, String> {
                value
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| format!("{flag}: `{value}` is not {what}"))
            };
            match flag.as_str() {
                "--seed" => {
                    s.seed = value
                        .parse()
                        .map_err(|_| format!("--seed: `{value}` is not an integer"))?;
                }
                "--scenes" => s.scenes = number("a positive count")? as usize,
                "--until" => s.until = number("a positive time")?,
                "--dt" => s.dt = number("a positive step")?,
                "--every" => s.every = number("a positive interval")?,
                "--jobs" => s.jobs = (number("a positive count")? as usize).max(1),
                "--timeout" => s.timeout = Duration::from_secs_f64(number("a positive time")?),
                "--out" => s.out = PathBuf::from(value),
                "--compare" => s.compare = Some(PathBuf::from(value)),
                other => return Err(format!("unknown flag `{other}`")),
            }
        }
        if s.out.as_os_str().is_empty() {
            s.out = PathBuf::from(format!("stepped-fuzz-{}", s.seed));
        }
        Ok(s)
    }
}

/// One run: a scene with an integrator in a precision.
#[derive(Clone, Copy, Debug)]
struct Run {
    scene: usize,
    integrator: Integrator,
    f32: bool,
}

/// What a run came to, and the largest excursions seen up to its end.
#[derive(Clone, Debug, Default)]
struct Outcome {
    kind: String,
    end: f64,
    message: String,
    /// Largest overlap of two balls (m).
    ball_overlap: f64,
    /// Largest overlap of a ball and a box (m).
    box_overlap: f64,
    /// Largest reach of a ball out of a reflecting border (m).
    border_out: f64,
    /// The precision's resolution at the scene's largest coordinate (m).
    resolution: f64,
    /// The time of the sample with the largest of the three above (s).
    worst_at: f64,
    /// Largest energy rise beyond the allowance, relative to the start's energy scale.
    energy_rise: f64,
    nan: bool,
    hash: u64,
}

impl Outcome {
    fn worst(&self) -> f64 {
        self.ball_overlap.max(self.box_overlap).max(self.border_out)
    }
}

fn main() {
    let settings = Settings::from_args().unwrap_or_else(|e| {
        eprintln!("stepped_fuzz: {e}");
        std::process::exit(2);
    });
    std::fs::create_dir_all(&settings.out).unwrap_or_else(|e| {
        eprintln!("stepped_fuzz: {}: {e}", settings.out.display());
        std::process::exit(2);
    });
    let scenes: Vec<String> = (0..settings.scenes)
        .map(|k| scene_text(settings.seed, k))
        .collect();
    for (k, text) in scenes.iter().enumerate() {
        let path = settings.out.join(format!("s{k:02}.toml"));
        std::fs::write(&path, text)
            .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    }
    let runs: Vec<Run> = (0..scenes.len())
        .flat_map(|scene| {
            let wide = Integrator::ALL.map(|integrator| Run {
                scene,
                integrator,
                f32: false,
            });
            let narrow = [Integrator::SemiImplicitEuler, Integrator::Exact].map(|integrator| Run {
                scene,
                integrator,
                f32: true,
            });
            wide.into_iter().chain(narrow)
        })
        .collect();
    let started = Instant::now();
    let outcomes = run_all(&settings, &Arc::new(scenes), &runs);
    let wall = started.elapsed().as_secs_f64();
    let table = results_table(&runs, &outcomes);
    let results = settings.out.join("results.tsv");
    std::fs::write(&results, &table)
        .unwrap_or_else(|e| panic!("cannot write {}: {e}", results.display()));
    print!("{}", summary(&settings, &runs, &outcomes, wall));
    if let Some(other) = &settings.compare {
        print!("{}", compare(other, &table));
    }
}

/// Runs every run on `settings.jobs` workers, each run on a thread of its own so that one
/// that never ends is reported as a timeout (its thread is left behind).
fn run_all(settings: &Settings, scenes: &Arc<Vec<String>>, runs: &[Run]) -> Vec<Outcome> {
    let next = AtomicUsize::new(0);
    let outcomes = Mutex::new(vec![Outcome::default(); runs.len()]);
    std::thread::scope(|scope| {
        for _ in 0..settings.jobs {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&run) = runs.get(k) else { break };
                    let (send, receive) = mpsc::channel();
                    let (scenes, settings_copy) = (Arc::clone(scenes), settings.clone());
                    std::thread::spawn(move || {
                        let outcome = run_text(&scenes[run.scene], run, &settings_copy);
                        let _ = send.send(outcome);
                    });
                    let outcome = match receive.recv_timeout(settings.timeout) {
                        Ok(outcome) => outcome,
                        Err(mpsc::RecvTimeoutError::Timeout) => Outcome {
                            kind: "timeout".into(),
                            ..Outcome::default()
                        },
                        Err(mpsc::RecvTimeoutError::Disconnected) => Outcome {
                            kind: "panic".into(),
                            ..Outcome::default()
                        },
                    };
                    eprintln!(
                        "s{:02} {} {}: {}",
                        run.scene,
                        if run.f32 { "f32" } else { "f64" },
                        run.integrator,
                        outcome.kind
                    );
                    outcomes.lock().expect("no worker panics holding the lock")[k] = outcome;
                }
            });
        }
    });
    outcomes
        .into_inner()
        .expect("no worker panics holding the lock")
}

/// One run of the scene file text `text`.
fn run_text(text: &str, run: Run, settings: &Settings) -> Outcome {
    let loaded = match parse_scene(text) {
        Ok(loaded) => loaded,
        Err(e) => return refusal("refused", &e.to_string()),
    };
    match (loaded, run.f32) {
        (LoadedScene::D2(s), false) => run_scene(&s, run, settings),
        (LoadedScene::D3(s), false) => run_scene(&s, run, settings),
        (LoadedScene::D2(s), true) => match s.cast::<f32>() {
            Ok(s) => run_scene(&s, run, settings),
            Err(e) => refusal("f32-refusal", &e.to_string()),
        },
        (LoadedScene::D3(s), true) => match s.cast::<f32>() {
            Ok(s) => run_scene(&s, run, settings),
            Err(e) => refusal("f32-refusal", &e.to_string()),
        },
    }
}

fn refusal(kind: &str, message: &str) -> Outcome {
    Outcome {
        kind: kind.into(),
        message: message.into(),
        ..Outcome::default()
    }
}

fn run_scene<T: Real, const D: usize>(scene: &Scene<T, D>, run: Run, settings: &Settings) -> Outcome
where
    Const<D>: Space<T, D> + Space<f64, D>,
{
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(run.integrator),
        dt: Some(settings.dt),
        broad: BroadChoice::Auto,
    };
    let p = match plan(scene, &options) {
        Ok(p) => p,
        Err(e) => return refusal(failure_kind(&e.0).unwrap_or("refused"), &e.0),
    };
    let mut sim = match SteppedEngine::new(scene, &p, Direction::Forward) {
        Ok(sim) => sim,
        Err(e) => return refusal("refused", &e.to_string()),
    };
    let mut states = BallStates::default();
    sim.states(&mut states);
    let mut invariants = Invariants::new(scene, &states);
    let mut outcome = Outcome {
        kind: "completed".into(),
        resolution: invariants.resolution(),
        ..Outcome::default()
    };
    let samples = (settings.until / settings.every).round() as u64;
    for k in 0..=samples {
        let t = (k as f64 * settings.every).min(settings.until);
        if let Err(e) = sim.advance_to(T::lit(t), &mut ()) {
            // The state after an error is for diagnosis only (`Simulation::advance_to`):
            // the checks stop at the last sample before it.
            outcome.kind = failure_kind(&e.message).unwrap_or("error").into();
            outcome.end = e.time;
            outcome.message = e.message;
            break;
        }
        outcome.end = t;
        sim.states(&mut states);
        outcome.hash = outcome.hash.wrapping_mul(0x0100_0000_01b3) ^ state_hash(&states);
        let sample = invariants.sample(scene, &states, t, settings.dt);
        outcome.nan |= !sample.finite;
        if sample.worst() > outcome.worst() {
            outcome.worst_at = t;
        }
        outcome.ball_overlap = outcome.ball_overlap.max(sample.ball_overlap);
        outcome.box_overlap = outcome.box_overlap.max(sample.box_overlap);
        outcome.border_out = outcome.border_out.max(sample.border_out);
        outcome.energy_rise = outcome.energy_rise.max(sample.energy_rise.unwrap_or(0.0));
    }
    outcome
}

/// One line per run: scene, precision, integrator, outcome, end time, the excursions and
/// the time of the worst, the energy rise, the samples' hash and the error message.
fn results_table(runs: &[Run], outcomes: &[Outcome]) -> String {
    let mut table = String::from(
        "scene\tprecision\tintegrator\toutcome\tend\tball_overlap\tbox_overlap\tborder_out\tworst_at\tresolution\tenergy_rise\tnan\thash\tmessage\n",
    );
    for (run, o) in runs.iter().zip(outcomes) {
        let _ = writeln!(
            table,
            "s{:02}\t{}\t{}\t{}\t{}\t{:e}\t{:e}\t{:e}\t{}\t{:e}\t{:e}\t{}\t{:016x}\t{}",
            run.scene,
            if run.f32 { "f32" } else { "f64" },
            run.integrator,
            o.kind,
            o.end,
            o.ball_overlap,
            o.box_overlap,
            o.border_out,
            o.worst_at,
            o.resolution,
            o.energy_rise,
            o.nan,
            o.hash,
            o.message.replace(['\t', '\n'], " ")
        );
    }
    table
}

/// Counts by outcome and precision, the worst excursions and energy rises.
fn summary(settings: &Settings, runs: &[Run], outcomes: &[Outcome], wall: f64) -> String {
    let mut counts: BTreeMap<&str, [usize; 2]> = BTreeMap::new();
    for (run, o) in runs.iter().zip(outcomes) {
        counts.entry(o.kind.as_str()).or_default()[usize::from(run.f32)] += 1;
    }
    let mut s = format!(
        "stepped_fuzz: seed {}, {} scenes, {} runs, --until {} --dt {}, sampled every {} s; {:.0} s; results in {}\n\n| outcome | f64 | f32 |\n|---|---|---|\n",
        settings.seed,
        settings.scenes,
        runs.len(),
        settings.until,
        settings.dt,
        settings.every,
        wall,
        settings.out.join("results.tsv").display()
    );
    for (kind, [wide, narrow]) in &counts {
        let _ = writeln!(s, "| {kind} | {wide} | {narrow} |");
    }
    let label = |run: &Run| {
        format!(
            "s{:02} {} {}",
            run.scene,
            if run.f32 { "f32" } else { "f64" },
            run.integrator
        )
    };
    let nan: Vec<String> = (runs.iter().zip(outcomes))
        .filter(|(_, o)| o.nan)
        .map(|(r, _)| label(r))
        .collect();
    let _ = writeln!(
        s,
        "\nnon-finite states: {}",
        if nan.is_empty() {
            "none".into()
        } else {
            nan.join(", ")
        }
    );
    for f32 in [false, true] {
        let mut worst: Vec<(f64, &Run, &Outcome)> = (runs.iter().zip(outcomes))
            .filter(|(r, o)| r.f32 == f32 && o.resolution > 0.0)
            .map(|(r, o)| (o.worst(), r, o))
            .collect();
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        let _ = writeln!(
            s,
            "\nlargest excursions in {} (overlap of balls / ball into box / out of border):",
            if f32 { "f32" } else { "f64" }
        );
        for (w, r, o) in worst.iter().take(5).filter(|(w, _, _)| *w > 0.0) {
            let _ = writeln!(
                s,
                "  {}: {w:.3e} m at {} s = {:.2} units of {:.2e} m ({:.2e} / {:.2e} / {:.2e}), {} at {} s",
                label(r),
                o.worst_at,
                w / o.resolution,
                o.resolution,
                o.ball_overlap,
                o.box_overlap,
                o.border_out,
                o.kind,
                o.end
            );
        }
    }
    let mut rises: Vec<(f64, &Run)> = (runs.iter().zip(outcomes))
        .filter(|(_, o)| o.energy_rise > 1e-9)
        .map(|(r, o)| (o.energy_rise, r))
        .collect();
    rises.sort_by(|a, b| b.0.total_cmp(&a.0));
    let _ = writeln!(
        s,
        "\nenergy rises above 1e-9 of the energy scale (scenes without moving boxes): {}",
        rises.len()
    );
    for (rise, r) in rises.iter().take(10) {
        let _ = writeln!(s, "  {}: {rise:.3e}", label(r));
    }
    s
}

/// The runs whose outcome or sample hash differ between `other` (an earlier
/// `results.tsv`) and this campaign's `table`.
fn compare(other: &Path, table: &str) -> String {
    let Ok(before) = std::fs::read_to_string(other) else {
        return format!("\n--compare: cannot read {}\n", other.display());
    };
    let key = |line: &str| -> Option<(String, (String, String, String))> {
        let f: Vec<&str> = line.split('\t').collect();
        (f.len() > 12 && f[0] != "scene").then(|| {
            (
                format!("{} {} {}", f[0], f[1], f[2]),
                (f[3].to_owned(), f[4].to_owned(), f[12].to_owned()),
            )
        })
    };
    let before: BTreeMap<_, _> = before.lines().filter_map(key).collect();
    let mut same = 0;
    let mut s = String::from("\nagainst --compare:\n");
    for (run, now) in table.lines().filter_map(key) {
        match before.get(&run) {
            Some(was) if *was == now => same += 1,
            Some(was) => {
                let _ = writeln!(
                    s,
                    "  {run}: {} at {} -> {} at {}{}",
                    was.0,
                    was.1,
                    now.0,
                    now.1,
                    if was.0 == now.0 && was.1 == now.1 {
                        " (samples differ)"
                    } else {
                        ""
                    }
                );
            }
            None => {
                let _ = writeln!(s, "  {run}: not in the other campaign");
            }
        }
    }
    let _ = writeln!(s, "  {same} runs identical bit for bit");
    s
}
