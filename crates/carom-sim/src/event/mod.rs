//! The exact event-driven engine: Collision Lab's continuous engine, generalised.
//!
//! Every collision is predicted exactly (carom-toi) and kept in a [`Calendar`]
//! with one pending event per ball; the engine jumps from event to event, applies the
//! response (carom-response) and re-predicts only the balls that changed. Balls are
//! advanced lazily (the `state` module); partners come from symmetric neighbour lists with a shell
//! ([`neighbours`]) or, for a handful of balls, from every pair. Nothing tunnels at any
//! speed, and positions at contact are exact (touching, not overlapping).
//!
//! Where PhET's engine has known gaps, this one does not:
//!
//! * no iteration cap that drops the rest of a step: a run either reaches its target or
//!   stops with a [`SimError`] saying why (a cascade of simultaneous events that does
//!   not end is reported, never cut silently);
//! * no linear fallback that invents collisions for slow closings (carom-toi solves the
//!   quadratic without one);
//! * a ball that starts partly outside the border is reflected back, never escapes;
//! * simultaneous and touching collisions (Newton's cradle) are processed one pair at a
//!   time in a deterministic order, which gives the textbook result;
//! * inelastic collapse and Zeno bouncing end in finite work under the guards of
//!   carom-response (the TC model and the resting guard, see [`EventEngine::new`]).
//!
//! Time runs backwards (`carom run --until -T`) by running forwards with every velocity
//! negated (gravity unchanged: `x(−s) = x₀ − v₀ s + g s²/2`) and reporting times and
//! velocities with their sign flipped.
//!
//! Positions are computed from the scene's middle ([`Scene::recentred`]) and reported
//! from its origin, so a scene far from the origin is simulated as finely as its size
//! allows; the guards that depend on what positions resolve keep the scene's own
//! scales (docs/event-engine.md, "Coordinates").

pub mod calendar;
pub mod cells;
mod cluster;
mod grid;
mod handle;
pub mod neighbours;
mod predict;
mod rows;
mod state;

use carom_geometry::{Ball, Border, Obb, Period};
use carom_math::{Real, Space, Vector};
use carom_response::{CollapseGuard, RestingGuard};
use carom_toi::Direction;
use nalgebra::Const;

use crate::engine::{BallStates, Counters, EngineKind, Observer, SimError, Simulation};
use crate::pages::Array;
use crate::plan::{BroadChoice, Plan};
use crate::prefetch::prefetch;
use crate::scene::{Inelastic, Scene, SceneError, coordinate_resolution};
use calendar::Calendar;
use cells::CellLists;
use cluster::ClusterBody;
use neighbours::{Domain, NeighbourLists};
use state::{Balls, Mode, Motion, Props, Support};

/// At most this many balls are paired by testing every pair instead of neighbour lists
/// (when `--broad auto`).
pub const ALL_PAIRS_MAX_BALLS: usize = 32;

/// How many partners a neighbour list should hold on average. The shell that gives it
/// follows from the density: dense gases get thin shells (lists of the nearest balls,
/// rebuilt often), dilute ones thick shells (a ball flies far between rebuilds). Ten
/// was the fastest of 7 to 24 in both dimensions, measured on the benchmark gases (2D
/// N = 1e5 at area fraction 0.3, 3D N = 32,000 at packing 0.45) from their lattice
/// start, and level with 13 in the relaxed 3D gas (docs/event-engine.md).
pub const LIST_PARTNERS_2D: f64 = 10.0;
/// As [`LIST_PARTNERS_2D`], in 3D.
pub const LIST_PARTNERS_3D: f64 = 10.0;

/// Cell lists are chosen (`PairSearch::Auto`) when a prediction would read at most this
/// many other balls from the cells around a ball on average; above it, neighbour lists.
pub const CELL_CANDIDATES_MAX: f64 = 12.0;

/// Consecutive events at one instant allowed per ball before the run is declared stuck
/// (a Newton's cradle of `n` balls takes `n` events at one instant), plus, with unequal
/// masses, the allowance of [`events_allowed_at_one_instant`].
const MAX_EVENTS_PER_INSTANT_PER_BALL: usize = 64;

