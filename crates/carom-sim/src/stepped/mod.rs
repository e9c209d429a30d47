//! The time-stepped engine: fixed steps of any integrator, with continuous collision
//! detection so that no ball passes through another ball, a box or a wall at any speed.
//!
//! For scenes an exact event-driven engine cannot serve (drag, arbitrary forces,
//! kinematic paddles driven from Rust, stuck clusters in 3D, under gravity, against boxes
//! or in a periodic border) and for engine authors who know the game loop. Each step of length `h`:
//!
//! 1. **Integrate** every ball with carom-integrate's [`Stepper`] (any [`Integrator`]),
//!    in parallel chunks. Each ball's motion within the step is the straight segment
//!    (chord) from its old to its new position.
//! 2. **Broad phase**: each ball's reach box (the ball grown by the distance it moves) and
//!    each box's swept box go into carom-broad ([`BroadChoice`](crate::plan::BroadChoice)), in parallel.
//! 3. **Narrow phase**: carom-toi's exact time of impact along the chords for every pair
//!    the broad phase returns (ball–ball, ball–box, ball–wall), in parallel.
//! 4. **Sub-step event loop**: the earliest contact of the step is processed (a
//!    carom-response impulse, the rest of the step re-integrated, a resting correction if
//!    the paths still close: see `response`), the balls it changed are predicted again,
//!    and so on to the end of the step. A ball bouncing a thousand times between a box
//!    and a wall within one step bounces a thousand times.
//!
//! **Stuck clusters** (`inelastic = "stick"`, 2D and 3D, see `clusters` and `stick`): a
//! ball–ball contact with pair restitution 0 fuses the two bodies into one rigid body
//! (carom-response's `RigidCluster`, linear and angular momentum kept). A cluster's
//! centre of mass is stepped by the same integrator and forces as a ball, its orientation
//! by the explicit midpoint rule on rotations with `ω = I_world⁻¹ L` (torque-free
//! precession in 3D), and each member ball moves on the chord to its rigid place at the
//! step's end, so the steps above serve members unchanged (members of one cluster are
//! never tested against each other). A member's contact is a rigid-body impulse at the
//! contact point; the cluster's rest of the step is integrated again and its members'
//! chords follow; a cluster resting on surfaces is held on all of them at once.
//!
//! Everything that runs in parallel computes each ball or pair on its own and merges in
//! a fixed order; the event loop is sequential with a total order on events. Results are
//! bit-identical for any number of threads and across runs.
//!
//! The work per step is bounded by [`SteppedEngine::set_event_budget`]: a step that would
//! need more contacts than the budget stops every ball where it is for the rest of that
//! step (velocities kept, no overlap created) and counts it in [`StepStats`]; nothing is
//! dropped silently. `docs/stepped.md` has the derivations, the policies and the
//! measurements against rapier2d.

mod awake;
mod balls;
mod clusters;
mod escapees;
mod forces;
mod lcp;
mod narrow;
mod obstacles;
mod piles;
mod queue;
mod response;
mod rest;
mod sparse_lcp;
mod stack;
mod stick;
mod sweep;
mod wedge;

use carom_geometry::{Ball, Border};
use carom_integrate::{Bodies, Integrator, Stepper, TimeStep};
use carom_math::{Real, Space, Vector, ensure_finite_vector};
use carom_toi::Direction;
use nalgebra::Const;
use rayon::prelude::*;

use self::balls::BallArrays;
use self::clusters::{Clusters, Flight};
use self::forces::WorldForces;
use self::narrow::{Event, Narrow, Overflow, Target, apart_speed, touch_tolerance};
use self::obstacles::BoxArrays;
use self::queue::EventQueue;
use self::response::{Contacts, Effect, RestSets, Rules, Surface};
use self::rest::{Support, Touch};
use self::stack::{Groups, SeedOther, Solvers};
use self::sweep::{CHUNK, Sweep, clear_of, path_box};
use self::wedge::{Repeat, Repeats, WEDGE_CONTACTS, wedge_limit};

use crate::engine::{BallStates, Collision, Counters, EngineKind, Observer, SimError, Simulation};
use crate::plan::{DEFAULT_DT, Plan, can_stick, stepped_broad_phase};
use crate::scene::{Scene, SceneError};

/// Escapees per parallel task of the step's first predictions (each is a broad-phase
/// query and a few times of impact: 1.4 µs on average, timed on a 1e5-ball gas).
const ESCAPEE_CHUNK: usize = 32;

/// How many pairs ahead the prediction of all pairs asks for a pair's second ball
/// (4, 8 and 16 timed: 8 and 16 level, both faster than 4 and than none; docs/stepped.md).
const PAIR_PREFETCH_AHEAD: usize = 8;

/// How often [`Observer::progress`] is called: every this many steps.
const PROGRESS_EVERY: u64 = 256;

/// Fewer balls than this are stepped on one thread (the result is the same).
const PARALLEL_MIN: usize = 2048;

/// The most a stuck cluster may turn in one step (rad): a step in which one would turn
/// more is cut into equal sub-steps (see [`SteppedEngine::steps_to`]).
const MAX_TURN: f64 = 0.2;

/// Contacts within this fraction of the step are simultaneous at most (see
/// [`SteppedEngine::instant_width`]).
const SIMULTANEITY: f64 = 1e-6;

/// The farthest a ball may move within one simultaneity window (m): contacts of one
/// window are answered bottom-up, not in time order, and a ball then meets a later
/// contact before an earlier one by up to this much (the overlap the contract lets a
/// scene start with).
const SIMULTANEOUS_TRAVEL: f64 = 1e-9;

/// The farthest a ball may travel in one last place of the step's time, in its radii
/// (a diameter), when a contact other than a free ball's with a wall changes it: beyond
/// it the run ends with an error naming the ball (see
/// [`SteppedEngine::resolved_in_time`]).
const RESOLVED_TRAVEL: f64 = 2.0;

/// The most sub-steps one step is cut into for turning clusters: a cluster turning
/// faster than [`MAX_TURN`] times this in a step ends the run with an error.
const MAX_SUBSTEPS: u64 = 4096;

/// What the engine did beyond the collisions it reports: for tests, reports and tuning.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Steps taken (full and shortened).
    pub steps: u64,
    /// Contacts processed (collisions and resting contacts).
    pub contacts: u64,
    /// Contacts that were resting support rather than collisions: no impulse faster than
    /// gravity adds in one step, only a correction of the paths (not reported to the
    /// observer, not counted in [`Counters`]).
    pub resting: u64,
    /// Broad-phase builds: when balls left their reach boxes (every few steps: see
    /// `docs/stepped.md`), every window in a periodic domain, and every window cut
    /// short.
    pub broad_builds: u64,
    /// Windows cut short: too many escapees, or a ball too fast for the periodic window.
    pub rebuilds: u64,
    /// The most contacts any single step needed.
    pub max_contacts_in_step: u64,
    /// Extra steps taken because a stuck cluster would have turned more than 0.2 rad in
    /// a step (see `docs/stepped.md`): each such step is cut into equal sub-steps, each
    /// counted in [`Self::steps`] too.
    pub substeps: u64,
    /// The most contacts held together in one complementarity problem (a stack's hold,
    /// see `docs/stepped.md`): up to 256 the problem is solved exactly, at a cost that
    /// grows with the cube of this; beyond, by projected conjugate gradients.
    pub largest_hold: u64,
    /// Steps that exhausted the event budget (see [`SteppedEngine::set_event_budget`]).
    pub capped_steps: u64,
    /// The simulated time those steps spent frozen (s).
    pub frozen_time: f64,
}

/// The most steps of the grid a run may reach: `2⁵³`, past which an `f64` no longer
/// counts every integer (see [`Clock::grid`]).
const MAX_GRID_STEPS: f64 = (1u64 << f64::MANTISSA_DIGITS) as f64;

/// The step grid: internal time `s` (forward in the run's direction), grid times `k·dt`.
#[derive(Clone, Copy, Debug)]
struct Clock<T: Real> {
    dt: f64,
    /// The last grid index at or before `s`.
    k: u64,
    /// The internal time.
    s: T,
    /// `+1` forward, `−1` backward.
    sign: T,
}

impl<T: Real> Clock<T> {
    /// Grid time `k·dt`: `k` converts to `f64` exactly up to [`MAX_GRID_STEPS`], and the
    /// product is rounded once.
    fn grid(&self, k: u64) -> T {
        T::lit(k as f64 * self.dt)
    }
}

