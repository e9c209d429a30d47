//! The rules of the scene contract, checked on a typed [`Scene`].
//!
//! Field rules (finite numbers, positive radius and mass, restitution in `[0, 1]`, ...)
//! and placement rules (balls inside the border, no overlap between balls or with a
//! box by more than [`OVERLAP_TOLERANCE`]). Every error names the entry and the field,
//! e.g. `balls[3].radius: must be > 0, got -0.1`.

use std::fmt;

use carom_math::{
    InvalidValue, Real, ensure_finite_vector, ensure_in_range, ensure_non_negative, ensure_positive,
};

use carom_broad::{Balls, BroadPhase, UniformGrid};
use carom_geometry::query::PointQuery;
use carom_math::Vector;

use super::Scene;

/// How much two bodies may overlap at the start (m): touching (gap 0) is allowed,
/// overlaps up to this are accepted as rounding in hand-written files.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// The resolution of a coordinate of magnitude `x`: `8 ε x` (`ε` the machine epsilon,
/// two unit roundoffs), sixteen roundings. A length or a rise below it is not seen by
/// positions of that size (the resting guard's height floor, the lift of a bounce, the
/// width of an instant, the link of a stepped contact chain): both engines read it.
pub(crate) fn coordinate_resolution<T: Real>(x: T) -> T {
    T::lit(8.0) * T::EPSILON * x
}

/// A scene that breaks a rule of the contract: where, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct SceneError {
    /// The scene file, when the scene came from one.
    pub file: Option<String>,
    /// The offending entry and field, e.g. `balls[3].radius` (empty for the whole file).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error at `field`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: None,
            field: field.into(),
            message: message.into(),
        }
    }

    /// The same error, attributed to the scene file `file`.
    #[must_use]
    pub fn in_file(mut self, file: impl Into<String>) -> Self {
        self.file = Some(file.into());
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(file) = &self.file {
            write!(f, "{file}: ")?;
        }
        if self.field.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.field, self.message)
        }
    }
}

impl From<InvalidValue> for SceneError {
    fn from(e: InvalidValue) -> Self {
        Self::new(e.field.into_owned(), e.problem.to_string())
    }
}

fn at(context: &str) -> impl Fn(InvalidValue) -> SceneError + '_ {
    move |e| SceneError::from(e.within(context))
}

fn restitution<T: Real>(x: T) -> Result<T, InvalidValue> {
    ensure_in_range("restitution", x, T::zero(), T::one())
}

