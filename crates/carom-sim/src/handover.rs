//! Handing a run over from the event-driven engine to the time-stepped one.
//!
//! `--engine auto` runs a scene on the exact event-driven engine whenever the scene can
//! start there. A scene can still come to need what that engine cannot do: balls
//! dropped under gravity settle into a pile, or, without gravity, a light ball ends up
//! pinned between heavier bodies: sustained contact that no finite sequence of exact
//! events resolves. The event engine then stops with a
//! [`SimErrorKind::SustainedContact`] error, its state consistent at that instant.
//! [`EventThenStepped`] is the engine `auto` builds: it runs the event engine, and at
//! such an error builds the time-stepped engine from the scene as it stands at that
//! instant (every ball's centre, velocity and spin; every kinematic box moved along its
//! path) and runs the rest of the time on it, its clock shifted so the run's times go
//! on. Everything before the instant is the event engine's exact run; everything after
//! is the stepped engine's (its default integrator and step, the same broad-phase
//! request). The instant and the reason are kept ([`Simulation::hand_over`]) and the
//! summary of `carom run` reports them.

use carom_math::{Real, Space};
use carom_toi::Direction;
use nalgebra::Const;

use crate::engine::{
    BallStates, Collision, Counters, EngineKind, HandOver, Observer, SimError, SimErrorKind,
    Simulation,
};
use crate::event::EventEngine;
use crate::plan::{BroadChoice, EngineChoice, Plan, RunOptions, plan};
use crate::scene::{Scene, SceneError};
use crate::stepped::SteppedEngine;

/// The event-driven engine, handing the run over to the time-stepped engine where it
/// meets sustained contact (see the module documentation).
pub struct EventThenStepped<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The scene as given, at time 0.
    scene: Scene<T, D>,
    /// The broad-phase request, which the stepped engine honours too.
    broad: BroadChoice,
    direction: Direction,
    stage: Stage<T, D>,
}

/// Which engine runs now. The event engine is dropped at the hand-over.
enum Stage<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    Event(Box<EventEngine<T, D>>),
    Stepped(Box<Shifted<T, D>>),
}

/// The stepped engine started at (signed) time `record.time`, its own clock at 0 then,
/// with what the run kept of the event engine.
struct Shifted<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    engine: SteppedEngine<T, D>,
    record: HandOver<T>,
    /// The event engine's components.
    event_pipeline: Vec<String>,
    /// The event engine's collisions before the hand-over.
    before: Counters,
}

impl<T: Real, const D: usize> EventThenStepped<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The event engine for `scene` under `plan`, running in `direction`, ready to hand
    /// over.
    ///
    /// # Errors
    /// As [`EventEngine::new`].
    pub fn new(scene: &Scene<T, D>, plan: &Plan, direction: Direction) -> Result<Self, SceneError> {
        Ok(Self {
            scene: scene.clone(),
            broad: plan.broad,
            direction,
            stage: Stage::Event(Box::new(EventEngine::new(scene, plan, direction)?)),
        })
    }

    /// Builds the stepped engine for `scene` (as given, at time 0; its broad phase
    /// `broad`, run `direction`) from `event`'s state at the instant of `error`, or gives
    /// the error back if it cannot take the run on. Not a method: the run's stage, which
    /// holds `event`, is borrowed meanwhile.
    fn switch_to_stepped(
        scene: &Scene<T, D>,
        broad: BroadChoice,
        direction: Direction,
        event: &EventEngine<T, D>,
        error: SimError,
    ) -> Result<Shifted<T, D>, SimError> {
        let start = event.time();
        let failed = |what: String| {
            SimError::new(
                start.to_f64(),
                format!(
                    "{}; handing the run over to the stepped engine failed: {what}",
                    error.message
                ),
            )
        };
        let mut states = BallStates::default();
        event.states(&mut states);
        let scene = scene_at(scene, start, &states);
        let options = RunOptions {
            engine: EngineChoice::Stepped,
            broad,
            ..RunOptions::default()
        };
        let stepped_plan = plan(&scene, &options).map_err(|e| failed(e.0))?;
        let engine = SteppedEngine::continuing(&scene, &stepped_plan, direction, &states.spin)
            .map_err(|e| failed(e.to_string()))?;
        Ok(Shifted {
            engine,
            record: HandOver {
                time: start,
                reason: error.message,
            },
            event_pipeline: event.pipeline(),
            before: event.counters(),
        })
    }
}

