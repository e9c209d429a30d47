//! What every engine offers the programs that drive it.
//!
//! [`Simulation`] is the common face of the event-driven and the time-stepped engine:
//! advance to a time (reporting collisions as they happen), read the state of every
//! ball, and the counters. Drivers — `carom run`, the examples, the report — only talk
//! to this trait, so a scene runs the same way on either engine.
//!
//! Times are signed: a simulation that runs backwards (`carom run --until -T`) has
//! decreasing times, and [`Simulation::advance_to`] is called with decreasing targets.

use core::fmt;

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

/// An angular velocity: `Vector1` in 2D (the z component), `Vector3` in 3D.
pub type Angular<T, const D: usize> = <Const<D> as Space<T, D>>::Angular;

/// Which engine runs a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EngineKind {
    /// The exact event-driven engine.
    Event,
    /// The time-stepped engine.
    Stepped,
}

impl fmt::Display for EngineKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            EngineKind::Event => "event",
            EngineKind::Stepped => "stepped",
        })
    }
}

/// A collision an engine processed, at the (signed) simulation time it happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collision<T: Real> {
    /// Balls `i < j` collided.
    BallBall {
        /// When.
        time: T,
        /// The lower ball index.
        i: usize,
        /// The higher ball index.
        j: usize,
    },
    /// Ball `i` bounced off the border.
    BallBorder {
        /// When.
        time: T,
        /// The ball.
        i: usize,
    },
    /// Ball `i` bounced off box `k`.
    BallBox {
        /// When.
        time: T,
        /// The ball.
        i: usize,
        /// The box, in scene order.
        k: usize,
    },
}

impl<T: Real> Collision<T> {
    /// When the collision happened.
    pub fn time(&self) -> T {
        match *self {
            Collision::BallBall { time, .. }
            | Collision::BallBorder { time, .. }
            | Collision::BallBox { time, .. } => time,
        }
    }

    /// The same collision `by` later.
    pub fn shifted(&self, by: T) -> Self {
        match *self {
            Collision::BallBall { time, i, j } => Collision::BallBall {
                time: time + by,
                i,
                j,
            },
            Collision::BallBorder { time, i } => Collision::BallBorder { time: time + by, i },
            Collision::BallBox { time, i, k } => Collision::BallBox {
                time: time + by,
                i,
                k,
            },
        }
    }
}

/// The number of collisions of each kind so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Ball–ball collisions.
    pub ball_ball: u64,
    /// Ball–border bounces.
    pub ball_border: u64,
    /// Ball–box bounces.
    pub ball_box: u64,
}

/// The state of every ball at one time, in scene order: the centre, the velocity of the
/// centre, and the angular velocity (a ball in a stuck cluster reports its own centre,
/// its centre's velocity and the cluster's angular velocity).
#[derive(Clone, Debug, PartialEq)]
pub struct BallStates<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Centres.
    pub pos: Vec<Vector<T, D>>,
    /// Velocities.
    pub vel: Vec<Vector<T, D>>,
    /// Angular velocities.
    pub spin: Vec<Angular<T, D>>,
}

impl<T: Real, const D: usize> Default for BallStates<T, D>
where
    Const<D>: Space<T, D>,
{
    fn default() -> Self {
        Self {
            pos: Vec::new(),
            vel: Vec::new(),
            spin: Vec::new(),
        }
    }
}

impl<T: Real, const D: usize> BallStates<T, D>
where
    Const<D>: Space<T, D>,
{
    /// Clears and reserves room for `n` balls.
    pub fn reset(&mut self, n: usize) {
        self.pos.clear();
        self.vel.clear();
        self.spin.clear();
        self.pos.reserve(n);
        self.vel.reserve(n);
        self.spin.reserve(n);
    }
}

/// Receives what happens during [`Simulation::advance_to`]; both methods default to
/// doing nothing.
pub trait Observer<T: Real> {
    /// A collision was processed.
    fn collision(&mut self, collision: &Collision<T>) {
        let _ = collision;
    }
    /// The simulation has reached time `t` (called every few thousand events or steps).
    fn progress(&mut self, t: T) {
        let _ = t;
    }
}

/// An observer that ignores everything.
impl<T: Real> Observer<T> for () {}

/// A failure while running: the engine cannot go on, so the run stops.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("at t = {time}: {message}")]
pub struct SimError {
    /// The simulation time of the failure.
    pub time: f64,
    /// What went wrong.
    pub message: String,
    /// What kind of failure it is: whether another engine can take the run on.
    pub kind: SimErrorKind,
}

/// What kind of failure a [`SimError`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimErrorKind {
    /// The engine cannot continue this run (the message says why).
    Failed,
    /// Bodies came to press on each other (under gravity a stack, a pile, a wedge;
    /// without it a light ball pinned between heavier bodies, walls or a moving box):
    /// sustained contact, which no finite sequence of exact events resolves and the
    /// time-stepped engine simulates. The state at the error's time is consistent
    /// (every ball where its motion puts it, nothing overlapping), so the run can go on
    /// from it with the stepped engine ([`HandOver`](crate::HandOver)).
    SustainedContact,
}

impl SimError {
    /// A failure of kind [`SimErrorKind::Failed`] at `time`.
    pub fn new(time: f64, message: impl Into<String>) -> Self {
        Self {
            time,
            message: message.into(),
            kind: SimErrorKind::Failed,
        }
    }

    /// A failure of kind [`SimErrorKind::SustainedContact`] at `time`.
    pub fn sustained_contact(time: f64, message: impl Into<String>) -> Self {
        Self {
            time,
            message: message.into(),
            kind: SimErrorKind::SustainedContact,
        }
    }
}

/// The common face of carom's engines.
pub trait Simulation<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Which engine this is.
    fn kind(&self) -> EngineKind;

    /// The components this run uses, e.g. `["event-driven", "neighbour-lists", ...]`: what
    /// the scene does not need is not in it.
    fn pipeline(&self) -> Vec<String>;

    /// The current simulation time.
    fn time(&self) -> T;

    /// Runs until `target` (at or beyond the current time in the run's direction),
    /// passing every collision to `observer` in time order and calling its `progress`
    /// now and then. Collisions exactly at `target` are processed before returning.
    /// How a run is cut into `advance_to` calls does not change its trajectory.
    ///
    /// # Errors
    /// A [`SimError`] if the engine cannot go on; the run is then over. Only a
    /// [`SimErrorKind::SustainedContact`] leaves a state to go on from (every ball at the
    /// failure's time, nothing overlapping: what
    /// [`EventThenStepped`](crate::EventThenStepped) continues). After any other error
    /// read the states for diagnosis only: the time-stepped engine, for one, leaves the
    /// failing step half done (its clock at the step's start, balls between their
    /// integrated ends and the failure's instant, possibly overlapping).
    fn advance_to(&mut self, target: T, observer: &mut dyn Observer<T>) -> Result<(), SimError>;

    /// Writes the state of every ball at the current time into `out`.
    fn states(&self, out: &mut BallStates<T, D>);

    /// The collisions so far.
    fn counters(&self) -> Counters;

    /// When and why the run was handed over from the event engine to the stepped
    /// engine, if it was (only the engine `--engine auto` builds does,
    /// [`EventThenStepped`](crate::EventThenStepped)).
    fn hand_over(&self) -> Option<&HandOver<T>> {
        None
    }
}

/// A run handed over from the event-driven engine to the time-stepped engine.
#[derive(Clone, Debug, PartialEq)]
pub struct HandOver<T: Real> {
    /// The (signed) simulation time of the hand-over.
    pub time: T,
    /// Why the event engine could not go on (its error message).
    pub reason: String,
}
