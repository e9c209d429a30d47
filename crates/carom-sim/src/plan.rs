//! The planner: which engine and which components a scene needs.
//!
//! `carom run` lets the user force an engine, an integrator, a step or a broad phase;
//! everything left on `auto` is decided here from the scene. The rule for the engine:
//! the exact event-driven engine whenever the scene can be simulated exactly, the
//! time-stepped engine otherwise (drag; balls that start stacked on each other under
//! gravity, a sustained contact; stuck clusters in 3D, whose torque-free tumbling has no
//! closed form the event engine could use, or under gravity, against boxes or in a
//! periodic border), or when the user asks for an integrator or a step. A run `auto`
//! starts on the event engine is handed over to the stepped engine if it meets sustained
//! contact on the way ([`Plan::hand_over`]).
//! The stepped engine runs every scene the format allows. The engine then builds only the parts the scene uses and
//! names them in [`Simulation::pipeline`](crate::Simulation::pipeline).

use core::fmt;
use core::str::FromStr;

use carom_integrate::Integrator;
use carom_math::Real;

use crate::engine::EngineKind;
use crate::scene::{Inelastic, OVERLAP_TOLERANCE, Scene};

/// The `--engine` choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EngineChoice {
    /// Event-driven where the scene allows it exactly, stepped otherwise.
    #[default]
    Auto,
    /// Force the event-driven engine.
    Event,
    /// Force the time-stepped engine.
    Stepped,
}

/// The `--broad` choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BroadChoice {
    /// Chosen from the ball count and density.
    #[default]
    Auto,
    /// Every pair (the best choice for a handful of balls).
    Brute,
    /// Sweep-and-prune (stepped engine).
    Sap,
    /// k-d tree (stepped engine).
    Kd,
    /// Uniform grid (the event engine's neighbour lists live on one).
    Grid,
}

/// An unknown name for a `--engine` or `--broad` choice.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{name}`, expected one of: {expected}")]
pub struct UnknownChoice {
    what: &'static str,
    name: String,
    expected: String,
}

macro_rules! named_choice {
    ($ty:ty, $what:literal, $($variant:ident => $name:literal),+) => {
        impl $ty {
            /// The command-line name.
            pub fn name(self) -> &'static str {
                match self { $(Self::$variant => $name),+ }
            }
        }
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
        impl FromStr for $ty {
            type Err = UnknownChoice;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                match s {
                    $($name => Ok(Self::$variant),)+
                    _ => Err(UnknownChoice { what: $what, name: s.to_owned(), expected: [$($name),+].join(", ") }),
                }
            }
        }
    };
}

named_choice!(EngineChoice, "engine", Auto => "auto", Event => "event", Stepped => "stepped");
named_choice!(BroadChoice, "broad phase", Auto => "auto", Brute => "brute", Sap => "sap", Kd => "kd", Grid => "grid");

/// What the user asked for; `None` and `Auto` leave the choice to the planner.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct RunOptions {
    /// The engine.
    pub engine: EngineChoice,
    /// The stepped engine's integrator.
    pub integrator: Option<Integrator>,
    /// The stepped engine's step (s).
    pub dt: Option<f64>,
    /// The broad phase.
    pub broad: BroadChoice,
}

/// The stepped engine's default step: 1/600 s.
pub const DEFAULT_DT: f64 = 1.0 / 600.0;

/// The decisions for one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// The engine.
    pub engine: EngineKind,
    /// Why this engine (for messages and the report).
    pub reason: &'static str,
    /// The integrator (stepped engine only).
    pub integrator: Option<Integrator>,
    /// The step (stepped engine only).
    pub dt: Option<f64>,
    /// The broad-phase request, resolved further by the engine.
    pub broad: BroadChoice,
    /// The event engine was chosen by `--engine auto`: a run that meets sustained contact
    /// is handed over to the stepped engine ([`EventThenStepped`](crate::EventThenStepped))
    /// instead of ending with an error.
    pub hand_over: bool,
}

