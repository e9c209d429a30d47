//! Every broad phase against the brute-force oracle: the same pairs (and the same order)
//! on random scenes of every kind the issue lists, in 2D and 3D, f64 and f32, boxes
//! and balls, one-shot and over coherent multi-frame sequences; the same query results;
//! and parallel pair finding identical to sequential on 1, 2 and 3 threads.
//!
//! The phases are driven through `ParallelBroadPhase`, so the file needs the (default)
//! `parallel` feature.
#![cfg(feature = "parallel")]

use carom_broad::scenes::SplitMix64;
use carom_broad::{
    Aabb, Balls, Border, BroadPhase, BruteForce, KdTree, ParallelBroadPhase, Real, SortPolicy,
    SweepAndPrune, UniformGrid, Vector, Volumes,
};
use proptest::prelude::*;

/// The kinds of scene the issue asks for.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Uniform,
    Clustered,
    AllOverlapping,
    Duplicates,
    ZeroSize,
    Huge,
    MixedRadii,
    /// Balls on an integer lattice with radius 0.5: every neighbour exactly touches.
    Touching,
}

const KINDS: [Kind; 8] = [
    Kind::Uniform,
    Kind::Clustered,
    Kind::AllOverlapping,
    Kind::Duplicates,
    Kind::ZeroSize,
    Kind::Huge,
    Kind::MixedRadii,
    Kind::Touching,
];

/// A test scene: balls, and boxes with the same centres and random half extents.
struct TestScene<T: Real, const D: usize> {
    centers: Vec<Vector<T, D>>,
    radii: Vec<T>,
    boxes: Vec<Aabb<T, D>>,
    rng: SplitMix64,
}

impl<T: Real, const D: usize> TestScene<T, D> {
    fn new(kind: Kind, n: usize, seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let side = (n as f64).powf(1.0 / D as f64) * 1.2 + 1.0;
        let mut centers = Vec::with_capacity(n);
        let mut radii = Vec::with_capacity(n);
        let hubs: Vec<[f64; D]> = (0..4)
            .map(|_| core::array::from_fn(|_| rng.range(0.0, side)))
            .collect();
        let points: Vec<[f64; D]> = (0..5)
            .map(|_| core::array::from_fn(|_| rng.range(0.0, 2.0)))
            .collect();
        for i in 0..n {
            let (c, r): ([f64; D], f64) = match kind {
                Kind::Uniform => (core::array::from_fn(|_| rng.range(0.0, side)), 0.5),
                Kind::Clustered => {
                    let h = hubs[i % hubs.len()];
                    (
                        core::array::from_fn(|k| h[k] + 0.6 * rng.normal()),
                        rng.range(0.2, 0.5),
                    )
                }
                Kind::AllOverlapping => (core::array::from_fn(|_| rng.range(0.0, 0.1)), 1.0),
                Kind::Duplicates => (points[i % points.len()], [0.0, 0.3, 1.0][i % 3]),
                Kind::ZeroSize => {
                    let p = points[i % points.len()];
                    (
                        core::array::from_fn(|k| {
                            p[k] + if i % 2 == 0 { 0.0 } else { rng.range(0.0, 1.0) }
                        }),
                        0.0,
                    )
                }
                Kind::Huge => (
                    core::array::from_fn(|_| 1e6 + rng.range(0.0, side * 0.1)),
                    rng.range(1e-3, 0.3),
                ),
                Kind::MixedRadii => (
                    core::array::from_fn(|_| rng.range(0.0, side * 0.5)),
                    rng.range(1e-3f64.ln(), 0.0).exp(),
                ),
                Kind::Touching => {
                    let w = (n as f64).powf(1.0 / D as f64).ceil().max(1.0) as usize;
                    let mut rest = i;
                    (
                        core::array::from_fn(|_| {
                            let x = rest % w;
                            rest /= w;
                            x as f64
                        }),
                        0.5,
                    )
                }
            };
            centers.push(Vector::<T, D>::from_fn(|k, _| T::lit(c[k])));
            radii.push(T::lit(r));
        }
        let boxes = centers
            .iter()
            .zip(&radii)
            .map(|(c, &r)| {
                let h = Vector::<T, D>::from_fn(|_, _| {
                    if r == T::zero() {
                        T::zero()
                    } else {
                        r * T::lit(rng.range(0.2, 1.5))
                    }
                });
                Aabb::from_center_half_extents(*c, h).expect("finite box")
            })
            .collect();
        Self {
            centers,
            radii,
            boxes,
            rng,
        }
    }