/// How many consecutive events at one instant end a run as a cascade that does not
/// end: [`MAX_EVENTS_PER_INSTANT_PER_BALL`] per ball, plus `4 √(m_max / m_min)`.
///
/// Unequal masses make finite cascades long. A light ball `m` touching a wall and a
/// heavy ball `M` closing on it, elastic, is struck back and forth at that instant until
/// the heavy ball turns back: `⌊π √(M/m)⌋` collisions with the ball and the wall in all
/// (Galperin's billiard count, 3,141 at the mass ratio 1e6 the engine is held to). The
/// term `4 √(M/m)` covers it; with equal masses the allowance is as before. The root is
/// capped at 1e7 (mass ratios past 1e14): a cascade longer than that is reported.
fn events_allowed_at_one_instant<T: Real>(masses: impl Iterator<Item = T>) -> usize {
    let (mut n, mut lightest, mut heaviest) = (0, T::INFINITY, T::zero());
    for m in masses {
        (n, lightest, heaviest) = (n + 1, lightest.min(m), heaviest.max(m));
    }
    let ratio = if n > 0 {
        (heaviest / lightest).to_f64()
    } else {
        1.0
    };
    let unequal = (4.0 * ratio.sqrt()).ceil().min(4e7) as usize;
    MAX_EVENTS_PER_INSTANT_PER_BALL * n.max(1) + unequal
}

/// A box as the engine sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxBody<T: Real, const D: usize> {
    /// The box at internal time 0.
    pub(crate) shape: Obb<T, D>,
    /// Its velocity (internal time).
    pub(crate) vel: Vector<T, D>,
    pub(crate) restitution: T,
}

impl<T: Real, const D: usize> BoxBody<T, D> {
    /// The box at internal time `t`.
    pub(crate) fn at(&self, t: T) -> Obb<T, D> {
        if self.vel.iter().all(|x| *x == T::zero()) {
            self.shape
        } else {
            self.shape.translated(&(self.vel * t))
        }
    }
}

/// How a ball finds its possible partners.
#[derive(Clone, Debug)]
pub(crate) enum Partners<T: Real, const D: usize> {
    /// Every other ball. In a periodic box a pair is predicted with its minimum image at
    /// the time of the prediction, which stays the image the pair can meet in only while
    /// their separation changes by less than `L_min / 2 − 2 r_max`: each ball is
    /// predicted again (`Pending::Recheck`) once it has moved `roam`, a third of that,
    /// from where it was predicted (`None` without a periodic box). Since the pair's
    /// latest prediction (by one of them) that one has moved less than `roam`, the other
    /// less than `2 roam` (`roam` from its own, earlier, prediction point, which the
    /// first's prediction time lies within).
    All { roam: Option<T> },
    /// Symmetric neighbour lists with a shell.
    Lists(NeighbourLists<T, D>),
    /// The balls of the cells around the ball's, cells changed at crossing events.
    Cells(CellLists<T, D>),
}

impl<T: Real, const D: usize> Partners<T, D> {
    /// Asks for what ball `i`'s next prediction reads first (its list or its cells'
    /// rows) to be brought into the cache.
    #[inline]
    fn prefetch(&self, i: usize) {
        match self {
            Self::All { .. } => {}
            Self::Lists(lists) => lists.prefetch(i),
            Self::Cells(cells) => cells.prefetch(i),
        }
    }

    /// Calls `f` with each possible partner of ball `i` (and perhaps `i` itself): every
    /// ball with [`Partners::All`] only if `all` (a read-ahead has no use for them).
    #[inline]
    fn for_each(&self, i: usize, n: usize, all: bool, mut f: impl FnMut(usize)) {
        match self {
            Self::All { .. } => {
                if all {
                    (0..n).for_each(f);
                }
            }
            Self::Lists(lists) => lists.partners(i).for_each(|j| f(j as usize)),
            Self::Cells(cells) => cells.for_each_near(i, f),
        }
    }
}

/// How the event-driven engine finds the possible partners of a ball
/// ([`EventEngine::with_pair_search`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PairSearch {
    /// From the scene: every pair for at most [`ALL_PAIRS_MAX_BALLS`] balls (or
    /// `--broad brute`); otherwise cell lists where they read fewer candidates per
    /// prediction than a neighbour list holds, neighbour lists elsewhere.
    #[default]
    Auto,
    /// Every pair.
    AllPairs,
    /// Symmetric neighbour lists with a shell (module [`neighbours`]); a periodic box must
    /// be longer than four times a ball's reach `r_max + δ` on every axis.
    NeighbourLists,
    /// Cell lists with crossing events (module [`cells`]). They need a walled or
    /// periodic border, and a periodic box at least five cells (ten diameters) long on
    /// every axis; otherwise neighbour lists are used, or every pair in a periodic box
    /// too small for lists.
    CellLists,
}