impl Plan {
    /// The event engine, as `--engine event --broad broad` plans it (no hand-over).
    pub fn event(broad: BroadChoice) -> Self {
        Self {
            engine: EngineKind::Event,
            reason: "requested with --engine event",
            integrator: None,
            dt: None,
            broad,
            hand_over: false,
        }
    }
}

/// Options that do not fit the scene or each other.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PlanError(pub String);

/// Why the event-driven engine cannot run a scene exactly, or `None` if it can.
pub fn event_engine_limitation<T: Real, const D: usize>(
    scene: &Scene<T, D>,
) -> Option<&'static str> {
    if scene.world.drag > T::zero() {
        return Some("the scene has drag, which has no exact time of impact");
    }
    if starts_pressed_together(scene) {
        return Some(
            "balls start pressed together under gravity (a stack or a pile: sustained contact, which no finite sequence of exact events resolves)",
        );
    }
    if can_stick(scene) {
        if D == 3 {
            return Some(
                "stuck clusters tumble in 3D (torque-free precession), which has no closed form",
            );
        }
        if scene.world.gravity.iter().any(|g| *g != T::zero()) {
            return Some(
                "stuck clusters under gravity would need resting rigid bodies, which the event engine does not model",
            );
        }
        if !scene.boxes.is_empty() {
            return Some("stuck clusters against boxes have no exact contact search in carom-toi");
        }
        if scene.world.border.is_some_and(|b| b.periodic) {
            return Some("stuck clusters in a periodic box are not supported by the event engine");
        }
    }
    None
}

/// Whether two balls of `scene` start touching (within the scene format's overlap
/// tolerance) along a line that gravity does not cross at right angles: one rests on
/// the other, and the event engine would meet that contact again and again at one
/// instant. (Balls touching side by side, level under gravity, do not press.)
pub fn starts_pressed_together<T: Real, const D: usize>(scene: &Scene<T, D>) -> bool {
    let g = scene.world.gravity;
    let g_norm = g.norm();
    if g_norm == T::zero() {
        return false;
    }
    let tol = T::lit(OVERLAP_TOLERANCE);
    scene
        .find_near_pair(|_, _, offset, gap| {
            // |cos| of the angle between the line of centres and gravity: level pairs
            // (to 1e-6 rad) are not pressed.
            let pressed =
                gap <= tol && offset.dot(&g).abs() > T::lit(1e-6) * offset.norm() * g_norm;
            pressed.then_some(())
        })
        .is_some()
}

/// Whether two balls of `scene` can stick: `inelastic = "stick"` and some ball's
/// restitution (its override, or the world's) is 0, so every pair with it has
/// restitution 0.
pub fn can_stick<T: Real, const D: usize>(scene: &Scene<T, D>) -> bool {
    scene.world.inelastic == Inelastic::Stick
        && scene
            .balls
            .iter()
            .any(|b| b.restitution.unwrap_or(scene.world.restitution) == T::zero())
}

/// Below this many balls the stepped engine's automatic broad phase tests every pair.
pub const STEPPED_BRUTE_FORCE_BELOW: usize = 64;

/// The broad phase the stepped engine builds for `scene` when asked for `choice`.
///
/// `Auto` resolves to: every pair (brute force) below [`STEPPED_BRUTE_FORCE_BELOW`]
/// balls; a uniform grid in a periodic border (the only structure besides brute force
/// that wraps around); sweep-and-prune when ball radii span more than a factor 8 (a grid
/// sized for the median ball sends every large ball down its slow oversized path);
/// a uniform grid otherwise. The stepped engine enters each ball as the box it can reach
/// within a step, so fast balls are large volumes too; the grid handles a few of them on
/// its oversized path.
///
/// # Errors
/// `--broad sap` and `--broad kd` in a periodic border (they have no periodic mode).
pub fn stepped_broad_phase<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    choice: BroadChoice,
) -> Result<BroadChoice, PlanError> {
    let periodic = scene.world.border.as_ref().is_some_and(|b| b.periodic);
    match choice {
        BroadChoice::Sap | BroadChoice::Kd if periodic => Err(PlanError(format!(
            "--broad {choice}: the scene has a periodic border, which only --broad grid and --broad brute handle"
        ))),
        BroadChoice::Auto => {
            let n = scene.balls.len();
            let (lo, hi) = scene
                .balls
                .iter()
                .fold((T::INFINITY, T::zero()), |(lo, hi), b| {
                    (lo.min(b.radius), hi.max(b.radius))
                });
            Ok(if n < STEPPED_BRUTE_FORCE_BELOW {
                BroadChoice::Brute
            } else if !periodic && hi > T::lit(8.0) * lo {
                BroadChoice::Sap
            } else {
                BroadChoice::Grid
            })
        }
        other => Ok(other),
    }
}