    fn balls(&self) -> Volumes<'_, T, D> {
        Balls::new(&self.centers, &self.radii)
            .expect("valid balls")
            .into()
    }

    fn aabbs(&self) -> Volumes<'_, T, D> {
        Volumes::boxes(&self.boxes).expect("few boxes")
    }

    /// A coherent frame: every volume moves by up to 5 % of its size.
    fn step(&mut self) {
        for i in 0..self.centers.len() {
            let dir = self.rng.direction::<D>();
            let d = 0.05 * (self.radii[i].to_f64() + 1e-3);
            let v = Vector::<T, D>::from_fn(|k, _| T::lit(dir[k] * d));
            self.centers[i] += v;
            self.boxes[i] = self.boxes[i].translated(&v);
        }
    }

    /// Query boxes and balls around some volumes and some random points.
    fn queries(&mut self) -> Vec<(Vector<T, D>, T)> {
        let n = self.centers.len();
        let mut q: Vec<_> = (0..n.min(6))
            .map(|i| (self.centers[i * n / n.min(6)], self.radii[i] + T::lit(0.25)))
            .collect();
        let lo = self
            .centers
            .iter()
            .fold(Vector::<T, D>::repeat(T::lit(1e30)), |a, c| a.inf(c));
        let hi = self
            .centers
            .iter()
            .fold(Vector::<T, D>::repeat(T::lit(-1e30)), |a, c| a.sup(c));
        for _ in 0..4 {
            let c = Vector::<T, D>::from_fn(|k, _| {
                lo[k] + (hi[k] - lo[k]) * T::lit(self.rng.next_f64())
            });
            q.push((c, T::lit(self.rng.range(0.0, 2.0))));
        }
        q.push((lo, T::zero()));
        q
    }
}

