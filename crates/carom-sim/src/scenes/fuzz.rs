//! Reproducible random scenes for robustness campaigns ("fuzzing"), and the invariants
//! every run of one must keep.
//!
//! [`scene_text`] draws scene `k` of a campaign from its seed as scene-file text (so a
//! scene that fails can be saved and rerun with `carom run`): 2D (three in four) and 3D;
//! 2 to 40 balls; reflecting or periodic borders; static and moving boxes, rotated or
//! not; coordinates near 0, 1e3 or −5e4 m; half the scenes on a grid `f32` holds exactly,
//! with balls touching each other and the walls; masses over twelve decades; speeds from
//! rest to 1e6 m/s; restitution 0 to 1 (per-ball overrides, sticking); friction, drag and
//! gravity. A draw is a deterministic function of the seed and `k` (the [`SplitMix64`]
//! stream), so a campaign is the same on every machine and at every commit.
//!
//! [`Invariants`] measures, in one sample of a run, what the engines promise: finite
//! states, how far a ball reaches into another ball (minimum image in a periodic border),
//! into a box at its place at that time or out of a reflecting border, and how far the
//! energy rose above its start (in a periodic border under gravity, with each ball
//! followed through the walls: its wrapped height would show energy appear from nothing
//! at every wrap). The `stepped_fuzz` example runs campaigns with them;
//! `tests/stepped_fuzz.rs` runs a small one in CI.

use std::fmt::Write as _;

use carom_geometry::query::signed_distance;
use carom_geometry::{Ball, Obb};
use carom_math::{Real, Space, Vector};
use nalgebra::{Const, Rotation};

use super::SplitMix64;
use crate::engine::BallStates;
use crate::observe::energy;
use crate::scene::{Scene, parse_scene};

/// What one sample of a run shows (lengths in metres).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Every coordinate of every position and velocity is finite.
    pub finite: bool,
    /// The largest overlap of two balls (negative: the smallest gap).
    pub ball_overlap: f64,
    /// The largest overlap of a ball and a box (negative: the smallest gap).
    pub box_overlap: f64,
    /// The largest reach of a ball out of a reflecting border (negative: inside).
    pub border_out: f64,
    /// The energy's rise above its start beyond [`Invariants`]' allowance, over the
    /// scene's energy scale; `None` for a scene with a moving box (which feeds energy in),
    /// and in a periodic border under gravity once a ball may have moved too far between
    /// samples to be followed through the walls.
    pub energy_rise: Option<f64>,
}

impl Sample {
    /// The largest of the three excursions.
    pub fn worst(&self) -> f64 {
        self.ball_overlap.max(self.box_overlap).max(self.border_out)
    }
}

/// What the checks need of a scene, worked out once from it and its start.
#[derive(Clone, Debug)]
pub struct Invariants<const D: usize>
where
    Const<D>: Space<f64, D>,
{
    /// The balls' radii, the boxes at time 0 with their velocities, and the border's
    /// corners and periods (when periodic), widened to `f64`, where the checks measure.
    radius: Vec<f64>,
    boxes: Vec<(Obb<f64, D>, Vector<f64, D>)>,
    border: Option<(Vector<f64, D>, Vector<f64, D>, bool)>,
    resolution: f64,
    mass: f64,
    gravity: f64,
    energy_scale: f64,
    start_energy: Option<f64>,
    /// In a periodic border under gravity, where the balls are in the unbounded space
    /// (the energy's potential term needs the height a ball has fallen, not its wrapped
    /// place).
    unwrap: Option<Unwrap<D>>,
}

