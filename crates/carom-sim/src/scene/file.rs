//! The TOML scene file of the `carom run` contract (docs/scene-format.md).
//!
//! Parsing has two stages. Serde reads the file into raw structs that mirror the format
//! key for key (`deny_unknown_fields` everywhere: a typo is an error, never ignored), with
//! `serde_path_to_error` so that a bad key is reported with its path (`balls[3].radiu`).
//! Then the raw structs become a typed [`Scene`] (vectors of exactly `dim` components,
//! rotations from `angle` in 2D or `axis_angle` in 3D) and [`Scene::validate`] checks
//! the numbers and the placement.

use std::path::Path;

use carom_geometry::{Border, Obb};
use carom_math::{Real, Vector};
use nalgebra::Vector3;
use serde::Deserialize;

use super::{BallSpec, BorderSpec, BoxSpec, Inelastic, Scene, SceneError, World};

/// A scene as read from a file: its dimension decides the type.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadedScene {
    /// `dim = 2`.
    D2(Scene<f64, 2>),
    /// `dim = 3`.
    D3(Scene<f64, 3>),
}

impl LoadedScene {
    /// The dimension, 2 or 3.
    pub fn dim(&self) -> usize {
        match self {
            LoadedScene::D2(_) => 2,
            LoadedScene::D3(_) => 3,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    dim: i64,
    name: Option<String>,
    #[serde(default)]
    world: RawWorld,
    #[serde(default)]
    balls: Vec<RawBall>,
    #[serde(default)]
    boxes: Vec<RawBox>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawWorld {
    gravity: Option<Vec<f64>>,
    restitution: Option<f64>,
    inelastic: Option<RawInelastic>,
    friction: Option<f64>,
    drag: Option<f64>,
    border: Option<RawBorder>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawInelastic {
    Slide,
    Stick,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBorder {
    min: Vec<f64>,
    max: Vec<f64>,
    restitution: Option<f64>,
    periodic: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBall {
    pos: Vec<f64>,
    vel: Option<Vec<f64>>,
    radius: f64,
    mass: f64,
    restitution: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBox {
    center: Vec<f64>,
    half_extents: Vec<f64>,
    angle: Option<f64>,
    axis_angle: Option<Vec<f64>>,
    vel: Option<Vec<f64>>,
    restitution: Option<f64>,
}

/// Reads and checks the scene file at `path`. Errors name the file.
///
/// # Errors
/// The file cannot be read, is not valid TOML, has an unknown or missing key, or breaks
/// a rule of the contract.
pub fn load_scene_file(path: &Path) -> Result<LoadedScene, SceneError> {
    let label = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| {
        SceneError::new("", format!("cannot read the scene file: {e}")).in_file(&label)
    })?;
    parse_scene(&text).map_err(|e| e.in_file(label))
}

/// Parses and checks a scene from TOML text.
///
/// # Errors
/// Invalid TOML, an unknown or missing key, a value of the wrong type, or a broken rule of
/// the contract, naming the entry and field.
pub fn parse_scene(text: &str) -> Result<LoadedScene, SceneError> {
    let de =
        toml::Deserializer::parse(text).map_err(|e| SceneError::new("", toml_message(&e, text)))?;
    let raw: RawScene = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let message = toml_message(e.inner(), text);
        SceneError::new(if path == "." { String::new() } else { path }, message)
    })?;
    match raw.dim {
        2 => Ok(LoadedScene::D2(typed(raw, rotation_2d)?)),
        3 => Ok(LoadedScene::D3(typed(raw, rotation_3d)?)),
        d => Err(SceneError::new("dim", format!("must be 2 or 3, got {d}"))),
    }
}

/// A TOML/serde error as one line: serde's words with "field" said as "key", and the
/// line number where the parser knows it.
fn toml_message(e: &toml::de::Error, text: &str) -> String {
    let msg = e.message().replace("field", "key").replace('\n', " ");
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            format!("{} (line {line})", msg.trim_end())
        }
        None => msg.trim_end().to_owned(),
    }
}

fn vector<const D: usize>(field: &str, v: &[f64]) -> Result<Vector<f64, D>, SceneError> {
    if v.len() != D {
        return Err(SceneError::new(
            field,
            format!(
                "must have exactly {D} components (dim = {D}), got {}",
                v.len()
            ),
        ));
    }
    Ok(Vector::<f64, D>::from_column_slice(v))
}

fn typed<const D: usize>(
    raw: RawScene,
    rotation: impl Fn(&RawBox, &str) -> Result<nalgebra::Rotation<f64, D>, SceneError>,
) -> Result<Scene<f64, D>, SceneError> {
    let w = raw.world;
    let border = match &w.border {
        None => None,
        Some(b) => Some(BorderSpec {
            border: Border::new(
                vector("world.border.min", &b.min)?,
                vector("world.border.max", &b.max)?,
            )
            .map_err(|e| SceneError::from(e.within("world.border")))?,
            restitution: b.restitution.unwrap_or(1.0),
            periodic: b.periodic.unwrap_or(false),
        }),
    };
    let world = World {
        gravity: match &w.gravity {
            Some(g) => vector("world.gravity", g)?,
            None => Vector::zeros(),
        },
        restitution: w.restitution.unwrap_or(1.0),
        inelastic: match w.inelastic {
            Some(RawInelastic::Stick) => Inelastic::Stick,
            Some(RawInelastic::Slide) | None => Inelastic::Slide,
        },
        friction: w.friction.unwrap_or(0.0),
        drag: w.drag.unwrap_or(0.0),
        border,
    };
    let mut balls = Vec::with_capacity(raw.balls.len());
    for (i, b) in raw.balls.iter().enumerate() {
        let ctx = format!("balls[{i}]");
        balls.push(BallSpec {
            pos: vector(&format!("{ctx}.pos"), &b.pos)?,
            vel: match &b.vel {
                Some(v) => vector(&format!("{ctx}.vel"), v)?,
                None => Vector::zeros(),
            },
            radius: b.radius,
            mass: b.mass,
            restitution: b.restitution,
        });
    }
    let mut boxes = Vec::with_capacity(raw.boxes.len());
    for (i, b) in raw.boxes.iter().enumerate() {
        let ctx = format!("boxes[{i}]");
        let shape = Obb::new(
            vector(&format!("{ctx}.center"), &b.center)?,
            vector(&format!("{ctx}.half_extents"), &b.half_extents)?,
            rotation(b, &ctx)?,
        )
        .map_err(|e| SceneError::from(e.within(&ctx)))?;
        boxes.push(BoxSpec {
            shape,
            vel: match &b.vel {
                Some(v) => vector(&format!("{ctx}.vel"), v)?,
                None => Vector::zeros(),
            },
            restitution: b.restitution.unwrap_or(1.0),
        });
    }
    let scene = Scene {
        name: raw.name,
        world,
        balls,
        boxes,
    };
    scene.validate()?;
    Ok(scene)
}

fn rotation_2d(b: &RawBox, ctx: &str) -> Result<nalgebra::Rotation<f64, 2>, SceneError> {
    if b.axis_angle.is_some() {
        return Err(SceneError::new(
            format!("{ctx}.axis_angle"),
            "is for dim = 3; a 2D box turns by `angle`",
        ));
    }
    let angle = b.angle.unwrap_or(0.0);
    if !angle.finite() {
        return Err(SceneError::new(
            format!("{ctx}.angle"),
            format!("must be finite, got {angle}"),
        ));
    }
    Ok(nalgebra::Rotation2::new(angle))
}

fn rotation_3d(b: &RawBox, ctx: &str) -> Result<nalgebra::Rotation<f64, 3>, SceneError> {
    if b.angle.is_some() {
        return Err(SceneError::new(
            format!("{ctx}.angle"),
            "is for dim = 2; a 3D box turns by `axis_angle`",
        ));
    }
    let v: Vector3<f64> = match &b.axis_angle {
        Some(v) => vector(&format!("{ctx}.axis_angle"), v)?,
        None => Vector3::zeros(),
    };
    if let Some(k) = (0..3).find(|&k| !v[k].finite()) {
        return Err(SceneError::new(
            format!("{ctx}.axis_angle[{k}]"),
            format!("must be finite, got {}", v[k]),
        ));
    }
    Ok(nalgebra::Rotation3::from_scaled_axis(v))
}
