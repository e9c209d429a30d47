//! Section 4, 2-core scaling: the 1 → 2 thread speedup of each parallel part, from the
//! rows sections 3 measured (no extra runs: the same medians, read in pairs).
//!
//! A part is one engine on one scene, or one broad phase on one scene; its row is taken
//! at the largest size measured on both 1 and 2 threads. The event-driven engine runs on
//! one core and has no row.

use std::collections::BTreeMap;

use crate::model::{BroadPhaseRow, ScalingRow, ThroughputRow};

/// A part's times by size: `n → (ms on 1 thread, ms on 2 threads)`.
type BySize = BTreeMap<usize, (Option<f64>, Option<f64>)>;

/// Records `ms` at `threads` (1 or 2) for `part` at `n`.
fn record(parts: &mut BTreeMap<String, BySize>, part: String, n: usize, threads: usize, ms: f64) {
    let slot = parts.entry(part).or_default().entry(n).or_default();
    match threads {
        1 => slot.0 = Some(ms),
        2 => slot.1 = Some(ms),
        _ => {}
    }
}

/// Every part's speedup at every size measured on both 1 and 2 threads, in part order
/// then size order (the points of the scaling plot).
pub fn all_sizes(throughput: &[ThroughputRow], broad: &[BroadPhaseRow]) -> Vec<ScalingRow> {
    let mut parts = BTreeMap::new();
    for r in throughput {
        if let Some(ms) = r.ms_per_step {
            record(
                &mut parts,
                format!("{} step, {}", r.engine, r.scene),
                r.n,
                r.threads,
                ms,
            );
        }
    }
    for r in broad {
        record(
            &mut parts,
            format!("{} broad phase, {}", r.method, r.scene),
            r.n,
            r.threads,
            r.ns_per_ball * r.n as f64 * 1e-6,
        );
    }
    parts
        .into_iter()
        .flat_map(|(part, sizes)| {
            sizes.into_iter().filter_map(move |(n, times)| match times {
                (Some(ms_1_thread), Some(ms_2_threads)) => Some(ScalingRow {
                    part: part.clone(),
                    n,
                    ms_1_thread,
                    ms_2_threads,
                }),
                _ => None,
            })
        })
        .collect()
}

/// Each part's speedup at its largest size measured on both thread counts.
pub fn from_rows(throughput: &[ThroughputRow], broad: &[BroadPhaseRow]) -> Vec<ScalingRow> {
    let mut rows = all_sizes(throughput, broad);
    // Rows come by part then ascending size: keep the last of each part.
    let mut largest: Vec<ScalingRow> = Vec::new();
    for r in rows.drain(..) {
        match largest.last_mut() {
            Some(last) if last.part == r.part => *last = r,
            _ => largest.push(r),
        }
    }
    largest
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(engine: &str, n: usize, threads: usize, ms: f64) -> ThroughputRow {
        ThroughputRow {
            scene: "gas".into(),
            engine: engine.into(),
            n,
            threads,
            ms_per_step: Some(ms),
            collisions_per_s: None,
            energy_drift: None,
        }
    }

    #[test]
    fn each_part_scales_at_its_largest_size_on_both_thread_counts() {
        let throughput = [
            step("carom-stepped", 1000, 1, 1.0),
            step("carom-stepped", 1000, 2, 0.8),
            step("carom-stepped", 10_000, 1, 10.0),
            step("carom-stepped", 10_000, 2, 6.0),
            // Only one thread at 1e5: not a scaling point.
            step("carom-stepped", 100_000, 1, 100.0),
        ];
        let broad = [
            BroadPhaseRow {
                method: "grid".into(),
                scene: "2D".into(),
                n: 1000,
                threads: 1,
                ns_per_ball: 30.0,
            },
            BroadPhaseRow {
                method: "grid".into(),
                scene: "2D".into(),
                n: 1000,
                threads: 2,
                ns_per_ball: 20.0,
            },
        ];
        let rows = from_rows(&throughput, &broad);
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0].part, "carom-stepped step, gas");
        assert_eq!(rows[0].n, 10_000);
        assert!((rows[0].speedup() - 10.0 / 6.0).abs() < 1e-12);
        assert_eq!(rows[1].part, "grid broad phase, 2D");
        assert!((rows[1].ms_1_thread - 0.03).abs() < 1e-12);
        assert!((rows[1].speedup() - 1.5).abs() < 1e-12);
        assert_eq!(all_sizes(&throughput, &broad).len(), 3);
    }
}