/// What a ball's pending event is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pending {
    /// Nothing scheduled.
    None,
    /// A collision with ball `j`, valid while `j`'s collision count is `count`.
    Ball { j: u32, count: u32 },
    /// A border wall.
    Wall { axis: u8, upper: bool },
    /// Box `k`.
    Box { k: u32 },
    /// The ball leaves its neighbour-list shell: rebuild its list.
    Rebuild,
    /// The ball slides off the face it rests on.
    LeaveSupport,
    /// A contact with stuck cluster `c`, valid while the cluster's count is `count`.
    Cluster { c: u32, count: u32 },
    /// Predict again: conservative advancement proved no contact only up to this time,
    /// or (every pair in a periodic box) the ball has moved as far as the minimum images
    /// it was predicted with stay right.
    Recheck,
}

/// The exact event-driven engine. See the [module documentation](self).
pub struct EventEngine<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// `+1` forward, `−1` backward: reported time = sign · internal time.
    sign: T,
    /// Where the scene's origin is in the engine's coordinates: positions are computed
    /// from the scene's middle, finer far from the origin, and reported with this added
    /// back ([`Scene::recentred`]).
    origin: Vector<T, D>,
    gravity: Vector<T, D>,
    border: Option<Border<T, D>>,
    border_restitution: T,
    periodic: bool,
    /// The border's periods, when it is periodic.
    period: Option<Period<T, D>>,
    boxes: Vec<BoxBody<T, D>>,
    world_restitution: T,
    stick: bool,
    friction: T,
    collapse: CollapseGuard<T>,
    resting: RestingGuard<T>,
    balls: Balls<T, D>,
    clusters: Vec<ClusterBody<T, D>>,
    /// The size of the scene, for the tolerance of cluster contact searches.
    length_scale: T,
    partners: Partners<T, D>,
    /// Scratch for the partners a prediction gathers from cell lists (kept to avoid an
    /// allocation per prediction).
    gathered: Vec<u32>,
    calendar: Calendar<T>,
    pending: Array<Pending>,
    /// Internal (forward-running) time.
    now: T,
    counters: Counters,
    /// Events processed at the current instant, to detect a cascade that never ends.
    events_at_instant: usize,
    /// Events closer than this to the one before belong to the same instant
    /// ([`instant_width`]).
    instant_width: T,
    /// The last pair of balls `(i, j)`, `i < j`, found resting on each other and when
    /// (a second such collision of the pair at a later time ends the run: sustained
    /// contact).
    resting_pair: Option<((usize, usize), T)>,
    /// The last ball held where this engine cannot rest it (between two surfaces, on an
    /// edge), when, and how many times in a row (`refuse_held`).
    held: Option<(usize, T, u32)>,
    /// The free ball that last met a wall or a box under gravity, when, which, and how
    /// many such contacts it has made in a row, each with a different surface soon
    /// after the last (`handle.rs`, `refuse_wedged`).
    wedged: Option<(usize, T, handle::Surface, u32)>,
    /// The most events at one instant before a cascade is declared endless.
    events_allowed_at_one_instant: usize,
    pipeline: Vec<String>,
}