/// The time-stepped engine (see the [module documentation](self)).
pub struct SteppedEngine<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    balls: BallArrays<T, D>,
    boxes: BoxArrays<T, D>,
    border: Option<Border<T, D>>,
    periodic: Option<Border<T, D>>,
    stepper: Stepper<T, D, WorldForces<T, D>>,
    rules: Rules<T, D>,
    rest: RestSets<T, D>,
    clusters: Clusters<T, D>,
    /// The balls the last contact changed (scratch).
    changed: Vec<u32>,
    /// Whether a contact at the very start of a step may end it for spinning a cluster
    /// up ([`WindowEnd::Spun`]): not in the step after one that ended so, which is cut
    /// for the spin that contact left (see [`SteppedEngine::steps_to`]).
    spun_at_start: bool,
    sweep: Sweep<T, D>,
    queue: EventQueue<T, D>,
    chunk_events: Vec<Vec<Event<T, D>>>,
    chunk_status: Vec<Result<(), Overflow>>,
    candidates: Vec<u32>,
    /// Events of one ball's prediction (scratch).
    found: Vec<Event<T, D>>,
    touches: [Vec<Touch<T, D>>; 2],
    /// The stacks' complementarity solvers and what they keep (see `stack`).
    solvers: Solvers<D>,
    /// The bodies held together in the current step (see `stack`).
    groups: Groups,
    /// Each ball's contacts at one instant in the current step (see `wedge`).
    repeats: Repeats<T>,
    clock: Clock<T>,
    counters: Counters,
    stats: StepStats,
    pipeline: Vec<String>,
    event_budget: u64,
    /// The current window's simultaneity window (see [`SteppedEngine::instant_width`]).
    instant: T,
    /// The current step's length (the end of every segment in it; the last step's
    /// while the next one is integrated).
    step_length: T,
    /// The largest distance a ball may move in one window of a periodic domain.
    periodic_reach: T,
    escape_bound: usize,
    /// Where the scene's origin is in the engine's coordinates: positions are computed
    /// from the scene's middle, finer far from the origin, and reported with this added
    /// back ([`Scene::recentred`]).
    origin: Vector<T, D>,
}

/// A chunk's segment starts: positions, their remainders, velocities, spins, times.
type Segment<'a, T, const D: usize> = (
    &'a mut [Vector<T, D>],
    &'a mut [Vector<T, D>],
    &'a mut [Vector<T, D>],
    &'a mut [crate::Angular<T, D>],
    &'a mut [T],
);

/// A chunk's state: positions, velocities, spins.
type State<'a, T, const D: usize> = (
    &'a mut [Vector<T, D>],
    &'a mut [Vector<T, D>],
    &'a mut [crate::Angular<T, D>],
);

/// How a window of the event loop ended.
enum WindowEnd<T> {
    /// At its planned end.
    Done,
    /// Early, at this in-step time: rebuild the broad phase from there.
    Cut(T),
    /// The event budget ran out at this in-step time.
    Budget(T),
    /// A contact at this in-step time set a cluster spinning so fast that it would turn
    /// more than [`MAX_TURN`] over the rest of the step: the step ends there (see
    /// [`SteppedEngine::steps_to`]).
    Spun(T),
}

