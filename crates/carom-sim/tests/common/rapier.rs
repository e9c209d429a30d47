//! The same 2D gas scene in rapier2d 0.36, the peer of the stepped engine's tests and
//! benches (`benches/stepped.rs` includes this file).
//!
//! Every ball is a dynamic body with a ball collider of the scene's radius and mass,
//! CCD on, restitution 1 combined with `Max` and friction 0 combined with `Min`, so every
//! pair is exactly elastic and frictionless; the border is four fixed cuboid walls, as
//! elastic. No gravity. Everything else is rapier's default `IntegrationParameters`
//! (4 solver iterations, `dt` set to the scene's step), recorded by [`RapierGas::settings`].

use carom_sim::scene::Scene;
use rapier2d::prelude::*;

/// A rapier2d world holding a carom 2D scene's balls and border.
pub(crate) struct RapierGas {
    /// The world.
    pub(crate) world: PhysicsWorld,
    /// The balls' body handles, in scene order.
    pub(crate) balls: Vec<RigidBodyHandle>,
}

impl RapierGas {
    /// The scene `s` (balls and a reflecting border; no boxes, no gravity) stepped at `dt`.
    pub(crate) fn new(s: &Scene<f64, 2>, dt: f64) -> Self {
        let mut world = PhysicsWorld {
            gravity: Vector::ZERO,
            ..PhysicsWorld::default()
        };
        world.integration_parameters.dt = dt as f32;
        let elastic = |c: ColliderBuilder| {
            c.restitution(1.0)
                .restitution_combine_rule(CoefficientCombineRule::Max)
                .friction(0.0)
                .friction_combine_rule(CoefficientCombineRule::Min)
        };
        let border = s.world.border.expect("a gas has a border").border;
        let (lo, hi) = (border.min(), border.max());
        let (cx, cy) = (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
        let (hx, hy) = (0.5 * (hi.x - lo.x), 0.5 * (hi.y - lo.y));
        let t = 1.0;
        for (x, y, half_x, half_y) in [
            (lo.x - t, cy, t, hy + 2.0 * t),
            (hi.x + t, cy, t, hy + 2.0 * t),
            (cx, lo.y - t, hx + 2.0 * t, t),
            (cx, hi.y + t, hx + 2.0 * t, t),
        ] {
            world.insert(
                RigidBodyBuilder::fixed().translation(Vector::new(x as f32, y as f32)),
                elastic(ColliderBuilder::cuboid(half_x as f32, half_y as f32)),
            );
        }
        let balls = s
            .balls
            .iter()
            .map(|b| {
                world
                    .insert(
                        RigidBodyBuilder::dynamic()
                            .translation(Vector::new(b.pos.x as f32, b.pos.y as f32))
                            .linvel(Vector::new(b.vel.x as f32, b.vel.y as f32))
                            .ccd_enabled(true),
                        elastic(ColliderBuilder::ball(b.radius as f32)).mass(b.mass as f32),
                    )
                    .0
            })
            .collect();
        Self { world, balls }
    }

    /// One step.
    pub(crate) fn step(&mut self) {
        self.world.step();
    }

    /// The kinetic energy of the balls (translation and rotation).
    pub(crate) fn energy(&self) -> f64 {
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

    /// The settings used, for reports.
    pub(crate) fn settings(&self) -> String {
        let p = &self.world.integration_parameters;
        format!(
            "rapier2d 0.36 (f32): dt {}, {} solver iterations, {} CCD substeps, CCD on, restitution 1 (Max), friction 0 (Min)",
            p.dt, p.num_solver_iterations, p.max_ccd_substeps
        )
    }
}