impl<T: Real, const D: usize> EventEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The engine for `scene`, running in `direction` (backward for `--until −T`).
    ///
    /// Guards (carom-response), with scales taken from the scene: the TC model with
    /// contact duration `t_c = 10⁻⁹ · r_min / v` (collisions of a ball within `t_c` of its
    /// previous one are elastic, which ends inelastic collapse and does nothing to a
    /// gas whose collision times are many orders longer), and the resting guard with
    /// minimum flight time `10⁻⁶ · √(r_min / |g|)` (a bounce whose flight would be
    /// shorter ends at rest). Here `r_min` is the smallest radius and `v` the larger of the
    /// RMS speed and `√(|g| r_min)`.
    ///
    /// # Errors
    /// The first rule the scene breaks ([`Scene::validate`]), or a scene this engine
    /// cannot run exactly: drag, stick clusters in 3D, a periodic box too small for the
    /// neighbour lists.
    pub fn new(scene: &Scene<T, D>, plan: &Plan, direction: Direction) -> Result<Self, SceneError> {
        Self::with_pair_search(scene, plan, direction, PairSearch::Auto)
    }

    /// As [`EventEngine::new`], with the way partners are found chosen by the caller
    /// (`Auto` is what `new` does). The choice changes the speed, not the physics.
    ///
    /// # Errors
    /// As [`EventEngine::new`].
    pub fn with_pair_search(
        scene: &Scene<T, D>,
        plan: &Plan,
        direction: Direction,
        search: PairSearch,
    ) -> Result<Self, SceneError> {
        scene.validate()?;
        if let Some(why) = crate::plan::event_engine_limitation(scene) {
            return Err(SceneError::new(
                "",
                format!("the event-driven engine cannot run this scene: {why}"),
            ));
        }
        // The guards' scales are the scene's own: they were tuned to what its coordinates
        // resolve as given (see `scene_amax`).
        let scale = length_scale(scene);
        let instant = instant_width(scene, scale);
        // Positions are computed from the scene's middle and reported from the origin.
        let (scene, origin) = scene.recentred();
        let scene = &scene;
        let sign = direction.sign::<T>();
        let n = scene.balls.len();
        let balls = Balls {
            motion: Array::filled(n, |i| {
                let b = &scene.balls[i];
                Motion {
                    pos: b.pos,
                    vel: b.vel * sign,
                    t_ref: T::zero(),
                    radius: b.radius,
                }
            }),
            props: Array::filled(n, |i| {
                let b = &scene.balls[i];
                Props {
                    mass: b.mass,
                    restitution: b.restitution,
                    last_collision: -T::INFINITY,
                    spin: <Const<D> as Space<T, D>>::angular_zero(),
                }
            }),
            accel: Array::filled(n, |_| scene.world.gravity),
            accelerated: scene.world.gravity != Vector::<T, D>::zeros(),
            count: Array::filled(n, |_| 0),
            mode: Array::filled(n, |_| Mode::Free),
        };
        let (border, border_restitution, periodic) = match &scene.world.border {
            Some(b) => (Some(b.border), b.restitution, b.periodic),
            None => (None, T::one(), false),
        };
        let partners = partners_for(scene, plan, search, &balls)?;
        let (collapse, resting) = guards(scene, &balls)?;
        // Stuck clusters take the calendar slots after the balls (at most n − 1 of them).
        let slots = if scene.world.inelastic == Inelastic::Stick {
            2 * n
        } else {
            n
        };
        let boxes: Vec<BoxBody<T, D>> = scene
            .boxes
            .iter()
            .map(|b| BoxBody {
                shape: b.shape,
                vel: b.vel * sign,
                restitution: b.restitution,
            })
            .collect();
        let mut engine = Self {
            sign,
            origin,
            gravity: scene.world.gravity,
            border,
            border_restitution,
            periodic,
            period: border.filter(|_| periodic).map(|b| b.period()),
            boxes,
            world_restitution: scene.world.restitution,
            stick: scene.world.inelastic == Inelastic::Stick,
            friction: scene.world.friction,
            collapse,
            resting,
            length_scale: scale,
            balls,
            clusters: Vec::new(),
            partners,
            gathered: Vec::new(),
            calendar: Calendar::sized_for(slots, T::one(), T::zero()),
            pending: Array::filled(slots, |_| Pending::None),
            now: T::zero(),
            counters: Counters::default(),
            events_at_instant: 0,
            instant_width: instant,
            resting_pair: None,
            held: None,
            wedged: None,
            events_allowed_at_one_instant: events_allowed_at_one_instant(
                scene.balls.iter().map(|b| b.mass),
            ),
            pipeline: Vec::new(),
        };
        engine.pipeline = engine.describe(scene);
        engine.schedule_all();
        Ok(engine)
    }

    /// Predicts every ball, then sizes the calendar's buckets from the predictions (the
    /// mean time to a ball's next event sets how events spread) and moves them into it.
    fn schedule_all(&mut self) {
        let n = self.balls.len();
        for i in 0..n {
            self.predict(i);
        }
        let (mut sum, mut count) = (T::zero(), 0usize);
        for i in 0..n {
            let t = self.calendar.time_of(i);
            if t.finite() {
                sum += t - self.now;
                count += 1;
            }
        }
        let horizon = if count > 0 {
            sum / T::from_count(count)
        } else {
            T::one()
        };
        let mut sized =
            Calendar::sized_for(self.pending.len(), horizon.max(T::MIN_POSITIVE), self.now);
        for i in 0..n {
            sized.schedule(i, self.calendar.time_of(i));
        }
        self.calendar = sized;
    }

    /// The components this scene uses.
    fn describe(&self, scene: &Scene<T, D>) -> Vec<String> {
        let mut p = vec!["event-driven".to_owned()];
        p.push(match &self.partners {
            Partners::All { .. } => "pairs:all".to_owned(),
            Partners::Lists(_) => "pairs:neighbour-lists(grid)".to_owned(),
            Partners::Cells(_) => "pairs:cell-lists(crossings)".to_owned(),
        });
        p.push("calendar:buckets+heap".to_owned());
        if self.balls.len() > 1 {
            p.push("toi:ball-ball".to_owned());
        }
        match (&self.border, self.periodic) {
            (Some(_), false) => p.push("toi:ball-border".to_owned()),
            (Some(_), true) => p.push("border:periodic".to_owned()),
            (None, _) => {}
        }
        if !self.boxes.is_empty() {
            p.push("toi:ball-box".to_owned());
        }
        if self.gravity.iter().any(|x| *x != T::zero()) {
            p.push("motion:ballistic".to_owned());
            p.push("guard:resting".to_owned());
        } else {
            p.push("motion:linear".to_owned());
        }
        p.push(if self.friction > T::zero() {
            "response:restitution+friction".to_owned()
        } else {
            "response:restitution".to_owned()
        });
        let inelastic_pairs = (0..scene.balls.len())
            .any(|i| scene.balls[i].restitution.unwrap_or(self.world_restitution) < T::one());
        if self.stick && inelastic_pairs {
            p.push("response:stick".to_owned());
        }
        if inelastic_pairs {
            p.push("guard:tc-model".to_owned());
        }
        p
    }

    /// The ball `i` as a shape at time `t`.
    #[inline]
    pub(crate) fn ball_at(&self, i: usize, t: T) -> Ball<T, D> {
        Ball::new_unchecked(self.balls.position_at(i, t), self.balls.motion[i].radius)
    }

    pub(crate) fn periodic_border(&self) -> Option<&Border<T, D>> {
        if self.periodic {
            self.border.as_ref()
        } else {
            None
        }
    }

    /// The separation `b − a` (minimum image in a periodic box).
    #[inline]
    pub(crate) fn separation(&self, a: &Vector<T, D>, b: &Vector<T, D>) -> Vector<T, D> {
        match &self.period {
            Some(period) => period.minimum_image(&(b - a)),
            None => b - a,
        }
    }

    /// Prefetches what the next events will read (see `crate::prefetch`): for the balls
    /// at the top of the calendar, their pending event and state, while the current
    /// event is handled (their first reads were the largest stalls in a profile; the
    /// measured gains are in `docs/event-engine.md`).
    ///
    /// With neighbour lists it also asks for the upcoming balls' lists and the states of
    /// the partners the next predictions will read. With cell lists it does not: those
    /// reads (nine cell rows per ball in 2D, and their balls) are many, and asking for
    /// them all filled the core's queue of outstanding misses, so that the prefetches
    /// themselves stalled (measured: 2D 0.62 M/s with them, 0.73 without).
    fn prefetch_upcoming(&self, current: usize) {
        let n = self.balls.len();
        let lists = matches!(self.partners, Partners::Lists(_));
        // The states of the current collision's partner's partners: predicted after the
        // current ball's (its list was asked for at the previous event).
        if lists
            && current < n
            && let Pending::Ball { j, .. } = self.pending[current]
        {
            self.partners.for_each(j as usize, n, false, |p| {
                prefetch(&self.balls.motion[p]);
            });
        }
        for b in self.calendar.upcoming(3) {
            if b >= n {
                continue;
            }
            prefetch(&self.pending[b]);
            prefetch(&self.balls.motion[b]);
            prefetch(&self.balls.props[b]);
            match &self.partners {
                Partners::Lists(lists) => lists.prefetch(b),
                Partners::Cells(cells) => cells.prefetch_place(b),
                Partners::All { .. } => {}
            }
        }
        // The next collision's partner, and the states of the next ball's partners (its
        // pending event and list were asked for at the previous event, most likely).
        if let Some(b) = self.calendar.upcoming(1).next()
            && b < n
        {
            if let Some(j) = self.due_partner(b) {
                prefetch(&self.balls.motion[j]);
                prefetch(&self.balls.props[j]);
                prefetch(&self.balls.count[j]);
                self.partners.prefetch(j);
            }
            if lists {
                self.partners.for_each(b, n, false, |p| {
                    prefetch(&self.balls.motion[p]);
                });
            }
        }
    }

    /// The partner of ball `b`'s collision, if a collision is what comes due for it next
    /// (with cell lists, a crossing may come first).
    fn due_partner(&self, b: usize) -> Option<usize> {
        match (&self.partners, self.pending[b]) {
            (Partners::Cells(cells), Pending::Ball { .. }) if cells.crossing_due(b).is_some() => {
                None
            }
            (_, Pending::Ball { j, .. }) => Some(j as usize),
            _ => None,
        }
    }

    /// `true` if ball `i` is a member of a stuck cluster. Without clusters the mode is
    /// not read: in a gas it is a cache miss at every prediction, and a ball's partners'
    /// modes one more each.
    #[inline]
    pub(crate) fn is_stuck(&self, i: usize) -> bool {
        !self.clusters.is_empty() && matches!(self.balls.mode[i], Mode::Stuck(_))
    }

    /// What ball `i` rests on, if it rests. Only gravity lets a ball rest (the resting
    /// guard decides a rest only for a ball pressed onto its support), so without it the
    /// mode is not read (a cache miss per prediction and per collision).
    #[inline]
    pub(crate) fn support_of(&self, i: usize) -> Option<Support> {
        if !self.balls.accelerated {
            return None;
        }
        match self.balls.mode[i] {
            Mode::Resting(support) => Some(support),
            _ => None,
        }
    }

    /// Calendar slot `i` named for a message: `ball i` or `cluster c` (clusters take the
    /// slots after the balls).
    fn slot_name(&self, i: usize) -> String {
        let n = self.balls.len();
        if i < n {
            format!("ball {i}")
        } else {
            format!("cluster {}", i - n)
        }
    }

    /// The largest coordinate of `x` (engine coordinates) in the scene's own
    /// coordinates: the guards that depend on what positions resolve use it, so that
    /// they hold as far as they did before the scene was moved to its middle (the
    /// arithmetic is finer there, but the scene's tolerances were tuned to what its
    /// own coordinates resolve).
    fn scene_amax(&self, x: &Vector<T, D>) -> T {
        (x + self.origin).amax()
    }

    /// The state of ball `i` now, in reported (signed) terms.
    fn reported_state(&self, i: usize) -> (Vector<T, D>, Vector<T, D>) {
        if let Mode::Stuck(c) = self.balls.mode[i] {
            let body = &self.clusters[c];
            let k = body
                .members
                .iter()
                .position(|&m| m as usize == i)
                .expect("a stuck ball is a member");
            let (p, v) = body.member_state(k, self.now);
            return (p, v.map(|x| x * self.sign + T::zero()));
        }
        let p = self.balls.position_at(i, self.now);
        let p = match self.periodic_border() {
            Some(b) => b.wrap(&p),
            None => p,
        };
        // `+ 0` turns the `−0` of a negated zero into `0`.
        (
            p,
            self.balls
                .velocity_at(i, self.now)
                .map(|x| x * self.sign + T::zero()),
        )
    }
}

