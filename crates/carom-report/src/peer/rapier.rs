//! rapier2d 0.36 as the peer of carom's engines: a carom 2D scene built in rapier.
//!
//! The translation keeps every physical property rapier can express exactly, and refuses
//! (with [`Unsupported`]) what it cannot, so a comparison is never between two different
//! scenes:
//!
//! * every ball is a dynamic body with CCD on and a ball collider of the scene's radius and
//!   mass (rapier's f32); linear drag `F = −c v` becomes rapier's linear damping `c / m`
//!   (rapier applies `v ← v / (1 + h c/m)` per step, the implicit Euler of the same law);
//! * friction is 0 everywhere (combine rule `Min`): carom's comparisons are frictionless;
//! * restitution: balls carry their own coefficient with the rule `Min`, which is carom's
//!   rule for a pair (the minimum of the two). A wall or box carries its coefficient `e_w`
//!   with `Min` when `e_w` is at most every ball's coefficient and with `Max` when it is at
//!   least every ball's (rapier applies the rule of higher precedence, `Max` over `Min`), so
//!   a ball–wall contact gets exactly `e_w`; other mixtures are refused;
//! * the reflecting border is four fixed cuboid walls outside it, boxes are fixed (or
//!   velocity-based kinematic, when they move) cuboids at their rotation;
//! * rapier's speed cap (`normalized_max_linear_velocity`, 400 m/s by default, which
//!   silently slows every faster body) is lifted: a carom scene has no speed limit;
//! * everything else is rapier's default `IntegrationParameters` (recorded by
//!   [`RapierScene::settings`]) with `dt` set to the step.
//!
//! Periodic borders, stick clusters and friction have no equivalent here and are refused.

use std::fmt;

use carom_sim::scene::{Inelastic, Scene};
use rapier2d::prelude::*;

/// Why a scene cannot be built in rapier2d with the same physics.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unsupported(pub &'static str);

impl fmt::Display for Unsupported {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "rapier2d cannot reproduce this scene: {}", self.0)
    }
}

impl std::error::Error for Unsupported {}

/// An empty world with `gravity`, stepping `dt`, without rapier's speed cap.
fn empty_world(gravity: [f64; 2], dt: f64) -> PhysicsWorld {
    let mut world = PhysicsWorld {
        gravity: Vector::new(gravity[0] as f32, gravity[1] as f32),
        ..PhysicsWorld::default()
    };
    world.integration_parameters.dt = dt as f32;
    world.integration_parameters.normalized_max_linear_velocity = f32::MAX;
    world
}

/// A rapier2d world holding a carom 2D scene.
pub struct RapierScene {
    /// The world.
    pub world: PhysicsWorld,
    /// The balls' body handles, in scene order.
    pub balls: Vec<RigidBodyHandle>,
}

