//! The event-driven engine's ways of finding partners (every pair, neighbour lists, cell
//! lists with crossing events) against each other: they change the speed, never the
//! physics. Every pair is the brute-force oracle; the runs are short enough that rounding
//! differences between the searches (each offers candidates in its own order, so a time
//! of impact may be sharpened within another horizon) cannot grow into a different
//! history, so the collisions must be the same pairs at the same times.

use carom_geometry::Border;
use carom_math::{Space, Vector};
use carom_sim::plan::{BroadChoice, Plan};
use carom_sim::scene::{BallSpec, BorderSpec, Scene, World};
use carom_sim::scenes::gas::{GasParams, gas};
use carom_sim::{BallStates, Collision, EventEngine, PairSearch, Simulation};
use carom_toi::Direction;
use nalgebra::{Const, Vector2};

use crate::common::{advance, min_gap};

const SEARCHES: [PairSearch; 3] = [
    PairSearch::AllPairs,
    PairSearch::NeighbourLists,
    PairSearch::CellLists,
];

fn plan() -> Plan {
    Plan::event(BroadChoice::Auto)
}

/// Runs `scene` to `t` with `search`: the collisions, the final states and the pipeline.
fn run<const D: usize>(
    scene: &Scene<f64, D>,
    t: f64,
    search: PairSearch,
) -> (Vec<Collision<f64>>, BallStates<f64, D>, Vec<String>)
where
    Const<D>: Space<f64, D>,
{
    let mut sim = EventEngine::with_pair_search(scene, &plan(), Direction::Forward, search)
        .expect("a valid scene");
    let (st, log) = advance(&mut sim, t);
    (log, st, sim.pipeline())
}

/// The time of a collision and what it involved, to compare logs.
fn key(c: &Collision<f64>) -> (f64, String) {
    match c {
        Collision::BallBall { time, i, j } => (*time, format!("ball {i}-{j}")),
        Collision::BallBorder { time, i, .. } => (*time, format!("border {i}")),
        Collision::BallBox { time, i, k } => (*time, format!("box {k} ball {i}")),
    }
}

/// Runs `scene` with every search and checks they agree with every pair, collision by
/// collision, and that no two balls overlap at the end.
fn assert_searches_agree<const D: usize>(scene: &Scene<f64, D>, t: f64, at_least: usize)
where
    Const<D>: Space<f64, D>,
{
    assert_searches_agree_to(scene, t, at_least, 1e-9, &SEARCHES[1..]);
}

/// As [`assert_searches_agree`] for `searches`, with times and positions agreeing to
/// `tolerance`.
fn assert_searches_agree_to<const D: usize>(
    scene: &Scene<f64, D>,
    t: f64,
    at_least: usize,
    tolerance: f64,
    searches: &[PairSearch],
) where
    Const<D>: Space<f64, D>,
{
    let (oracle, st0, _) = run(scene, t, PairSearch::AllPairs);
    assert!(oracle.len() >= at_least, "{} collisions", oracle.len());
    for search in searches {
        let (log, st, pipeline) = run(scene, t, *search);
        assert_eq!(log.len(), oracle.len(), "{search:?} ({pipeline:?})");
        for (k, (a, b)) in log.iter().zip(&oracle).enumerate() {
            let ((ta, wa), (tb, wb)) = (key(a), key(b));
            assert_eq!(wa, wb, "{search:?}: collision {k}");
            assert!(
                (ta - tb).abs() <= tolerance * tb.abs().max(1.0),
                "{search:?}: collision {k} at {ta} against {tb}"
            );
        }
        for (p, q) in st.pos.iter().zip(&st0.pos) {
            assert!(
                (p - q).norm() < tolerance,
                "{search:?}: {p:?} against {q:?}"
            );
        }
        assert!(min_gap(scene, &st) >= -1e-9, "{search:?}: overlap");
    }
}

#[test]
fn cell_lists_and_neighbour_lists_give_the_collisions_of_every_pair_in_2d_and_3d() {
    for periodic in [false, true] {
        let p = GasParams {
            n: 300,
            fraction: 0.3,
            periodic,
            seed: 21,
            ..GasParams::default()
        };
        assert_searches_agree(&gas::<2>(&p).unwrap(), 4.0, 1000);
    }
    let p = GasParams {
        n: 400,
        fraction: 0.3,
        periodic: true,
        seed: 22,
        ..GasParams::default()
    };
    assert_searches_agree(&gas::<3>(&p).unwrap(), 0.5, 1000);
}