impl<T: Real, const D: usize> Simulation<T, D> for EventEngine<T, D>
where
    Const<D>: Space<T, D>,
{
    fn kind(&self) -> EngineKind {
        EngineKind::Event
    }

    fn pipeline(&self) -> Vec<String> {
        self.pipeline.clone()
    }

    fn time(&self) -> T {
        self.now * self.sign
    }

    fn advance_to(&mut self, target: T, observer: &mut dyn Observer<T>) -> Result<(), SimError> {
        let target = target * self.sign;
        if target < self.now {
            return Err(SimError::new(
                (self.now * self.sign).to_f64(),
                format!(
                    "cannot advance to {} which is behind the current time",
                    (target * self.sign).to_f64()
                ),
            ));
        }
        let mut processed: u64 = 0;
        while let Some((i, t)) = self.calendar.peek() {
            if t > target {
                break;
            }
            self.calendar.pop();
            self.prefetch_upcoming(i);
            if t > self.now {
                if t - self.now > self.instant_width {
                    self.events_at_instant = 0;
                }
                self.now = t;
            }
            self.events_at_instant += 1;
            if self.events_at_instant > self.events_allowed_at_one_instant {
                let time = (self.now * self.sign).to_f64();
                let message = format!(
                    "more than {} events at one instant: a cascade of simultaneous collisions that does not end ({})",
                    self.events_allowed_at_one_instant,
                    self.slot_name(i),
                );
                // Under gravity, balls pressed together; without it, a light ball pinned
                // between heavier bodies, walls or a box. Either is sustained contact:
                // the stepped engine simulates it (fuzzed cascades without gravity that
                // end here ran 2 s on it in 0.03-0.21 s) or names the crush.
                let why = if self.balls.accelerated {
                    "under gravity this is usually balls pressed together (a stack, a pile, a wedge)"
                } else {
                    "without gravity this is usually a light ball pinned between heavier bodies, walls or a moving box"
                };
                return Err(SimError::sustained_contact(
                    time,
                    format!(
                        "{message}; {why}, sustained contact that only the stepped engine simulates (--engine auto hands the run over to it)"
                    ),
                ));
            }
            self.handle(i, observer)?;
            processed += 1;
            if processed.is_multiple_of(4096) {
                observer.progress(self.now * self.sign);
            }
        }
        self.now = target;
        Ok(())
    }

    fn states(&self, out: &mut BallStates<T, D>) {
        let n = self.balls.len();
        out.reset(n);
        for i in 0..n {
            let (p, v) = self.reported_state(i);
            out.pos.push(p + self.origin);
            out.vel.push(v);
            let spin = match self.balls.mode[i] {
                Mode::Stuck(c) => self.clusters[c].rigid.angular_velocity(),
                _ => self.balls.props[i].spin,
            };
            out.spin
                .push(spin * self.sign + <Const<D> as Space<T, D>>::angular_zero());
        }
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}

/// How close in time two events must be to count as one instant: the time the fastest
/// body of the scene takes to move by the resolution of its coordinates,
/// [`coordinate_resolution`]`(X) / V` (`X` the scene's [`length_scale`], `V` the largest
/// initial ball or box speed or the speed of a fall through `X`). Positions cannot tell
/// such events apart: a ball crushed into a corner by a kinematic box 5e4 m from the
/// origin was struck every 1e-14 s, each event a little later than the last, and the
/// run crept on forever instead of ending as the cascade it is.
fn instant_width<T: Real, const D: usize>(scene: &Scene<T, D>, length_scale: T) -> T {
    let speed = scene
        .balls
        .iter()
        .map(|b| b.vel.norm())
        .chain(scene.boxes.iter().map(|b| b.vel.norm()))
        .fold(T::zero(), T::max)
        .max((T::lit(2.0) * scene.world.gravity.norm() * length_scale).sqrt());
    let width = coordinate_resolution(length_scale) / speed;
    if width.finite() { width } else { T::zero() }
}

/// The size of a scene: the largest border extent, or the spread of the balls.
fn length_scale<T: Real, const D: usize>(scene: &Scene<T, D>) -> T {
    let spread = scene
        .balls
        .iter()
        .map(|b| b.pos.amax() + b.radius)
        .fold(T::zero(), T::max);
    let border = scene
        .world
        .border
        .map_or(T::zero(), |b| b.border.extents().amax());
    spread.max(border).max(T::MIN_POSITIVE.sqrt())
}

/// The way partners are found (see [`PairSearch`]): every pair when asked or for a
/// handful of balls; otherwise cell lists if asked or if they read few candidates (and
/// a periodic box has the cells for them), else neighbour lists if a periodic box is
/// long enough for their reach (an error if they were asked for and it is not), else
/// every pair. A periodic box must at least be longer than two diameters.
fn partners_for<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    plan: &Plan,
    search: PairSearch,
    balls: &Balls<T, D>,
) -> Result<Partners<T, D>, SceneError>
where
    Const<D>: Space<T, D>,
{
    let n = balls.len();
    let r_max = balls
        .motion
        .iter()
        .map(|m| m.radius)
        .fold(T::zero(), T::max);
    let shell = list_shell(scene, balls);
    let search = match (search, plan.broad) {
        (PairSearch::Auto, BroadChoice::Brute) => PairSearch::AllPairs,
        (PairSearch::Auto, BroadChoice::Grid) => PairSearch::Auto,
        (PairSearch::Auto, _) if n <= ALL_PAIRS_MAX_BALLS => PairSearch::AllPairs,
        (search, _) => search,
    };
    let border = scene.world.border;
    let period = border.filter(|b| b.periodic).map(|b| b.border);
    // Lists' partners are up to `2 (r_max + δ)` apart: the minimum image is theirs
    // when every period is longer than twice that.
    let lists_fit = period.is_none_or(|b| check_period(&b, (r_max + shell) * T::lit(2.0)).is_ok());
    if n >= 2 && search != PairSearch::AllPairs {
        let positions: Vec<Vector<T, D>> = balls.motion.iter().map(|m| m.pos).collect();
        if let Some(b) = border
            && search != PairSearch::NeighbourLists
        {
            let cells = CellLists::new(
                &positions,
                r_max,
                b.border.min(),
                b.border.max(),
                b.periodic,
            );
            let fewer = cells.candidates_per_prediction(n) <= T::lit(CELL_CANDIDATES_MAX);
            if cells.images_are_unique() && (search == PairSearch::CellLists || fewer) {
                return Ok(Partners::Cells(cells));
            }
        }
        if lists_fit || search == PairSearch::NeighbourLists {
            if let Some(b) = &period {
                check_period(b, (r_max + shell) * T::lit(2.0))?;
            }
            let domain = match &border {
                Some(b) if b.periodic => Domain::Periodic {
                    min: b.border.min(),
                    max: b.border.max(),
                },
                Some(b) => Domain::Bounded {
                    min: b.border.min(),
                    max: b.border.max(),
                },
                None => Domain::Unbounded,
            };
            return Ok(Partners::Lists(NeighbourLists::new(
                &positions,
                &balls.motion.iter().map(|m| m.radius).collect::<Vec<_>>(),
                shell,
                domain,
            )));
        }
    }
    // Every pair: asked for, a handful of balls, or a periodic box too small for cells
    // and lists.
    let roam = match period {
        Some(b) => {
            // Contact must be closer than half a period, with room to move.
            check_period(&b, r_max * T::lit(2.0))?;
            let half = b.extents().min() * T::lit(0.5);
            Some((half - r_max * T::lit(2.0)) / T::lit(3.0))
        }
        None => None,
    };
    Ok(Partners::All { roam })
}

