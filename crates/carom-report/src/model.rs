//! The report's data: one row type per section, as `report.json` holds them.
//!
//! Every row is a measurement, never a target: targets and verdicts are computed from
//! rows when the report is rendered. Times are seconds or milliseconds as the field
//! name says; `None` serialises as `null` (a quantity that does not apply to the row,
//! e.g. collisions per second of a time-stepped engine).

use serde::{Deserialize, Serialize};

/// How much the report measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// The default: small and medium sizes, under 3 minutes on a 2-core machine.
    Quick,
    /// The large sizes (engines to 1e5 balls, broad phases to 1e6).
    Full,
}

/// The whole report, as written to `report.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Which sizes were run.
    pub mode: Mode,
    /// The machine the figures come from.
    pub machine: Machine,
    /// Section 3: engines side by side.
    pub throughput: Vec<ThroughputRow>,
    /// Section 1: error against run time.
    pub work_precision: Vec<WorkPrecisionRow>,
    /// Section 2: stiff and extreme cases.
    pub stability: Vec<StabilityRow>,
    /// Section 3: broad phases.
    pub broad_phase: Vec<BroadPhaseRow>,
    /// Section 4: 1 → 2 thread speedups.
    pub scaling: Vec<ScalingRow>,
}

/// The machine and build the report ran on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// Logical CPUs available to the process.
    pub cpus: usize,
    /// The CPU model, when the system tells it.
    pub cpu_model: Option<String>,
    /// Operating system and architecture, e.g. `linux x86_64`.
    pub os: String,
    /// carom's version.
    pub carom_version: String,
    /// `true` when the report was built with optimisations (figures from debug builds
    /// are not comparable).
    pub optimized: bool,
    /// When the report was run, seconds since the Unix epoch.
    pub unix_time: u64,
    /// The system's 1-minute load average when the report started (Linux), a measure of
    /// the other work competing for the CPUs.
    #[serde(default)]
    pub load_average: Option<f64>,
    /// The machine's own 1 → 2 thread speedups on loops that share no data, measured in
    /// the report's run (`ceiling`); `None` where not measured.
    #[serde(default)]
    pub ceiling: Option<Ceiling>,
}

/// The 1 → 2 thread speedups of three kinds of work on this machine, each of two equal
/// tasks that share no data (see `ceiling`): what a parallel part doing that kind of
/// work can reach at best; and the rates of one core on each.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ceiling {
    /// Dependent floating-point operations in registers.
    pub compute: f64,
    /// Reading and rewriting a buffer larger than the cache, front to back.
    pub streaming_memory: f64,
    /// Reads at random places of a table larger than the cache.
    pub random_reads: f64,
    /// What one core did of each loop, to compare machines (or one VM on two days)
    /// before comparing reports' timings: square roots per second, …
    pub one_core_square_roots_per_s: f64,
    /// … bytes read and written per second streaming, …
    pub one_core_stream_bytes_per_s: f64,
    /// … and random reads per second.
    pub one_core_random_reads_per_s: f64,
}

/// One engine on one scene at one size and thread count.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThroughputRow {
    /// The scene, e.g. `gas2d-phi0.1`.
    pub scene: String,
    /// `carom-stepped`, `carom-event` or `rapier2d`.
    pub engine: String,
    /// Number of balls.
    pub n: usize,
    /// Threads of the pool the engine ran on.
    pub threads: usize,
    /// Median wall-clock milliseconds per step (time-stepped engines).
    pub ms_per_step: Option<f64>,
    /// Collisions per wall-clock second (event-driven engine).
    pub collisions_per_s: Option<f64>,
    /// Relative change of the kinetic energy over the run, `(E_end − E_0) / E_0`.
    pub energy_drift: Option<f64>,
}

/// One method on one problem at one step size: the error it reaches and what it costs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorkPrecisionRow {
    /// The problem, e.g. `projectile-drag`.
    pub problem: String,
    /// The method, e.g. `carom-stepped/velocity-verlet`, `carom-event`, `rapier2d`.
    pub method: String,
    /// The step, for methods that have one.
    pub dt: Option<f64>,
    /// The error at the final time against the reference (the problem says which norm).
    pub error: f64,
    /// Minimum wall-clock seconds of several runs.
    pub seconds: f64,
}

/// One stiff or extreme case: whether it passed, and the figure that says so.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StabilityRow {
    /// The case, e.g. `speed 1e6 m/s, stepped engine`.
    pub case: String,
    /// Whether the case did what the report expects of it.
    pub pass: bool,
    /// The measured figure behind the verdict, e.g. `max overlap 0 m`.
    pub figure: String,
}

/// One broad phase at one size and thread count.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BroadPhaseRow {
    /// The broad phase, e.g. `grid`, `sap`, `kd`, `parry-bvh`.
    pub method: String,
    /// The scene, e.g. `2D uniform0.1 coherent`.
    pub scene: String,
    /// Number of balls.
    pub n: usize,
    /// Threads of the pool.
    pub threads: usize,
    /// Median nanoseconds per ball per frame (update and pairs).
    pub ns_per_ball: f64,
}

/// The speedup of one parallel part from 1 to 2 threads.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalingRow {
    /// The part, e.g. `stepped engine step`, `grid broad phase`.
    pub part: String,
    /// Size it was measured at.
    pub n: usize,
    /// Median milliseconds on 1 thread.
    pub ms_1_thread: f64,
    /// Median milliseconds on 2 threads.
    pub ms_2_threads: f64,
}

impl ScalingRow {
    /// `ms_1_thread / ms_2_threads`.
    pub fn speedup(&self) -> f64 {
        self.ms_1_thread / self.ms_2_threads
    }
}
