//! `carom run`: load a scene file, plan, build the engine, run it, print JSON Lines.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use carom_integrate::Integrator;
use carom_math::Space;
use carom_sim::plan::{BroadChoice, EngineChoice, RunOptions};
use carom_sim::run::{RunSink, Summary, drive, sample_times};
use carom_sim::scene::{LoadedScene, Scene, load_scene_file};
use carom_sim::{BallStates, Collision, EngineKind};
use carom_toi::Direction;
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::Const;

use crate::json::{self, JsonFloat};

/// The scalar the simulation computes in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Precision {
    /// 64-bit floats.
    F64,
    /// 32-bit floats.
    F32,
}

/// `carom run SCENE.toml --until T [...]`.
#[derive(Args, Debug)]
pub(crate) struct RunArgs {
    /// The scene file (TOML, see docs/scene-format.md).
    scene: PathBuf,
    /// Run until this time (s); negative runs backwards in time from the initial state.
    #[arg(long, allow_negative_numbers = true)]
    until: f64,
    /// auto | event | stepped (auto: event-driven where the scene allows it exactly).
    #[arg(long, default_value = "auto")]
    engine: EngineChoice,
    /// explicit-euler | semi-implicit-euler | verlet | rk4 | exact (stepped engine only).
    #[arg(long)]
    integrator: Option<Integrator>,
    /// The stepped engine's step (s); default 1/600.
    #[arg(long)]
    dt: Option<f64>,
    /// auto | brute | sap | kd | grid.
    #[arg(long, default_value = "auto")]
    broad: BroadChoice,
    /// The scalar precision.
    #[arg(long, value_enum, default_value = "f64")]
    precision: Precision,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Sample times, comma separated (negative for a backward run).
    // `allow_negative_numbers` alone takes `-0.5` but not `-0.25,-0.5` (not a number as
    // a whole, so clap read it as a flag): the value is taken whatever it starts with.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    at: Vec<f64>,
    /// Also sample every S seconds, from 0.
    #[arg(long)]
    every: Option<f64>,
    /// Also print one line per collision.
    #[arg(long)]
    events: bool,
    /// Write to this file instead of standard output.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// A failure of `carom run`, with its exit status.
enum Failure {
    /// Bad scene or bad flags: status 2.
    Input(String),
    /// The simulation or the output failed: status 1.
    Run(String),
}

pub(crate) fn main(args: &RunArgs) -> ExitCode {
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(message)) => {
            eprintln!("carom: {message}");
            ExitCode::from(2)
        }
        Err(Failure::Run(message)) => {
            eprintln!("carom: {message}");
            ExitCode::from(1)
        }
    }
}

/// The most worker threads `--threads` accepts. Starting the pool alone took 1.8 s for
/// 1,000 threads and 12 s for 4,000 on the project's 2-core VM, 10,000 did not start
/// within a minute, and 100,000 ended in a stack overflow: a typo, not a setting.
const MAX_THREADS: usize = 1024;

fn run(args: &RunArgs) -> Result<(), Failure> {
    let scene = load_scene_file(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    let options = RunOptions {
        engine: args.engine,
        integrator: args.integrator,
        dt: args.dt,
        broad: args.broad,
    };
    let times = sample_times(args.until, &args.at, args.every)
        .map_err(|e| Failure::Input(e.to_string()))?;
    if let Some(n) = args.threads
        && !(1..=MAX_THREADS).contains(&n)
    {
        return Err(Failure::Input(format!(
            "--threads: must be between 1 and {MAX_THREADS}, got {n}"
        )));
    }
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| Failure::Run(format!("cannot start the worker threads: {e}")))?;
    let out: Box<dyn Write + Send> = match &args.out {
        Some(path) => Box::new(
            File::create(path)
                .map_err(|e| Failure::Input(format!("--out {}: {e}", path.display())))?,
        ),
        None => Box::new(io::stdout()),
    };
    let out = BufWriter::new(out);
    let label = args.scene.display().to_string();
    pool.install(|| match (scene, args.precision) {
        (LoadedScene::D2(s), Precision::F64) => simulate(&s, &times, &options, args, out, &label),
        (LoadedScene::D3(s), Precision::F64) => simulate(&s, &times, &options, args, out, &label),
        (LoadedScene::D2(s), Precision::F32) => {
            simulate(&cast(&s, &label)?, &times, &options, args, out, &label)
        }
        (LoadedScene::D3(s), Precision::F32) => {
            simulate(&cast(&s, &label)?, &times, &options, args, out, &label)
        }
    })
}

fn cast<const D: usize>(scene: &Scene<f64, D>, label: &str) -> Result<Scene<f32, D>, Failure> {
    scene
        .cast::<f32>()
        .map_err(|e| Failure::Input(format!("{} (in f32)", e.in_file(label))))
}