/// `scene` as it stands at (signed) time `t`: the balls in `states`, every box moved
/// along its path (`centre + vel · t`), everything else as given.
fn scene_at<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    t: T,
    states: &BallStates<T, D>,
) -> Scene<T, D>
where
    Const<D>: Space<T, D>,
{
    let mut at = scene.clone();
    for ((ball, pos), vel) in at.balls.iter_mut().zip(&states.pos).zip(&states.vel) {
        ball.pos = *pos;
        ball.vel = *vel;
    }
    for b in &mut at.boxes {
        b.shape = b.shape.translated(&(b.vel * t));
    }
    at
}

/// Passes the stepped engine's collisions and progress on at the run's times.
struct ShiftedObserver<'a, T: Real> {
    inner: &'a mut dyn Observer<T>,
    start: T,
}

impl<T: Real> Observer<T> for ShiftedObserver<'_, T> {
    fn collision(&mut self, collision: &Collision<T>) {
        self.inner.collision(&collision.shifted(self.start));
    }
    fn progress(&mut self, t: T) {
        self.inner.progress(t + self.start);
    }
}

impl<T: Real, const D: usize> Simulation<T, D> for EventThenStepped<T, D>
where
    Const<D>: Space<T, D>,
{
    fn kind(&self) -> EngineKind {
        match self.stage {
            Stage::Event(_) => EngineKind::Event,
            Stage::Stepped(_) => EngineKind::Stepped,
        }
    }

    /// The event engine's components, then (after a hand-over) the stepped engine's.
    fn pipeline(&self) -> Vec<String> {
        match &self.stage {
            Stage::Event(event) => event.pipeline(),
            Stage::Stepped(s) => {
                let mut p = s.event_pipeline.clone();
                p.extend(s.engine.pipeline());
                p
            }
        }
    }

    fn time(&self) -> T {
        match &self.stage {
            Stage::Event(event) => event.time(),
            Stage::Stepped(s) => s.record.time + s.engine.time(),
        }
    }

    fn advance_to(&mut self, target: T, observer: &mut dyn Observer<T>) -> Result<(), SimError> {
        if let Stage::Event(event) = &mut self.stage {
            match event.advance_to(target, observer) {
                Err(e) if e.kind == SimErrorKind::SustainedContact => {
                    let shifted =
                        Self::switch_to_stepped(&self.scene, self.broad, self.direction, event, e)?;
                    self.stage = Stage::Stepped(Box::new(shifted));
                }
                done => return done,
            }
        }
        let Stage::Stepped(s) = &mut self.stage else {
            unreachable!("handed over above")
        };
        let start = s.record.time;
        let mut shifted = ShiftedObserver {
            inner: observer,
            start,
        };
        s.engine
            .advance_to(target - start, &mut shifted)
            .map_err(|e| SimError {
                time: e.time + start.to_f64(),
                ..e
            })
    }

    fn states(&self, out: &mut BallStates<T, D>) {
        match &self.stage {
            Stage::Event(event) => event.states(out),
            Stage::Stepped(s) => s.engine.states(out),
        }
    }

    fn counters(&self) -> Counters {
        match &self.stage {
            Stage::Event(event) => event.counters(),
            Stage::Stepped(s) => {
                let after = s.engine.counters();
                Counters {
                    ball_ball: s.before.ball_ball + after.ball_ball,
                    ball_border: s.before.ball_border + after.ball_border,
                    ball_box: s.before.ball_box + after.ball_box,
                }
            }
        }
    }

    fn hand_over(&self) -> Option<&HandOver<T>> {
        match &self.stage {
            Stage::Event(_) => None,
            Stage::Stepped(s) => Some(&s.record),
        }
    }
}
