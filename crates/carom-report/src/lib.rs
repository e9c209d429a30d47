//! carom's benchmark report: carom measured against its peers on the same scenes.
//!
//! [`run`] measures, in one process, the sections of the report a [`Mode`] asks for and
//! writes `REPORT.md`, `report.json` and SVG plots into a folder; [`summary_table`] is the
//! table `carom report` prints. The sections:
//!
//! 1. error against run time ([`work_precision`]) and 2. stability on stiff and extreme
//!    cases ([`stability`]), measured against the closed forms of
//!    [`reference`](mod@reference) with the engines built by [`engines`];
//! 3. throughput: the stepped engine against rapier2d, the event-driven engine's
//!    collisions per second ([`throughput`]), the broad phases ([`broad`]);
//! 4. 2-core scaling ([`scaling`]), read from section 3's rows.
//!
//! [`model`] holds the rows, which `report.json` serialises as they are; [`targets`]
//! checks them against the issues' targets and [`worse`] lists where carom loses; [`peer`]
//! builds carom scenes in rapier2d, so every comparison runs the same physical scene in
//! both engines.
//!
//! ```no_run
//! use carom_report::{Mode, run, summary_table};
//!
//! let report = run(Mode::Quick, "carom-report".as_ref(), &|p| {
//!     eprintln!("[{}/{}] {}", p.done + 1, p.total, p.message);
//! })?;
//! println!("{}", summary_table(&report));
//! # Ok::<(), carom_report::ReportError>(())
//! ```

pub mod broad;
pub mod ceiling;
pub mod engines;
mod error;
pub mod font;
mod machine;
pub mod model;
pub mod peer;
pub mod plot;
pub mod reference;
pub mod render;
pub mod scaling;
pub mod stability;
pub mod targets;
pub mod throughput;
pub mod timing;
pub mod work_precision;
pub mod worse;

use std::path::Path;
use std::time::Duration;

pub use error::ReportError;
pub use model::{Mode, Report};
pub use targets::summary_table;

use crate::broad::Distribution;
use crate::model::Machine;
use crate::timing::Sampling;

/// What one report measures: sizes and sampling of each case.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// The mode recorded in the report.
    pub mode: Mode,
    /// Section 1's problems, step sizes and repetitions.
    pub work_precision: work_precision::Sizes,
    /// Section 2's sizes.
    pub stability: stability::Sizes,
    /// Ball counts of the stepped gas (each on 1 and 2 threads).
    pub stepped_sizes: Vec<usize>,
    /// Steps of each stepped run (300 steps of 1/60 s = 5 s).
    pub stepped_steps: usize,
    /// Discs of the 2D event-driven gas.
    pub event_2d: usize,
    /// Spheres of the 3D event-driven gas.
    pub event_3d: usize,
    /// Time units each event-driven gas relaxes before it is measured.
    pub event_relax: f64,
    /// Sampling of each event-driven gas.
    pub event_sampling: Sampling,
    /// Ball counts of the broad-phase scenes.
    pub broad_sizes: Vec<usize>,
    /// Distributions of the broad-phase scenes (each 2D and 3D, one-shot and coherent).
    pub broad_distributions: Vec<Distribution>,
    /// Sampling of each broad phase on each scene.
    pub broad_sampling: Sampling,
    /// Also measure Terdiman's 10,000 random boxes.
    pub random_boxes: bool,
    /// The machine's 2-thread ceilings' loops (`ceiling`).
    pub ceiling: ceiling::CeilingSizes,
}

impl Config {
    /// The quick report: under 100 s for these sections on a 2-core machine.
    pub fn quick() -> Self {
        Self {
            mode: Mode::Quick,
            work_precision: work_precision::Sizes::for_mode(Mode::Quick),
            stability: stability::Sizes::for_mode(Mode::Quick),
            stepped_sizes: vec![1_000, 10_000],
            stepped_steps: 300,
            event_2d: 100_000,
            event_3d: 32_000,
            event_relax: 2.0,
            event_sampling: Sampling {
                min_samples: 5,
                budget: Duration::from_secs(2),
            },
            broad_sizes: vec![1_000, 10_000, 100_000],
            broad_distributions: vec![Distribution::Uniform(0.1)],
            broad_sampling: Sampling {
                min_samples: 5,
                budget: Duration::from_millis(150),
            },
            random_boxes: true,
            ceiling: ceiling::CeilingSizes::report(),
        }
    }

