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
//! **The scenes** mix what the stepped engine must survive (docs/stepped.md, "Fuzzing"):
//! 2D (three in four) and 3D; 2 to 40 balls; reflecting or periodic borders; static and
//! moving boxes, rotated or not; coordinates near 0, 1e3 or −5e4 m; half the scenes on a
//! grid `f32` holds exactly, with balls touching each other and the walls; masses over
//! twelve decades; speeds from rest to 1e6 m/s; restitution 0 to 1 (per-ball overrides,
//! sticking); friction, drag and gravity. Each is written to `DIR/sNN.toml`, so one run
//! is reproduced with `carom run DIR/sNN.toml --engine stepped --until 2 --dt 0.01
//! --integrator ... --precision ...`.
//!
//! **The runs.** Every scene with each of the five integrators in `f64`, and with
//! semi-implicit Euler and the exact integrator in `f32`: 7 runs per scene. A run ends
//! as `completed`, or with what stopped it: `f32-refusal` (the scene does not survive
//! rounding to `f32`: the contract's `(in f32)` refusal), `drag-refusal` (the step is
//! too long for the scheme under the scene's drag: the planner names a step that works),
//! `refused` (another planning error), `crush`, `spin`, `moves-at`, `overflow` or `error`
//! (the engine's errors, sorted by their messages), `timeout` or `panic`.
//!
//! **The checks**, at every sample up to the end (the last before an error): every coordinate finite (`nan`); how far
//! a ball reaches out of a reflecting border, into another ball (minimum image in a
//! periodic border) or into a box at its place at that time; and for scenes without a
//! moving box, how far the energy rose above its start, beyond what a first-order scheme's
//! truncation under gravity allows (`Σm |g|² dt t`: explicit Euler gains `m g² dt²/2`
//! per step in free flight). The largest excursions are given in metres and in units of
//! the precision's resolution at the scene's largest coordinate (`ε · max|x|`).
//!
//! `DIR/results.tsv` holds one line per run; the summary (counts by outcome and
//! precision, the worst excursions, the energy rises) goes to standard output.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use carom_broad::scenes::SplitMix64;
use carom_integrate::Integrator;
use carom_math::{Real, Space, Vector};
use carom_sim::observe::{energy, state_hash};
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions, plan};
use carom_sim::scene::{LoadedScene, Scene, parse_scene};
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
        .map(|k| generate(settings.seed, k))
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

/// The kind of an engine error, from its message.
fn error_kind(message: &str) -> &'static str {
    const KINDS: [(&str, &str); 4] = [
        ("is crushed", "crush"),
        ("spins at", "spin"),
        (" moves at ", "moves-at"),
        ("overflowed", "overflow"),
    ];
    KINDS
        .iter()
        .find(|(needle, _)| message.contains(needle))
        .map_or("error", |(_, kind)| kind)
}

fn run_scene<T: Real, const D: usize>(scene: &Scene<T, D>, run: Run, settings: &Settings) -> Outcome
where
    Const<D>: Space<T, D>,
{
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(run.integrator),
        dt: Some(settings.dt),
        broad: BroadChoice::Auto,
    };
    let p = match plan(scene, &options) {
        Ok(p) => p,
        Err(e) if e.0.contains("world.drag") => return refusal("drag-refusal", &e.0),
        Err(e) => return refusal("refused", &e.0),
    };
    let mut sim = match SteppedEngine::new(scene, &p, Direction::Forward) {
        Ok(sim) => sim,
        Err(e) => return refusal("refused", &e.to_string()),
    };
    let check = Checks::new(scene);
    let mut outcome = Outcome {
        kind: "completed".into(),
        resolution: check.resolution,
        ..Outcome::default()
    };
    let mut states = BallStates::default();
    sim.states(&mut states);
    let start_energy = energy(scene, &states).to_f64();
    let samples = (settings.until / settings.every).round() as u64;
    for k in 0..=samples {
        let t = (k as f64 * settings.every).min(settings.until);
        if let Err(e) = sim.advance_to(T::lit(t), &mut ()) {
            outcome.kind = error_kind(&e.message).into();
            outcome.end = e.time;
            outcome.message = e.message;
            // The state after an error is for diagnosis only (`Simulation::advance_to`):
            // the checks stop at the last sample before it.
            break;
        }
        outcome.end = t;
        sim.states(&mut states);
        check.sample(scene, &states, t, start_energy, settings, &mut outcome);
    }
    outcome
}

/// What the checks need of a scene, worked out once.
struct Checks {
    resolution: f64,
    mass: f64,
    gravity_squared: f64,
    energy_scale: f64,
    energy_checked: bool,
}

