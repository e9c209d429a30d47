//! Textbook set-ups with closed-form answers, used by tests, the report and examples.

use carom_geometry::Border;
use carom_math::Vector;
use nalgebra::Vector2;

use crate::scene::{BallSpec, BorderSpec, Scene, World};

/// Two balls on the x axis approaching head-on, ball 0 at `x = −1` moving at `v0`, ball 1
/// at `x = +1` moving at `v1`, radii 0.1, restitution `e`, no border.
pub fn head_on(m0: f64, m1: f64, v0: f64, v1: f64, e: f64) -> Scene<f64, 2> {
    Scene {
        name: Some("head-on".to_owned()),
        world: World {
            restitution: e,
            ..World::default()
        },
        balls: vec![
            BallSpec::new(Vector2::new(-1.0, 0.0), Vector2::new(v0, 0.0), 0.1, m0),
            BallSpec::new(Vector2::new(1.0, 0.0), Vector2::new(v1, 0.0), 0.1, m1),
        ],
        boxes: Vec::new(),
    }
}

/// `balls` in the box `[−1, 1]²` with elastic walls (restitution 1), no gravity.
pub fn elastic_box(balls: Vec<BallSpec<f64, 2>>) -> Scene<f64, 2> {
    Scene {
        name: Some("box".to_owned()),
        world: World {
            border: Some(BorderSpec {
                border: Border::new(Vector2::new(-1.0, -1.0), Vector2::new(1.0, 1.0))
                    .expect("[-1, 1]² is a valid box"),
                restitution: 1.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls,
        boxes: Vec::new(),
    }
}

/// Newton's cradle: `n` equal balls of radius 0.1 touching in a row on the x axis
/// (centres 0.2 apart, starting at `x = 0`), and one more ball coming in from the left at
/// speed `v`, 0.5 m away. With restitution 1 the textbook result is that the last ball
/// leaves at `v` and all the others end at rest.
pub fn newtons_cradle(n: usize, v: f64) -> Scene<f64, 2> {
    let mut balls = vec![BallSpec::new(
        Vector2::new(-0.7, 0.0),
        Vector2::new(v, 0.0),
        0.1,
        1.0,
    )];
    balls.extend((0..n).map(|k| {
        BallSpec::new(
            Vector2::new(0.2 * k as f64, 0.0),
            Vector2::zeros(),
            0.1,
            1.0,
        )
    }));
    Scene {
        name: Some(format!("newtons-cradle-{n}")),
        world: World::default(),
        balls,
        boxes: Vec::new(),
    }
}

/// A ball of radius 0.1 dropped from rest with its bottom at height `h` above the floor of
/// a tall box, under `g = 9.81`, with floor restitution `e`. In `D` dimensions, the last
/// axis is up.
pub fn ball_drop<const D: usize>(h: f64, e: f64) -> Scene<f64, D> {
    let r = 0.1;
    let mut gravity = Vector::<f64, D>::zeros();
    gravity[D - 1] = -9.81;
    let mut pos = Vector::<f64, D>::zeros();
    pos[D - 1] = h + r;
    let mut min = Vector::<f64, D>::repeat(-1.0);
    min[D - 1] = 0.0;
    let mut max = Vector::<f64, D>::repeat(1.0);
    max[D - 1] = 2.0 * (h + r) + 1.0;
    Scene {
        name: Some("ball-drop".to_owned()),
        world: World {
            gravity,
            restitution: e,
            border: Some(BorderSpec {
                border: Border::new(min, max).expect("a tall box"),
                restitution: e,
                periodic: false,
            }),
            ..World::default()
        },
        balls: vec![BallSpec::new(pos, Vector::zeros(), r, 1.0)],
        boxes: Vec::new(),
    }
}