    /// The full report: engines to 1e5 balls, broad phases to 1e6, more scenes and
    /// samples.
    pub fn full() -> Self {
        Self {
            mode: Mode::Full,
            work_precision: work_precision::Sizes::for_mode(Mode::Full),
            stability: stability::Sizes::for_mode(Mode::Full),
            stepped_sizes: vec![1_000, 10_000, 100_000],
            event_sampling: Sampling {
                min_samples: 9,
                budget: Duration::from_secs(6),
            },
            broad_sizes: vec![1_000, 10_000, 100_000, 1_000_000],
            broad_distributions: vec![
                Distribution::Uniform(0.1),
                Distribution::Uniform(0.5),
                Distribution::Clustered,
            ],
            broad_sampling: Sampling {
                min_samples: 7,
                budget: Duration::from_millis(500),
            },
            ..Self::quick()
        }
    }

    /// The configuration of `mode`.
    pub fn for_mode(mode: Mode) -> Self {
        match mode {
            Mode::Quick => Self::quick(),
            Mode::Full => Self::full(),
        }
    }

    /// A report in a second or two, for tests of the machinery (figures meaningless).
    pub fn tiny() -> Self {
        Self {
            work_precision: work_precision::Sizes::tiny(),
            stability: stability::Sizes::tiny(),
            stepped_sizes: vec![100, 300],
            stepped_steps: 6,
            event_2d: 300,
            event_3d: 300,
            event_relax: 0.2,
            event_sampling: Sampling {
                min_samples: 2,
                budget: Duration::ZERO,
            },
            broad_sizes: vec![200, 2_000],
            broad_sampling: Sampling {
                min_samples: 1,
                budget: Duration::ZERO,
            },
            random_boxes: false,
            ceiling: ceiling::CeilingSizes::tiny(),
            ..Self::quick()
        }
    }
}

/// Where a report is: `done` of `total` measurements finished, `message` the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress<'a> {
    /// Measurements finished.
    pub done: usize,
    /// Measurements in the report.
    pub total: usize,
    /// What runs now.
    pub message: &'a str,
}

/// One measurement of the report.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Task {
    /// Section 1: every problem and method.
    WorkPrecision,
    /// Section 2: every case.
    Stability,
    /// The stepped gas of `n` balls on `threads` threads.
    Stepped { n: usize, threads: usize },
    /// The event-driven gas in `dim` dimensions.
    Event { dim: usize },
    /// Every broad phase on one scene.
    Broad {
        dim: usize,
        dist: Distribution,
        n: usize,
        coherent: bool,
    },
    /// Terdiman's random boxes.
    RandomBoxes,
}

impl Task {
    fn describe(self, config: &Config) -> String {
        match self {
            Self::WorkPrecision => "error against run time".to_owned(),
            Self::Stability => "stiff and extreme cases".to_owned(),
            Self::Stepped { n, threads } => format!(
                "stepped engine + rapier2d, gas N = {}, {threads} thread(s)",
                targets::count(n)
            ),
            Self::Event { dim } => format!(
                "event-driven engine, {dim}D gas N = {}",
                targets::count(if dim == 2 {
                    config.event_2d
                } else {
                    config.event_3d
                })
            ),
            Self::Broad {
                dim,
                dist,
                n,
                coherent,
            } => format!(
                "broad phases, {} N = {}",
                broad::scene_name(dim, dist, coherent),
                targets::count(n)
            ),
            Self::RandomBoxes => "broad phases, 10,000 random boxes".to_owned(),
        }
    }
}

/// The measurements `config` asks for, in the order they run.
fn tasks(config: &Config) -> Vec<Task> {
    let mut tasks = vec![Task::WorkPrecision, Task::Stability];
    for &n in &config.stepped_sizes {
        for threads in [1, 2] {
            tasks.push(Task::Stepped { n, threads });
        }
    }
    tasks.push(Task::Event { dim: 2 });
    tasks.push(Task::Event { dim: 3 });
    if config.random_boxes {
        tasks.push(Task::RandomBoxes);
    }
    for dim in [2, 3] {
        for &dist in &config.broad_distributions {
            for coherent in [false, true] {
                for &n in &config.broad_sizes {
                    tasks.push(Task::Broad {
                        dim,
                        dist,
                        n,
                        coherent,
                    });
                }
            }
        }
    }
    tasks
}

/// parry's 2D BVH when the peers are built (feature `rapier`), `None` otherwise.
#[cfg_attr(feature = "rapier", expect(clippy::unnecessary_wraps))]
fn peer_bvh_2d() -> Option<Box<dyn broad::Peer<2>>> {
    #[cfg(feature = "rapier")]
    return Some(Box::new(peer::parry::ParryBvh2::default()));
    #[cfg(not(feature = "rapier"))]
    None
}