/// A periodic box whose every period is longer than twice `reach` (the longest
/// separation at which two balls are tested), or the error naming the short axis.
fn check_period<T: Real, const D: usize>(
    border: &Border<T, D>,
    reach: T,
) -> Result<(), SceneError> {
    match (0..D).find(|&k| border.extents()[k] <= reach * T::lit(2.0)) {
        Some(k) => Err(SceneError::new(
            "world.border",
            format!(
                "a periodic box must be longer than {} on every axis (axis {k} is {})",
                reach * T::lit(2.0),
                border.extents()[k]
            ),
        )),
        None => Ok(()),
    }
}

/// The shell `δ` whose lists hold about [`LIST_PARTNERS_2D`] (3D: [`LIST_PARTNERS_3D`])
/// partners: anchors within `R = 2r̄ + 2δ` of a ball number `ρ c_D R^D` at number density
/// `ρ` (`c_D` the unit ball's content), so `R = (K / (ρ c_D))^(1/D)`. The density is taken
/// over the border, or the box spanned by the balls. `δ` is kept within `[r̄/4, 8 r̄]`.
fn list_shell<T: Real, const D: usize>(scene: &Scene<T, D>, balls: &Balls<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    let n = balls.len().max(1);
    let r_mean = balls.motion.iter().fold(T::zero(), |a, m| a + m.radius) / T::from_count(n);
    let r_max = balls
        .motion
        .iter()
        .map(|m| m.radius)
        .fold(T::zero(), T::max);
    let volume = scene.world.border.map_or_else(
        || {
            let (mut lo, mut hi) = (
                Vector::<T, D>::repeat(T::INFINITY),
                Vector::<T, D>::repeat(-T::INFINITY),
            );
            for m in balls.motion.iter() {
                lo = lo.inf(&m.pos);
                hi = hi.sup(&m.pos);
            }
            (hi - lo).add_scalar(T::lit(2.0) * r_max).product()
        },
        |b| b.border.extents().product(),
    );
    let (partners, unit) = if D == 2 {
        (T::lit(LIST_PARTNERS_2D), T::pi())
    } else {
        (T::lit(LIST_PARTNERS_3D), T::lit(4.0 / 3.0) * T::pi())
    };
    let density = T::from_count(n) / volume;
    let reach = (partners / (density * unit)).powf(T::one() / T::from_count(D));
    let shell = (reach - T::lit(2.0) * r_mean) * T::lit(0.5);
    let shell = shell.max(r_mean * T::lit(0.25)).min(r_mean * T::lit(8.0));
    if shell.finite() {
        shell
    } else {
        r_mean * T::lit(0.5)
    }
}

