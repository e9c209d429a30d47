//! Running a Collision Lab screen on carom's event engine and recording what the sim
//! shows: ball paths, the state just before and just after every collision, which balls
//! are stuck together, and the quantities the sim teaches.
//!
//! The engine reports collisions through the [`Observer`] trait, at their exact times,
//! but an observer cannot look at the engine's state. The run is therefore made twice
//! from the same scene (a few balls: microseconds). The first run logs the collision
//! times. The second advances to a time grid for the paths plus, for every collision
//! instant, that instant itself (`advance_to` processes the collisions at its target
//! before returning: the states are *after*) and the midpoint between it and the
//! previous instant (nothing happens in between: the free balls' velocities and every
//! stuck cluster's momentum are those just *before*). carom's engine guarantees that
//! cutting a run into any `advance_to` calls does not change its trajectory, so both runs
//! are the same run, bit for bit.

use std::error::Error;

use carom::sim::observe::energy;
use carom::sim::plan::{RunOptions, plan};
use carom::sim::scene::{BallSpec, Inelastic, Scene};
use carom::sim::scenes::collision_lab::{self, InelasticPreset, Options, Screen};
use carom::sim::{BallStates, Collision, Counters, Observer, build};
use carom::toi::Direction;
use nalgebra::Vector2;

/// What to run: a screen of the sim, or the demonstration of a gap in PhET's engine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Case {
    /// A screen of Collision Lab with its defaults and the given options.
    Screen(Screen),
    /// Two balls stick next to the right wall into a cluster that spins fast and drifts
    /// slowly into the wall. PhET detects cluster–wall contact by bisection on a sampled
    /// grid, which can miss it; carom's conservative advancement cannot.
    SpinningClusterWall,
}

/// A run request.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Setup {
    /// What to run.
    pub(crate) case: Case,
    /// The sim's options.
    pub(crate) options: Options,
    /// The end time; negative runs backwards from the initial state.
    pub(crate) until: f64,
    /// The spacing of path samples (s).
    pub(crate) sample_step: f64,
}

/// The state of every ball at one time.
#[derive(Clone, Debug)]
pub(crate) struct Frame {
    /// The (signed) time.
    pub(crate) t: f64,
    /// The states.
    pub(crate) states: BallStates<f64, 2>,
}

/// Everything that happened at one collision instant.
#[derive(Clone, Debug)]
pub(crate) struct Instant {
    /// When.
    pub(crate) t: f64,
    /// The collisions, in the order the engine processed them.
    pub(crate) collisions: Vec<Collision<f64>>,
    /// The states just before.
    pub(crate) before: BallStates<f64, 2>,
    /// The states just after.
    pub(crate) after: BallStates<f64, 2>,
    /// The body of each ball before (the lowest ball index of its stuck cluster).
    pub(crate) body_before: Vec<usize>,
    /// ... and after.
    pub(crate) body_after: Vec<usize>,
}

impl Instant {
    /// Whether a wall took part.
    pub(crate) fn has_wall(&self) -> bool {
        self.collisions
            .iter()
            .any(|c| matches!(c, Collision::BallBorder { .. }))
    }
}

/// A recorded run.
#[derive(Clone, Debug)]
pub(crate) struct Record {
    /// The scene that ran.
    pub(crate) scene: Scene<f64, 2>,
    /// What ran.
    pub(crate) case: Case,
    /// The options it ran with.
    pub(crate) options: Options,
    /// The end time (negative: backwards).
    pub(crate) until: f64,
    /// States on the sample grid and at every instant, in run order.
    pub(crate) frames: Vec<Frame>,
    /// The collision instants, in run order.
    pub(crate) instants: Vec<Instant>,
    /// The engine's components.
    pub(crate) pipeline: Vec<String>,
    /// The collision counts.
    pub(crate) counters: Counters,
}

impl Record {
    /// The body of every ball at the end of the run.
    pub(crate) fn final_bodies(&self) -> Vec<usize> {
        self.instants.last().map_or_else(
            || (0..self.scene.balls.len()).collect(),
            |i| i.body_after.clone(),
        )
    }