/// parry's 3D BVH when the peers are built (feature `rapier`), `None` otherwise.
#[cfg_attr(feature = "rapier", expect(clippy::unnecessary_wraps))]
fn peer_bvh_3d() -> Option<Box<dyn broad::Peer<3>>> {
    #[cfg(feature = "rapier")]
    return Some(Box::new(peer::parry::ParryBvh3::default()));
    #[cfg(not(feature = "rapier"))]
    None
}

/// Measures what `config` asks for into a [`Report`] (nothing written).
///
/// # Errors
/// A case fails to build or run (a bug), or no thread pool can be made.
pub fn measure(config: &Config, progress: &dyn Fn(Progress<'_>)) -> Result<Report, ReportError> {
    let tasks = tasks(config);
    progress(Progress {
        done: 0,
        total: tasks.len(),
        message: "the machine's own 2-thread ceilings",
    });
    let mut report = Report {
        mode: config.mode,
        machine: Machine {
            ceiling: Some(ceiling::measure(&config.ceiling)?),
            ..Machine::detect()
        },
        throughput: Vec::new(),
        work_precision: Vec::new(),
        stability: Vec::new(),
        broad_phase: Vec::new(),
        scaling: Vec::new(),
    };
    let two = throughput::pool(2)?;
    for (done, &task) in tasks.iter().enumerate() {
        progress(Progress {
            done,
            total: tasks.len(),
            message: &task.describe(config),
        });
        let detail = |message: &str| {
            progress(Progress {
                done,
                total: tasks.len(),
                message,
            });
        };
        match task {
            Task::WorkPrecision => {
                report.work_precision = work_precision::run_with(&config.work_precision, &detail);
            }
            Task::Stability => report.stability = stability::run_with(&config.stability, &detail),
            Task::Stepped { n, threads } => {
                let rows = throughput::stepped(n, threads, config.stepped_steps)?;
                report.throughput.extend(rows);
            }
            Task::Event { dim: 2 } => report.throughput.push(throughput::event::<2>(
                config.event_2d,
                config.event_relax,
                config.event_sampling,
            )?),
            Task::Event { .. } => report.throughput.push(throughput::event::<3>(
                config.event_3d,
                config.event_relax,
                config.event_sampling,
            )?),
            Task::RandomBoxes => report
                .broad_phase
                .extend(broad::random_boxes(config.broad_sampling)),
            Task::Broad {
                dim,
                dist,
                n,
                coherent,
            } => {
                let sampling = config.broad_sampling;
                let rows = if dim == 2 {
                    broad::case::<2>(dist, n, coherent, sampling, &two, peer_bvh_2d())
                } else {
                    broad::case::<3>(dist, n, coherent, sampling, &two, peer_bvh_3d())
                };
                report.broad_phase.extend(rows);
            }
        }
    }
    progress(Progress {
        done: tasks.len(),
        total: tasks.len(),
        message: "writing the report",
    });
    report.scaling = scaling::from_rows(&report.throughput, &report.broad_phase);
    Ok(report)
}

/// Writes `report` into `out_dir` (created if needed): `REPORT.md`, `report.json` and the
/// plots.
///
/// # Errors
/// A file cannot be written.
pub fn write(report: &Report, out_dir: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(out_dir).map_err(ReportError::io(out_dir))?;
    let plots = render::draw_plots(report, out_dir)?;
    let json = out_dir.join("report.json");
    let text = serde_json::to_string_pretty(report).map_err(|e| ReportError::Io {
        path: json.clone(),
        source: e.into(),
    })?;
    std::fs::write(&json, text + "\n").map_err(ReportError::io(&json))?;
    let md = out_dir.join("REPORT.md");
    std::fs::write(&md, render::markdown(report, &plots)).map_err(ReportError::io(&md))
}

/// Runs the report of `mode` and writes it into `out_dir` ([`measure`] then [`write()`]),
/// telling `progress` before each measurement.
///
/// # Errors
/// As [`measure`] and [`write()`].
pub fn run(
    mode: Mode,
    out_dir: &Path,
    progress: &dyn Fn(Progress<'_>),
) -> Result<Report, ReportError> {
    run_with(&Config::for_mode(mode), out_dir, progress)
}

/// [`run`] with an explicit configuration (tests use [`Config::tiny`]).
///
/// # Errors
/// As [`measure`] and [`write()`].
pub fn run_with(
    config: &Config,
    out_dir: &Path,
    progress: &dyn Fn(Progress<'_>),
) -> Result<Report, ReportError> {
    let report = measure(config, progress)?;
    write(&report, out_dir)?;
    Ok(report)
}
