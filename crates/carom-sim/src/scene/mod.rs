//! The scene: what a simulation starts from.
//!
//! A [`Scene`] holds the world settings, the balls and the boxes, generic over the
//! scalar and the dimension. It is plain data with public fields so programs can build
//! one directly; [`Scene::validate`] checks every rule of the scene contract
//! (docs/scene-format.md) and every engine calls it before running. Scene files are
//! read by [`load_scene_file`] / [`parse_scene`], which return a [`LoadedScene`] (2D or 3D,
//! in `f64`); [`Scene::cast`] converts to `f32` for `--precision f32`.

mod file;
mod origin;
mod validate;

use carom_geometry::{Border, Obb};
use carom_math::{Real, Vector};

pub use file::{LoadedScene, load_scene_file, parse_scene};
pub(crate) use validate::coordinate_resolution;
pub use validate::{OVERLAP_TOLERANCE, SceneError};

/// What restitution 0 means between two balls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Inelastic {
    /// The normal relative velocity is removed; the balls slide on (the default).
    #[default]
    Slide,
    /// The balls fuse into a rigid cluster keeping linear and angular momentum.
    Stick,
}

/// The axis-aligned container around the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BorderSpec<T: Real, const D: usize> {
    /// The box.
    pub border: Border<T, D>,
    /// Coefficient of restitution of ball–wall bounces, in `[0, 1]`.
    pub restitution: T,
    /// `true`: balls wrap around (a periodic box) instead of bouncing.
    pub periodic: bool,
}

/// World-wide settings.
#[derive(Clone, Debug, PartialEq)]
pub struct World<T: Real, const D: usize> {
    /// Constant acceleration of every ball.
    pub gravity: Vector<T, D>,
    /// Ball–ball coefficient of restitution in `[0, 1]`.
    pub restitution: T,
    /// Meaning of restitution 0 between balls.
    pub inelastic: Inelastic,
    /// Coulomb coefficient at ball contacts, `>= 0`.
    pub friction: T,
    /// Linear drag coefficient: force `= −drag · velocity`, `>= 0`.
    pub drag: T,
    /// The container, if any.
    pub border: Option<BorderSpec<T, D>>,
}

impl<T: Real, const D: usize> Default for World<T, D> {
    fn default() -> Self {
        Self {
            gravity: Vector::zeros(),
            restitution: T::one(),
            inelastic: Inelastic::Slide,
            friction: T::zero(),
            drag: T::zero(),
            border: None,
        }
    }
}

/// One ball's initial state and properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallSpec<T: Real, const D: usize> {
    /// Initial centre.
    pub pos: Vector<T, D>,
    /// Initial velocity.
    pub vel: Vector<T, D>,
    /// Radius, `> 0`.
    pub radius: T,
    /// Mass, `> 0`.
    pub mass: T,
    /// Per-ball restitution override; a pair uses the minimum of the two.
    pub restitution: Option<T>,
}

impl<T: Real, const D: usize> BallSpec<T, D> {
    /// A ball at rest unless `vel` is given, with the world's restitution.
    pub fn new(pos: Vector<T, D>, vel: Vector<T, D>, radius: T, mass: T) -> Self {
        Self {
            pos,
            vel,
            radius,
            mass,
            restitution: None,
        }
    }
}

/// A static (zero velocity) or kinematic (constant velocity) box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxSpec<T: Real, const D: usize> {
    /// The box at time 0.
    pub shape: Obb<T, D>,
    /// Constant velocity; zero for a static box.
    pub vel: Vector<T, D>,
    /// Coefficient of restitution of ball–box bounces, in `[0, 1]`.
    pub restitution: T,
}

/// A complete scene: world settings, balls and boxes.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene<T: Real, const D: usize> {
    /// Free-text name.
    pub name: Option<String>,
    /// World settings.
    pub world: World<T, D>,
    /// The balls, in input order (outputs keep this order).
    pub balls: Vec<BallSpec<T, D>>,
    /// The boxes, in input order.
    pub boxes: Vec<BoxSpec<T, D>>,
}

impl<T: Real, const D: usize> Default for Scene<T, D> {
    fn default() -> Self {
        Self {
            name: None,
            world: World::default(),
            balls: Vec::new(),
            boxes: Vec::new(),
        }
    }
}

impl<T: Real, const D: usize> Scene<T, D> {
    /// The restitution of the pair of balls `i` and `j`: the minimum of their
    /// overrides and the world value where a ball has none.
    pub fn pair_restitution(&self, i: usize, j: usize) -> T {
        let e = |k: usize| self.balls[k].restitution.unwrap_or(self.world.restitution);
        e(i).min(e(j))
    }

    /// The same scene in another precision (`f64` → `f32` rounds to nearest), validated:
    /// values that fit `f64` may overflow `f32`, and that is reported, never hidden.
    ///
    /// # Errors
    /// The first rule of [`Scene::validate`] the converted scene breaks.
    pub fn cast<U: Real>(&self) -> Result<Scene<U, D>, SceneError> {
        let c = |x: T| U::lit(x.to_f64());
        let v = |x: &Vector<T, D>| x.map(c);
        let border = match &self.world.border {
            None => None,
            Some(b) => Some(BorderSpec {
                border: Border::new(v(&b.border.min()), v(&b.border.max()))
                    .map_err(|e| SceneError::from(e.within("world.border")))?,
                restitution: c(b.restitution),
                periodic: b.periodic,
            }),
        };
        let mut boxes = Vec::with_capacity(self.boxes.len());
        for (i, b) in self.boxes.iter().enumerate() {
            let rotation =
                nalgebra::Rotation::from_matrix_unchecked(b.shape.rotation().matrix().map(c));
            let shape = Obb::new(v(&b.shape.center()), v(&b.shape.half_extents()), rotation)
                .map_err(|e| SceneError::from(e.within(&format!("boxes[{i}]"))))?;
            boxes.push(BoxSpec {
                shape,
                vel: v(&b.vel),
                restitution: c(b.restitution),
            });
        }
        let scene = Scene {
            name: self.name.clone(),
            world: World {
                gravity: v(&self.world.gravity),
                restitution: c(self.world.restitution),
                inelastic: self.world.inelastic,
                friction: c(self.world.friction),
                drag: c(self.world.drag),
                border,
            },
            balls: self
                .balls
                .iter()
                .map(|b| BallSpec {
                    pos: v(&b.pos),
                    vel: v(&b.vel),
                    radius: c(b.radius),
                    mass: c(b.mass),
                    restitution: b.restitution.map(c),
                })
                .collect(),
            boxes,
        };
        scene.validate()?;
        Ok(scene)
    }
}