/// Follows the balls of a periodic border through its walls from sample to sample.
///
/// A ball's displacement between two samples is taken as the minimum image of the
/// difference of its wrapped places. That is its true displacement while it moves less
/// than half a period between samples; the check assumes so only while every ball's
/// reach, `(max(|v|, |v'|) + |g| Δt) Δt` from the velocities at both samples, is under a
/// quarter of the narrowest period, and gives up the energy check for the rest of the
/// run otherwise.
#[derive(Clone, Debug)]
struct Unwrap<const D: usize>
where
    Const<D>: Space<f64, D>,
{
    period: Vector<f64, D>,
    gravity: Vector<f64, D>,
    mass: Vec<f64>,
    /// The previous sample's time, wrapped places and speeds.
    t: f64,
    last: Vec<Vector<f64, D>>,
    speed: Vec<f64>,
    /// Unwrapped minus wrapped place of each ball: whole periods.
    shift: Vec<Vector<f64, D>>,
}

impl<const D: usize> Invariants<D>
where
    Const<D>: Space<f64, D>,
{
    /// The invariants of `scene`, whose states at the start are `start`.
    pub fn new<T: Real>(scene: &Scene<T, D>, start: &BallStates<T, D>) -> Self
    where
        Const<D>: Space<T, D>,
    {
        let wide = |v: &Vector<T, D>| v.map(T::to_f64);
        // Widened exactly, and not checked again: an `f32` rotation is orthonormal only
        // to `f32`'s precision, which `Obb::new` in `f64` would refuse.
        let boxes = (scene.boxes.iter())
            .map(|b| {
                let rotation =
                    Rotation::from_matrix_unchecked(b.shape.rotation().matrix().map(T::to_f64));
                let shape = Obb::new_unchecked(
                    wide(&b.shape.center()),
                    wide(&b.shape.half_extents()),
                    rotation,
                );
                (shape, wide(&b.vel))
            })
            .collect();
        let mut largest = 1.0_f64;
        for b in &scene.balls {
            largest = b.pos.iter().fold(largest, |m, x| m.max(x.to_f64().abs()));
        }
        if let Some(border) = &scene.world.border {
            let (lo, hi) = (border.border.min(), border.border.max());
            largest = (lo.iter().chain(hi.iter())).fold(largest, |m, x| m.max(x.to_f64().abs()));
        }
        let mass: f64 = scene.balls.iter().map(|b| b.mass.to_f64()).sum();
        let speed_energy: f64 = (scene.balls.iter())
            .map(|b| 0.5 * b.mass.to_f64() * b.vel.norm_squared().to_f64())
            .sum();
        let g = scene.world.gravity.norm().to_f64();
        let extent = scene.world.border.as_ref().map_or(1.0, |b| {
            (b.border.extents().iter()).fold(0.0_f64, |m, x| m.max(x.to_f64()))
        });
        let moving_box = scene.boxes.iter().any(|b| b.vel.norm_squared() > T::zero());
        let unwrap = match &scene.world.border {
            Some(b) if b.periodic && g > 0.0 && !moving_box => Some(Unwrap {
                period: wide(&b.border.extents()),
                gravity: wide(&scene.world.gravity),
                mass: scene.balls.iter().map(|b| b.mass.to_f64()).collect(),
                t: 0.0,
                last: start.pos.iter().map(wide).collect(),
                speed: start.vel.iter().map(|v| wide(v).norm()).collect(),
                shift: vec![Vector::zeros(); start.pos.len()],
            }),
            _ => None,
        };
        Self {
            radius: scene.balls.iter().map(|b| b.radius.to_f64()).collect(),
            boxes,
            border: (scene.world.border.as_ref())
                .map(|b| (wide(&b.border.min()), wide(&b.border.max()), b.periodic)),
            resolution: T::EPSILON.to_f64() * largest,
            mass,
            gravity: g,
            // Kinetic energy plus the potential energy over the border's height: the scale
            // a relative rise is measured against (the start's total may be near zero).
            energy_scale: (speed_energy + mass * g * extent).max(f64::MIN_POSITIVE),
            start_energy: (!moving_box).then(|| energy(scene, start).to_f64()),
            unwrap,
        }
    }

    /// The precision's resolution at the scene's largest coordinate, `ε · max|x|` (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The checks of the states at time `t` of a run with steps of `dt` (0 for the
    /// event-driven engine), the samples taken in time order. The energy may rise by
    /// `Σm |g|² dt t`, a first-order scheme's truncation under gravity (explicit Euler
    /// gains `m g² dt²/2` per step in free flight), plus `Σm |g| ε max|x|`, the rounding
    /// of the states' positions along gravity (the engine computes from the scene's
    /// middle and hands positions back rounded to the precision at their place: 5e4 m
    /// out in `f32`, 3.9e-3 m).
    pub fn sample<T: Real>(
        &mut self,
        scene: &Scene<T, D>,
        states: &BallStates<T, D>,
        t: f64,
        dt: f64,
    ) -> Sample
    where
        Const<D>: Space<T, D>,
    {
        let wide = |v: &Vector<T, D>| v.map(T::to_f64);
        let mut sample = Sample {
            finite: (states.pos.iter().chain(&states.vel)).all(|v| v.iter().all(|x| x.finite())),
            ball_overlap: f64::NEG_INFINITY,
            box_overlap: f64::NEG_INFINITY,
            border_out: f64::NEG_INFINITY,
            energy_rise: None,
        };
        if !sample.finite {
            return sample;
        }
        let periodic = (self.border.filter(|b| b.2)).map(|(lo, hi, _)| hi - lo);
        let image = |mut d: Vector<f64, D>| {
            if let Some(l) = &periodic {
                for (x, l) in d.iter_mut().zip(l.iter()) {
                    *x -= l * (*x / l).round();
                }
            }
            d
        };
        for (i, (x, &r)) in states.pos.iter().zip(&self.radius).enumerate() {
            let x = wide(x);
            for (y, &q) in states.pos.iter().zip(&self.radius).skip(i + 1) {
                let d = image(wide(y) - x).norm();
                sample.ball_overlap = sample.ball_overlap.max(r + q - d);
            }
            if let Some((lo, hi, false)) = &self.border {
                for k in 0..D {
                    let out = (lo[k] - (x[k] - r)).max(x[k] + r - hi[k]);
                    sample.border_out = sample.border_out.max(out);
                }
            }
            for (shape, vel) in &self.boxes {
                // The box at time `t`, in its periodic image nearest the ball.
                let centre = shape.center() + vel * t;
                let at = shape.translated(&(x - centre - image(x - centre) + vel * t));
                let depth = -signed_distance(&Ball::new_unchecked(x, r), &at);
                sample.box_overlap = sample.box_overlap.max(depth);
            }
        }
        let hidden = match &mut self.unwrap {
            None => Some(0.0),
            Some(unwrap) => unwrap.follow(states, t),
        };
        if hidden.is_none() {
            self.start_energy = None;
        }
        sample.energy_rise = self.start_energy.zip(hidden).map(|(start, hidden)| {
            let g = self.gravity;
            let allowed = self.mass * g * (g * dt * t + self.resolution);
            (energy(scene, states).to_f64() + hidden - start - allowed) / self.energy_scale
        });
        sample
    }
}

