//! Section 3, broad phases: nanoseconds per ball per frame of each carom broad phase, on
//! the shared scenes of [`carom_broad::scenes`] (the scenes of `benches/broad.rs`).
//!
//! A frame is `update` + `pairs`, everything a stepped engine pays per step; on 2 threads
//! it is `par_update` + `par_pairs` on a rayon pool of 2. One-shot frames alternate between
//! two unrelated scenes of the same distribution; coherent frames between a scene and the
//! same scene with every ball moved by 1 % of its radius. The figure is the median frame
//! time (wall clock, [`crate::timing::median_per_call`]) divided by the ball count.
//! Brute force runs to 1,000 balls only, on one thread. Terdiman's 10,000 random boxes
//! (3D, one-shot) are measured too: the broad-phase issue's target is under 1 ms.

use carom_broad::scenes::Scene;
use carom_broad::{
    BruteForce, KdTree, Pair, ParallelBroadPhase, SortPolicy, SweepAndPrune, UniformGrid, Volumes,
};

use crate::model::BroadPhaseRow;
use crate::timing::{Sampling, median_per_call};

/// A peer's broad phase (parry's BVH, [`crate::peer::parry`]) in `D` dimensions.
pub trait Peer<const D: usize> {
    /// One frame on `scene` (rebuilt, or refitted when `coherent` and a tree exists);
    /// returns the number of pairs it reports.
    fn frame(&mut self, scene: &Scene<f64, D>, coherent: bool) -> usize;
}

/// The peer's name in the rows.
pub const PEER: &str = "parry-bvh";

/// The broad phases measured, by their names in the rows.
pub const METHODS: [&str; 5] = ["sap", "kd", "grid", "hashed", "brute"];

/// The largest ball count brute force is run at.
pub const BRUTE_MAX: usize = 1_000;

/// Ball count of Terdiman's random-boxes case.
pub const RANDOM_BOXES: usize = 10_000;

/// The scene name of Terdiman's random-boxes case.
pub const RANDOM_BOXES_SCENE: &str = "3D 10k random boxes one-shot";

/// How the balls of a broad-phase scene are placed (radius 0.5 unless mixed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Distribution {
    /// Uniform in a cube sized for this packing fraction.
    Uniform(f64),
    /// 16 clumps, packing fraction 0.1 over the whole domain.
    Clustered,
}

impl Distribution {
    /// The name in the rows' scenes.
    pub fn name(self) -> String {
        match self {
            Self::Uniform(f) => format!("uniform{f}"),
            Self::Clustered => "clustered".to_owned(),
        }
    }

    fn scene<const D: usize>(self, n: usize, seed: u64) -> Scene<f64, D> {
        match self {
            Self::Uniform(f) => Scene::uniform(n, 0.5, f, 0.0, seed),
            Self::Clustered => Scene::clustered(n, 0.5, 0.1, 16, seed),
        }
    }
}

/// The scene name of a row: `2D uniform0.1 coherent`.
pub fn scene_name(dim: usize, dist: Distribution, coherent: bool) -> String {
    let frames = if coherent { "coherent" } else { "one-shot" };
    format!("{dim}D {} {frames}", dist.name())
}

/// The broad phase named `name` (one of [`METHODS`]) as the report runs it: sweep-and-prune
/// sorts incrementally on coherent frames and by radix sort on one-shot ones.
pub fn make_phase<const D: usize>(
    name: &str,
    coherent: bool,
) -> Box<dyn ParallelBroadPhase<f64, D>> {
    match name {
        // Incremental insertion sort pays off only when frames are coherent.
        "sap" if coherent => Box::new(SweepAndPrune::new()),
        "sap" => Box::new(SweepAndPrune::with_policy(SortPolicy::Radix)),
        "kd" => Box::new(KdTree::new()),
        "grid" => Box::new(UniformGrid::dense()),
        "hashed" => Box::new(UniformGrid::hashed()),
        _ => Box::new(BruteForce::new()),
    }
}

/// One frame: update and pairs, in parallel on the current pool when `parallel`.
fn frame<const D: usize>(
    phase: &mut dyn ParallelBroadPhase<f64, D>,
    volumes: Volumes<'_, f64, D>,
    parallel: bool,
    out: &mut Vec<Pair>,
) {
    if parallel {
        phase.par_update(volumes);
        phase.par_pairs(out);
    } else {
        phase.update(volumes);
        phase.pairs(out);
    }
}

