//! REPORT.md and the plots of the performance sections, from a [`Report`]'s rows.
//!
//! Every sentence that judges carom is computed from the rows ([`crate::targets`],
//! [`crate::worse`]); sections without rows say they were not run.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::ReportError;
use crate::model::{Mode, Report};
use crate::plot::{self, Chart, Series};
use crate::scaling;
use crate::targets::{self, count, ms, si};
use crate::throughput::{STEPPED_SCENE, engine};
use crate::worse::where_carom_is_worse;

/// The plots a REPORT.md links, by section (file names relative to the report's folder).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plots {
    /// Section 1: one work-precision diagram per problem.
    pub work_precision: Vec<PathBuf>,
    /// Section 3: the stepped engine against rapier2d.
    pub stepped: Option<PathBuf>,
    /// Section 3: one plot per broad-phase scene.
    pub broad: Vec<PathBuf>,
    /// Section 4: speedups against size.
    pub scaling: Option<PathBuf>,
}

/// `name` in `dir`, for a plot file.
fn file(dir: &Path, name: &str) -> (PathBuf, PathBuf) {
    (dir.join(name), PathBuf::from(name))
}

/// The broad-phase scenes of `report` that have ball counts (not Terdiman's boxes), in
/// the order they were measured.
fn broad_scenes(report: &Report) -> Vec<&str> {
    let mut seen = BTreeSet::new();
    report
        .broad_phase
        .iter()
        .map(|r| r.scene.as_str())
        .filter(|s| *s != crate::broad::RANDOM_BOXES_SCENE && seen.insert(*s))
        .collect()
}

/// Draws the report's plots into `dir` (those whose rows exist).
///
/// # Errors
/// A plot cannot be written.
pub fn draw_plots(report: &Report, dir: &Path) -> Result<Plots, ReportError> {
    let work_precision = crate::work_precision::plot(&report.work_precision, dir)
        .map_err(ReportError::io(dir))?
        .iter()
        .filter_map(|p| p.file_name().map(PathBuf::from))
        .collect();
    Ok(Plots {
        work_precision,
        stepped: stepped_plot(report, dir)?,
        broad: broad_plots(report, dir)?,
        scaling: scaling_plot(report, dir)?,
    })
}

/// Time per step against N, both engines on 1 and 2 threads.
fn stepped_plot(report: &Report, dir: &Path) -> Result<Option<PathBuf>, ReportError> {
    let stepped: Vec<Series> = [engine::STEPPED, engine::RAPIER]
        .into_iter()
        .enumerate()
        .flat_map(|(colour, e)| {
            [1, 2].into_iter().map(move |threads| Series {
                label: format!(
                    "{e}, {threads} thread{}",
                    if threads == 1 { "" } else { "s" }
                ),
                points: report
                    .throughput
                    .iter()
                    .filter(|r| r.scene == STEPPED_SCENE && r.engine == e && r.threads == threads)
                    .filter_map(|r| Some((r.n as f64, r.ms_per_step?)))
                    .collect(),
                colour,
                dashed: threads == 2,
            })
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    if stepped.is_empty() {
        return Ok(None);
    }
    let (path, name) = file(dir, "stepped-vs-rapier2d.svg");
    plot::draw(
        &Chart {
            title: "Stepped engine against rapier2d: elastic gas, dt = 1/60".into(),
            x_label: "balls".into(),
            y_label: "ms per step (median)".into(),
            log_y: true,
            references: Vec::new(),
            series: stepped,
        },
        &path,
    )?;
    Ok(Some(name))
}

/// ns per ball against N, one plot per broad-phase scene.
fn broad_plots(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    let mut plots = Vec::new();
    for scene in broad_scenes(report) {
        let rows: Vec<_> = report
            .broad_phase
            .iter()
            .filter(|r| r.scene == scene)
            .collect();
        let methods: Vec<&str> = crate::broad::METHODS
            .into_iter()
            .chain([crate::broad::PEER])
            .filter(|m| rows.iter().any(|r| r.method == *m))
            .collect();
        let series = methods
            .iter()
            .enumerate()
            .flat_map(|(colour, m)| {
                let rows = &rows;
                [1, 2].into_iter().map(move |threads| Series {
                    label: format!(
                        "{m}, {threads} thread{}",
                        if threads == 1 { "" } else { "s" }
                    ),
                    points: rows
                        .iter()
                        .filter(|r| r.method == *m && r.threads == threads)
                        .map(|r| (r.n as f64, r.ns_per_ball))
                        .collect(),
                    colour,
                    dashed: threads == 2,
                })
            })
            .filter(|s| !s.points.is_empty())
            .collect();
        let slug: String = scene
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '.' {
                    c.to_ascii_lowercase()
                } else {
                    '-'
                }
            })
            .collect();
        let (path, name) = file(dir, &format!("broad-{slug}.svg"));
        plot::draw(
            &Chart {
                title: format!("Broad phases, {scene}: update + pairs per frame"),
                x_label: "balls".into(),
                y_label: "ns per ball (median frame)".into(),
                log_y: true,
                references: Vec::new(),
                series,
            },
            &path,
        )?;
        plots.push(name);
    }
    Ok(plots)
}