/// Why `integrator` with step `dt` cannot integrate the scene's drag, if it cannot: on
/// the lightest ball, drag decays at `k = drag/mass`, and beyond the scheme's
/// [`Integrator::drag_step_limit`] in `k dt` a step turns the ball back or speeds it up
/// instead (a milligram ball under `drag = 0.2` at the default step: `k dt = 333`, its
/// speed times −332 per step with semi-implicit Euler; at `k dt = 1.88` the same scheme
/// turned light balls back every step and their collisions pumped a 1,000 kg ball to
/// 3e19 m/s).
fn drag_instability<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    integrator: Integrator,
    dt: f64,
) -> Option<String> {
    let drag = scene.world.drag.to_f64();
    let (i, lightest) = (scene.balls.iter().map(|b| b.mass.to_f64()).enumerate())
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let (kh, limit) = (drag / lightest * dt, integrator.drag_step_limit());
    (drag > 0.0 && kh > limit).then(|| {
        format!(
            "--dt: {dt} s is too long for --integrator {integrator} under world.drag = {drag}: on balls[{i}] (mass {lightest} kg) drag/mass x dt = {kh:.4} exceeds the scheme's limit {limit:.4}, beyond which a step turns the ball back or speeds it up; use a step below {:.3e} s or --integrator exact",
            limit * lightest / drag
        )
    })
}

