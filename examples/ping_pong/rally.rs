//! The ping-pong scene and one rally on carom's time-stepped engine.
//!
//! Numbers are the ITTF's (Handbook, Laws of Table Tennis 2.1–2.3): the playing surface
//! is 2.74 m × 1.525 m with its top 0.76 m above the floor, the net 15.25 cm high and
//! reaching 15.25 cm beyond each side line, the ball 40 mm across and 2.7 g. A ball
//! dropped from 30.5 cm must bounce to about 23 cm, so ball–table restitution is
//! `√(23/30.5) ≈ 0.87`.
//!
//! Air drag on a 40 mm ball is `F = ½ ρ C_D A v²` with `C_D ≈ 0.5` over the speeds of play
//! (flight measurements: "Aerodynamic Properties of a Table Tennis Ball", JSME, and
//! "Lift crisis of a spinning table tennis ball", which cover `2·10⁴ < Re < 9·10⁴`; the
//! same works report lift coefficients `C_L` of 0.1–0.3 for spinning balls). carom's
//! stepped engine has linear drag `F = −b v` and no Magnus field in its world forces
//! (carom-integrate has one, but the engine's scene model does not expose it), so the
//! rally uses the linear coefficient that matches the quadratic law at 6 m/s,
//! `b = ½ ρ C_D A · 6 m/s ≈ 2.3·10⁻³ kg/s`, and balls gain spin only from friction at
//! their contacts, without the Magnus force.
//!
//! The table is tilted (turned 25° about the vertical and rolled 3° about its long
//! axis): every box of the scene is an OBB at an arbitrary rotation. Balls: one served
//! from the far end that the paddle returns, and two launched towards each other from
//! both ends so that they meet above the net (the scene is mirror-symmetric about the
//! net's plane, so they meet there exactly).

use std::error::Error;

use carom::d3::Obb;
use carom::geometry::Border;
use carom::integrate::Integrator;
use carom::sim::observe::energy;
use carom::sim::plan::{EngineChoice, RunOptions, plan};
use carom::sim::scene::{BallSpec, BorderSpec, BoxSpec, Scene, World};
use carom::sim::stepped::SteppedEngine;
use carom::sim::{BallStates, Collision, Observer, Simulation};
use carom::toi::Direction;
use nalgebra::{Rotation3, Vector3};

/// Ball radius (m).
pub(crate) const BALL_RADIUS: f64 = 0.02;
/// Ball mass (kg).
pub(crate) const BALL_MASS: f64 = 0.0027;
/// Half the table's length and width, and the height of its top (m).
pub(crate) const TABLE: (f64, f64, f64) = (1.37, 0.7625, 0.76);
/// Net height (m).
pub(crate) const NET_HEIGHT: f64 = 0.1525;
/// Linear drag coefficient (kg/s), see the module documentation.
pub(crate) const DRAG: f64 =
    0.5 * 1.2 * 0.5 * std::f64::consts::PI * BALL_RADIUS * BALL_RADIUS * 6.0;
/// Where along the table (local x) the paddle meets the served ball (m).
const HIT_X: f64 = 1.55;
/// The paddle blade: half thickness, half width, half height (m).
const PADDLE: [f64; 3] = [0.006, 0.08, 0.08];
/// Radius of the paddle's swing arc (m) and its angular speed (rad/s): 3 m/s at the hit.
const SWING: (f64, f64) = (0.4, 7.5);

/// The boxes of the scene, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Part {
    /// The table top.
    Table,
    /// The net.
    Net,
    /// A side wall of the court.
    Wall,
    /// The paddle.
    Paddle,
}

/// Box `k`'s part.
pub(crate) fn part(k: usize) -> Part {
    match k {
        0 => Part::Table,
        1 => Part::Net,
        2 | 3 => Part::Wall,
        _ => Part::Paddle,
    }
}

/// The paddle's box index.
pub(crate) const PADDLE_BOX: usize = 4;

/// The table's frame: world = rotation · local + origin (origin at the top's centre).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    /// Table to world.
    pub(crate) rotation: Rotation3<f64>,
    /// The centre of the table top.
    pub(crate) origin: Vector3<f64>,
}

impl Frame {
    /// The tilted table of the example.
    pub(crate) fn tilted() -> Self {
        let yaw = Rotation3::from_axis_angle(&Vector3::z_axis(), 25f64.to_radians());
        let roll = Rotation3::from_axis_angle(&Vector3::x_axis(), 3f64.to_radians());
        Self {
            rotation: yaw * roll,
            origin: Vector3::new(0.0, 0.0, TABLE.2),
        }
    }