/// Speedup against N of the engines and of the fastest broad phase of each coherent
/// uniform scene.
fn scaling_plot(report: &Report, dir: &Path) -> Result<Option<PathBuf>, ReportError> {
    let points = scaling::all_sizes(&report.throughput, &report.broad_phase);
    let mut parts: Vec<String> = Vec::new();
    for r in report.throughput.iter().filter(|r| r.ms_per_step.is_some()) {
        let part = format!("{} step, {}", r.engine, r.scene);
        if !parts.contains(&part) {
            parts.push(part);
        }
    }
    // carom's broad phase fastest on one thread at each coherent uniform scene's largest
    // size (the peer runs on one thread only).
    for scene in ["2D uniform0.1 coherent", "3D uniform0.1 coherent"] {
        let best = report
            .broad_phase
            .iter()
            .filter(|r| r.scene == scene && r.threads == 1 && r.method != crate::broad::PEER)
            .max_by(|a, b| a.n.cmp(&b.n).then(b.ns_per_ball.total_cmp(&a.ns_per_ball)));
        if let Some(b) = best {
            parts.push(format!("{} broad phase, {scene}", b.method));
        }
    }
    let series: Vec<Series> = parts
        .iter()
        .enumerate()
        .map(|(colour, part)| Series {
            label: part.clone(),
            points: points
                .iter()
                .filter(|p| &p.part == part)
                .map(|p| (p.n as f64, p.speedup()))
                .collect(),
            colour,
            dashed: part.starts_with(engine::RAPIER),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    if series.is_empty() {
        return Ok(None);
    }
    let (path, name) = file(dir, "scaling.svg");
    plot::draw(
        &Chart {
            title: "1 → 2 threads: speedup against size".into(),
            x_label: "balls".into(),
            y_label: "speedup (time on 1 thread / on 2)".into(),
            log_y: false,
            references: vec![(2.0, "ideal (2×)".into()), (1.0, "no gain".into())],
            series,
        },
        &path,
    )?;
    Ok(Some(name))
}

/// Appends a markdown image line for each plot.
fn images(md: &mut String, plots: &[PathBuf]) {
    for p in plots {
        let _ = writeln!(md, "\n![{}]({})", p.display(), p.display());
    }
}

fn header(md: &mut String, report: &Report) {
    let m = &report.machine;
    let mode = match report.mode {
        Mode::Quick => "quick",
        Mode::Full => "full",
    };
    let _ = writeln!(md, "# carom benchmark report\n");
    let _ = writeln!(
        md,
        "The {mode} report of {}: carom {} on {} CPU{} ({}), {}, {} build.",
        m.date(),
        m.carom_version,
        m.cpus,
        if m.cpus == 1 { "" } else { "s" },
        m.cpu_model.as_deref().unwrap_or("model unknown"),
        m.os,
        if m.optimized {
            "optimized"
        } else {
            "**unoptimized (debug) — these timings are not comparable**"
        },
    );
    let _ = writeln!(
        md,
        "\nEvery timing is a median of repeated runs in this one process, carom and its peer \
         side by side on the same scene; timings from a machine shared with other work are \
         noisy, ratios measured in the same run less so. docs/benchmarks.md says how to \
         reproduce each figure. `report.json` holds every row."
    );
    if let Some(c) = &m.ceiling {
        let _ = writeln!(
            md,
            "\nThis machine's own 1 → 2 thread speedups, measured at the report's start on \
             loops whose threads share no data: {}. A parallel part that waits on memory \
             cannot scale beyond the memory figures (section 4). One core of it did {:.0} M \
             square roots/s, streamed {:.1} GB/s and made {:.0} M random reads/s: compare \
             these before comparing two reports' timings.",
            c.speedups(),
            c.one_core_square_roots_per_s / 1e6,
            c.one_core_stream_bytes_per_s / 1e9,
            c.one_core_random_reads_per_s / 1e6,
        );
    }
    if m.busy() {
        let _ = writeln!(
            md,
            "\n**The machine was busy:** its load average was {:.1} on {} CPUs when the report \
             started, so other work shared the cores. Timings are inflated and 2-thread \
             speedups understated; rerun on a quiet machine before quoting them.",
            m.load_average.unwrap_or(0.0),
            m.cpus
        );
    }
    let has_rapier = report.throughput.iter().any(|r| r.engine == engine::RAPIER)
        || report
            .work_precision
            .iter()
            .any(|r| r.method.starts_with("rapier"));
    if !has_rapier {
        let _ = writeln!(
            md,
            "\n**No rapier2d rows:** this build left the peer out (cargo feature `rapier` of \
             carom-cli / carom-report), so carom is compared with its targets only."
        );
    }
}

fn summary(md: &mut String, report: &Report) {
    let _ = writeln!(md, "\n## Summary: the targets side by side with rapier2d\n");
    md.push_str(&targets::summary_table(report));
    let _ = writeln!(md, "\n## Where carom is worse\n");
    let worse = where_carom_is_worse(report);
    if worse.is_empty() {
        let _ = writeln!(
            md,
            "In every comparison this report made, carom is ahead of its peer and meets its targets."
        );
    }
    for w in worse {
        let _ = writeln!(md, "- {w}");
    }
}

fn work_precision(md: &mut String, report: &Report, plots: &Plots) {
    let _ = writeln!(md, "\n## 1. Error against run time\n");
    if report.work_precision.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let _ = writeln!(
        md,
        "How to read: each line is one method; lower-left is better (smaller error for less \
         time). Error at the final time against the closed form or a high-precision \
         reference; time is the minimum of several runs.\n"
    );
    let _ = writeln!(
        md,
        "| problem | method | dt | error | seconds |\n|---|---|---|---|---|"
    );
    for r in &report.work_precision {
        let dt =
            r.dt.map_or_else(|| "–".to_owned(), |dt| format!("{dt:.3e}"));
        let _ = writeln!(
            md,
            "| {} | {} | {dt} | {:.3e} | {:.3e} |",
            r.problem, r.method, r.error, r.seconds
        );
    }
    images(md, &plots.work_precision);
}

fn stability(md: &mut String, report: &Report) {
    let _ = writeln!(md, "\n## 2. Stability on stiff and extreme cases\n");
    if report.stability.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let passed = report.stability.iter().filter(|s| s.pass).count();
    let _ = writeln!(
        md,
        "How to read: each case states what it expects; pass means the expectation held, and \
         the figure is the measurement behind the verdict. {passed} of {} cases pass.\n",
        report.stability.len()
    );
    let _ = writeln!(md, "| case | verdict | figure |\n|---|---|---|");
    for s in &report.stability {
        let verdict = if s.pass { "pass" } else { "**FAIL**" };
        let _ = writeln!(md, "| {} | {verdict} | {} |", s.case, s.figure);
    }
}

fn stepped_table(md: &mut String, report: &Report, plots: &Plots) {
    let _ = writeln!(md, "\n### Stepped engine against rapier2d\n");
    let carom: Vec<_> = report
        .throughput
        .iter()
        .filter(|r| r.engine == engine::STEPPED)
        .collect();
    if carom.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let _ = writeln!(
        md,
        "How to read: the same elastic gas (packing fraction 0.1, restitution 1, no gravity, \
         dt = 1/60) stepped by both engines from the same start, their steps alternating; \
         median time per step, and the relative change of kinetic energy over the whole run \
         (5 s of simulated time; 0 is exact). rapier2d / carom above 1 means carom is faster.\n"
    );
    let _ = writeln!(
        md,
        "| N | threads | carom ms/step | rapier2d ms/step | rapier2d / carom | carom energy drift | rapier2d energy drift |\n|---|---|---|---|---|---|---|"
    );
    for c in carom {
        let r = report.throughput.iter().find(|r| {
            r.engine == engine::RAPIER && r.scene == c.scene && r.n == c.n && r.threads == c.threads
        });
        let cm = c.ms_per_step.unwrap_or(f64::NAN);
        let rm = r.and_then(|r| r.ms_per_step);
        let drift = |d: Option<f64>| d.map_or_else(|| "–".to_owned(), |d| format!("{d:+.1e}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            count(c.n),
            c.threads,
            ms(cm),
            rm.map_or_else(|| "–".to_owned(), ms),
            rm.map_or_else(|| "–".to_owned(), |rm| format!("{:.1}×", rm / cm)),
            drift(c.energy_drift),
            drift(r.and_then(|r| r.energy_drift)),
        );
    }
    images(md, plots.stepped.as_slice());
}

fn event_table(md: &mut String, report: &Report) {
    let _ = writeln!(md, "\n### Event-driven engine\n");
    let rows: Vec<_> = report
        .throughput
        .iter()
        .filter(|r| r.engine == engine::EVENT)
        .collect();
    if rows.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let _ = writeln!(
        md,
        "How to read: ball–ball collisions per second of wall-clock time on one core, median \
         of several spans after the gas relaxed from its lattice start; the targets are the \
         event-driven engine issue's; EDMD (Smallenburg 2022, its published code) did \
         {:.2}–{:.2} M/s in 3D at N = 32,000 on this project's VM (measured {}, carom \
         {:.2} M/s in the same rounds; see docs/event-engine.md). That VM's speed changes \
         from day to day by more than the two engines differ, so this report's rates are \
         not a ratio to EDMD's. Energy drift over the whole run should be rounding only.\n",
        crate::targets::EDMD.0 / 1e6,
        crate::targets::EDMD.1 / 1e6,
        crate::targets::EDMD_MEASURED,
        crate::targets::CAROM_BESIDE_EDMD / 1e6,
    );
    let _ = writeln!(
        md,
        "| scene | N | collisions/s | target | energy drift |\n|---|---|---|---|---|"
    );
    for r in rows {
        let target = if r.scene.starts_with("spheres3d") {
            format!("≥ {}/s at N = 32,000", si(targets::EVENT_3D))
        } else {
            format!("≥ {}/s at N = 100,000", si(targets::EVENT_2D))
        };
        let _ = writeln!(
            md,
            "| {} | {} | {}/s | {target} | {} |",
            r.scene,
            count(r.n),
            si(r.collisions_per_s.unwrap_or(f64::NAN)),
            r.energy_drift
                .map_or_else(|| "–".to_owned(), |d| format!("{d:+.1e}")),
        );
    }
}

fn broad_table(md: &mut String, report: &Report, plots: &Plots) {
    let _ = writeln!(md, "\n### Broad phases\n");
    if report.broad_phase.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let _ = writeln!(
        md,
        "How to read: one frame is an update and the sorted pair list (what a stepped engine \
         pays per step); median frame time per ball, lower is better. One-shot frames jump \
         between unrelated scenes, coherent frames move every ball by 1 % of its radius. \
         sap = sweep-and-prune, kd = k-d tree, grid = dense uniform grid, hashed = hashed \
         grid, brute = all pairs (to 1,000 balls); parry-bvh = parry 0.31's BVH (`f32`, \
         rebuilt one-shot, refitted coherent), the peer, which reports overlapping boxes \
         unsorted where carom's phases report exact ball pairs, sorted.\n"
    );
    let _ = writeln!(
        md,
        "| scene | N | method | ns/ball 1 thread | ns/ball 2 threads | speedup |\n|---|---|---|---|---|---|"
    );
    for r in report.broad_phase.iter().filter(|r| r.threads == 1) {
        let two = report
            .broad_phase
            .iter()
            .find(|t| t.threads == 2 && t.scene == r.scene && t.n == r.n && t.method == r.method);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.1} | {} | {} |",
            r.scene,
            count(r.n),
            r.method,
            r.ns_per_ball,
            two.map_or_else(|| "–".to_owned(), |t| format!("{:.1}", t.ns_per_ball)),
            two.map_or_else(
                || "–".to_owned(),
                |t| format!("{:.2}×", r.ns_per_ball / t.ns_per_ball)
            ),
        );
    }
    images(md, &plots.broad);
}

fn scaling_table(md: &mut String, report: &Report, plots: &Plots) {
    let _ = writeln!(md, "\n## 4. 2-core scaling\n");
    if report.scaling.is_empty() {
        let _ = writeln!(md, "Not run in this report.");
        return;
    }
    let _ = writeln!(
        md,
        "How to read: time on 1 thread over time on 2 threads of each parallel part, at the \
         largest size this report ran on both (the medians of section 3); 2× is ideal. The \
         event-driven engine runs on one core and has no row.\n"
    );
    if let Some(c) = &report.machine.ceiling {
        let _ = writeln!(
            md,
            "This machine's ceilings in the same run (loops whose threads share no data): \
             {}.\n",
            c.speedups()
        );
    }
    let _ = writeln!(
        md,
        "| part | N | 1 thread | 2 threads | speedup |\n|---|---|---|---|---|"
    );
    for s in &report.scaling {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2}× |",
            s.part,
            count(s.n),
            ms(s.ms_1_thread),
            ms(s.ms_2_threads),
            s.speedup()
        );
    }
    images(md, plots.scaling.as_slice());
}

/// The text of REPORT.md, linking `plots`.
pub fn markdown(report: &Report, plots: &Plots) -> String {
    let mut md = String::new();
    header(&mut md, report);
    summary(&mut md, report);
    work_precision(&mut md, report, plots);
    stability(&mut md, report);
    let _ = writeln!(md, "\n## 3. Throughput");
    stepped_table(&mut md, report, plots);
    event_table(&mut md, report);
    broad_table(&mut md, report, plots);
    scaling_table(&mut md, report, plots);
    md
}