type Phase<T, const D: usize> = (&'static str, Box<dyn ParallelBroadPhase<T, D>>);

fn phases<T: Real, const D: usize>() -> Vec<Phase<T, D>> {
    vec![
        ("sap adaptive", Box::new(SweepAndPrune::new())),
        (
            "sap radix",
            Box::new(SweepAndPrune::with_policy(SortPolicy::Radix)),
        ),
        ("kd", Box::new(KdTree::new())),
        (
            "kd no oversize",
            Box::new(KdTree::with_oversize_ratio(f64::INFINITY).unwrap()),
        ),
        ("grid dense", Box::new(UniformGrid::dense())),
        (
            "grid dense no oversize",
            Box::new(
                UniformGrid::dense()
                    .with_oversize_ratio(f64::INFINITY)
                    .unwrap(),
            ),
        ),
        ("grid hashed", Box::new(UniformGrid::hashed())),
        (
            "grid hashed ratio 1",
            Box::new(UniformGrid::hashed().with_oversize_ratio(1.0).unwrap()),
        ),
    ]
}

/// Pairs and queries of `phase` on `volumes` equal the brute force's.
fn assert_matches_oracle<T: Real, const D: usize>(
    name: &str,
    phase: &mut dyn ParallelBroadPhase<T, D>,
    oracle: &mut BruteForce<T, D>,
    volumes: Volumes<'_, T, D>,
    queries: &[(Vector<T, D>, T)],
) {
    oracle.update(volumes);
    phase.update(volumes);
    assert_eq!(phase.len(), volumes.len());
    let (mut expected, mut got) = (Vec::new(), Vec::new());
    oracle.pairs(&mut expected);
    phase.pairs(&mut got);
    assert_eq!(got, expected, "{name}: pairs");
    assert!(expected.windows(2).all(|w| w[0] < w[1]) && expected.iter().all(|&(i, j)| i < j));
    let (mut qe, mut qg) = (Vec::new(), Vec::new());
    for (c, r) in queries {
        oracle.query_ball(c, *r, &mut qe);
        phase.query_ball(c, *r, &mut qg);
        assert_eq!(qg, qe, "{name}: query_ball({c:?}, {r:?})");
        let q = Aabb::from_center_half_extents(*c, Vector::repeat(*r)).unwrap();
        oracle.query_aabb(&q, &mut qe);
        phase.query_aabb(&q, &mut qg);
        assert_eq!(qg, qe, "{name}: query_aabb");
    }
}

fn check_scene<T: Real, const D: usize>(kind: Kind, n: usize, seed: u64, frames: usize) {
    let mut scene = TestScene::<T, D>::new(kind, n, seed);
    let mut oracle = BruteForce::new();
    for (name, mut phase) in phases::<T, D>() {
        for boxes in [false, true] {
            let mut s = TestScene::<T, D>::new(kind, n, seed);
            for _ in 0..frames {
                let queries = s.queries();
                let volumes = if boxes { s.aabbs() } else { s.balls() };
                assert_matches_oracle(name, phase.as_mut(), &mut oracle, volumes, &queries);
                s.step();
            }
        }
    }
    // The margin of a neighbour-list shell: pairs within r_i + r_j + 2 m.
    let margin = T::lit(0.1);
    let queries = scene.queries();
    let balls = Balls::new(&scene.centers, &scene.radii)
        .unwrap()
        .with_margin(margin)
        .unwrap();
    for (name, mut phase) in phases::<T, D>() {
        assert_matches_oracle(name, phase.as_mut(), &mut oracle, balls.into(), &queries);
    }
}

fn kind() -> impl Strategy<Value = Kind> {
    (0..KINDS.len()).prop_map(|k| KINDS[k])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn every_phase_matches_brute_force_2d(kind in kind(), n in 0usize..160, seed in any::<u64>()) {
        check_scene::<f64, 2>(kind, n, seed, 1);
    }

    #[test]
    fn every_phase_matches_brute_force_3d(kind in kind(), n in 0usize..160, seed in any::<u64>()) {
        check_scene::<f64, 3>(kind, n, seed, 1);
    }

    #[test]
    fn every_phase_matches_brute_force_in_f32(kind in kind(), n in 0usize..120, seed in any::<u64>()) {
        check_scene::<f32, 2>(kind, n, seed, 1);
        check_scene::<f32, 3>(kind, n, seed, 1);
    }

    #[test]
    fn coherent_sequences_match_brute_force_every_frame(kind in kind(), n in 2usize..120, seed in any::<u64>()) {
        check_scene::<f64, 2>(kind, n, seed, 6);
        check_scene::<f64, 3>(kind, n, seed, 4);
    }

    #[test]
    fn periodic_grid_matches_periodic_brute_force(n in 0usize..200, seed in any::<u64>(), side in 3.0f64..12.0, mixed in any::<bool>()) {
        check_periodic::<2>(n, seed, side, mixed);
        check_periodic::<3>(n, seed, side, mixed);
    }
}

fn check_periodic<const D: usize>(n: usize, seed: u64, side: f64, mixed: bool) {
    let mut rng = SplitMix64::new(seed);
    let border = Border::new(Vector::<f64, D>::repeat(-1.0), Vector::repeat(side - 1.0)).unwrap();
    // Positions partly outside the border: the grid wraps them itself.
    let centers: Vec<Vector<f64, D>> = (0..n)
        .map(|_| Vector::from_fn(|_, _| rng.range(-1.5, side - 0.5)))
        .collect();
    let radii: Vec<f64> = (0..n)
        .map(|i| {
            if mixed && i % 7 == 0 {
                rng.range(0.3, 0.9)
            } else {
                rng.range(0.05, 0.3)
            }
        })
        .collect();
    let boxes: Vec<Aabb<f64, D>> = centers
        .iter()
        .zip(&radii)
        .map(|(c, &r)| Aabb::from_center_half_extents(*c, Vector::repeat(r)).unwrap())
        .collect();
    let mut oracle = BruteForce::periodic(&border);
    let mut grid = UniformGrid::periodic(border);
    for volumes in [
        Balls::new(&centers, &radii).unwrap().into(),
        Volumes::boxes(&boxes).unwrap(),
    ] {
        let queries: Vec<_> = centers
            .iter()
            .take(5)
            .map(|c| (*c, 0.4))
            .chain([(Vector::repeat(side - 1.0), 0.7)])
            .collect();
        assert_matches_oracle("periodic grid", &mut grid, &mut oracle, volumes, &queries);
        let (mut seq, mut par) = (Vec::new(), Vec::new());
        grid.pairs(&mut seq);
        grid.par_pairs(&mut par);
        assert_eq!(seq, par);
    }
}

/// Runs `f` on a rayon pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

fn check_parallel<T: Real, const D: usize>(kind: Kind, n: usize, seed: u64) {
    let mut scene = TestScene::<T, D>::new(kind, n, seed);
    let mut phases = phases::<T, D>();
    phases.push(("brute", Box::new(BruteForce::new())));
    for frame in 0..3 {
        for (name, phase) in &mut phases {
            for volumes in [scene.balls(), scene.aabbs()] {
                phase.update(volumes);
                let mut seq = Vec::new();
                phase.pairs(&mut seq);
                for threads in [1, 2, 3] {
                    let mut par = vec![(7, 7)]; // stale content must be replaced
                    on_threads(threads, || phase.par_pairs(&mut par));
                    assert_eq!(par, seq, "{name}, frame {frame}, {threads} threads");
                    // A parallel update leaves the same state: same pairs, same queries.
                    on_threads(threads, || {
                        phase.par_update(volumes);
                        phase.par_pairs(&mut par);
                    });
                    assert_eq!(
                        par, seq,
                        "{name}, frame {frame}, {threads} threads, par_update"
                    );
                }
            }
        }
        scene.step();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn parallel_pairs_equal_sequential_on_1_2_and_3_threads(kind in kind(), n in 0usize..400, seed in any::<u64>()) {
        check_parallel::<f64, 2>(kind, n, seed);
        check_parallel::<f64, 3>(kind, n, seed);
        check_parallel::<f32, 3>(kind, n, seed);
    }
}

#[test]
fn larger_scenes_match_brute_force_and_are_thread_independent() {
    use carom_broad::scenes::Scene;
    let scenes: Vec<Scene<f64, 3>> = vec![
        Scene::uniform(3000, 0.5, 0.3, 0.0, 1),
        Scene::clustered(3000, 0.5, 0.1, 5, 2),
        Scene::mixed(2000, 1e-3, 1.0, 0.2, 3),
        Scene::uniform(2000, 0.5, 0.2, 1e6, 4),
    ];
    let mut oracle = BruteForce::new();
    for scene in &scenes {
        let mut expected = Vec::new();
        oracle.update(scene.balls());
        oracle.pairs(&mut expected);
        assert!(!expected.is_empty());
        for (name, mut phase) in phases::<f64, 3>() {
            phase.update(scene.balls());
            let mut got = Vec::new();
            phase.pairs(&mut got);
            assert_eq!(got, expected, "{name}");
            on_threads(2, || phase.par_pairs(&mut got));
            assert_eq!(got, expected, "{name} on 2 threads");
        }
    }
}

#[test]
fn box_input_equals_bounding_volume_intersects() {
    use carom_geometry::BoundingVolume;
    let boxes = TestScene::<f64, 3>::new(Kind::Clustered, 300, 9).boxes;
    let mut expected = Vec::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if boxes[i].intersects(&boxes[j]) {
                expected.push((i as u32, j as u32));
            }
        }
    }
    let mut got = Vec::new();
    for (name, mut phase) in phases::<f64, 3>() {
        phase.update(Volumes::boxes(&boxes).unwrap());
        phase.pairs(&mut got);
        assert_eq!(got, expected, "{name}");
    }
}