impl<T: Real, const D: usize> SteppedEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The engine for `scene` with the planner's `plan` (integrator, step, broad phase;
    /// unset values take the defaults: semi-implicit Euler, [`DEFAULT_DT`], the automatic
    /// broad phase), running in `direction`.
    ///
    /// # Errors
    /// The first rule of [`Scene::validate`] the scene breaks; `--dt` if the step is not
    /// finite and positive in this precision; `--broad` for a broad phase that cannot
    /// serve a periodic border; `world.border` for a periodic border too small for its
    /// balls (two ball diameters must fit in half a period).
    pub fn new(scene: &Scene<T, D>, plan: &Plan, direction: Direction) -> Result<Self, SceneError> {
        scene.validate()?;
        Self::with_valid_fields(scene, plan, direction)
    }

    /// The engine taking a run on from another engine's state: `scene` holds the balls
    /// where that engine left them, and `spins` their angular velocities as
    /// [`Simulation::states`] reports them (a scene has none; friction gives balls
    /// spin). The fields are checked, not the placement: balls the event engine hands
    /// over pressed together may overlap by a little more than a scene may start with
    /// (up to [`OVERLAP_TOLERANCE`](crate::scene::OVERLAP_TOLERANCE) plus the resolution
    /// of their coordinates, see [`EventThenStepped`](crate::EventThenStepped)), and the
    /// stepped engine resolves such contacts as it does its own.
    pub(crate) fn continuing(
        scene: &Scene<T, D>,
        plan: &Plan,
        direction: Direction,
        spins: &[crate::Angular<T, D>],
    ) -> Result<Self, SceneError> {
        scene.validate_fields()?;
        let mut engine = Self::with_valid_fields(scene, plan, direction)?;
        for (w, spin) in engine.balls.spin.iter_mut().zip(spins) {
            *w = *spin * engine.clock.sign;
        }
        Ok(engine)
    }

    /// [`SteppedEngine::new`] for a scene whose fields are valid.
    fn with_valid_fields(
        scene: &Scene<T, D>,
        plan: &Plan,
        direction: Direction,
    ) -> Result<Self, SceneError> {
        // Positions are computed from the scene's middle and reported from the origin.
        let (scene, origin) = scene.recentred();
        let scene = &scene;
        let n = scene.balls.len();
        if u32::try_from(n + scene.boxes.len()).is_err() {
            return Err(SceneError::new("balls", "more than 2^32 balls and boxes"));
        }
        let dt = plan.dt.unwrap_or(DEFAULT_DT);
        let h = T::lit(dt);
        if !(dt.is_finite() && dt > 0.0 && h > T::zero() && h.finite()) {
            return Err(SceneError::new(
                "--dt",
                format!("must be a finite step > 0, got {dt}"),
            ));
        }
        let integrator = plan.integrator.unwrap_or(Integrator::SemiImplicitEuler);
        let broad =
            stepped_broad_phase(scene, plan.broad).map_err(|e| SceneError::new("--broad", e.0))?;
        let sign = direction.sign::<T>();
        let world = &scene.world;
        let (border, periodic) = match &world.border {
            Some(b) if b.periodic => (None, Some(b.border)),
            Some(b) => (Some(b.border), None),
            None => (None, None),
        };
        let periodic_reach = periodic_reach(scene, periodic.as_ref())?;
        let forces = WorldForces::new(world.gravity, world.drag, direction == Direction::Backward);
        let stepper = Stepper::new(integrator, forces)
            .map_err(|e| SceneError::new("--integrator", e.to_string()))?;
        let rules = Rules::for_scene(scene, h)?;
        let balls = BallArrays::from_scene(scene, sign)?;
        let boxes = BoxArrays::new(&scene.boxes, sign);
        let sweep = Sweep::new(broad, n, periodic.as_ref());
        let mut engine = Self {
            balls,
            boxes,
            border,
            periodic,
            stepper,
            rules,
            rest: RestSets::new(n),
            clusters: Clusters::new(periodic.as_ref().map(|b| b.extents().min())),
            changed: Vec::new(),
            spun_at_start: true,
            sweep,
            queue: EventQueue::new(),
            chunk_events: Vec::new(),
            chunk_status: Vec::new(),
            candidates: Vec::new(),
            found: Vec::new(),
            touches: [Vec::new(), Vec::new()],
            solvers: Solvers::default(),
            groups: Groups::new(n),
            repeats: Repeats::new(n),
            clock: Clock {
                dt,
                k: 0,
                s: T::zero(),
                sign,
            },
            counters: Counters::default(),
            stats: StepStats::default(),
            pipeline: Vec::new(),
            event_budget: 1_000_000_u64.max(256 * n as u64),
            instant: T::lit(dt * SIMULTANEITY),
            step_length: T::lit(dt),
            periodic_reach,
            escape_bound: 64.max(n / 16),
            origin,
        };
        engine.pipeline = engine.describe(scene, integrator);
        Ok(engine)
    }

    /// The pipeline names (see [`Simulation::pipeline`]).
    fn describe(&self, scene: &Scene<T, D>, integrator: Integrator) -> Vec<String> {
        let mut p = vec![
            "time-stepped".to_owned(),
            format!("integrator:{integrator}"),
            self.sweep.name().to_owned(),
        ];
        let n = self.balls.len();
        if n >= 2 {
            p.push("narrow:ball-ball".into());
        }
        if self.border.is_some() {
            p.push("narrow:ball-border".into());
        }
        if self.periodic.is_some() {
            p.push("periodic-border".into());
        }
        if self.boxes.len() > 0 {
            p.push("narrow:ball-box".into());
        }
        if self.boxes.any_moving() {
            p.push("kinematic-boxes".into());
        }
        p.push("ccd:time-of-impact-sub-steps".into());
        p.push("response:restitution".into());
        if can_stick(scene) && n >= 2 {
            p.push("response:stick".into());
        }
        if scene.world.friction > T::zero() {
            p.push("response:friction".into());
        }
        let surfaces = self.border.is_some() || self.boxes.len() > 0;
        if surfaces && self.rules.has_gravity() {
            p.push("guard:resting".into());
        }
        if n >= 2 && self.balls.restitution.iter().any(|&e| e < T::one()) {
            p.push("guard:collapse".into());
        }
        for name in self.stepper.field().names() {
            p.push(format!("field:{name}"));
        }
        p
    }

    /// What the engine did so far beyond the collisions: contacts, resting corrections,
    /// broad-phase builds, steps that hit the event budget.
    pub fn stats(&self) -> StepStats {
        StepStats {
            broad_builds: self.sweep.builds(),
            largest_hold: self.solvers.largest() as u64,
            ..self.stats
        }
    }

    /// The most contacts one step may process (default: `max(10⁶, 256 N)`).
    ///
    /// A step that needs more (a pathological cluster: thousands of balls in a resting
    /// pile inside a narrow wedge, or a ball trapped between two walls closer than its
    /// step's travel by a factor above the budget) processes the budget, then **freezes**:
    /// every ball stays where it is at that moment for the rest of the step, keeping its
    /// velocity. Freezing never creates an overlap and loses no energy; the step and the
    /// frozen time are counted in [`StepStats::capped_steps`] and
    /// [`StepStats::frozen_time`].
    pub fn set_event_budget(&mut self, budget: u64) {
        self.event_budget = budget.max(1);
    }

    /// Sets the velocity of box `k` (world time direction) from now on: the box moves at
    /// `vel` during the following steps, until the next call. This is how a paddle follows
    /// a scripted path: before each step (or each `advance_to`), set the velocity that
    /// brings it where the script wants it at the end of the step. Balls the box hits
    /// receive its velocity as a kinematic body's (`(1 + e) u` for a ball at rest).
    ///
    /// # Errors
    /// `boxes[k]` if there is no box `k`, `boxes[k].vel[i]` if a component is not finite.
    pub fn set_box_velocity(&mut self, k: usize, vel: Vector<T, D>) -> Result<(), SceneError> {
        if k >= self.boxes.len() {
            return Err(SceneError::new(
                format!("boxes[{k}]"),
                format!("no such box: the scene has {}", self.boxes.len()),
            ));
        }
        let vel = ensure_finite_vector("vel", &vel)
            .map_err(|e| SceneError::from(e.within(&format!("boxes[{k}]"))))?;
        self.boxes
            .set_velocity(k, vel * self.clock.sign, self.clock.s);
        if vel != Vector::<T, D>::zeros() && !self.pipeline.iter().any(|p| p == "kinematic-boxes") {
            let at = self
                .pipeline
                .iter()
                .position(|p| p.starts_with("ccd:"))
                .unwrap_or(self.pipeline.len());
            self.pipeline.insert(at, "kinematic-boxes".into());
        }
        Ok(())
    }

    /// Box `k`'s centre now, or `None` if there is no box `k`.
    pub fn box_center(&self, k: usize) -> Option<Vector<T, D>> {
        self.boxes.shape.get(k).map(|b| b.center() + self.origin)
    }

    /// The step `dt` (s).
    pub fn dt(&self) -> f64 {
        self.clock.dt
    }

    /// The integrator.
    pub fn integrator(&self) -> Integrator {
        self.stepper.integrator()
    }

    fn parallel(&self) -> bool {
        self.balls.len() >= PARALLEL_MIN && rayon::current_num_threads() > 1
    }

    /// Integrates every ball over `h` from internal time `t0` and starts the segments.
    fn integrate(&mut self, h: T, t0: T, parallel: bool) {
        let Ok(dt) = TimeStep::new(h) else {
            return;
        };
        self.rest.clear();
        self.groups.clear();
        self.solvers.warm.next_step();
        self.repeats.clear();
        let stepper = &self.stepper;
        let previous = self.step_length;
        // Per chunk: the segments start where the balls are, with what the last step's
        // end could not hold (see `balls`: remainders); the balls are stepped from the
        // origin, so that `pos` holds each one's displacement, and the chords and ends
        // follow from it.
        let run = |(start, (pos, vel, spin)): (Segment<'_, T, D>, State<'_, T, D>),
                   inverse_mass: &[T],
                   chord: &mut [Vector<T, D>],
                   supported: &mut [bool]| {
            let (seg_x, seg_r, seg_v, seg_w, seg_t) = start;
            for ((((x, r), t), c), p) in (seg_x.iter_mut().zip(seg_r.iter_mut()))
                .zip(seg_t.iter_mut())
                .zip(chord.iter())
                .zip(pos.iter_mut())
            {
                *r = (*r + c * (previous - *t)) - (*p - *x);
                *x = *p;
                *t = T::zero();
                *p = Vector::zeros();
            }
            seg_v.copy_from_slice(vel);
            seg_w.copy_from_slice(spin);
            supported.fill(false);
            if let Ok(mut bodies) =
                Bodies::new(pos, vel, inverse_mass).and_then(|bodies| bodies.with_spins(spin))
            {
                stepper.step(&mut bodies, t0, dt);
            }
            for (((c, p), x), r) in chord
                .iter_mut()
                .zip(pos.iter_mut())
                .zip(seg_x.iter())
                .zip(seg_r.iter())
            {
                *c = *p / h;
                *p = x + (r + *p);
            }
        };
        let b = &mut self.balls;
        if parallel {
            b.seg_x
                .par_chunks_mut(CHUNK)
                .zip(b.seg_r.par_chunks_mut(CHUNK))
                .zip(b.seg_v.par_chunks_mut(CHUNK))
                .zip(b.seg_w.par_chunks_mut(CHUNK))
                .zip(b.seg_t.par_chunks_mut(CHUNK))
                .zip(b.pos.par_chunks_mut(CHUNK))
                .zip(b.vel.par_chunks_mut(CHUNK))
                .zip(b.spin.par_chunks_mut(CHUNK))
                .zip(b.inverse_mass.par_chunks(CHUNK))
                .zip(b.chord.par_chunks_mut(CHUNK))
                .zip(b.supported.par_chunks_mut(CHUNK))
                .for_each(|((((((((((x, r), v), w), t), p), u), s), m), c), f)| {
                    run(((x, r, v, w, t), (p, u, s)), m, c, f);
                });
        } else {
            run(
                (
                    (
                        &mut b.seg_x,
                        &mut b.seg_r,
                        &mut b.seg_v,
                        &mut b.seg_w,
                        &mut b.seg_t,
                    ),
                    (&mut b.pos, &mut b.vel, &mut b.spin),
                ),
                &b.inverse_mass,
                &mut b.chord,
                &mut b.supported,
            );
        }
        (self.clusters).integrate(&mut self.balls, &Flight::new(&self.stepper, h, t0));
    }

    fn narrow(&self, end: T) -> Narrow<'_, T, D> {
        Narrow {
            balls: &self.balls,
            boxes: &self.boxes,
            border: self.border.as_ref(),
            periodic: self.periodic.as_ref(),
            end,
            allowance: self.rules.allowance(self.step_length),
            gravity: self.rules.gravity,
            instant: self.instant,
        }
    }

    /// Predicts every contact of the window `[a, b]`: the broad phase's pairs, each ball
    /// against the walls, and the escapees by query.
    fn predict_all(&mut self, a: T, b: T, parallel: bool) -> Result<(), Overflow> {
        let n = self.balls.len();
        let pairs = &self.sweep.pairs;
        let escapees = self.sweep.escapees();
        let pair_chunks = pairs.len().div_ceil(CHUNK);
        let ball_chunks = n.div_ceil(CHUNK);
        let escapee_chunks = escapees.len().div_ceil(ESCAPEE_CHUNK);
        let chunks = pair_chunks + ball_chunks + escapee_chunks;
        if self.chunk_events.len() < chunks {
            self.chunk_events.resize_with(chunks, Vec::new);
        }
        let narrow = Narrow {
            balls: &self.balls,
            boxes: &self.boxes,
            border: self.border.as_ref(),
            periodic: self.periodic.as_ref(),
            end: b,
            allowance: self.rules.allowance(self.step_length),
            gravity: self.rules.gravity,
            instant: self.instant,
        };
        let periodic_boxes = self.periodic.is_some() && self.boxes.len() > 0;
        let sweep = &self.sweep;
        let entries = sweep.entries();
        let nboxes = self.boxes.len();
        let work = |c: usize, out: &mut Vec<Event<T, D>>| -> Result<(), Overflow> {
            out.clear();
            let mut push = |p: Result<Option<Event<T, D>>, Overflow>| -> Result<(), Overflow> {
                if let Some(e) = p? {
                    out.push(e);
                }
                Ok(())
            };
            if c < pair_chunks {
                let chunk = &pairs[c * CHUNK..((c + 1) * CHUNK).min(pairs.len())];
                for (k, &(i, j)) in chunk.iter().enumerate() {
                    // The second ball of a pair is anywhere in memory; its data is asked
                    // for a few pairs ahead so that the misses overlap.
                    if let Some(&(_, ahead)) = chunk.get(k + PAIR_PREFETCH_AHEAD)
                        && (ahead as usize) < n
                    {
                        narrow.balls.prefetch_partner(ahead as usize);
                    }
                    let (i, j) = (i as usize, j as usize);
                    if j < n {
                        push(narrow.ball_ball(i, j, a))?;
                    } else if i < n {
                        push(narrow.ball_box(i, j - n, a))?;
                    }
                }
            } else if c >= pair_chunks + ball_chunks {
                // An escapee's path left its entry: its candidates come from a query.
                let first = (c - pair_chunks - ball_chunks) * ESCAPEE_CHUNK;
                let last = (first + ESCAPEE_CHUNK).min(escapees.len());
                let mut candidates = Vec::new();
                let mut result = Ok(());
                for &e in &escapees[first..last] {
                    let r = narrow.ball_events(sweep, e as usize, a, &[], &mut candidates, out);
                    result = result.and(r);
                }
                result?;
            } else {
                let first = (c - pair_chunks) * CHUNK;
                let last = (first + CHUNK).min(n);
                for (i, entry) in (first..last).zip(&entries[first..last]) {
                    // A ball whose entry is clear of the walls cannot reach one (an
                    // escapee is predicted by query, walls included).
                    if narrow.border.is_some_and(|border| !clear_of(entry, border)) {
                        push(narrow.ball_border(i, a))?;
                    }
                    if periodic_boxes {
                        for k in 0..nboxes {
                            push(narrow.ball_box(i, k, a))?;
                        }
                    }
                }
            }
            Ok(())
        };
        self.chunk_status.resize(self.chunk_events.len(), Ok(()));
        let (buffers, status) = (
            &mut self.chunk_events[..chunks],
            &mut self.chunk_status[..chunks],
        );
        if parallel {
            buffers
                .par_iter_mut()
                .zip(status.par_iter_mut())
                // One chunk per task: pair chunks cost far more than ball chunks, and
                // rayon's default split hands each thread a few long runs.
                .with_max_len(1)
                .enumerate()
                .for_each(|(c, (out, status))| *status = work(c, out));
        } else {
            for (c, (out, status)) in buffers.iter_mut().zip(status.iter_mut()).enumerate() {
                *status = work(c, out);
            }
        }
        // The first failing chunk in chunk order: the same error on any thread count.
        self.chunk_status[..chunks]
            .iter()
            .copied()
            .collect::<Result<(), Overflow>>()?;
        self.queue
            .start(self.chunk_events[..chunks].iter().flatten().copied());
        Ok(())
    }

    /// Predicts the contacts of ball `i` after `s` within the window ending at `end`,
    /// skipping partners in `skip` (already predicted against `i`).
    fn predict_ball(&mut self, i: usize, s: T, end: T, skip: &[u32]) -> Result<(), Overflow> {
        let mut candidates = core::mem::take(&mut self.candidates);
        let mut found = core::mem::take(&mut self.found);
        found.clear();
        let result =
            self.narrow(end)
                .ball_events(&self.sweep, i, s, skip, &mut candidates, &mut found);
        self.queue.push(&found);
        self.candidates = candidates;
        self.found = found;
        result
    }

    /// Prefetches what answering the next contacts will read, in three stages so that
    /// each stage's reads hit the lines the one before fetched: three contacts ahead
    /// their balls' rows, entries and partner-list starts, and their records in the
    /// step's bookkeeping (repeats, resting sets, groups); two ahead the partner lists;
    /// one ahead the partners' rows (see `queue` and `prefetch`). A hint only.
    fn prefetch_ahead(&self) {
        if let Some(e) = self.queue.ahead(2) {
            for ball in e.balls() {
                self.balls.prefetch_row(ball);
                self.sweep.prefetch_entry(ball);
                self.repeats.prefetch(ball);
                self.rest.prefetch(ball);
                self.groups.prefetch(ball);
            }
        }
        if let Some(e) = self.queue.ahead(1) {
            for ball in e.balls() {
                self.sweep.prefetch_partner_list(ball);
            }
        }
        if let Some(e) = self.queue.ahead(0) {
            for ball in e.balls() {
                self.sweep.prefetch_partner_rows(ball, &self.balls);
            }
        }
    }

    /// Whether the event's balls are unchanged since it was predicted.
    fn current(&self, e: &Event<T, D>) -> bool {
        let v = &self.balls.version;
        v[e.ball as usize] == e.versions[0]
            && match e.target {
                Target::Ball(j) => v[j as usize] == e.versions[1],
                Target::Border | Target::Box(_) => true,
            }
    }

    /// Notes the event's contacts (see `wedge`): whether a ball of it is wedged.
    ///
    /// # Errors
    /// A ball of it is crushed.
    fn note_contacts(&mut self, e: &Event<T, D>, h: T, t0: T) -> Result<bool, SimError> {
        let [i, other] = e.balls();
        let instant = h * T::lit(1e-9);
        // A chain's link: also the time in which the contact's bodies move by no more
        // than the resolution of their coordinates (a squeeze far from the origin answers
        // its contacts that far apart, whatever the step).
        let speed = self.balls.chord[i].norm()
            + match e.target {
                Target::Ball(j) => self.balls.chord[j as usize].norm(),
                Target::Box(k) => self.boxes.vel[k as usize].norm(),
                Target::Border => T::zero(),
            };
        let resolution = crate::scene::coordinate_resolution(self.balls.seg_x[i].amax());
        let link = if speed > T::zero() {
            instant.max(resolution / speed)
        } else {
            instant
        };
        // An elastic squeeze of a light ball by a heavy one takes about π √(M/m)
        // contacts, which may crowd into one instant (see `wedge`).
        let b = &self.balls;
        let limit = match e.target {
            Target::Ball(j) if b.pair_restitution(i, j as usize) == T::one() => {
                let (a, c) = (b.inverse_mass[i], b.inverse_mass[j as usize]);
                wedge_limit((a.max(c) / a.min(c)).to_f64())
            }
            Target::Ball(_) | Target::Border | Target::Box(_) => WEDGE_CONTACTS,
        };
        let mut repeat = self.repeats.note(i, e.time, instant, link, limit);
        // The ball named crushed is the one whose count crossed the limit: the other ball
        // of a pair where only it did.
        let mut crushed = (repeat == Repeat::Crushed).then_some(i);
        if other != i {
            let other_repeat = self.repeats.note(other, e.time, instant, link, limit);
            if other_repeat == Repeat::Crushed && crushed.is_none() {
                crushed = Some(other);
            }
            repeat = repeat.max(other_repeat);
        }
        if let Some(k) = crushed {
            let reason = self.crush_reason(k, e.time);
            let by = match e.target {
                Target::Ball(_) if k != i => format!("balls[{i}]"),
                Target::Ball(j) => format!("balls[{j}]"),
                Target::Border => "the border".to_string(),
                Target::Box(b) => format!("boxes[{b}]"),
            };
            return Err(SimError::new(
                ((t0 + e.time) * self.clock.sign + T::zero()).to_f64(),
                format!(
                    "balls[{k}] is crushed: more than {} contacts at one instant (the last with {by}); {reason}",
                    self.repeats.crush_limit(k)
                ),
            ));
        }
        Ok(repeat == Repeat::Wedged)
    }

    /// Processes one event: the balls it changed go to `self.changed` (a cluster changes
    /// all its members, a hold every ball of its stack); returns the collision to report,
    /// if any.
    ///
    /// # Errors
    /// A fusion of two clusters that overflows the precision.
    fn process(&mut self, e: &Event<T, D>, h: T, t0: T) -> Result<Option<Collision<T>>, SimError> {
        let [i, other] = e.balls();
        let mut touches = core::mem::take(&mut self.touches);
        for (ball, out) in [i, other].into_iter().zip(touches.iter_mut()) {
            out.clear();
            if self.rules.has_gravity() {
                self.gather(ball, e.time, h, out);
            }
        }
        let in_cluster = |b: &BallArrays<T, D>, k: usize| Clusters::of(b, k).is_some();
        let clustered = in_cluster(&self.balls, i) || in_cluster(&self.balls, other);
        let grouped_i = self.groups.grouped(i);
        let wedged = self.note_contacts(e, h, t0)?;
        self.changed.clear();
        let time = (t0 + e.time) * self.clock.sign + T::zero();
        let stick = self.rules.stick;
        let box_velocity = |k: usize| self.boxes.vel[k];
        let surface = match e.target {
            Target::Box(k) => Surface::Box(k as usize, box_velocity(k as usize)),
            Target::Border | Target::Ball(_) => Surface::Wall,
        };
        let mut contacts = self.contacts([(i, &touches[0]), (other, &touches[1])], h, t0);
        let stuck_error = |message: String| SimError::new(time.to_f64(), message);
        let (effect, collision): (Effect, Collision<T>) = match e.target {
            Target::Ball(j) => {
                let j = j as usize;
                let sticks = stick && contacts.balls.pair_restitution(i, j) == T::zero();
                let grouped = contacts.groups.grouped(i) || contacts.groups.grouped(j);
                let onto_pile = (grouped && !clustered && !sticks)
                    .then(|| contacts.onto_held_pile(i, j, e.time))
                    .flatten();
                let effect = if wedged && !clustered && !sticks {
                    contacts.wedged(i, SeedOther::Ball(j), e.time)
                } else if let Some((upper, lower)) = onto_pile {
                    let n = if upper == i { e.normal } else { -e.normal };
                    contacts.onto_pile(upper, lower, &n, e.time)
                } else if clustered || sticks || grouped {
                    contacts
                        .stuck_pair(i, j, &e.shift, e.time, &e.normal)
                        .map_err(stuck_error)?
                } else {
                    contacts.ball_ball(i, j, &e.shift, e.time, &e.normal)
                };
                (effect, Collision::BallBall { time, i, j })
            }
            Target::Border | Target::Box(_) => {
                let collision = match e.target {
                    Target::Box(k) => Collision::BallBox {
                        time,
                        i,
                        k: k as usize,
                    },
                    _ => Collision::BallBorder { time, i },
                };
                let effect = if wedged && !clustered {
                    contacts.wedged(i, SeedOther::Surface(e.normal), e.time)
                } else if clustered || grouped_i {
                    contacts.stuck_surface(i, surface, &e.normal, e.time)
                } else {
                    contacts.ball_surface(i, surface, &e.normal, e.time)
                };
                (effect, collision)
            }
        };
        self.touches = touches;
        for ball in [i, other] {
            match Clusters::of(&self.balls, ball) {
                Some(c) => self
                    .changed
                    .extend_from_slice(&self.clusters.list[c].members),
                None => self.changed.push(ball as u32),
            }
        }
        self.changed.sort_unstable();
        self.changed.dedup();
        self.stats.contacts += 1;
        if !effect.collided {
            self.stats.resting += 1;
        }
        Ok(effect.collided.then(|| {
            match collision {
                Collision::BallBall { .. } => self.counters.ball_ball += 1,
                Collision::BallBorder { .. } => self.counters.ball_border += 1,
                Collision::BallBox { .. } => self.counters.ball_box += 1,
            }
            collision
        }))
    }

    /// The engine's balls, bodies and rules for answering contacts in the step of length
    /// `h` from internal time `t0`, with the supports the contact's balls touch.
    fn contacts<'a>(
        &'a mut self,
        touching: [(usize, &'a [Touch<T, D>]); 2],
        h: T,
        t0: T,
    ) -> Contacts<'a, T, D, WorldForces<T, D>> {
        Contacts {
            balls: &mut self.balls,
            changed: &mut self.changed,
            boxes: &self.boxes,
            border: self.border.as_ref(),
            periodic: self.periodic.as_ref(),
            sweep: &self.sweep,
            candidates: &mut self.candidates,
            solvers: &mut self.solvers,
            groups: &mut self.groups,
            stepper: &self.stepper,
            rules: &self.rules,
            rest: &mut self.rest,
            clusters: &mut self.clusters,
            touching,
            h,
            t0,
        }
    }

    /// Holds every large pile at the step's start as one stack (see `piles`), under
    /// gravity: its contacts answered one at a time would each hold it again.
    fn hold_piles(&mut self, h: T, t0: T) {
        if !self.rules.has_gravity() {
            return;
        }
        let piles = piles::resting_piles(
            &self.balls,
            &self.boxes,
            self.border.as_ref(),
            self.periodic.as_ref(),
            &self.sweep.pairs,
            h,
            self.rules.support_speed,
        );
        for pile in &piles {
            self.contacts([(usize::MAX, &[]), (usize::MAX, &[])], h, t0)
                .hold_resting(pile);
            self.groups.note_pile(pile);
        }
        self.changed.clear();
    }

    /// The supports ball `i` touches at in-step time `s` (within `1e-9` of its radius):
    /// walls of the border, boxes, and balls below it (along gravity) that do not move
    /// up into it (`h` the step's length).
    fn gather(&mut self, i: usize, s: T, h: T, out: &mut Vec<Touch<T, D>>) {
        let b = &self.balls;
        let (x, r) = (b.position_at(i, s), b.radius[i]);
        let tolerance = touch_tolerance(&x, r);
        if let Some(border) = &self.border {
            let gaps = border.wall_gaps(&Ball::new_unchecked(x, r));
            for (axis, (below, above)) in gaps.into_iter().enumerate() {
                for (upper, gap) in [(false, below), (true, above)] {
                    if gap <= tolerance {
                        let mut normal = Vector::zeros();
                        normal[axis] = if upper { T::one() } else { -T::one() };
                        out.push(Touch {
                            support: Support::Wall(axis, upper),
                            normal,
                            velocity: Vector::zeros(),
                        });
                    }
                }
            }
        }
        let path = path_box(&x, &b.pos[i], r + tolerance);
        let mut candidates = core::mem::take(&mut self.candidates);
        self.sweep.candidates(i, &path, &mut candidates);
        // Ascending, each once: the supports come in index order whatever the source.
        candidates.sort_unstable();
        candidates.dedup();
        for (k, normal) in self.touching_boxes((&x, r), s, tolerance, &candidates) {
            out.push(Touch {
                support: Support::Box(k as u32),
                normal,
                velocity: self.boxes.vel[k],
            });
        }
        let allowance = self.rules.allowance(h);
        for (j, y, normal) in self.touching_balls(i, (&x, r), s, tolerance, &candidates) {
            // Below the ball (not beside it on a common floor), and not moving up into it
            // (within rounding): it can hold it.
            if self.rules.lies_below((&x, r), (&y, b.radius[j]))
                && b.chord[j].dot(&normal) >= -self.rules.floor
            {
                // A pair sunk deeper than the narrow phase lets is held apart (see
                // `narrow::Allowance`): the support recedes at that speed.
                let apart = apart_speed(&allowance, (&x, r), (&y, b.radius[j]), h - s);
                out.push(Touch {
                    support: Support::Ball(j as u32),
                    normal,
                    velocity: b.chord[j] - normal * apart,
                });
            }
        }
        self.candidates = candidates;
    }

    /// The boxes among `candidates` (indices past the balls'; every box where the broad
    /// phase does not file them) that a ball (centre and radius) touches at in-step time
    /// `s` within `tolerance`: each with the unit normal from the ball into it.
    fn touching_boxes<'a>(
        &'a self,
        (x, r): (&'a Vector<T, D>, T),
        s: T,
        tolerance: T,
        candidates: &'a [u32],
    ) -> impl Iterator<Item = (usize, Vector<T, D>)> + 'a {
        let n = self.balls.len();
        let unfiled = (!self.sweep.boxes_inside()).then_some(0..self.boxes.len());
        candidates
            .iter()
            .filter(move |&&c| c as usize >= n)
            .map(move |&c| c as usize - n)
            .chain(unfiled.into_iter().flatten())
            .filter_map(move |k| {
                let (normal, d) = self.boxes.nearest(k, s, x, self.periodic.as_ref())?;
                (d - r <= tolerance).then_some((k, normal))
            })
    }

    /// The balls among `candidates` (indices, boxes' included) that touch ball `i` (centre
    /// and radius) at in-step time `s` within `tolerance`: each with its centre (the
    /// minimum image seen from ball `i`'s in a periodic domain) and the unit normal from
    /// ball `i` to it.
    fn touching_balls<'a>(
        &'a self,
        i: usize,
        (x, r): (&'a Vector<T, D>, T),
        s: T,
        tolerance: T,
        candidates: &'a [u32],
    ) -> impl Iterator<Item = (usize, Vector<T, D>, Vector<T, D>)> + 'a {
        let b = &self.balls;
        candidates
            .iter()
            .map(|&c| c as usize)
            .filter(move |&j| j < b.len() && j != i)
            .filter_map(move |j| {
                let y = b.position_at(j, s);
                let y = self.periodic.map_or(y, |p| x + p.minimum_image(&(y - x)));
                let d = (y - x).norm();
                (d > T::zero() && d - r - b.radius[j] <= tolerance).then(|| (j, y, (y - x) / d))
            })
    }

    /// Why ball `i` could not be held at in-step time `s`, for a crush error: where no box
    /// it touches moves and a ball it touches is heavier or lighter by more than the
    /// contacts' solve resolves (`lcp::RESOLVABLE_MASS_RATIO`), the mass ratio; otherwise
    /// that the ball cannot give way, with whether a hold took it in in this step and the
    /// speed that hold left a contact closing at, if it did ([`Groups::last_hold`]).
    fn crush_reason(&mut self, i: usize, s: T) -> String {
        let why = "it cannot give way (as when a kinematic box presses it into the border or another box from every side it could leave by)";
        let cannot_give_way = match self.groups.last_hold(i) {
            Some(speed) if speed > 0.0 => format!(
                "even held against all of them at once they still close at {speed:.3e} m/s: {why}"
            ),
            Some(_) => format!("even held against all of them at once: {why}"),
            None => why.to_string(),
        };
        let b = &self.balls;
        let (x, r) = (b.position_at(i, s), b.radius[i]);
        let tolerance = touch_tolerance(&x, r);
        let mut candidates = core::mem::take(&mut self.candidates);
        self.sweep
            .candidates(i, &path_box(&x, &b.pos[i], r + tolerance), &mut candidates);
        let pressed_by_a_box = self
            .touching_boxes((&x, r), s, tolerance, &candidates)
            .any(|(k, _)| self.boxes.vel[k] != Vector::<T, D>::zeros());
        let ratio = |j: usize| {
            let (m, n) = (b.inverse_mass[i], b.inverse_mass[j]);
            (m / n).max(n / m)
        };
        let widest = self
            .touching_balls(i, (&x, r), s, tolerance, &candidates)
            .map(|(j, ..)| (j, ratio(j)))
            .fold(None, |w: Option<(usize, T)>, (j, q)| match w {
                Some((_, best)) if best >= q => w,
                _ => Some((j, q)),
            });
        self.candidates = candidates;
        let limit = lcp::RESOLVABLE_MASS_RATIO;
        match widest {
            Some((j, q)) if q.to_f64() > limit && !pressed_by_a_box => format!(
                "no box it touches moves, but balls[{j}] touching it differs from it in mass by a factor {:.2e}, beyond the {limit:.1e} that the contacts' solve resolves: the lighter ball's share of the contacts' impulses is lost to rounding, and they cannot be held (try masses closer together)",
                q.to_f64()
            ),
            _ => cannot_give_way,
        }
    }

    /// Stops every ball and cluster at in-step time `s` for the rest of the step
    /// (velocities kept).
    fn freeze(&mut self, s: T, h: T, t0: T) {
        self.end_at(s, h, t0);
        self.stats.capped_steps += 1;
        self.stats.frozen_time += (h - s).to_f64();
    }

    /// Makes every ball's and cluster's state at in-step time `s` its end of the step
    /// (a member where its chord is, its cluster's pose on its arc).
    fn end_at(&mut self, s: T, h: T, t0: T) {
        (self.clusters).freeze(s, &Flight::new(&self.stepper, h, t0));
        let b = &mut self.balls;
        for i in 0..b.len() {
            b.restart(i, s, h);
            let (x, v, w) = (b.seg_x[i], b.seg_v[i], b.seg_w[i]);
            b.chord[i] = Vector::zeros();
            b.pos[i] = x;
            b.vel[i] = v;
            b.spin[i] = w;
        }
    }

    /// Whether a cluster of the `changed` balls would now turn more than [`MAX_TURN`]
    /// over the `rest` of the step (at its spin at either end of its segment).
    fn spun_up(&self, changed: &[u32], rest: f64) -> bool {
        changed.iter().any(|&m| {
            Clusters::of(&self.balls, m as usize).is_some_and(|c| {
                let c = &self.clusters.list[c];
                let fastest = c.start.angular_speed().max(c.end.angular_speed());
                fastest.to_f64() * rest > MAX_TURN
            })
        })
    }

    /// Runs the events of the window `[a, b]` of a step of length `h` starting at
    /// internal time `t0`.
    ///
    /// # Errors
    /// A ball crushed ([`Self::note_contacts`]), a fusion or a time of impact overflowing
    /// the precision, and a ball that meets a ball or a box faster than the step's time
    /// places its contacts ([`Self::resolved_in_time`]).
    fn run_window(
        &mut self,
        b: T,
        h: T,
        t0: T,
        step_contacts: &mut u64,
        observer: &mut dyn Observer<T>,
    ) -> Result<WindowEnd<T>, SimError> {
        while let Some(e) = self.queue.pop() {
            self.prefetch_ahead();
            if !self.current(&e) {
                continue;
            }
            if *step_contacts >= self.event_budget {
                self.queue.clear();
                return Ok(WindowEnd::Budget(e.time));
            }
            *step_contacts += 1;
            if let Some(c) = self.process(&e, h, t0)? {
                observer.collision(&c);
            }
            let changed = core::mem::take(&mut self.changed);
            let mut cut = false;
            let only_a_wall = matches!(e.target, Target::Border) && changed.len() == 1;
            for &c in &changed {
                let c = c as usize;
                self.balls.version[c] = self.balls.version[c].wrapping_add(1);
                let path = path_box(
                    &self.balls.seg_x[c],
                    &self.balls.pos[c],
                    self.balls.radius[c],
                );
                cut |= self.sweep.moved(c, path) > self.escape_bound;
                let speed = self.balls.chord[c].norm();
                cut |= speed * (b - e.time) > self.periodic_reach;
                if !only_a_wall {
                    self.resolved_in_time(c, speed, h, t0 + e.time)?;
                }
            }
            if cut {
                self.changed = changed;
                self.queue.clear();
                self.stats.rebuilds += 1;
                return Ok(WindowEnd::Cut(e.time));
            }
            if (e.time > T::zero() || self.spun_at_start)
                && self.spun_up(&changed, (h - e.time).to_f64())
            {
                self.changed = changed;
                self.queue.clear();
                return Ok(WindowEnd::Spun(e.time));
            }
            for (k, &c) in changed.iter().enumerate() {
                self.predict_ball(c as usize, e.time, b, &changed[..k])
                    .map_err(|o| self.overflow(o, t0 + e.time))?;
            }
            self.changed = changed;
        }
        Ok(WindowEnd::Done)
    }

    fn overflow(&self, o: Overflow, s: T) -> SimError {
        SimError::new(
            (s * self.clock.sign).to_f64(),
            format!(
                "a time of impact of ball {} overflowed this precision (coordinates or speeds too large)",
                o.ball
            ),
        )
    }

    /// The error of a periodic window that would end where it starts: at internal time
    /// `t` a ball moves at `fastest`, so fast that the window in which no ball moves more
    /// than the periodic reach is shorter than the precision resolves in the step's time.
    /// Without it the step repeated that empty window for ever: a fuzzed `f32` scene whose
    /// 52 mg ball was squeezed between a static box and an 11,423 kg ball at 3.4e4 m/s (a
    /// mass ratio of 2e8, beyond `f32`'s 1/ε) had the heavy ball thrown to 1.8e8 m/s and
    /// the light one to 2.8e11 m/s.
    fn too_fast_for_a_window(&self, t: T, fastest: T) -> SimError {
        let chord = &self.balls.chord;
        let ball = (0..chord.len())
            .find(|&i| chord[i].norm() >= fastest)
            .unwrap_or_default();
        SimError::new(
            (t * self.clock.sign).to_f64(),
            format!(
                "balls[{ball}] moves at {:e} m/s: the periodic border's window in which no ball moves more than {:e} m is shorter than this precision resolves within the step, and the run cannot go on (speeds like this follow from squeezes at mass ratios beyond the precision's; try --precision f64)",
                fastest.to_f64(),
                self.periodic_reach.to_f64()
            ),
        )
    }

    /// Whether ball `i`, just changed at internal time `t` by a contact (other than a
    /// free ball's with a wall) and now moving at `speed` in a step of length `h`, moves
    /// slowly enough for the step's time to place its contacts: an error naming it if
    /// not.
    ///
    /// Contacts are found and answered at in-step times, whose last place near the step's
    /// end is `ε h` (1.2e-9 s for `f32` and `h = 0.01` s; 2.2e-18 s in `f64`). Rounding a
    /// contact's time moves the ball's place at it along its path by up to half of `v ε h`;
    /// beyond [`RESOLVED_TRAVEL`] radii per last place, a diameter, that is more than its
    /// radius, so the ball can be placed past the ball it meets, and the order of
    /// contacts less than a last place apart (a light ball squeezed between a heavy ball
    /// and a wall meets them ever faster) is left to rounding. The campaigns' seed 42,
    /// s01 (`f32`, a 3.8 mg ball pumped by balls of up to 451 t) went on from there to
    /// 0.37 m outside the border and a time of impact overflowing; every other run of the
    /// six campaigns stays below the limit (a periodic one reached 1.5 radii). A free
    /// ball's contact with a wall is exempt: a wall is a half-space, which its reflection
    /// keeps the ball inside of wherever along its path the rounded time puts the contact
    /// (a ball of radius 1 mm at 1.04e7 m/s, six diameters per last place, bounces in a
    /// box with its speed kept; `docs/stepped.md`). A wall contact that changes more balls (a
    /// cluster's, a hold's) is not: those balls touch each other.
    fn resolved_in_time(&self, i: usize, speed: T, h: T, t: T) -> Result<(), SimError> {
        let spacing = T::EPSILON * h;
        let radius = self.balls.radius[i];
        if speed * spacing <= T::lit(RESOLVED_TRAVEL) * radius {
            return Ok(());
        }
        Err(SimError::new(
            (t * self.clock.sign + T::zero()).to_f64(),
            format!(
                "balls[{i}] moves at {:.3e} m/s: in one last place of the step's time ({:.3e} s) it travels {:.3e} m, more than its diameter {:.3e} m, so this precision cannot place its contacts with balls and boxes (speeds like this follow from squeezes at mass ratios beyond the precision's; try --precision f64 or a smaller --dt)",
                speed.to_f64(),
                spacing.to_f64(),
                (speed * spacing).to_f64(),
                (radius + radius).to_f64()
            ),
        ))
    }

    /// The fastest chord of any ball (m/s).
    fn fastest_chord(&self, parallel: bool) -> T {
        let chord = &self.balls.chord;
        let fastest = |part: &[Vector<T, D>]| part.iter().fold(T::zero(), |m, u| m.max(u.norm()));
        if parallel {
            chord.par_chunks(CHUNK).map(fastest).reduce(T::zero, T::max)
        } else {
            fastest(chord)
        }
    }

    /// The simultaneity window of a window of the step whose fastest ball or box moves at
    /// `fastest`: contacts within it are one instant, answered bottom-up along gravity
    /// rather than in time order (see `narrow::Event::key_cmp`), so that a pile touching
    /// within rounding settles from the floor up. A millionth of the step ([`SIMULTANEITY`]),
    /// or less, so that no ball moves more than [`SIMULTANEOUS_TRAVEL`] within it: a 9.7
    /// mg ball pumped to 700 m/s between a 3.6 g ball and the top wall of a box, in its
    /// corner, met the ball again 7e-9 s after the wall, lower, so first, and each time
    /// ran on past the side wall, which only the wall's answer would have shown it; it
    /// ended 1.2e-5 m beyond it (a fuzzed scene, `--dt 0.01`: the millionth of the step
    /// was 1e-8 s).
    ///
    /// At least `ε` of the step, so that a step holds at most `1/ε` instants (`2⁵²` in
    /// `f64`), each numbered exactly: at absurd speeds every contact is then its own
    /// instant but for those that close.
    fn instant_width(&self, fastest: T) -> T {
        let width = T::lit(self.clock.dt * SIMULTANEITY);
        let travel = T::lit(SIMULTANEOUS_TRAVEL);
        if fastest * width > travel {
            (travel / fastest).max(T::lit(self.clock.dt) * T::EPSILON)
        } else {
            width
        }
    }

    /// The end of the window starting at `a` in a step of length `h` when the fastest
    /// ball moves at `fastest`: the step's end, or earlier in a periodic domain so that
    /// no ball moves more than `periodic_reach`.
    fn window_end(&self, a: T, h: T, fastest: T) -> T {
        if self.periodic.is_none() {
            return h;
        }
        if fastest * (h - a) <= self.periodic_reach {
            h
        } else {
            (a + self.periodic_reach / fastest).min(h)
        }
    }

    /// Wraps every ball's segment into the periodic cell at in-step time `s`; a stuck
    /// cluster wraps as a whole, when its centre of mass leaves the cell (its members may
    /// then lie outside the cell: everything is computed with minimum images).
    fn wrap(&mut self, s: T, h: T, t0: T) {
        let Some(border) = self.periodic else {
            return;
        };
        let b = &mut self.balls;
        (self.clusters).wrap(b, &border, s, &Flight::new(&self.stepper, h, t0));
        for i in 0..b.len() {
            if Clusters::of(b, i).is_some() {
                continue;
            }
            let x = b.position_at(i, s);
            let shift = border.wrap(&x) - x;
            if shift != Vector::<T, D>::zeros() {
                b.restart(i, s, h);
                b.seg_x[i] += shift;
                b.pos[i] += shift;
            }
        }
    }

    /// Steps from the current time to internal time `end` (at most a grid step on): in one
    /// step, or, while a stuck cluster would turn more than [`MAX_TURN`] in it, in equal
    /// sub-steps in which none does (cut again after each: collisions change the spins).
    ///
    /// A cluster's members move along straight chords within a step (see `clusters`),
    /// which cut across their arcs when the cluster turns radians in it: a member then
    /// meets walls and balls where its arc does not, the impulses act at arms the chords
    /// do not have, and the energy rose (a pair spinning at 2,000 rad/s in a box whose
    /// walls halve its speed at each bounce gained up to 5.3e3 J in one step of 1/100 s;
    /// a fuzzed scene whose balls at 1e6 m/s fused into clusters spinning at 1e7 rad/s
    /// went from 9.6e11 J to 4.3e15 J in a quarter of a second). Sub-steps keep a member
    /// at arm `a` from the centre within `a MAX_TURN²/8` (the sagitta) of its arc. A
    /// contact within a (sub-)step that sets a cluster spinning faster than that (two fast
    /// balls fusing) ends the step at its instant ([`WindowEnd::Spun`]: every ball and
    /// cluster ends there, where its chord and its arc still agree), and the rest is cut
    /// anew; before, such a pair ran on along its chords for the rest of the step (a
    /// fuzzed pair fused at 465 m/s ended 8 cm through a wall, its members' chords and
    /// its pose apart by 12 cm, and the hold then found the wall contact again every
    /// 4e-10 s). Those cuts count among the sub-steps.
    ///
    /// A step that ends so at its very start (a contact at its first instant) is cut
    /// again for the spin that contact left, and that step does not end at its first
    /// instant again: a cluster held in a corner spinning at 8.7e3 rad/s (a fuzzed
    /// scene, `--dt 0.01`) met the corner at the start of every sub-step, the hold's
    /// torque over the sub-step raised its spin by a little more than its cut allowed,
    /// and every sub-step ended where it began, until the run ended with the spin error
    /// at 8.5e-4 s (after 4,096 sub-steps of no length).
    ///
    /// # Errors
    ///
    /// A cluster that would need more than [`MAX_SUBSTEPS`] sub-steps in one step, named
    /// with its spin, and the errors of [`Self::step`].
    fn steps_to(&mut self, end: T, observer: &mut dyn Observer<T>) -> Result<(), SimError> {
        let mut taken = 0;
        self.spun_at_start = true;
        loop {
            let rest = end - self.clock.s;
            let (spin, cluster) = self.fastest_spin();
            let turn = (spin * rest).to_f64();
            let cuts = (turn / MAX_TURN).ceil();
            if cuts.is_nan() || cuts > (MAX_SUBSTEPS - taken) as f64 {
                return Err(self.spinning_too_fast(cluster, spin, rest, taken));
            }
            let len = if cuts <= 1.0 {
                rest
            } else {
                rest / T::lit(cuts)
            };
            let took = self.step(len, observer)?;
            self.spun_at_start = took > T::zero();
            let last = cuts <= 1.0 && took == len;
            self.clock.s = if last { end } else { self.clock.s + took };
            self.boxes.advance(self.clock.s, self.periodic.as_ref());
            if last {
                return Ok(());
            }
            taken += 1;
            self.stats.substeps += 1;
        }
    }

    /// The fastest angular speed of any stuck cluster now (rad/s) and its index (0 and
    /// `None` without clusters).
    fn fastest_spin(&self) -> (T, Option<usize>) {
        (self.clusters.list.iter().enumerate()).fold((T::zero(), None), |best, (k, c)| {
            let spin = c.end.angular_speed();
            if spin > best.0 || !spin.finite() {
                (spin, Some(k))
            } else {
                best
            }
        })
    }

    /// The error for cluster `cluster` spinning at `spin` rad/s, too fast to follow over
    /// the `rest` of a step in what is left of [`MAX_SUBSTEPS`] sub-steps after the
    /// `taken` ones.
    fn spinning_too_fast(&self, cluster: Option<usize>, spin: T, rest: T, taken: u64) -> SimError {
        let members = cluster.map_or_else(Vec::new, |k| self.clusters.list[k].members.clone());
        let named: Vec<String> = (members.iter().take(4))
            .map(|m| format!("balls[{m}]"))
            .collect();
        let more = if members.len() > 4 { ", ..." } else { "" };
        let limit = MAX_TURN * MAX_SUBSTEPS as f64;
        let turn = (spin * rest).to_f64();
        // When the whole budget would serve and the sub-steps already taken (contacts
        // that spin a cluster up end them early) leave too little of it, say so.
        let budget = if (turn / MAX_TURN).ceil() > MAX_SUBSTEPS as f64 {
            format!("more than the {limit} rad")
        } else {
            format!(
                "more than the {:.1} rad left after the {taken} sub-steps it has taken, of the {limit} rad",
                MAX_TURN * (MAX_SUBSTEPS - taken) as f64
            )
        };
        SimError::new(
            self.time().to_f64(),
            format!(
                "a stuck cluster of {} balls ({}{more}) spins at {:e} rad/s: it would turn {turn:e} rad in the rest of the step, {budget} the stepped engine follows in one step ({MAX_SUBSTEPS} sub-steps of at most {MAX_TURN} rad); use a --dt below {:e} s (below {:e} s it needs no sub-steps)",
                members.len(),
                named.join(", "),
                spin.to_f64(),
                limit / spin.to_f64(),
                MAX_TURN / spin.to_f64()
            ),
        )
    }

    /// One step of length `h` from the current time; returns the length it took: `h`, or
    /// less when a contact set a cluster spinning too fast for the rest of it
    /// ([`WindowEnd::Spun`]).
    fn step(&mut self, h: T, observer: &mut dyn Observer<T>) -> Result<T, SimError> {
        let t0 = self.clock.s;
        let parallel = self.parallel();
        self.integrate(h, t0, parallel);
        self.step_length = h;
        let mut a = T::zero();
        let mut step_contacts = 0;
        let mut first = self.periodic.is_none();
        while a < h {
            let fastest = self.fastest_chord(parallel);
            let boxes = (self.boxes.vel.iter()).fold(T::zero(), |m, v| m.max(v.norm()));
            self.instant = self.instant_width(fastest.max(boxes));
            let b = self.window_end(a, h, fastest);
            if b <= a {
                return Err(self.too_fast_for_a_window(t0 + a, fastest));
            }
            if first {
                self.sweep
                    .begin_step(&self.balls, &self.boxes, h, self.escape_bound, parallel);
            } else {
                let reach = if self.periodic.is_some() {
                    b - a
                } else {
                    let steps = self.sweep.reach_steps(&self.balls, h, parallel);
                    (h - a) + h * T::from_count(steps - 1)
                };
                self.sweep
                    .build(&self.balls, &self.boxes, a, reach, parallel);
            }
            if a == T::zero() {
                self.hold_piles(h, t0);
            }
            self.predict_all(a, b, parallel)
                .map_err(|o| self.overflow(o, t0 + a))?;
            first = false;
            let ended = awake::hold_pool(parallel, || {
                self.run_window(b, h, t0, &mut step_contacts, observer)
            });
            a = match ended? {
                WindowEnd::Done => b,
                WindowEnd::Cut(s) => s,
                WindowEnd::Budget(s) => {
                    self.freeze(s, h, t0);
                    h
                }
                WindowEnd::Spun(s) => {
                    self.end_at(s, h, t0);
                    self.wrap(s, h, t0);
                    self.finish_step(step_contacts);
                    return Ok(s);
                }
            };
            self.wrap(a, h, t0);
        }
        self.finish_step(step_contacts);
        Ok(h)
    }

    /// Counts a step that needed `contacts` contacts.
    fn finish_step(&mut self, contacts: u64) {
        self.stats.steps += 1;
        self.stats.max_contacts_in_step = self.stats.max_contacts_in_step.max(contacts);
    }
}