impl<T: Real, const D: usize> Scene<T, D> {
    /// Checks every rule of the scene contract.
    ///
    /// # Errors
    /// The first broken rule, naming the entry and field (`world.gravity[1]`,
    /// `balls[3].radius`, `boxes[0].half_extents[2]`, `balls[4]` for a placement).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_fields()?;
        self.validate_placement()
    }

    /// Every ball's radius against the resolution of the scene's coordinates
    /// ([`coordinate_resolution`] of the largest coordinate of a ball or the border): a
    /// ball smaller than that has contacts whose normal, taken between two centres known
    /// to that resolution, points anywhere, and which no engine can find. In `f32` at
    /// 5e4 m the resolution is 0.048 m: a fuzzed scene's balls of radius 0.016 and 0.020
    /// m there passed through each other (0.024 m of overlap, no contact found), where
    /// the same scene in `f64` (resolution 8.9e-11 m) collides.
    ///
    /// # Errors
    /// `balls[i].radius` of the first ball below the resolution.
    fn validate_resolution(&self) -> Result<(), SceneError> {
        let border = self.world.border.as_ref().map_or(T::zero(), |b| {
            b.border.min().amax().max(b.border.max().amax())
        });
        let largest = (self.balls.iter()).fold(border, |m, b| m.max(b.pos.amax()));
        let resolution = coordinate_resolution(largest);
        // Only a precision coarser than `f64` can be helped by `f64`.
        let remedy = if T::EPSILON.to_f64() > f64::EPSILON {
            "use --precision f64 or coordinates nearer the origin"
        } else {
            "use coordinates nearer the origin"
        };
        match self.balls.iter().position(|b| b.radius < resolution) {
            None => Ok(()),
            Some(i) => Err(SceneError::new(
                format!("balls[{i}].radius"),
                format!(
                    "{} m is below what this precision resolves at coordinates of {} m ({} m): its contacts could not be found; {remedy}",
                    self.balls[i].radius, largest, resolution
                ),
            )),
        }
    }

    /// The field rules alone (not the placement).
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub(crate) fn validate_fields(&self) -> Result<(), SceneError> {
        let w = &self.world;
        let world = at("world");
        ensure_finite_vector("gravity", &w.gravity).map_err(&world)?;
        restitution(w.restitution).map_err(&world)?;
        ensure_non_negative("friction", w.friction).map_err(&world)?;
        ensure_non_negative("drag", w.drag).map_err(&world)?;
        if let Some(b) = &w.border {
            restitution(b.restitution).map_err(at("world.border"))?;
        }
        for (i, b) in self.balls.iter().enumerate() {
            // The entry's name is formatted only for an error.
            let check = || -> Result<(), InvalidValue> {
                ensure_finite_vector("pos", &b.pos)?;
                ensure_finite_vector("vel", &b.vel)?;
                ensure_positive("radius", b.radius)?;
                ensure_positive("mass", b.mass)?;
                if let Some(e) = b.restitution {
                    restitution(e)?;
                }
                Ok(())
            };
            check().map_err(|e| SceneError::from(e.within(&format!("balls[{i}]"))))?;
        }
        for (i, b) in self.boxes.iter().enumerate() {
            let check = || -> Result<(), InvalidValue> {
                ensure_finite_vector("vel", &b.vel)?;
                restitution(b.restitution)?;
                Ok(())
            };
            check().map_err(|e| SceneError::from(e.within(&format!("boxes[{i}]"))))?;
        }
        Ok(())
    }

    fn validate_placement(&self) -> Result<(), SceneError> {
        self.validate_resolution()?;
        let tol = T::lit(OVERLAP_TOLERANCE);
        if let Some(spec) = &self.world.border {
            let (lo, hi) = (spec.border.min(), spec.border.max());
            for (i, b) in self.balls.iter().enumerate() {
                // A periodic box only needs the centre inside; a reflecting one the whole ball.
                let r = if spec.periodic { T::zero() } else { b.radius };
                if let Some(k) =
                    (0..D).find(|&k| b.pos[k] - r < lo[k] - tol || b.pos[k] + r > hi[k] + tol)
                {
                    let what = if spec.periodic { "centre" } else { "ball" };
                    return Err(SceneError::new(
                        format!("balls[{i}].pos"),
                        format!(
                            "the {what} must start inside the border: axis {k} spans [{}, {}], border [{}, {}]",
                            b.pos[k] - r,
                            b.pos[k] + r,
                            lo[k],
                            hi[k]
                        ),
                    ));
                }
            }
        }
        self.validate_ball_overlaps()?;
        self.validate_box_overlaps()
    }

    /// No two balls overlap by more than [`OVERLAP_TOLERANCE`] (minimum image in a
    /// periodic box). Candidate pairs come from a carom-broad uniform grid, so large
    /// scenes are checked in about linear time.
    fn validate_ball_overlaps(&self) -> Result<(), SceneError> {
        let tol = T::lit(OVERLAP_TOLERANCE);
        self.find_near_pair(|i, j, _, gap| {
            (-gap > tol).then(|| {
                SceneError::new(
                    format!("balls[{j}].pos"),
                    format!(
                        "overlaps balls[{i}] by {:.3e} m at the start (at most 1e-9 m is allowed)",
                        (-gap).to_f64()
                    ),
                )
            })
        })
        .map_or(Ok(()), Err)
    }

    /// The first answer `found(i, j, offset, gap)` gives for a pair of balls `i < j`
    /// at most [`OVERLAP_TOLERANCE`] apart (and perhaps some farther), with `offset` from
    /// `i` to `j` (the minimum image in a periodic box) and `gap` the distance between
    /// their surfaces (negative when they overlap).
    pub(crate) fn find_near_pair<R>(
        &self,
        mut found: impl FnMut(usize, usize, Vector<T, D>, T) -> Option<R>,
    ) -> Option<R> {
        if self.balls.len() < 2 {
            return None;
        }
        let centers: Vec<Vector<T, D>> = self.balls.iter().map(|b| b.pos).collect();
        // The grid pairs overlapping balls: each grown by the tolerance so that balls
        // that far apart are among them.
        let reach = T::lit(OVERLAP_TOLERANCE);
        let grown: Vec<T> = self.balls.iter().map(|b| b.radius + reach).collect();
        let periodic = self.world.border.filter(|b| b.periodic).map(|b| b.border);
        let mut grid = match periodic {
            Some(border) => UniformGrid::periodic(border),
            None => UniformGrid::hashed(),
        };
        grid.update(Balls::new_unchecked(&centers, &grown).into());
        let mut pairs = Vec::new();
        grid.pairs(&mut pairs);
        pairs.into_iter().find_map(|(i, j)| {
            let (i, j) = (i as usize, j as usize);
            let d = centers[j] - centers[i];
            let d = periodic.map_or(d, |b| b.minimum_image(&d));
            let gap = d.norm() - self.balls[i].radius - self.balls[j].radius;
            found(i, j, d, gap)
        })
    }

    /// No ball overlaps a box by more than [`OVERLAP_TOLERANCE`] at the start.
    fn validate_box_overlaps(&self) -> Result<(), SceneError> {
        let periodic = self.world.border.filter(|b| b.periodic).map(|b| b.border);
        let tol = T::lit(OVERLAP_TOLERANCE);
        for (k, b) in self.boxes.iter().enumerate() {
            for (i, ball) in self.balls.iter().enumerate() {
                let d = ball.pos - b.shape.center();
                let image = b.shape.center() + periodic.map_or(d, |p| p.minimum_image(&d));
                let overlap = ball.radius - b.shape.signed_distance_to_point(&image);
                if overlap > tol {
                    return Err(SceneError::new(
                        format!("balls[{i}].pos"),
                        format!(
                            "overlaps boxes[{k}] by {:.3e} m at the start (at most 1e-9 m is allowed)",
                            overlap.to_f64()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}