impl Checks {
    fn new<T: Real, const D: usize>(scene: &Scene<T, D>) -> Self
    where
        Const<D>: Space<T, D>,
    {
        let mut largest = 1.0_f64;
        for b in &scene.balls {
            largest = b.pos.iter().fold(largest, |m, x| m.max(x.to_f64().abs()));
        }
        if let Some(border) = &scene.world.border {
            let (lo, hi) = (border.border.min(), border.border.max());
            largest = lo
                .iter()
                .chain(hi.iter())
                .fold(largest, |m, x| m.max(x.to_f64().abs()));
        }
        let mass: f64 = scene.balls.iter().map(|b| b.mass.to_f64()).sum();
        let speed_energy: f64 = (scene.balls.iter())
            .map(|b| 0.5 * b.mass.to_f64() * b.vel.norm_squared().to_f64())
            .sum();
        let g = scene.world.gravity.norm().to_f64();
        let extent = scene.world.border.as_ref().map_or(1.0, |b| {
            b.border
                .extents()
                .iter()
                .fold(0.0_f64, |m, x| m.max(x.to_f64()))
        });
        Checks {
            resolution: T::EPSILON.to_f64() * largest,
            mass,
            gravity_squared: g * g,
            // Kinetic energy plus the potential energy over the border's height: the scale
            // a relative rise is measured against (the start's total may be near zero).
            energy_scale: (speed_energy + mass * g * extent).max(f64::MIN_POSITIVE),
            energy_checked: scene
                .boxes
                .iter()
                .all(|b| b.vel.norm_squared() == T::zero()),
        }
    }

    /// Checks the states at time `t` and keeps the largest excursions in `outcome`.
    fn sample<T: Real, const D: usize>(
        &self,
        scene: &Scene<T, D>,
        states: &BallStates<T, D>,
        t: f64,
        start_energy: f64,
        settings: &Settings,
        outcome: &mut Outcome,
    ) where
        Const<D>: Space<T, D>,
    {
        outcome.hash = outcome.hash.wrapping_mul(0x0100_0000_01b3) ^ state_hash(states);
        let wide = |v: &Vector<T, D>| v.map(T::to_f64);
        if states
            .pos
            .iter()
            .chain(&states.vel)
            .any(|v| v.iter().any(|x| !x.finite()))
        {
            outcome.nan = true;
            return;
        }
        let border = scene.world.border.as_ref();
        let periodic = border
            .filter(|b| b.periodic)
            .map(|b| wide(&b.border.extents()));
        let image = |mut d: Vector<f64, D>| {
            if let Some(l) = &periodic {
                for (x, l) in d.iter_mut().zip(l.iter()) {
                    *x -= l * (*x / l).round();
                }
            }
            d
        };
        let pos: Vec<Vector<f64, D>> = states.pos.iter().map(wide).collect();
        let before = outcome.worst();
        let radius: Vec<f64> = scene.balls.iter().map(|b| b.radius.to_f64()).collect();
        for i in 0..pos.len() {
            for j in i + 1..pos.len() {
                let d = image(pos[j] - pos[i]).norm();
                outcome.ball_overlap = outcome.ball_overlap.max(radius[i] + radius[j] - d);
            }
            if let Some(b) = border.filter(|b| !b.periodic) {
                let (lo, hi) = (wide(&b.border.min()), wide(&b.border.max()));
                for k in 0..D {
                    let out = (lo[k] - (pos[i][k] - radius[i])).max(pos[i][k] + radius[i] - hi[k]);
                    outcome.border_out = outcome.border_out.max(out);
                }
            }
            for b in &scene.boxes {
                let centre = wide(&b.shape.center()) + wide(&b.vel) * t;
                let offset = image(pos[i] - centre);
                let local = Vector::<f64, D>::from_fn(|k, _| offset.dot(&wide(&b.shape.axis(k))));
                let half = wide(&b.shape.half_extents());
                outcome.box_overlap = outcome
                    .box_overlap
                    .max(radius[i] - box_distance(&local, &half));
            }
        }
        if outcome.worst() > before {
            outcome.worst_at = t;
        }
        if self.energy_checked {
            let allowed = self.mass * self.gravity_squared * settings.dt * t;
            let rise = energy(scene, states).to_f64() - start_energy - allowed;
            outcome.energy_rise = outcome.energy_rise.max(rise / self.energy_scale);
        }
    }
}

/// The signed distance from a point in a box's frame to the box of half extents `half`
/// (negative inside: minus the distance to the nearest face).
fn box_distance<const D: usize>(local: &Vector<f64, D>, half: &Vector<f64, D>) -> f64 {
    let outside = local.zip_map(half, |x, h| (x.abs() - h).max(0.0)).norm();
    if outside > 0.0 {
        return outside;
    }
    -local.zip_map(half, |x, h| h - x.abs()).min()
}