/// The collapse and resting guards with scales from the scene (see [`EventEngine::new`]).
fn guards<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    balls: &Balls<T, D>,
) -> Result<(CollapseGuard<T>, RestingGuard<T>), SceneError>
where
    Const<D>: Space<T, D>,
{
    let n = balls.len();
    let g = scene.world.gravity.norm();
    let r_min = balls
        .motion
        .iter()
        .map(|m| m.radius)
        .fold(T::INFINITY, T::min);
    let r_scale = if r_min.finite() { r_min } else { T::one() };
    let rms = if n == 0 {
        T::zero()
    } else {
        (balls
            .motion
            .iter()
            .map(|m| m.vel.norm_squared())
            .fold(T::zero(), |a, b| a + b)
            / T::from_count(n))
        .sqrt()
    };
    let v_scale = rms.max((g * r_scale).sqrt()).max(T::MIN_POSITIVE.sqrt());
    let collapse = CollapseGuard::tc_model((T::lit(1e-9) * r_scale / v_scale).max(T::MIN_POSITIVE))
        .map_err(|e| SceneError::new("", format!("collapse guard: {e}")))?;
    let flight = if g > T::zero() {
        T::lit(1e-6) * (r_scale / g).sqrt()
    } else {
        T::one()
    };
    let resting = RestingGuard::new(flight.max(T::MIN_POSITIVE))
        .map_err(|e| SceneError::new("", format!("resting guard: {e}")))?;
    Ok((collapse, resting))
}