#[test]
fn under_gravity_balls_cross_cells_on_parabolas_and_meet_the_same_partners() {
    // Crossing times under gravity come from the parabola's level crossings.
    let p = GasParams {
        n: 200,
        fraction: 0.2,
        periodic: false,
        seed: 23,
        ..GasParams::default()
    };
    let mut scene = gas::<2>(&p).unwrap();
    scene.world.gravity = Vector2::new(0.3, -2.0);
    assert_searches_agree(&scene, 2.0, 300);
}

#[test]
fn a_gas_far_from_the_origin_and_a_fast_gas_are_searched_alike() {
    // A periodic box whose corner is at 1e6 (coordinates with 1e-10 of rounding, which
    // the searches round differently and the gas's chaos amplifies: compared over the
    // first ~200 collisions, to 1e-6 m: 1e-12 of the coordinates), and balls at 1e6 m/s crossing a cell every
    // microsecond.
    let p = GasParams {
        n: 200,
        fraction: 0.3,
        periodic: true,
        seed: 24,
        ..GasParams::default()
    };
    let mut far = gas::<2>(&p).unwrap();
    let shift = Vector::<f64, 2>::repeat(1e6);
    let border = far.world.border.expect("a gas has a box");
    far.world.border = Some(BorderSpec {
        border: Border::new(border.border.min() + shift, border.border.max() + shift).unwrap(),
        ..border
    });
    for b in &mut far.balls {
        b.pos += shift;
    }
    assert_searches_agree_to(&far, 1.2, 200, 1e-6, &SEARCHES[1..]);
    let mut fast = gas::<2>(&p).unwrap();
    for b in &mut fast.balls {
        b.vel *= 1e6;
    }
    assert_searches_agree(&fast, 4e-6, 500);
}

#[test]
fn auto_uses_cell_lists_for_moderate_densities_and_neighbour_lists_for_dense_3d() {
    let pipeline_of = |fraction: f64, d3: bool| {
        let p = GasParams {
            n: 2000,
            fraction,
            periodic: true,
            seed: 25,
            ..GasParams::default()
        };
        let search = PairSearch::Auto;
        if d3 {
            run(&gas::<3>(&p).unwrap(), 0.0, search).2
        } else {
            run(&gas::<2>(&p).unwrap(), 0.0, search).2
        }
    };
    assert!(pipeline_of(0.3, false).contains(&"pairs:cell-lists(crossings)".to_owned()));
    assert!(pipeline_of(0.2, true).contains(&"pairs:cell-lists(crossings)".to_owned()));
    assert!(pipeline_of(0.45, true).contains(&"pairs:neighbour-lists(grid)".to_owned()));
    // Without a border there are no cells to cut: neighbour lists.
    let scene = Scene {
        world: World::default(),
        balls: (0..40)
            .map(|k| {
                let x = f64::from(k);
                BallSpec::new(Vector2::new(x, 0.5 * x), Vector2::new(-1.0, 0.3), 0.2, 1.0)
            })
            .collect(),
        ..Scene::default()
    };
    let (log, st, pipeline) = run(&scene, 1.0, PairSearch::CellLists);
    assert!(pipeline.contains(&"pairs:neighbour-lists(grid)".to_owned()));
    assert!(min_gap(&scene, &st) >= -1e-9);
    assert_eq!(log.len(), run(&scene, 1.0, PairSearch::AllPairs).0.len());
}

/// Balls of radius 0.25 in a periodic square of `side`, at `positions` with unit speeds.
fn periodic_square(side: f64, positions: &[Vector2<f64>]) -> Scene<f64, 2> {
    Scene {
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector2::zeros(), Vector2::repeat(side)).unwrap(),
                restitution: 1.0,
                periodic: true,
            }),
            ..World::default()
        },
        balls: positions
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let a = 1.7 * k as f64;
                BallSpec::new(*p, Vector2::new(a.cos(), a.sin()), 0.25, 1.0)
            })
            .collect(),
        ..Scene::default()
    }
}