    /// A table-frame point in the world.
    pub(crate) fn world(&self, local: Vector3<f64>) -> Vector3<f64> {
        self.rotation * local + self.origin
    }

    /// A world point in the table frame.
    pub(crate) fn local(&self, world: &Vector3<f64>) -> Vector3<f64> {
        self.rotation.inverse() * (world - self.origin)
    }

    /// A table-frame direction in the world.
    pub(crate) fn direction(&self, local: Vector3<f64>) -> Vector3<f64> {
        self.rotation * local
    }

    fn obb(&self, centre: Vector3<f64>, half: Vector3<f64>) -> Obb {
        Obb::new(self.world(centre), half, self.rotation).expect("the scene's boxes are valid")
    }
}

/// The swing's angle past its lowest point at the hit (rad): the blade is rising, so
/// the return clears the net.
const LIFT: f64 = 0.35;

/// The paddle's scripted centre at time `t` (table frame): still until the swing, then
/// an arc of radius `SWING.0` in the table's x–z plane through the hit point at
/// `t_hit`, moving at `SWING.0 · SWING.1` m/s towards the net and upwards, then still
/// again.
pub(crate) fn paddle_local(t: f64, hit: Vector3<f64>, t_hit: f64) -> Vector3<f64> {
    let (radius, speed) = SWING;
    let arc = |phi: f64| Vector3::new(-radius * phi.sin(), 0.0, -radius * phi.cos());
    let pivot = hit - arc(LIFT);
    pivot + arc((speed * (t - t_hit) + LIFT).clamp(-1.2, 1.4))
}