impl<const D: usize> Unwrap<D>
where
    Const<D>: Space<f64, D>,
{
    /// Follows the balls to the sample `states` at `t`, and returns the potential energy
    /// their wrapping hides, `−Σ m g·shift` (what the energy of the wrapped places lacks),
    /// or `None` if a ball may have moved too far since the last sample to follow.
    fn follow<T: Real>(&mut self, states: &BallStates<T, D>, t: f64) -> Option<f64>
    where
        Const<D>: Space<T, D>,
    {
        let dt = t - self.t;
        let narrowest = self.period.min();
        let mut hidden = 0.0;
        for (i, (x, v)) in states.pos.iter().zip(&states.vel).enumerate() {
            let (x, speed) = (x.map(T::to_f64), v.map(T::to_f64).norm());
            let reach = (speed.max(self.speed[i]) + self.gravity.norm() * dt) * dt;
            if reach >= 0.25 * narrowest {
                return None;
            }
            let moved = x - self.last[i];
            let mut through = Vector::<f64, D>::zeros();
            for k in 0..D {
                // Whole periods between the wrapped and the true displacement.
                through[k] = self.period[k] * (moved[k] / self.period[k]).round();
            }
            self.shift[i] -= through;
            self.last[i] = x;
            self.speed[i] = speed;
            hidden -= self.mass[i] * self.gravity.dot(&self.shift[i]);
        }
        self.t = t;
        Some(hidden)
    }
}