/// Decides the engine and its options for `scene`.
///
/// # Errors
/// A [`PlanError`] naming the flag when the options cannot work for this scene: the
/// event engine forced on a scene it cannot simulate exactly, an integrator or a step
/// with the event engine, a non-positive step, a step too long for the integrator under
/// the scene's drag (see `drag_instability`; without `--integrator`, the exact one is
/// chosen there instead), a broad phase the engine does not have.
pub fn plan<T: Real, const D: usize>(
    scene: &Scene<T, D>,
    options: &RunOptions,
) -> Result<Plan, PlanError> {
    let stepped_asked = options.integrator.is_some() || options.dt.is_some();
    let limitation = event_engine_limitation(scene);
    let (engine, reason) = match options.engine {
        EngineChoice::Event => {
            if let Some(why) = limitation {
                return Err(PlanError(format!(
                    "--engine event: {why}; use --engine stepped (or auto)"
                )));
            }
            if stepped_asked {
                return Err(PlanError(
                    "--integrator and --dt apply to the stepped engine; the event engine is exact and has no step".into(),
                ));
            }
            (EngineKind::Event, "requested with --engine event")
        }
        EngineChoice::Stepped => (EngineKind::Stepped, "requested with --engine stepped"),
        EngineChoice::Auto => match (limitation, stepped_asked) {
            (Some(why), _) => (EngineKind::Stepped, why),
            (None, true) => (EngineKind::Stepped, "an integrator or a step was requested"),
            (None, false) => (EngineKind::Event, "the scene can be simulated exactly"),
        },
    };
    if let Some(dt) = options.dt
        && !(dt.is_finite() && dt > 0.0)
    {
        return Err(PlanError(format!(
            "--dt: must be a finite step > 0, got {dt}"
        )));
    }
    if engine == EngineKind::Stepped {
        stepped_broad_phase(scene, options.broad)?;
    }
    if engine == EngineKind::Event && matches!(options.broad, BroadChoice::Sap | BroadChoice::Kd) {
        return Err(PlanError(format!(
            "--broad {}: the event engine finds partners with neighbour lists on a grid (--broad grid) or tests every pair (--broad brute)",
            options.broad
        )));
    }
    let (integrator, dt) = match engine {
        EngineKind::Event => (None, None),
        EngineKind::Stepped => {
            let dt = options.dt.unwrap_or(DEFAULT_DT);
            let integrator = match options.integrator {
                Some(integrator) => {
                    if let Some(why) = drag_instability(scene, integrator, dt) {
                        return Err(PlanError(why));
                    }
                    integrator
                }
                // The default scheme where drag lets it decay, the exact one where not.
                None if drag_instability(scene, Integrator::SemiImplicitEuler, dt).is_some() => {
                    Integrator::Exact
                }
                None => Integrator::SemiImplicitEuler,
            };
            (Some(integrator), Some(dt))
        }
    };
    Ok(Plan {
        engine,
        reason,
        integrator,
        dt,
        broad: options.broad,
        hand_over: engine == EngineKind::Event && options.engine == EngineChoice::Auto,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::classic;
    use nalgebra::Vector2;

    #[test]
    fn auto_picks_the_exact_engine_unless_the_scene_or_the_user_needs_steps() {
        let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
        let auto = plan(&s, &RunOptions::default()).unwrap();
        assert_eq!((auto.engine, auto.hand_over), (EngineKind::Event, true));
        let forced = RunOptions {
            engine: EngineChoice::Event,
            ..RunOptions::default()
        };
        assert_eq!(plan(&s, &forced).unwrap(), Plan::event(BroadChoice::Auto));
        let rk4 = RunOptions {
            integrator: Some(Integrator::Rk4),
            ..RunOptions::default()
        };
        let p = plan(&s, &rk4).unwrap();
        assert_eq!(
            (p.engine, p.integrator, p.dt),
            (EngineKind::Stepped, Some(Integrator::Rk4), Some(DEFAULT_DT))
        );
        s.world.drag = 0.1;
        let p = plan(&s, &RunOptions::default()).unwrap();
        assert_eq!(p.engine, EngineKind::Stepped);
        assert_eq!(p.integrator, Some(Integrator::SemiImplicitEuler));
    }

    #[test]
    fn balls_stacked_under_gravity_go_to_the_stepped_engine_and_level_ones_do_not() {
        // Two touching balls: ball 1 at angle θ from ball 0, gravity straight down.
        let pair = |angle: f64, gap: f64| {
            let mut s = classic::head_on(1.0, 1.0, 0.0, 0.0, 1.0);
            let d = 2.0 * s.balls[0].radius + gap;
            s.balls[1].pos = s.balls[0].pos + Vector2::new(angle.cos(), angle.sin()) * d;
            s.world.gravity = Vector2::new(0.0, -9.81);
            s
        };
        let auto = RunOptions::default();
        let stacked = plan(&pair(1.2, 0.0), &auto).unwrap();
        assert_eq!(stacked.engine, EngineKind::Stepped);
        assert!(
            stacked.reason.contains("pressed together"),
            "{}",
            stacked.reason
        );
        // Within the overlap the format allows, and 5e-10 m apart: still pressed.
        assert_eq!(
            plan(&pair(0.3, -1e-9), &auto).unwrap().engine,
            EngineKind::Stepped
        );
        assert_eq!(
            plan(&pair(0.3, 5e-10), &auto).unwrap().engine,
            EngineKind::Stepped
        );
        // Level, or a hair more than the tolerance apart, or without gravity: exact.
        assert_eq!(
            plan(&pair(0.0, 0.0), &auto).unwrap().engine,
            EngineKind::Event
        );
        assert_eq!(
            plan(&pair(0.3, 1e-8), &auto).unwrap().engine,
            EngineKind::Event
        );
        let mut weightless = pair(1.2, 0.0);
        weightless.world.gravity = Vector2::zeros();
        assert_eq!(plan(&weightless, &auto).unwrap().engine, EngineKind::Event);
        let forced = RunOptions {
            engine: EngineChoice::Event,
            ..RunOptions::default()
        };
        let e = plan(&pair(1.2, 0.0), &forced).unwrap_err();
        assert!(
            e.0.starts_with("--engine event: balls start pressed together"),
            "{e}"
        );
    }

    #[test]
    fn a_step_too_long_for_the_drag_on_the_lightest_ball_is_refused_or_integrated_exactly() {
        // Ball 1 weighs a gram: k = drag/m = 200 /s, so k dt = 1 at dt = 1/200 s, the
        // limit of the Euler schemes (beyond it their step turns the ball back), and 2
        // at dt = 1/100 s, Verlet's (RK4: 2.785).
        let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
        s.balls[1].mass = 1e-3;
        s.world.drag = 0.2;
        let with = |integrator: Option<Integrator>, dt: f64| RunOptions {
            integrator,
            dt: Some(dt),
            ..RunOptions::default()
        };
        for euler in [Integrator::ExplicitEuler, Integrator::SemiImplicitEuler] {
            let e = plan(&s, &with(Some(euler), 0.00505)).unwrap_err();
            assert!(
                e.0.starts_with("--dt") && e.0.contains("balls[1]") && e.0.contains("world.drag"),
                "{e}"
            );
            assert!(plan(&s, &with(Some(euler), 0.00495)).is_ok());
        }
        assert!(plan(&s, &with(Some(Integrator::VelocityVerlet), 0.0099)).is_ok());
        assert!(plan(&s, &with(Some(Integrator::VelocityVerlet), 0.0101)).is_err());
        assert!(plan(&s, &with(Some(Integrator::Rk4), 0.0101)).is_ok());
        assert!(plan(&s, &with(Some(Integrator::Rk4), 0.014)).is_err());
        assert!(plan(&s, &with(Some(Integrator::Exact), 100.0)).is_ok());
        // Without --integrator the exact one takes over where the default would turn the
        // ball back.
        let p = plan(&s, &with(None, 0.00505)).unwrap();
        assert_eq!(p.integrator, Some(Integrator::Exact));
        let p = plan(&s, &with(None, 0.00495)).unwrap();
        assert_eq!(p.integrator, Some(Integrator::SemiImplicitEuler));
    }

    #[test]
    fn impossible_requests_name_the_flag() {
        let mut s = classic::head_on(1.0, 1.0, 1.0, -1.0, 1.0);
        let event = RunOptions {
            engine: EngineChoice::Event,
            ..RunOptions::default()
        };
        let e = plan(
            &s,
            &RunOptions {
                dt: Some(0.01),
                ..event
            },
        )
        .unwrap_err();
        assert!(e.0.starts_with("--integrator and --dt"), "{e}");
        let e = plan(
            &s,
            &RunOptions {
                broad: BroadChoice::Kd,
                ..event
            },
        )
        .unwrap_err();
        assert!(e.0.starts_with("--broad kd"), "{e}");
        let e = plan(
            &s,
            &RunOptions {
                dt: Some(-1.0),
                ..RunOptions::default()
            },
        )
        .unwrap_err();
        assert!(e.0.starts_with("--dt"), "{e}");
        s.world.drag = 1.0;
        assert!(plan(&s, &event).unwrap_err().0.contains("drag"));
    }

    #[test]
    fn choices_parse_their_command_line_names() {
        assert_eq!("stepped".parse::<EngineChoice>(), Ok(EngineChoice::Stepped));
        assert_eq!("kd".parse::<BroadChoice>(), Ok(BroadChoice::Kd));
        let e = "fast".parse::<EngineChoice>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown engine `fast`, expected one of: auto, event, stepped"
        );
    }
}