/// Scene `k` of the campaign `seed`, as scene-file text: retried with the next draw of
/// its own stream until it is a valid scene in `f64` (the generator places bodies apart
/// to its own tolerance; the loader decides).
fn generate(seed: u64, k: usize) -> String {
    let mut rng = SplitMix64::new(seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    loop {
        let text = if rng.next_f64() < 0.75 {
            draw::<2>(&mut rng, k)
        } else {
            draw::<3>(&mut rng, k)
        };
        if parse_scene(&text).is_ok() {
            return text;
        }
    }
}

/// A float as the scene file writes it (Rust's shortest round-trip form, with an exponent
/// where it is shorter: TOML reads both).
fn num(x: f64) -> String {
    format!("{x:?}")
}

fn vector<const D: usize>(v: &[f64; D]) -> String {
    let parts: Vec<String> = v.iter().map(|&x| num(x)).collect();
    format!("[{}]", parts.join(", "))
}

/// Log-uniform in `[lo, hi]`.
fn log_uniform(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    (rng.range(lo.ln(), hi.ln())).exp()
}

/// Where a scene's bodies may go: its border and the grid it snaps to.
struct Frame<const D: usize> {
    origin: f64,
    half: f64,
    periodic: bool,
    /// The unit coordinates are rounded to (`None`: not rounded).
    grid: Option<f64>,
}

impl<const D: usize> Frame<D> {
    fn snap(&self, x: f64) -> f64 {
        self.grid.map_or(x, |q| (x / q).round() * q)
    }

    /// A point whose ball of `margin` fits inside the border, snapped to the grid.
    fn point(&self, rng: &mut SplitMix64, margin: f64) -> [f64; D] {
        std::array::from_fn(|_| {
            self.snap(self.origin + rng.range(-1.0, 1.0) * (self.half - margin).max(0.0))
        })
    }

    /// The distance between two points (the minimum image in a periodic border).
    fn distance(&self, p: &[f64; D], q: &[f64; D]) -> f64 {
        let period = 2.0 * self.half;
        (0..D)
            .map(|a| {
                let d = p[a] - q[a];
                let d = if self.periodic {
                    d - period * (d / period).round()
                } else {
                    d
                };
                d * d
            })
            .sum::<f64>()
            .sqrt()
    }
}

/// One draw of a `D`-dimensional scene.
fn draw<const D: usize>(rng: &mut SplitMix64, k: usize) -> String {
    let origin = match rng.next_f64() {
        u if u < 0.5 => 0.0,
        u if u < 0.8 => 1e3,
        _ => -5e4,
    };
    // Half the scenes on a grid f32 holds exactly at their coordinates (its unit is at
    // least 4 f32 ulps there), so that contacts touching in the file touch in f32 too.
    let grid = (rng.next_f64() < 0.5).then_some(if origin == -5e4 {
        0.015_625
    } else {
        1.0 / 1024.0
    });
    let frame = Frame::<D> {
        origin,
        half: [1.0, 2.0, 4.0][(rng.next_f64() * 3.0) as usize],
        periodic: rng.next_f64() < 0.2,
        grid,
    };
    let mut text = world(rng, k, &frame);
    let boxes = boxes(rng, &frame, &mut text);
    balls(rng, &frame, &boxes, &mut text);
    text
}

/// The scene's header and `[world]` tables.
fn world<const D: usize>(rng: &mut SplitMix64, k: usize, frame: &Frame<D>) -> String {
    let mut text = String::new();
    let _ = writeln!(
        text,
        "dim = {D}\nname = \"stepped-fuzz-s{k:02}\"\n\n[world]"
    );
    let restitution = match rng.next_f64() {
        u if u < 0.3 => 1.0,
        u if u < 0.5 => 0.0,
        _ => frame.snap(rng.next_f64()),
    };
    let _ = writeln!(text, "restitution = {}", num(restitution));
    if restitution == 0.0 && rng.next_f64() < 0.5 {
        let _ = writeln!(text, "inelastic = \"stick\"");
    }
    if rng.next_f64() < 0.25 {
        let _ = writeln!(text, "friction = {}", num(frame.snap(rng.next_f64())));
    }
    if rng.next_f64() < 0.2 {
        let _ = writeln!(text, "drag = {}", num(log_uniform(rng, 1e-3, 1.0)));
    }
    if rng.next_f64() < 0.4 {
        let mut g = [0.0; D];
        g[D - 1] = -9.81;
        let _ = writeln!(text, "gravity = {}", vector(&g));
    }
    let _ = writeln!(
        text,
        "\n[world.border]\nmin = {}\nmax = {}\nrestitution = {}\nperiodic = {}",
        vector(&[frame.origin - frame.half; D]),
        vector(&[frame.origin + frame.half; D]),
        num([1.0, 0.0, 0.5][(rng.next_f64() * 3.0) as usize]),
        frame.periodic
    );
    text
}

/// Up to three boxes, rotated or not, static or moving, inside the border; returns each
/// one's centre and the radius of its bounding ball.
fn boxes<const D: usize>(
    rng: &mut SplitMix64,
    frame: &Frame<D>,
    text: &mut String,
) -> Vec<([f64; D], f64)> {
    let count = if rng.next_f64() < 0.5 {
        0
    } else {
        1 + (rng.next_f64() * 3.0) as usize
    };
    (0..count)
        .map(|_| {
            let extents: [f64; D] =
                std::array::from_fn(|_| frame.snap(frame.half * log_uniform(rng, 0.05, 0.3)));
            let reach = extents.iter().map(|e| e * e).sum::<f64>().sqrt();
            let centre = frame.point(rng, reach);
            let vel: [f64; D] = if rng.next_f64() < 0.5 {
                let speed = log_uniform(rng, 0.1, 100.0);
                rng.direction::<D>().map(|x| x * speed)
            } else {
                [0.0; D]
            };
            let _ = writeln!(
                text,
                "\n[[boxes]]\ncenter = {}\nhalf_extents = {}\nvel = {}\nrestitution = {}",
                vector(&centre),
                vector(&extents),
                vector(&vel),
                num(frame.snap(rng.next_f64()))
            );
            if rng.next_f64() < 0.5 {
                let angle = rng.range(-3.0, 3.0);
                if D == 2 {
                    let _ = writeln!(text, "angle = {}", num(angle));
                } else {
                    let axis = rng.direction::<3>().map(|x| x * angle);
                    let _ = writeln!(text, "axis_angle = {}", vector(&axis));
                }
            }
            (centre, reach)
        })
        .collect()
}

/// 2 to 40 balls (few more often than many), apart from each other and the boxes; a
/// quarter of them placed touching another ball along an axis, a tenth touching a wall.
fn balls<const D: usize>(
    rng: &mut SplitMix64,
    frame: &Frame<D>,
    boxes: &[([f64; D], f64)],
    text: &mut String,
) {
    let (lo, hi) = (frame.origin - frame.half, frame.origin + frame.half);
    let n = 2 + (38.0 * rng.next_f64().powi(2)) as usize;
    let mut placed: Vec<([f64; D], f64)> = Vec::new();
    for _ in 0..n {
        let radius = frame
            .snap(frame.half * log_uniform(rng, 5e-3, 0.12))
            .max(frame.grid.unwrap_or(0.0) * 4.0);
        for _attempt in 0..100 {
            let pos: [f64; D] = match rng.next_f64() {
                u if u < 0.25 && !placed.is_empty() => {
                    let (other, r) = placed[(rng.next_f64() * placed.len() as f64) as usize];
                    let axis = (rng.next_f64() * D as f64) as usize;
                    let sign = if rng.next_f64() < 0.5 { -1.0 } else { 1.0 };
                    let mut p = other;
                    p[axis] += sign * (r + radius);
                    p
                }
                u if u < 0.35 && !frame.periodic => {
                    let mut p = frame.point(rng, radius);
                    let axis = (rng.next_f64() * D as f64) as usize;
                    p[axis] = if rng.next_f64() < 0.5 {
                        lo + radius
                    } else {
                        hi - radius
                    };
                    p
                }
                _ => frame.point(rng, radius),
            };
            let inside = frame.periodic || pos.iter().all(|x| x - radius >= lo && x + radius <= hi);
            let apart = (placed.iter())
                .all(|(q, r)| frame.distance(&pos, q) >= (r + radius) * (1.0 - 1e-15));
            let off_boxes =
                (boxes.iter()).all(|(c, reach)| frame.distance(&pos, c) > reach + radius);
            if inside && apart && off_boxes {
                placed.push((pos, radius));
                break;
            }
        }
    }
    for (pos, radius) in &placed {
        let mass = if rng.next_f64() < 0.5 {
            log_uniform(rng, 1e-6, 1e6)
        } else {
            log_uniform(rng, 0.1, 10.0)
        };
        let speed = match rng.next_f64() {
            u if u < 0.1 => 0.0,
            u if u < 0.2 => log_uniform(rng, 1e3, 1e6),
            u if u < 0.5 => log_uniform(rng, 1.0, 100.0),
            _ => log_uniform(rng, 1e-2, 3.0),
        };
        let vel = rng.direction::<D>().map(|x| x * speed);
        let _ = writeln!(
            text,
            "\n[[balls]]\npos = {}\nvel = {}\nradius = {}\nmass = {}",
            vector(pos),
            vector(&vel),
            num(*radius),
            num(mass)
        );
        if rng.next_f64() < 0.2 {
            let _ = writeln!(text, "restitution = {}", num(frame.snap(rng.next_f64())));
        }
    }
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