/// The kind of a run's failure, from its message: `crush` (a ball held against more
/// contacts at one instant than the engine takes), `spin` (a cluster spinning too fast
/// for the step), `moves-at` (a speed the periodic window cannot follow), `overflow` (a
/// time of impact out of the precision's range), `drag-refusal` (the planner's refusal
/// of a step too long for the scene's drag), or `None` for a failure the engines do not
/// name.
pub fn failure_kind(message: &str) -> Option<&'static str> {
    const KINDS: [(&str, &str); 4] = [
        ("is crushed", "crush"),
        ("spins at", "spin"),
        (" moves at ", "moves-at"),
        ("overflowed", "overflow"),
    ];
    if message.starts_with("--dt") && message.contains("world.drag") {
        return Some("drag-refusal");
    }
    KINDS
        .iter()
        .find(|(needle, _)| message.contains(needle))
        .map(|&(_, kind)| kind)
}

/// Scene `k` of the campaign `seed`, as scene-file text: retried with the next draw of
/// its own stream until it is a valid scene in `f64` (the generator places bodies apart
/// to its own tolerance; the loader decides).
pub fn scene_text(seed: u64, k: usize) -> String {
    let mut rng = SplitMix64::new(seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    loop {
        let text = if rng.next_f64() < 0.75 {
            draw::<2>(&mut rng, k)
        } else {
            draw::<3>(&mut rng, k)
        };
        if parse_scene(&text).is_ok() {
            return text;
        }
    }
}

/// A float as the scene file writes it (Rust's shortest round-trip form, with an exponent
/// where it is shorter: TOML reads both).
fn num(x: f64) -> String {
    format!("{x:?}")
}

fn vector<const D: usize>(v: &[f64; D]) -> String {
    let parts: Vec<String> = v.iter().map(|&x| num(x)).collect();
    format!("[{}]", parts.join(", "))
}

/// Log-uniform in `[lo, hi]`.
fn log_uniform(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    (rng.range(lo.ln(), hi.ln())).exp()
}

/// Where a scene's bodies may go: its border and the grid it snaps to.
struct Frame<const D: usize> {
    origin: f64,
    half: f64,
    periodic: bool,
    /// The unit coordinates are rounded to (`None`: not rounded).
    grid: Option<f64>,
}

impl<const D: usize> Frame<D> {
    fn snap(&self, x: f64) -> f64 {
        self.grid.map_or(x, |q| (x / q).round() * q)
    }

    /// A point whose ball of `margin` fits inside the border, snapped to the grid.
    fn point(&self, rng: &mut SplitMix64, margin: f64) -> [f64; D] {
        std::array::from_fn(|_| {
            self.snap(self.origin + rng.range(-1.0, 1.0) * (self.half - margin).max(0.0))
        })
    }

    /// The distance between two points (the minimum image in a periodic border).
    fn distance(&self, p: &[f64; D], q: &[f64; D]) -> f64 {
        let period = 2.0 * self.half;
        (0..D)
            .map(|a| {
                let d = p[a] - q[a];
                let d = if self.periodic {
                    d - period * (d / period).round()
                } else {
                    d
                };
                d * d
            })
            .sum::<f64>()
            .sqrt()
    }
}

/// One draw of a `D`-dimensional scene.
fn draw<const D: usize>(rng: &mut SplitMix64, k: usize) -> String {
    let origin = match rng.next_f64() {
        u if u < 0.5 => 0.0,
        u if u < 0.8 => 1e3,
        _ => -5e4,
    };
    // Half the scenes on a grid f32 holds exactly at their coordinates (its unit is at
    // least 4 f32 ulps there), so that contacts touching in the file touch in f32 too.
    let grid = (rng.next_f64() < 0.5).then_some(if origin == -5e4 {
        0.015_625
    } else {
        1.0 / 1024.0
    });
    let frame = Frame::<D> {
        origin,
        half: [1.0, 2.0, 4.0][(rng.next_f64() * 3.0) as usize],
        periodic: rng.next_f64() < 0.2,
        grid,
    };
    let mut text = world(rng, k, &frame);
    let boxes = boxes(rng, &frame, &mut text);
    balls(rng, &frame, &boxes, &mut text);
    text
}

/// The scene's header and `[world]` tables.
fn world<const D: usize>(rng: &mut SplitMix64, k: usize, frame: &Frame<D>) -> String {
    let mut text = String::new();
    let _ = writeln!(
        text,
        "dim = {D}\nname = \"stepped-fuzz-s{k:02}\"\n\n[world]"
    );
    let restitution = match rng.next_f64() {
        u if u < 0.3 => 1.0,
        u if u < 0.5 => 0.0,
        _ => frame.snap(rng.next_f64()),
    };
    let _ = writeln!(text, "restitution = {}", num(restitution));
    if restitution == 0.0 && rng.next_f64() < 0.5 {
        let _ = writeln!(text, "inelastic = \"stick\"");
    }
    if rng.next_f64() < 0.25 {
        let _ = writeln!(text, "friction = {}", num(frame.snap(rng.next_f64())));
    }
    if rng.next_f64() < 0.2 {
        let _ = writeln!(text, "drag = {}", num(log_uniform(rng, 1e-3, 1.0)));
    }
    if rng.next_f64() < 0.4 {
        let mut g = [0.0; D];
        g[D - 1] = -9.81;
        let _ = writeln!(text, "gravity = {}", vector(&g));
    }
    let _ = writeln!(
        text,
        "\n[world.border]\nmin = {}\nmax = {}\nrestitution = {}\nperiodic = {}",
        vector(&[frame.origin - frame.half; D]),
        vector(&[frame.origin + frame.half; D]),
        num([1.0, 0.0, 0.5][(rng.next_f64() * 3.0) as usize]),
        frame.periodic
    );
    text
}

/// Up to three boxes, rotated or not, static or moving, inside the border; returns each
/// one's centre and the radius of its bounding ball.
fn boxes<const D: usize>(
    rng: &mut SplitMix64,
    frame: &Frame<D>,
    text: &mut String,
) -> Vec<([f64; D], f64)> {
    let count = if rng.next_f64() < 0.5 {
        0
    } else {
        1 + (rng.next_f64() * 3.0) as usize
    };
    (0..count)
        .map(|_| {
            let extents: [f64; D] =
                std::array::from_fn(|_| frame.snap(frame.half * log_uniform(rng, 0.05, 0.3)));
            let reach = extents.iter().map(|e| e * e).sum::<f64>().sqrt();
            let centre = frame.point(rng, reach);
            let vel: [f64; D] = if rng.next_f64() < 0.5 {
                let speed = log_uniform(rng, 0.1, 100.0);
                rng.direction::<D>().map(|x| x * speed)
            } else {
                [0.0; D]
            };
            let _ = writeln!(
                text,
                "\n[[boxes]]\ncenter = {}\nhalf_extents = {}\nvel = {}\nrestitution = {}",
                vector(&centre),
                vector(&extents),
                vector(&vel),
                num(frame.snap(rng.next_f64()))
            );
            if rng.next_f64() < 0.5 {
                let angle = rng.range(-3.0, 3.0);
                if D == 2 {
                    let _ = writeln!(text, "angle = {}", num(angle));
                } else {
                    let axis = rng.direction::<3>().map(|x| x * angle);
                    let _ = writeln!(text, "axis_angle = {}", vector(&axis));
                }
            }
            (centre, reach)
        })
        .collect()
}

/// 2 to 40 balls (few more often than many), apart from each other and the boxes; a
/// quarter of them placed touching another ball along an axis, a tenth touching a wall.
fn balls<const D: usize>(
    rng: &mut SplitMix64,
    frame: &Frame<D>,
    boxes: &[([f64; D], f64)],
    text: &mut String,
) {
    let (lo, hi) = (frame.origin - frame.half, frame.origin + frame.half);
    let n = 2 + (38.0 * rng.next_f64().powi(2)) as usize;
    let mut placed: Vec<([f64; D], f64)> = Vec::new();
    for _ in 0..n {
        let radius = frame
            .snap(frame.half * log_uniform(rng, 5e-3, 0.12))
            .max(frame.grid.unwrap_or(0.0) * 4.0);
        for _attempt in 0..100 {
            let pos: [f64; D] = match rng.next_f64() {
                u if u < 0.25 && !placed.is_empty() => {
                    let (other, r) = placed[(rng.next_f64() * placed.len() as f64) as usize];
                    let axis = (rng.next_f64() * D as f64) as usize;
                    let sign = if rng.next_f64() < 0.5 { -1.0 } else { 1.0 };
                    let mut p = other;
                    p[axis] += sign * (r + radius);
                    p
                }
                u if u < 0.35 && !frame.periodic => {
                    let mut p = frame.point(rng, radius);
                    let axis = (rng.next_f64() * D as f64) as usize;
                    p[axis] = if rng.next_f64() < 0.5 {
                        lo + radius
                    } else {
                        hi - radius
                    };
                    p
                }
                _ => frame.point(rng, radius),
            };
            let inside = frame.periodic || pos.iter().all(|x| x - radius >= lo && x + radius <= hi);
            let apart = (placed.iter())
                .all(|(q, r)| frame.distance(&pos, q) >= (r + radius) * (1.0 - 1e-15));
            let off_boxes =
                (boxes.iter()).all(|(c, reach)| frame.distance(&pos, c) > reach + radius);
            if inside && apart && off_boxes {
                placed.push((pos, radius));
                break;
            }
        }
    }
    for (pos, radius) in &placed {
        let mass = if rng.next_f64() < 0.5 {
            log_uniform(rng, 1e-6, 1e6)
        } else {
            log_uniform(rng, 0.1, 10.0)
        };
        let speed = match rng.next_f64() {
            u if u < 0.1 => 0.0,
            u if u < 0.2 => log_uniform(rng, 1e3, 1e6),
            u if u < 0.5 => log_uniform(rng, 1.0, 100.0),
            _ => log_uniform(rng, 1e-2, 3.0),
        };
        let vel = rng.direction::<D>().map(|x| x * speed);
        let _ = writeln!(
            text,
            "\n[[balls]]\npos = {}\nvel = {}\nradius = {}\nmass = {}",
            vector(pos),
            vector(&vel),
            num(*radius),
            num(mass)
        );
        if rng.next_f64() < 0.2 {
            let _ = writeln!(text, "restitution = {}", num(frame.snap(rng.next_f64())));
        }
    }
}

#[cfg(test)]
mod tests {
    use carom_integrate::Integrator;
    use carom_toi::Direction;

    use super::*;
    use crate::observe::energy;
    use crate::plan::{EngineChoice, RunOptions, plan};
    use crate::scene::LoadedScene;
    use crate::stepped::SteppedEngine;
    use crate::{BallStates, Simulation};

    /// A ball falling in a periodic box 1 m high, from `speed` m/s down.
    fn falling(speed: f64) -> Scene<f64, 2> {
        let text = format!(
            "dim = 2\n[world]\ngravity = [0.0, -9.81]\n[world.border]\nmin = [0.0, 0.0]\n\
             max = [1.0, 1.0]\nperiodic = true\n[[balls]]\npos = [0.5, 0.5]\n\
             vel = [0.0, -{speed}]\nradius = 0.05\nmass = 2.0\n"
        );
        match parse_scene(&text).unwrap() {
            LoadedScene::D2(scene) => scene,
            LoadedScene::D3(_) => unreachable!(),
        }
    }

    /// Samples the fall every 0.01 s for 2 s with the exact integrator: the largest
    /// energy rise the invariants report, and the rise of the energy of the wrapped
    /// places over the energy scale (`observe::energy`, which knows no walls).
    fn fall(speed: f64) -> (Option<f64>, f64) {
        let scene = falling(speed);
        let options = RunOptions {
            engine: EngineChoice::Stepped,
            integrator: Some(Integrator::Exact),
            dt: Some(0.01),
            ..RunOptions::default()
        };
        let p = plan(&scene, &options).unwrap();
        let mut sim = SteppedEngine::new(&scene, &p, Direction::Forward).unwrap();
        let mut states = BallStates::default();
        sim.states(&mut states);
        let start = energy(&scene, &states);
        let mut invariants = Invariants::new(&scene, &states);
        let mut rise: Option<f64> = Some(f64::NEG_INFINITY);
        for k in 1..=200 {
            let t = f64::from(k) * 0.01;
            sim.advance_to(t, &mut ()).unwrap();
            sim.states(&mut states);
            let sample = invariants.sample(&scene, &states, t, 0.01);
            rise = rise.zip(sample.energy_rise).map(|(a, b)| a.max(b));
        }
        (
            rise,
            (energy(&scene, &states) - start) / invariants.energy_scale,
        )
    }

    #[test]
    fn a_ball_falling_through_a_periodic_floor_keeps_its_energy() {
        // 19.6 m of fall: 19 wraps, each of which the wrapped height turns into m g L of
        // energy from nothing.
        let (rise, wrapped) = fall(0.0);
        assert!(wrapped > 10.0, "the wrapped height shows {wrapped}");
        let rise = rise.expect("a ball under 20 m/s is followed at 0.01 s samples");
        // The exact integrator keeps the energy to rounding; the report is the rise less
        // the first-order allowance, so at most rounding above zero.
        assert!(rise < 1e-12, "rise {rise}");
    }

    /// A 2 kg ball at rest 5e4 m up in `f32`, where a coordinate's last place is 3.9e-3
    /// m and the resolution `ε max|x|` 6.0e-3 m: handed back one last place higher (the
    /// rounding of a position computed from the scene's middle), it shows no energy
    /// rise; two resolutions higher, a rise.
    #[test]
    fn a_position_rounded_far_out_is_no_energy_rise_and_a_real_rise_is() {
        let text = "dim = 2\n[world]\ngravity = [0.0, -9.81]\n[[balls]]\n\
                    pos = [0.0, 50000.0]\nvel = [0.0, 0.0]\nradius = 0.05\nmass = 2.0\n";
        let LoadedScene::D2(scene) = parse_scene(text).unwrap() else {
            unreachable!()
        };
        let scene = scene.cast::<f32>().unwrap();
        let start = BallStates {
            pos: vec![scene.balls[0].pos],
            vel: vec![scene.balls[0].vel],
            spin: vec![nalgebra::Vector1::new(0.0)],
        };
        let mut invariants = Invariants::new(&scene, &start);
        let rise_at = |invariants: &mut Invariants<2>, up: f32| {
            let mut now = start.clone();
            now.pos[0].y += up;
            invariants
                .sample(&scene, &now, 0.0, 0.0)
                .energy_rise
                .unwrap()
        };
        let last_place = 5e4_f32.next_up() - 5e4;
        let scale = invariants.energy_scale;
        let rounded = rise_at(&mut invariants, last_place);
        assert!(rounded <= 0.0, "one last place up: rise {rounded:e}");
        let resolution = invariants.resolution() as f32;
        let real = rise_at(&mut invariants, 2.0 * resolution);
        assert!(real > 0.0, "two resolutions up: rise {real:e} of {scale} J");
    }

    #[test]
    fn a_ball_too_fast_to_follow_between_samples_leaves_the_energy_unchecked() {
        // 30 m/s: 0.3 m between samples, more than a quarter of the 1 m period.
        assert_eq!(fall(30.0).0, None);
    }
}