#[test]
fn parallel_updates_of_large_scenes_leave_identical_state() {
    // Above the size where the update passes go parallel (8192 volumes).
    use carom_broad::scenes::Scene;
    for mut scene in [
        Scene::<f64, 3>::uniform(20_000, 0.5, 0.2, 0.0, 5),
        Scene::<f64, 3>::clustered(20_000, 0.5, 0.1, 7, 6),
        Scene::<f64, 3>::mixed(12_000, 1e-3, 1.0, 0.2, 8),
    ] {
        let mut sequential = phases::<f64, 3>();
        let mut parallel = phases::<f64, 3>();
        let mut oracle_pairs = None;
        for frame in 0..3 {
            for ((name, seq), (_, par)) in sequential.iter_mut().zip(&mut parallel) {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                seq.update(scene.balls());
                seq.pairs(&mut a);
                on_threads(2, || {
                    par.par_update(scene.balls());
                    par.par_pairs(&mut b);
                });
                assert_eq!(a, b, "{name}, frame {frame}");
                // Every phase agrees with the first one (itself checked against brute
                // force on the first frame).
                let expected = oracle_pairs.get_or_insert_with(|| {
                    let mut brute = BruteForce::new();
                    brute.update(scene.balls());
                    let mut e = Vec::new();
                    brute.pairs(&mut e);
                    e
                });
                assert_eq!(&a, expected, "{name}, frame {frame}");
                let (mut qa, mut qb) = (Vec::new(), Vec::new());
                for i in (0..scene.len()).step_by(997) {
                    seq.query_ball(&scene.centers[i], 1.5, &mut qa);
                    par.query_ball(&scene.centers[i], 1.5, &mut qb);
                    assert_eq!(qa, qb, "{name}: queries after a parallel update");
                }
            }
            scene.step(0.01);
            oracle_pairs = None;
        }
    }
}