impl RapierScene {
    /// The scene `s` stepped at `dt` seconds, or why rapier cannot hold it.
    ///
    /// # Errors
    /// [`Unsupported`] for periodic borders, stick clusters, friction, and wall or box
    /// restitutions between the balls' smallest and largest (module docs).
    pub fn new(s: &Scene<f64, 2>, dt: f64) -> Result<Self, Unsupported> {
        if s.world.friction != 0.0 {
            return Err(Unsupported("friction (the comparisons are frictionless)"));
        }
        if s.world.inelastic == Inelastic::Stick && s.world.restitution == 0.0 {
            return Err(Unsupported("stick clusters (world.inelastic = \"stick\")"));
        }
        if s.world.border.is_some_and(|b| b.periodic) {
            return Err(Unsupported("a periodic border"));
        }
        let ball_e: Vec<f64> = s
            .balls
            .iter()
            .map(|b| b.restitution.unwrap_or(s.world.restitution))
            .collect();
        let (e_lo, e_hi) = ball_e
            .iter()
            .fold((1.0_f64, 0.0_f64), |(lo, hi), &e| (lo.min(e), hi.max(e)));
        let wall = |e: f64| -> Result<CoefficientCombineRule, Unsupported> {
            if e <= e_lo {
                Ok(CoefficientCombineRule::Min)
            } else if e >= e_hi {
                Ok(CoefficientCombineRule::Max)
            } else {
                Err(Unsupported(
                    "a wall or box restitution between the balls' smallest and largest",
                ))
            }
        };
        let surface = |c: ColliderBuilder, e: f64, rule| {
            c.restitution(e as f32)
                .restitution_combine_rule(rule)
                .friction(0.0)
                .friction_combine_rule(CoefficientCombineRule::Min)
        };

        let g = s.world.gravity;
        let mut world = empty_world([g.x, g.y], dt);

        if let Some(border) = s.world.border {
            let rule = wall(border.restitution)?;
            let (lo, hi) = (border.border.min(), border.border.max());
            let (cx, cy) = (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
            let (hx, hy) = (0.5 * (hi.x - lo.x), 0.5 * (hi.y - lo.y));
            // Walls as thick as the border is wide, so no ball can cross one in a step.
            let t = hx.max(hy);
            for (x, y, half_x, half_y) in [
                (lo.x - t, cy, t, hy + 2.0 * t),
                (hi.x + t, cy, t, hy + 2.0 * t),
                (cx, lo.y - t, hx + 2.0 * t, t),
                (cx, hi.y + t, hx + 2.0 * t, t),
            ] {
                world.insert(
                    RigidBodyBuilder::fixed().translation(Vector::new(x as f32, y as f32)),
                    surface(
                        ColliderBuilder::cuboid(half_x as f32, half_y as f32),
                        border.restitution,
                        rule,
                    ),
                );
            }
        }
        for b in &s.boxes {
            let rule = wall(b.restitution)?;
            let (c, h) = (b.shape.center(), b.shape.half_extents());
            let body = if b.vel == nalgebra::Vector2::zeros() {
                RigidBodyBuilder::fixed()
            } else {
                RigidBodyBuilder::kinematic_velocity_based()
                    .linvel(Vector::new(b.vel.x as f32, b.vel.y as f32))
            };
            world.insert(
                body.translation(Vector::new(c.x as f32, c.y as f32))
                    .rotation(b.shape.rotation().angle() as f32),
                surface(
                    ColliderBuilder::cuboid(h.x as f32, h.y as f32),
                    b.restitution,
                    rule,
                ),
            );
        }
        let balls = s
            .balls
            .iter()
            .zip(&ball_e)
            .map(|(b, &e)| {
                let body = RigidBodyBuilder::dynamic()
                    .translation(Vector::new(b.pos.x as f32, b.pos.y as f32))
                    .linvel(Vector::new(b.vel.x as f32, b.vel.y as f32))
                    .linear_damping((s.world.drag / b.mass) as f32)
                    .can_sleep(false)
                    .ccd_enabled(true);
                let collider = surface(
                    ColliderBuilder::ball(b.radius as f32),
                    e,
                    CoefficientCombineRule::Min,
                )
                .mass(b.mass as f32);
                world.insert(body, collider).0
            })
            .collect();
        Ok(Self { world, balls })
    }

    /// One ball of `mass` and `radius` tied to a fixed point at the origin by rapier's
    /// spring joint (force-based: `stiffness` in N/m and `damping` in N·s/m, as carom's
    /// `Spring`, of `rest_length`), starting at rest at `pos`, without gravity: the damped
    /// spring of the work-precision section. rapier integrates joint springs implicitly
    /// (its documentation: "implicit integration which adds some numerical damping").
    pub fn anchored_spring(
        mass: f64,
        radius: f64,
        (stiffness, damping, rest_length): (f64, f64, f64),
        pos: [f64; 2],
        dt: f64,
    ) -> Self {
        let mut world = empty_world([0.0, 0.0], dt);
        let anchor = world.insert_body(RigidBodyBuilder::fixed());
        let (ball, _) = world.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(pos[0] as f32, pos[1] as f32))
                .can_sleep(false),
            ColliderBuilder::ball(radius as f32).mass(mass as f32),
        );
        world.insert_impulse_joint(
            anchor,
            ball,
            SpringJointBuilder::new(rest_length as f32, stiffness as f32, damping as f32)
                .spring_model(MotorModel::ForceBased),
        );
        Self {
            world,
            balls: vec![ball],
        }
    }

    /// One step of `dt`.
    pub fn step(&mut self) {
        self.world.step();
    }

    /// Ball `i`'s centre.
    pub fn position(&self, i: usize) -> [f64; 2] {
        let p = self.world.bodies[self.balls[i]].translation();
        [f64::from(p.x), f64::from(p.y)]
    }

    /// Ball `i`'s velocity.
    pub fn velocity(&self, i: usize) -> [f64; 2] {
        let v = self.world.bodies[self.balls[i]].linvel();
        [f64::from(v.x), f64::from(v.y)]
    }

    /// The kinetic energy of the balls (translation and rotation).
    pub fn kinetic_energy(&self) -> f64 {
        self.balls
            .iter()
            .map(|&h| {
                let b = &self.world.bodies[h];
                let v = b.linvel();
                let w = f64::from(b.angvel());
                0.5 * f64::from(b.mass()) * f64::from(v.length_squared())
                    + 0.5 * f64::from(b.mass_properties().effective_angular_inertia()) * w * w
            })
            .sum()
    }

    /// The total linear momentum of the balls.
    pub fn momentum(&self) -> [f64; 2] {
        self.balls.iter().fold([0.0, 0.0], |[px, py], &h| {
            let b = &self.world.bodies[h];
            let (m, v) = (f64::from(b.mass()), b.linvel());
            [px + m * f64::from(v.x), py + m * f64::from(v.y)]
        })
    }

    /// The settings used, for reports.
    pub fn settings(&self) -> String {
        let p = &self.world.integration_parameters;
        format!(
            "rapier2d 0.36 (f32): dt {}, {} solver iterations, {} CCD substeps, CCD on, friction 0, no speed cap",
            p.dt, p.num_solver_iterations, p.max_ccd_substeps
        )
    }
}