    /// The stuck clusters at the end (bodies of more than one ball), as ball lists.
    pub(crate) fn final_clusters(&self) -> Vec<Vec<usize>> {
        groups(&self.final_bodies())
    }

    /// `+1` forwards, `−1` backwards.
    pub(crate) fn sign(&self) -> f64 {
        if self.until < 0.0 { -1.0 } else { 1.0 }
    }
}

/// The groups of balls with the same body label that have more than one ball.
pub(crate) fn groups(body: &[usize]) -> Vec<Vec<usize>> {
    let mut out: Vec<Vec<usize>> = Vec::new();
    for root in 0..body.len() {
        let members: Vec<usize> = (0..body.len()).filter(|&k| body[k] == root).collect();
        if members.len() > 1 {
            out.push(members);
        }
    }
    out
}

/// The screen name of a case, for file names and titles.
pub(crate) fn case_name(case: Case) -> &'static str {
    match case {
        Case::Screen(Screen::Intro) => "intro",
        Case::Screen(Screen::Explore1d) => "explore1d",
        Case::Screen(Screen::Explore2d) => "explore2d",
        Case::Screen(Screen::Inelastic(InelasticPreset::HeadOn)) => "inelastic-head-on",
        Case::Screen(Screen::Inelastic(InelasticPreset::CrissCross)) => "inelastic-criss-cross",
        Case::Screen(Screen::Inelastic(InelasticPreset::Glancing)) => "inelastic-glancing",
        Case::SpinningClusterWall => "spinning-cluster-wall",
    }
}

/// The screen whose play area a case uses.
pub(crate) fn screen_of(case: Case) -> Screen {
    match case {
        Case::Screen(s) => s,
        Case::SpinningClusterWall => Screen::Inelastic(InelasticPreset::HeadOn),
    }
}

/// Whether a case runs on a 1D screen (balls on the x axis).
pub(crate) fn is_1d(case: Case) -> bool {
    matches!(screen_of(case), Screen::Intro | Screen::Explore1d)
}

/// The scene of a case.
pub(crate) fn scene_of(case: Case, options: &Options) -> Scene<f64, 2> {
    match case {
        Case::Screen(screen) => collision_lab::scene(screen, options),
        Case::SpinningClusterWall => {
            // The Inelastic screen at elasticity 0 % with "stick": two 0.5 kg balls run up
            // and down along the right wall at 1.5 m/s and meet off-centre. Their momenta
            // cancel, so the cluster they form does not move: it only spins (about
            // 3 rad/s), and its upper ball sweeps into the wall at once. PhET's engine lets
            // a purely spinning cluster pass through a wall (docs/event-engine.md).
            let stick = Options {
                elasticity_percent: Some(0.0),
                inelastic: Inelastic::Stick,
                ..*options
            };
            let mut scene =
                collision_lab::scene(Screen::Inelastic(InelasticPreset::HeadOn), &stick);
            let r = collision_lab::radius_for_mass(0.5, options.constant_size);
            scene.name = Some("spinning-cluster-wall".to_owned());
            scene.balls = vec![
                BallSpec::new(Vector2::new(1.70, -0.45), Vector2::new(0.0, 1.5), r, 0.5),
                BallSpec::new(
                    Vector2::new(2.0 - r - 0.01, 0.45),
                    Vector2::new(0.0, -1.5),
                    r,
                    0.5,
                ),
            ];
            scene
        }
    }
}

/// Collects collisions.
struct Log(Vec<Collision<f64>>);

impl Observer<f64> for Log {
    fn collision(&mut self, collision: &Collision<f64>) {
        self.0.push(*collision);
    }
}

/// What a sample time is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Purpose {
    /// A point of the paths.
    Path,
    /// Just before instant `k`.
    Before(usize),
    /// Just after instant `k`.
    After(usize),
}