/// Every broad phase on one `D`-dimensional scene of `n` balls: a row per method and
/// thread count (1, and 2 on `two`), and one for `peer` (1 thread) when given.
pub fn case<const D: usize>(
    dist: Distribution,
    n: usize,
    coherent: bool,
    sampling: Sampling,
    two: &rayon::ThreadPool,
    peer: Option<Box<dyn Peer<D>>>,
) -> Vec<BroadPhaseRow> {
    let first = dist.scene::<D>(n, 1);
    let second = if coherent {
        let mut s = first.clone();
        s.step(0.01);
        s
    } else {
        dist.scene::<D>(n, 2)
    };
    let frames = [&first, &second];
    let scene = scene_name(D, dist, coherent);
    let mut out = Vec::new();
    let mut rows = Vec::new();
    for name in METHODS {
        if name == "brute" && n > BRUTE_MAX {
            continue;
        }
        let threads: &[usize] = if name == "brute" { &[1] } else { &[1, 2] };
        for &t in threads {
            let mut phase = make_phase::<D>(name, coherent);
            let mut measure = || {
                median_per_call(sampling, |k| {
                    frame(phase.as_mut(), frames[k % 2].balls(), t == 2, &mut out);
                })
            };
            let d = if t == 2 {
                two.install(measure)
            } else {
                measure()
            };
            rows.push(BroadPhaseRow {
                method: name.to_owned(),
                scene: scene.clone(),
                n,
                threads: t,
                ns_per_ball: d.as_secs_f64() * 1e9 / n as f64,
            });
        }
    }
    if let Some(mut peer) = peer {
        let d = median_per_call(sampling, |k| {
            peer.frame(frames[k % 2], coherent);
        });
        rows.push(BroadPhaseRow {
            method: PEER.to_owned(),
            scene,
            n,
            threads: 1,
            ns_per_ball: d.as_secs_f64() * 1e9 / n as f64,
        });
    }
    rows
}

/// Terdiman's 10,000 random boxes (3D, one-shot, spread 2000, half extents to 20): a row
/// per method that takes boxes well (sweep-and-prune, grid, k-d tree), one thread.
pub fn random_boxes(sampling: Sampling) -> Vec<BroadPhaseRow> {
    let a = Scene::<f64, 3>::boxes(RANDOM_BOXES, 2000.0, 20.0, 1);
    let b = Scene::<f64, 3>::boxes(RANDOM_BOXES, 2000.0, 20.0, 2);
    let mut out = Vec::new();
    ["sap", "grid", "kd"]
        .into_iter()
        .map(|name| {
            let mut phase = make_phase::<3>(name, false);
            let d = median_per_call(sampling, |k| {
                let boxes = if k % 2 == 0 { a.aabbs() } else { b.aabbs() };
                frame(phase.as_mut(), boxes, false, &mut out);
            });
            BroadPhaseRow {
                method: name.to_owned(),
                scene: RANDOM_BOXES_SCENE.to_owned(),
                n: RANDOM_BOXES,
                threads: 1,
                ns_per_ball: d.as_secs_f64() * 1e9 / RANDOM_BOXES as f64,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_case_measures_every_method_on_its_threads() {
        let sampling = Sampling {
            min_samples: 1,
            budget: Duration::ZERO,
        };
        let two = crate::throughput::pool(2).unwrap();
        let rows = case::<2>(Distribution::Uniform(0.1), 500, true, sampling, &two, None);
        // Four methods on 1 and 2 threads, brute force on 1.
        assert_eq!(rows.len(), 9);
        assert!(rows.iter().all(|r| r.ns_per_ball > 0.0 && r.n == 500));
        assert!(rows.iter().all(|r| r.scene == "2D uniform0.1 coherent"));
        let rows = case::<3>(Distribution::Clustered, 2000, false, sampling, &two, None);
        assert_eq!(rows.len(), 8, "no brute force above {BRUTE_MAX}");
        assert_eq!(rows[0].scene, "3D clustered one-shot");
        #[cfg(feature = "rapier")]
        {
            let peer = Box::new(crate::peer::parry::ParryBvh3::default());
            let rows = case::<3>(
                Distribution::Clustered,
                300,
                true,
                sampling,
                &two,
                Some(peer),
            );
            let last = rows.last().unwrap();
            assert_eq!((last.method.as_str(), last.threads), (PEER, 1));
        }
    }
}