#[test]
fn small_periodic_boxes_keep_the_right_images() {
    // Five cells per axis (0.52 wide), the fewest with which neighbouring cells' balls
    // are always each other's minimum image: cells, agreeing with every pair.
    let grid: Vec<Vector2<f64>> = (0..9)
        .map(|k| Vector2::new(0.4 + 0.85 * f64::from(k % 3), 0.4 + 0.85 * f64::from(k / 3)))
        .collect();
    let five = periodic_square(2.6, &grid);
    let (log, st, pipeline) = run(&five, 30.0, PairSearch::CellLists);
    assert!(pipeline.contains(&"pairs:cell-lists(crossings)".to_owned()));
    assert!(log.len() > 100 && min_gap(&five, &st) >= -1e-9);
    // (Too small a box for neighbour lists' shells.)
    assert_searches_agree_to(&five, 3.0, 30, 1e-9, &[PairSearch::CellLists]);
    // Four cells: a ball two widths away in a neighbouring cell may be nearer through
    // the other side, so cells are not used (every pair is, for nine balls).
    let four = periodic_square(
        2.2,
        &grid.iter().map(|p| p * (2.2 / 2.6)).collect::<Vec<_>>(),
    );
    let (log, st, pipeline) = run(&four, 30.0, PairSearch::CellLists);
    assert!(!pipeline.contains(&"pairs:cell-lists(crossings)".to_owned()));
    assert!(log.len() > 100 && min_gap(&four, &st) >= -1e-9);
}

#[test]
fn every_pair_in_a_periodic_box_meets_through_the_image_it_was_not_nearest_in() {
    // In a box 10 wide, B starts 4.8 to the right of A (its nearest image) and moves
    // right at 1 m/s: it meets A's image on the right when their centres are 0.5 apart,
    // after (10 − 4.8 − 0.5) / 1 = 4.7 s. Predicted with the first minimum image only,
    // the pair separates and never meets.
    let scene = Scene {
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector2::zeros(), Vector2::repeat(10.0)).unwrap(),
                restitution: 1.0,
                periodic: true,
            }),
            ..World::default()
        },
        balls: vec![
            BallSpec::new(Vector2::new(1.0, 5.0), Vector2::zeros(), 0.25, 1.0),
            BallSpec::new(Vector2::new(5.8, 5.0), Vector2::new(1.0, 0.0), 0.25, 1.0),
        ],
        ..Scene::default()
    };
    let (log, st, pipeline) = run(&scene, 6.0, PairSearch::Auto);
    assert!(pipeline.contains(&"pairs:all".to_owned()));
    assert_eq!(log.len(), 1, "{log:?}");
    let (time, _) = key(&log[0]);
    assert!((time - 4.7).abs() < 1e-12, "{time}");
    // Equal masses, head-on: A leaves at 1 m/s, B stops.
    assert!((st.vel[0] - Vector2::new(1.0, 0.0)).norm() < 1e-12);
    assert!(st.vel[1].norm() < 1e-12);
}

#[test]
fn single_precision_cells_keep_a_large_gas_apart() {
    // 3,000 discs in a periodic square 87 diameters wide: f32 coordinates carry 5e-6 of
    // rounding, more than the cells' 1e-6 margin in f64, so the margin grows with it.
    let p = GasParams {
        n: 3000,
        fraction: 0.3,
        periodic: true,
        seed: 26,
        ..GasParams::default()
    };
    let scene = gas::<2>(&p).unwrap().cast::<f32>().unwrap();
    let mut sim =
        EventEngine::with_pair_search(&scene, &plan(), Direction::Forward, PairSearch::CellLists)
            .unwrap();
    assert!(
        sim.pipeline()
            .contains(&"pairs:cell-lists(crossings)".to_owned())
    );
    let mut st = BallStates::<f32, 2>::default();
    sim.states(&mut st);
    let e0 = carom_sim::observe::energy(&scene, &st);
    sim.advance_to(3.0, &mut ()).unwrap();
    sim.states(&mut st);
    assert!(sim.counters().ball_ball > 10_000, "{:?}", sim.counters());
    let e1 = carom_sim::observe::energy(&scene, &st);
    assert!(((e1 - e0) / e0).abs() < 1e-4, "{}", (e1 - e0) / e0);
    let border = scene.world.border.unwrap().border;
    let mut worst = f32::INFINITY;
    for i in 0..st.pos.len() {
        for j in i + 1..st.pos.len() {
            worst = worst.min(border.minimum_image(&(st.pos[j] - st.pos[i])).norm() - 1.0);
        }
    }
    // Single precision: contacts are exact to a few ulps of the coordinates (87 · 6e-8).
    assert!(worst > -1e-4, "f32 overlap {worst}");
}