/// Runs a case and records it.
///
/// # Errors
/// A scene the options make invalid (e.g. elasticity 150 %), or an engine failure.
pub(crate) fn simulate(setup: &Setup) -> Result<Record, Box<dyn Error>> {
    let scene = scene_of(setup.case, &setup.options);
    scene.validate()?;
    if !(setup.until.is_finite() && setup.until != 0.0) {
        return Err(format!(
            "--until must be a finite non-zero time, got {}",
            setup.until
        )
        .into());
    }
    if !(setup.sample_step.is_finite() && setup.sample_step > 0.0) {
        return Err("the sample step must be positive".into());
    }
    let plan = plan(&scene, &RunOptions::default())?;
    let (sign, direction) = if setup.until < 0.0 {
        (-1.0, Direction::Backward)
    } else {
        (1.0, Direction::Forward)
    };

    // First run: when do collisions happen?
    let mut sim = build(&scene, &plan, direction)?;
    let mut log = Log(Vec::new());
    sim.advance_to(setup.until, &mut log)?;
    let mut grouped: Vec<(f64, Vec<Collision<f64>>)> = Vec::new();
    for c in log.0 {
        match grouped.last_mut() {
            Some((t, list)) if *t == c.time() => list.push(c),
            _ => grouped.push((c.time(), vec![c])),
        }
    }

    // Second run: the same run, stopping at every time we need.
    let span = setup.until.abs();
    let mut stops: Vec<(f64, Purpose)> = Vec::new();
    let steps = (span / setup.sample_step).ceil() as usize;
    stops.extend((1..=steps).map(|k| ((k as f64 * setup.sample_step).min(span), Purpose::Path)));
    let mut previous = 0.0;
    for (k, (t, _)) in grouped.iter().enumerate() {
        let s = t.abs();
        if s > 0.0 {
            stops.push((previous + (s - previous) / 2.0, Purpose::Before(k)));
        }
        stops.push((s, Purpose::After(k)));
        previous = s;
    }
    // Stable: at one time, a Before precedes its After (distinct times anyway), Paths keep order.
    stops.sort_by(|a, b| a.0.total_cmp(&b.0));

    let mut sim = build(&scene, &plan, direction)?;
    let mut initial = BallStates::default();
    sim.states(&mut initial);
    let mut frames = vec![Frame {
        t: 0.0,
        states: initial.clone(),
    }];
    let mut before: Vec<Option<BallStates<f64, 2>>> = vec![None; grouped.len()];
    let mut after: Vec<Option<BallStates<f64, 2>>> = vec![None; grouped.len()];
    let mut states = BallStates::default();
    for &(s, purpose) in &stops {
        sim.advance_to(sign * s, &mut ())?;
        sim.states(&mut states);
        match purpose {
            Purpose::Path => {}
            Purpose::Before(k) => before[k] = Some(states.clone()),
            Purpose::After(k) => after[k] = Some(states.clone()),
        }
        if frames.last().is_none_or(|f| f.t.abs() < s) {
            frames.push(Frame {
                t: sign * s,
                states: states.clone(),
            });
        }
    }

    let instants = label_bodies(&scene, grouped, &mut before, &mut after, &initial);
    Ok(Record {
        case: setup.case,
        options: setup.options,
        until: setup.until,
        frames,
        instants,
        pipeline: sim.pipeline(),
        counters: sim.counters(),
        scene,
    })
}

/// The instants with their states and which balls are stuck together before and after
/// (every ball–ball collision at elasticity 0 % with "stick" fuses the two bodies).
fn label_bodies(
    scene: &Scene<f64, 2>,
    grouped: Vec<(f64, Vec<Collision<f64>>)>,
    before: &mut [Option<BallStates<f64, 2>>],
    after: &mut [Option<BallStates<f64, 2>>],
    initial: &BallStates<f64, 2>,
) -> Vec<Instant> {
    let stick = |i: usize, j: usize| {
        scene.world.inelastic == Inelastic::Stick && scene.pair_restitution(i, j) == 0.0
    };
    let mut body: Vec<usize> = (0..scene.balls.len()).collect();
    let mut instants = Vec::with_capacity(grouped.len());
    for (k, (t, collisions)) in grouped.into_iter().enumerate() {
        let body_before = body.clone();
        for c in &collisions {
            if let Collision::BallBall { i, j, .. } = *c
                && stick(i, j)
            {
                let (a, b) = (body[i], body[j]);
                let (keep, gone) = (a.min(b), a.max(b));
                for x in &mut body {
                    if *x == gone {
                        *x = keep;
                    }
                }
            }
        }
        instants.push(Instant {
            t,
            collisions,
            before: before[k].take().unwrap_or_else(|| initial.clone()),
            after: after[k].take().expect("every instant has a stop after it"),
            body_before,
            body_after: body.clone(),
        });
    }
    instants
}