/// The farthest a ball may move within one window of a periodic domain, so that the
/// minimum image is the only image of another ball it can reach: a quarter of what half
/// the narrowest period leaves after two diameters (infinite without a periodic border).
///
/// # Errors
/// `world.border` if two ball diameters do not fit in half the narrowest period.
fn periodic_reach<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    periodic: Option<&Border<T, D>>,
) -> Result<T, SceneError> {
    let Some(p) = periodic else {
        return Ok(T::INFINITY);
    };
    let r_max = scene.balls.iter().fold(T::zero(), |m, b| m.max(b.radius));
    let half = p.extents().min() * T::lit(0.5);
    if T::lit(2.0) * r_max >= half {
        return Err(SceneError::new(
            "world.border",
            format!(
                "a periodic border must be wider than 4 ball radii on every axis (the largest radius is {r_max}, the narrowest period {})",
                p.extents().min()
            ),
        ));
    }
    Ok((half - T::lit(2.0) * r_max) * T::lit(0.25))
}

impl<T: Real, const D: usize> Simulation<T, D> for SteppedEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    fn kind(&self) -> EngineKind {
        EngineKind::Stepped
    }

    fn pipeline(&self) -> Vec<String> {
        self.pipeline.clone()
    }

    fn time(&self) -> T {
        self.clock.s * self.clock.sign + T::zero()
    }

    fn advance_to(&mut self, target: T, observer: &mut dyn Observer<T>) -> Result<(), SimError> {
        let sign = self.clock.sign;
        let goal = target * sign;
        let h = T::lit(self.clock.dt);
        // The internal time is always a grid time `k·dt` (rounded once to `T`) or a goal
        // exactly, so the goal is reached when it lies within rounding of the time: two
        // units in its last place (`ε |goal|` is at least one), or a billionth of a step
        // near 0. A wider tolerance stops the run short of its goal: with 64 ε, a free
        // ball in `f32` asked for 2e4 s in steps of 0.01 s stopped 0.15 s short.
        let tolerance = (T::lit(1e-9) * h).max(T::lit(2.0) * T::EPSILON * goal.abs());
        if !goal.finite() || goal < self.clock.s - tolerance {
            return Err(SimError::new(
                self.time().to_f64(),
                format!(
                    "cannot advance to {target}: the run is at {} and goes {}",
                    self.time(),
                    if sign > T::zero() {
                        "forward"
                    } else {
                        "backward"
                    }
                ),
            ));
        }
        // Grid times are `k·dt` with `k` counted exactly in an `f64` up to 2⁵³; a run
        // needing more steps would never end in practice, and its grid would lose them.
        let steps = goal.to_f64() / self.clock.dt;
        if steps > MAX_GRID_STEPS {
            return Err(SimError::new(
                self.time().to_f64(),
                format!(
                    "cannot advance to {target} in steps of {:e} s: that is {steps:.3e} steps, more than 2^53, beyond which the step grid's times k·dt are not exact",
                    self.clock.dt
                ),
            ));
        }
        while goal - self.clock.s > tolerance {
            let next = self.clock.grid(self.clock.k + 1);
            let (end, on_grid) = if next <= goal + tolerance {
                (next, true)
            } else {
                (goal, false)
            };
            self.steps_to(end, observer)?;
            if on_grid {
                self.clock.k += 1;
            }
            if self.stats.steps.is_multiple_of(PROGRESS_EVERY) {
                observer.progress(self.time());
            }
        }
        Ok(())
    }

    fn states(&self, out: &mut BallStates<T, D>) {
        let sign = self.clock.sign;
        out.reset(self.balls.len());
        out.pos
            .extend(self.balls.pos.iter().map(|p| p + self.origin));
        out.vel.extend(self.balls.vel.iter().map(|v| v * sign));
        out.spin.extend(self.balls.spin.iter().map(|w| *w * sign));
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}
