//! "Where carom is worse": every comparison in a report's rows that carom loses, as
//! sentences for REPORT.md. Computed from the rows, never written by hand.

use std::collections::BTreeMap;

use crate::broad::PEER;
use crate::model::Report;
use crate::targets::{self, EDMD, count, ms};
use crate::throughput::engine;

/// Time per step and energy drift against rapier2d on the same scene, size and threads.
fn stepped(report: &Report, out: &mut Vec<String>) {
    for c in report
        .throughput
        .iter()
        .filter(|r| r.engine == engine::STEPPED)
    {
        let Some(r) = report.throughput.iter().find(|r| {
            r.engine == engine::RAPIER && r.scene == c.scene && r.n == c.n && r.threads == c.threads
        }) else {
            continue;
        };
        if let (Some(cm), Some(rm)) = (c.ms_per_step, r.ms_per_step)
            && cm > rm
        {
            out.push(format!(
                "Time per step, {} N = {} on {} thread(s): carom {} against rapier2d {} ({:.2}× slower).",
                c.scene,
                count(c.n),
                c.threads,
                ms(cm),
                ms(rm),
                cm / rm
            ));
        }
        if let (Some(cd), Some(rd)) = (c.energy_drift, r.energy_drift)
            && cd.abs() > rd.abs()
        {
            out.push(format!(
                "Energy drift, {} N = {} on {} thread(s): carom {cd:+.1e} against rapier2d {rd:+.1e}.",
                c.scene,
                count(c.n),
                c.threads
            ));
        }
    }
    for c in report
        .scaling
        .iter()
        .filter(|s| s.part.starts_with(engine::STEPPED))
    {
        let peer = c.part.replacen(engine::STEPPED, engine::RAPIER, 1);
        if let Some(r) = report.scaling.iter().find(|r| r.part == peer && r.n == c.n)
            && c.speedup() < r.speedup()
        {
            out.push(format!(
                "2-thread speedup, {} N = {}: carom {:.2}× against rapier2d {:.2}×.",
                c.part,
                count(c.n),
                c.speedup(),
                r.speedup()
            ));
        }
    }
}

/// The event-driven engine below EDMD's rate measured on this machine on another day
/// (see [`targets::edmd_beside`]).
fn event(report: &Report, out: &mut Vec<String>) {
    for r in report
        .throughput
        .iter()
        .filter(|r| r.engine == engine::EVENT && r.scene.starts_with("spheres3d"))
    {
        if let Some(rate) = r.collisions_per_s
            && rate < EDMD.1
        {
            let (low, high) = targets::carom_over_edmd();
            out.push(format!(
                "Event-driven 3D hard spheres N = {}: {:.3} M collisions/s, below the best of EDMD's {:.2}–{:.2} M/s on this project's VM ({}; side by side carom ran at {low:.2}–{high:.2}× EDMD that day, so a gap beyond that is the VM's speed on the day of this run or a regression).",
                count(r.n),
                rate / 1e6,
                EDMD.0 / 1e6,
                EDMD.1 / 1e6,
                targets::EDMD_MEASURED,
            ));
        }
    }
}

/// Broad-phase scenes and sizes where parry's BVH is faster than carom's fastest broad
/// phase (both on one thread).
fn broad(report: &Report, out: &mut Vec<String>) {
    for p in report.broad_phase.iter().filter(|r| r.method == PEER) {
        let best = report
            .broad_phase
            .iter()
            .filter(|r| r.scene == p.scene && r.n == p.n && r.threads == 1 && r.method != PEER)
            .min_by(|a, b| a.ns_per_ball.total_cmp(&b.ns_per_ball));
        if let Some(b) = best
            && b.ns_per_ball > p.ns_per_ball
        {
            out.push(format!(
                "Broad phase, {} N = {} on 1 thread: parry's BVH {:.1} ns per ball against carom's fastest ({}) {:.1} ns ({:.2}× slower; parry reports box pairs unsorted, carom exact ball pairs sorted).",
                p.scene,
                count(p.n),
                p.ns_per_ball,
                b.method,
                b.ns_per_ball,
                b.ns_per_ball / p.ns_per_ball
            ));
        }
    }
}

/// Work-precision points of rapier2d that no carom method matches on both axes (as
/// accurate and as fast).
fn work_precision(report: &Report, out: &mut Vec<String>) {
    let mut problems: BTreeMap<&str, Vec<_>> = BTreeMap::new();
    for r in &report.work_precision {
        problems.entry(r.problem.as_str()).or_default().push(r);
    }
    for (problem, rows) in problems {
        let (peer, carom): (Vec<_>, Vec<_>) = rows
            .into_iter()
            .partition(|r| r.method.starts_with("rapier"));
        for p in peer {
            let matched = carom
                .iter()
                .any(|c| c.error <= p.error && c.seconds <= p.seconds);
            if !matched && !carom.is_empty() {
                let dt =
                    p.dt.map_or_else(String::new, |dt| format!(" at dt = {dt:.3e}"));
                out.push(format!(
                    "Work-precision, {problem}: {}{dt} reaches error {:.2e} in {:.2e} s; no carom method is both as accurate and as fast.",
                    p.method, p.error, p.seconds
                ));
            }
        }
    }
}

/// Every comparison carom loses in `report`, plus every missed target and failed
/// stability case.
pub fn where_carom_is_worse(report: &Report) -> Vec<String> {
    let mut out = Vec::new();
    stepped(report, &mut out);
    event(report, &mut out);
    broad(report, &mut out);
    work_precision(report, &mut out);
    for s in report.stability.iter().filter(|s| !s.pass) {
        out.push(format!("Stability case failed: {} ({}).", s.case, s.figure));
    }
    for c in targets::checks(report)
        .into_iter()
        .filter(|c| c.verdict.starts_with("MISSED"))
    {
        out.push(format!(
            "Target missed: {}: {} (target {}).",
            c.measure, c.carom, c.target
        ));
    }
    out
}