fn simulate<T: JsonFloat, const D: usize>(
    scene: &Scene<T, D>,
    times: &[f64],
    options: &RunOptions,
    args: &RunArgs,
    out: BufWriter<Box<dyn Write + Send>>,
    label: &str,
) -> Result<(), Failure>
where
    Const<D>: Space<T, D>,
{
    let plan = carom_sim::plan::plan(scene, options).map_err(|e| Failure::Input(e.to_string()))?;
    let direction = if args.until < 0.0 {
        Direction::Backward
    } else {
        Direction::Forward
    };
    let mut sim = carom_sim::build(scene, &plan, direction)
        .map_err(|e| Failure::Input(e.in_file(label).to_string()))?;
    let times: Vec<T> = times.iter().map(|&t| T::lit(t)).collect();
    let progress = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("{spinner} t = {msg} [{bar:40}] {percent}% ({elapsed})")
                .expect("a valid template"),
        );
        bar
    });
    let mut sink = JsonSink {
        out,
        line: String::new(),
        error: None,
        progress,
    };
    let summary = drive(sim.as_mut(), scene, &times, &mut sink, args.events);
    if let Some(bar) = &sink.progress {
        bar.finish_and_clear();
    }
    let summary = summary.map_err(|e| Failure::Run(format!("{label}: simulation failed {e}")))?;
    if let Some(h) = &summary.hand_over {
        eprintln!(
            "carom: note: {label}: at t = {} the run went over from the event engine to the stepped engine: {}",
            h.time.to_f64(),
            h.reason
        );
    }
    sink.summary(&summary);
    if let Some(e) = sink.error.take() {
        return Err(Failure::Run(format!("writing the output: {e}")));
    }
    sink.out
        .flush()
        .map_err(|e| Failure::Run(format!("writing the output: {e}")))
}

/// Writes samples, events and the summary as JSON Lines.
struct JsonSink {
    out: BufWriter<Box<dyn Write + Send>>,
    line: String,
    error: Option<io::Error>,
    progress: Option<ProgressBar>,
}

impl JsonSink {
    fn emit(&mut self) {
        self.line.push('\n');
        if self.error.is_none()
            && let Err(e) = self.out.write_all(self.line.as_bytes())
        {
            self.error = Some(e);
        }
        self.line.clear();
    }

    fn summary<T: JsonFloat, const D: usize>(&mut self, s: &Summary<T, D>) {
        let l = &mut self.line;
        l.push_str("{\"summary\": {\"engine\": ");
        match &s.hand_over {
            None => json::string(l, &s.engine.to_string()),
            Some(_) => json::string(l, &format!("{}+{}", EngineKind::Event, s.engine)),
        }
        if let Some(h) = &s.hand_over {
            l.push_str(", \"hand_over\": {\"t\": ");
            h.time.write_json(l);
            l.push_str(", \"reason\": ");
            json::string(l, &h.reason);
            l.push('}');
        }
        l.push_str(", \"pipeline\": [");
        for (k, p) in s.pipeline.iter().enumerate() {
            if k > 0 {
                l.push_str(", ");
            }
            json::string(l, p);
        }
        let _ = write!(
            l,
            "], \"ball_ball\": {}, \"ball_border\": {}, \"ball_box\": {}, \"energy_initial\": ",
            s.counters.ball_ball, s.counters.ball_border, s.counters.ball_box
        );
        s.energy_initial.write_json(l);
        l.push_str(", \"energy_final\": ");
        s.energy_final.write_json(l);
        l.push_str(", \"momentum_initial\": ");
        json::vector::<T, D>(l, &s.momentum_initial);
        l.push_str(", \"momentum_final\": ");
        json::vector::<T, D>(l, &s.momentum_final);
        l.push_str(", \"wall_s\": ");
        s.wall_s.write_json(l);
        l.push_str("}}");
        self.emit();
    }
}

impl<T: JsonFloat, const D: usize> RunSink<T, D> for JsonSink
where
    Const<D>: Space<T, D>,
{
    fn sample(&mut self, t: T, states: &BallStates<T, D>) {
        let l = &mut self.line;
        l.push_str("{\"t\": ");
        t.write_json(l);
        l.push_str(", \"pos\": ");
        json::vectors::<T, D>(l, &states.pos);
        l.push_str(", \"vel\": ");
        json::vectors::<T, D>(l, &states.vel);
        l.push('}');
        self.emit();
    }

    fn collision(&mut self, c: &Collision<T>) {
        let l = &mut self.line;
        match *c {
            Collision::BallBall { time, i, j } => {
                l.push_str("{\"event\": \"ball-ball\", \"t\": ");
                time.write_json(l);
                let _ = write!(l, ", \"i\": {i}, \"j\": {j}}}");
            }
            Collision::BallBorder { time, i } => {
                l.push_str("{\"event\": \"ball-border\", \"t\": ");
                time.write_json(l);
                let _ = write!(l, ", \"i\": {i}}}");
            }
            Collision::BallBox { time, i, k } => {
                l.push_str("{\"event\": \"ball-box\", \"t\": ");
                time.write_json(l);
                let _ = write!(l, ", \"i\": {i}, \"box\": {k}}}");
            }
        }
        self.emit();
    }

    fn progress(&mut self, t: T, until: T) {
        if let Some(bar) = &self.progress {
            let fraction = if until == T::zero() {
                1.0
            } else {
                (t / until).to_f64().clamp(0.0, 1.0)
            };
            bar.set_position((fraction * 1000.0) as u64);
            bar.set_message(format!("{:.4}", t.to_f64()));
        }
    }
}