/// The scene with the paddle at `paddle` (table frame), restitutions from the module
/// documentation.
pub(crate) fn scene(frame: &Frame, paddle: Vector3<f64>) -> Scene<f64, 3> {
    let (hx, hy, _) = TABLE;
    let thickness = 0.025;
    let boxes = [
        // The table top: its upper face is the table frame's z = 0.
        (
            frame.obb(
                Vector3::new(0.0, 0.0, -thickness),
                Vector3::new(hx, hy, thickness),
            ),
            0.87,
        ),
        // The net: 15.25 cm high, 15.25 cm beyond each side line, 1 cm thick.
        (
            frame.obb(
                Vector3::new(0.0, 0.0, NET_HEIGHT / 2.0),
                Vector3::new(0.005, hy + NET_HEIGHT, NET_HEIGHT / 2.0),
            ),
            0.2,
        ),
        // Side walls of the court, 1.4 m from each side line.
        (
            frame.obb(
                Vector3::new(0.0, hy + 1.4, 0.3),
                Vector3::new(2.2, 0.05, 1.0),
            ),
            0.6,
        ),
        (
            frame.obb(
                Vector3::new(0.0, -hy - 1.4, 0.3),
                Vector3::new(2.2, 0.05, 1.0),
            ),
            0.6,
        ),
        // The paddle blade, facing the net.
        (frame.obb(paddle, Vector3::from(PADDLE)), 0.85),
    ];
    let serve = |p: [f64; 3], v: [f64; 3]| {
        BallSpec::new(
            frame.world(Vector3::from(p)),
            frame.direction(Vector3::from(v)),
            BALL_RADIUS,
            BALL_MASS,
        )
    };
    Scene {
        name: Some("ping-pong".to_owned()),
        world: World {
            gravity: Vector3::new(0.0, 0.0, -9.81),
            restitution: 0.9,
            friction: 0.2,
            drag: DRAG,
            border: Some(BorderSpec {
                border: Border::new(Vector3::new(-4.0, -4.0, 0.0), Vector3::new(4.0, 4.0, 4.0))
                    .expect("the room is valid"),
                restitution: 0.7,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![
            // Served from behind the far end, bounces once on the paddle's side.
            serve([-1.45, 0.2, 0.25], [7.0, -0.25, 1.3]),
            // A symmetric pair that meets above the net.
            serve([-1.2, -0.45, 0.35], [4.0, 0.0, 2.3]),
            serve([1.2, -0.45, 0.35], [-4.0, 0.0, 2.3]),
        ],
        boxes: boxes
            .into_iter()
            .map(|(shape, restitution)| BoxSpec {
                shape,
                vel: Vector3::zeros(),
                restitution,
            })
            .collect(),
    }
}

/// What happened in a rally.
#[derive(Clone, Debug)]
pub(crate) struct Rally {
    /// The integrator.
    pub(crate) integrator: Integrator,
    /// The step (s).
    pub(crate) dt: f64,
    /// The scene at t = 0.
    pub(crate) scene: Scene<f64, 3>,
    /// The states at the end of every step, with their times (starting with t = 0).
    pub(crate) frames: Vec<(f64, BallStates<f64, 3>)>,
    /// The paddle's centre (world) at each frame.
    pub(crate) paddle: Vec<Vector3<f64>>,
    /// Collisions in time order.
    pub(crate) events: Vec<Collision<f64>>,
}

struct Log(Vec<Collision<f64>>);

impl Observer<f64> for Log {
    fn collision(&mut self, c: &Collision<f64>) {
        self.0.push(*c);
    }
}

/// The paddle's script: where it meets the served ball, and when.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Script {
    /// The hit point (table frame).
    pub(crate) hit: Vector3<f64>,
    /// The hit time (s).
    pub(crate) t_hit: f64,
}

/// Plays a rally until `until` with `integrator` at step `dt`, the paddle following
/// `script` (or parked behind the table with `None`).
///
/// # Errors
/// The engine refuses the scene or fails.
pub(crate) fn play(
    frame: &Frame,
    integrator: Integrator,
    dt: f64,
    until: f64,
    script: Option<Script>,
) -> Result<Rally, Box<dyn Error>> {
    let parked = Vector3::new(HIT_X + 0.6, 0.0, 0.5);
    let paddle_at = |t: f64| script.map_or(parked, |s| paddle_local(t, s.hit, s.t_hit));
    let scene = scene(frame, paddle_at(0.0));
    let options = RunOptions {
        engine: EngineChoice::Stepped,
        integrator: Some(integrator),
        dt: Some(dt),
        ..RunOptions::default()
    };
    let plan = plan(&scene, &options)?;
    let mut engine = SteppedEngine::new(&scene, &plan, Direction::Forward)?;
    let mut log = Log(Vec::new());
    let mut states = BallStates::default();
    engine.states(&mut states);
    let mut frames = vec![(0.0, states.clone())];
    let mut paddle = vec![frame.world(paddle_at(0.0))];
    let steps = (until / dt).round() as usize;
    for k in 0..steps {
        let (t0, t1) = (k as f64 * dt, (k + 1) as f64 * dt);
        let velocity = frame.direction(paddle_at(t1) - paddle_at(t0)) / dt;
        engine.set_box_velocity(PADDLE_BOX, velocity)?;
        engine.advance_to(t1, &mut log)?;
        engine.states(&mut states);
        frames.push((t1, states.clone()));
        paddle.push(engine.box_center(PADDLE_BOX).expect("the paddle exists"));
    }
    Ok(Rally {
        integrator,
        dt,
        scene,
        frames,
        paddle,
        events: log.0,
    })
}

/// Finds when and where the served ball (ball 0) first reaches `HIT_X` along the table
/// after bouncing on the paddle's side, in an accurate rally without the paddle.
///
/// # Errors
/// The engine fails, or the ball never gets there.
pub(crate) fn script(frame: &Frame) -> Result<Script, Box<dyn Error>> {
    let probe = play(frame, Integrator::Exact, 1.0 / 2000.0, 1.5, None)?;

    let bounced = probe
        .events
        .iter()
        .find(|c| matches!(c, Collision::BallBox { i: 0, k: 0, .. }))
        .map(Collision::time)
        .ok_or("the served ball does not reach the table")?;
    probe
        .frames
        .iter()
        .find(|(t, s)| *t > bounced && frame.local(&s.pos[0]).x >= HIT_X)
        .map(|(t, s)| {
            // Meet the ball with the blade's face, not its centre.
            let mut hit = frame.local(&s.pos[0]);
            hit.x += BALL_RADIUS + PADDLE[0];
            Script { hit, t_hit: *t }
        })
        .ok_or_else(|| "the served ball does not reach the paddle".into())
}

/// Kinetic plus potential energy of all balls at each frame.
pub(crate) fn energies(r: &Rally) -> Vec<(f64, f64)> {
    r.frames
        .iter()
        .map(|(t, s)| (*t, energy(&r.scene, s)))
        .collect()
}

/// The velocity of ball `i` along the table's length at frame `f`.
pub(crate) fn along_table(frame: &Frame, r: &Rally, f: usize, i: usize) -> f64 {
    (frame.rotation.inverse() * r.frames[f].1.vel[i]).x
}