/// The quantities Collision Lab teaches, for the whole system at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Quantities {
    /// Total momentum `Σ m v` (kg m/s).
    pub(crate) momentum: Vector2<f64>,
    /// Kinetic energy, translation plus each ball's spin in a cluster (J).
    pub(crate) kinetic: f64,
    /// Centre of mass (m).
    pub(crate) com: Vector2<f64>,
    /// Velocity of the centre of mass (m/s).
    pub(crate) com_velocity: Vector2<f64>,
    /// Angular momentum about the origin, `Σ m r × v + Σ I ω` (kg m²/s).
    pub(crate) angular_momentum: f64,
}

/// The 2D cross product `a × b` (its z component).
pub(crate) fn cross(a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// A ball's moment of inertia about its centre: a uniform disk, `m r² / 2` (as carom's
/// clusters count it).
pub(crate) fn own_inertia(b: &BallSpec<f64, 2>) -> f64 {
    0.5 * b.mass * b.radius * b.radius
}

/// The system's quantities in `states`.
pub(crate) fn quantities(scene: &Scene<f64, 2>, states: &BallStates<f64, 2>) -> Quantities {
    let mass: f64 = scene.balls.iter().map(|b| b.mass).sum();
    let mut momentum = Vector2::zeros();
    let mut moment = Vector2::zeros();
    let mut angular_momentum = 0.0;
    for (k, b) in scene.balls.iter().enumerate() {
        momentum += states.vel[k] * b.mass;
        moment += states.pos[k] * b.mass;
        angular_momentum +=
            b.mass * cross(&states.pos[k], &states.vel[k]) + own_inertia(b) * states.spin[k].x;
    }
    Quantities {
        momentum,
        kinetic: energy(scene, states),
        com: moment / mass,
        com_velocity: momentum / mass,
        angular_momentum,
    }
}

/// The momentum of the balls `members` (kg m/s).
pub(crate) fn momentum_of(
    scene: &Scene<f64, 2>,
    states: &BallStates<f64, 2>,
    members: &[usize],
) -> Vector2<f64> {
    members.iter().fold(Vector2::zeros(), |p, &k| {
        p + states.vel[k] * scene.balls[k].mass
    })
}

/// A stuck cluster's centre of mass, angular momentum about it (kg m²/s) and angular
/// velocity (rad/s).
pub(crate) fn cluster_spin(
    scene: &Scene<f64, 2>,
    states: &BallStates<f64, 2>,
    members: &[usize],
) -> (Vector2<f64>, f64, f64) {
    let mass: f64 = members.iter().map(|&k| scene.balls[k].mass).sum();
    let com = members.iter().fold(Vector2::zeros(), |c, &k| {
        c + states.pos[k] * scene.balls[k].mass
    }) / mass;
    let v = momentum_of(scene, states, members) / mass;
    let l = members
        .iter()
        .map(|&k| {
            let b = &scene.balls[k];
            b.mass * cross(&(states.pos[k] - com), &(states.vel[k] - v))
                + own_inertia(b) * states.spin[k].x
        })
        .sum();
    (com, l, states.spin[members[0]].x)
}

/// Which wall ball `i` touches in `states`: the side of the border nearest to it.
pub(crate) fn wall_name(
    scene: &Scene<f64, 2>,
    states: &BallStates<f64, 2>,
    i: usize,
) -> &'static str {
    let Some(border) = scene.world.border else {
        return "wall";
    };
    let (p, r) = (states.pos[i], scene.balls[i].radius);
    let gaps = [
        (p.x - r - border.border.min().x, "left wall"),
        (border.border.max().x - p.x - r, "right wall"),
        (p.y - r - border.border.min().y, "bottom wall"),
        (border.border.max().y - p.y - r, "top wall"),
    ];
    gaps.iter()
        .min_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        .map_or("wall", |g| g.1)
}
