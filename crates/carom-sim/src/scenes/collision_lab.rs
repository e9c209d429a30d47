//! PhET Collision Lab's four screens as carom scenes.
//!
//! Default initial states, play areas and options follow the simulation
//! (phetsims/collision-lab): the play area spans `x ∈ [−2, 2]` with `y ∈ [−0.55, 0.55]`
//! on the 1D screens and `y ∈ [−1, 1]` on the 2D ones; a ball's radius follows from its
//! mass at a uniform density of 35 kg/m³ as for a sphere, `r = ∛(3m / (4π ρ))`, or is the
//! constant 0.15 m when "constant size" is on. The Inelastic screen starts at
//! elasticity 0 %; the other screens at 100 %.

use carom_math::Vector;
use nalgebra::Vector2;

use crate::scene::{BallSpec, BorderSpec, Inelastic, Scene, World};
use carom_geometry::Border;

/// The density PhET derives radii from (kg/m³).
pub const DENSITY: f64 = 35.0;
/// The radius of every ball when "constant size" is on (m).
pub const CONSTANT_RADIUS: f64 = 0.15;

/// The screens of Collision Lab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Screen {
    /// Two balls on a line.
    Intro,
    /// Up to five balls on a line.
    Explore1d,
    /// Up to four balls in the plane.
    Explore2d,
    /// Two balls, perfectly inelastic, with a preset.
    Inelastic(InelasticPreset),
}

/// The presets of the Inelastic screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InelasticPreset {
    /// Equal balls meeting head-on at equal speeds.
    HeadOn,
    /// Equal balls on crossing diagonal paths.
    CrissCross,
    /// A light fast ball glancing off a heavy ball at rest.
    Glancing,
}

impl InelasticPreset {
    /// Every preset, in the sim's order.
    pub const ALL: [Self; 3] = [Self::HeadOn, Self::CrissCross, Self::Glancing];
}

impl Screen {
    /// Every screen, each Inelastic preset as its own, in the sim's order.
    pub const ALL: [Self; 6] = [
        Self::Intro,
        Self::Explore1d,
        Self::Explore2d,
        Self::Inelastic(InelasticPreset::HeadOn),
        Self::Inelastic(InelasticPreset::CrissCross),
        Self::Inelastic(InelasticPreset::Glancing),
    ];
}

/// The options of the simulation's control panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Elasticity in percent, 0..=100; `None` for the screen's default (0 on Inelastic,
    /// 100 elsewhere).
    pub elasticity_percent: Option<f64>,
    /// Whether the play area's border reflects balls (on by default); off, balls leave.
    pub reflecting_border: bool,
    /// What elasticity 0 means: slide (default) or stick.
    pub inelastic: Inelastic,
    /// How many of the screen's preset balls take part; `None` for the screen's default
    /// (every preset ball).
    pub balls: Option<usize>,
    /// Constant radius 0.15 m instead of the radius from mass.
    pub constant_size: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            elasticity_percent: None,
            reflecting_border: true,
            inelastic: Inelastic::Slide,
            balls: None,
            constant_size: false,
        }
    }
}

/// A ball's radius in Collision Lab: from its mass at [`DENSITY`], or [`CONSTANT_RADIUS`].
pub fn radius_for_mass(mass: f64, constant_size: bool) -> f64 {
    if constant_size {
        CONSTANT_RADIUS
    } else {
        (3.0 * mass / (4.0 * std::f64::consts::PI * DENSITY)).cbrt()
    }
}

/// `(position, velocity, mass)` of each preset ball of a screen, in order.
pub fn preset_balls(screen: Screen) -> Vec<([f64; 2], [f64; 2], f64)> {
    match screen {
        Screen::Intro => vec![
            ([-1.0, 0.0], [1.0, 0.0], 0.5),
            ([1.0, 0.0], [-0.5, 0.0], 1.5),
        ],
        Screen::Explore1d => vec![
            ([-1.8, 0.0], [1.0, 0.0], 0.5),
            ([-0.1, 0.0], [-0.5, 0.0], 1.5),
            ([0.8, 0.0], [-0.5, 0.0], 1.0),
            ([1.3, 0.0], [1.1, 0.0], 1.0),
            ([1.8, 0.0], [-1.1, 0.0], 1.0),
        ],
        Screen::Explore2d => vec![
            ([-1.0, 0.0], [1.0, 0.3], 0.5),
            ([0.0, 0.5], [-0.5, -0.5], 1.5),
            ([-1.0, -0.5], [-0.25, -0.5], 1.0),
            ([0.2, -0.65], [1.1, 0.2], 1.0),
        ],
        Screen::Inelastic(InelasticPreset::HeadOn) => {
            vec![
                ([-0.5, 0.0], [0.5, 0.0], 0.5),
                ([0.5, 0.0], [-0.5, 0.0], 0.5),
            ]
        }
        Screen::Inelastic(InelasticPreset::CrissCross) => {
            vec![
                ([-0.5, 0.0], [1.0, 0.5], 0.5),
                ([0.5, 0.0], [-1.0, 0.5], 0.5),
            ]
        }
        Screen::Inelastic(InelasticPreset::Glancing) => {
            vec![
                ([-0.65, 0.0], [0.0, 0.0], 1.8),
                ([0.6, 0.12], [-1.0, 0.0], 0.3),
            ]
        }
    }
}

/// The play area of a screen: `[−2, 2] × [−0.55, 0.55]` in 1D, `[−2, 2] × [−1, 1]` in 2D.
pub fn play_area(screen: Screen) -> Border<f64, 2> {
    let half_height = match screen {
        Screen::Intro | Screen::Explore1d => 0.55,
        Screen::Explore2d | Screen::Inelastic(_) => 1.0,
    };
    Border::new(
        Vector2::new(-2.0, -half_height),
        Vector2::new(2.0, half_height),
    )
    .expect("the play areas are valid")
}

/// The scene of a screen with the given options. The scene is validated by the engine
/// (and by [`Scene::validate`]); out-of-range options such as elasticity 150 % are
/// reported there, naming `world.restitution`.
pub fn scene(screen: Screen, options: &Options) -> Scene<f64, 2> {
    let presets = preset_balls(screen);
    let count = options.balls.unwrap_or(presets.len()).min(presets.len());
    let default_elasticity = if matches!(screen, Screen::Inelastic(_)) {
        0.0
    } else {
        100.0
    };
    let restitution = options.elasticity_percent.unwrap_or(default_elasticity) / 100.0;
    let balls = presets[..count]
        .iter()
        .map(|&(p, v, m)| {
            BallSpec::new(
                Vector::<f64, 2>::from(p),
                Vector::<f64, 2>::from(v),
                radius_for_mass(m, options.constant_size),
                m,
            )
        })
        .collect();
    let name = match screen {
        Screen::Intro => "collision-lab-intro",
        Screen::Explore1d => "collision-lab-explore-1d",
        Screen::Explore2d => "collision-lab-explore-2d",
        Screen::Inelastic(InelasticPreset::HeadOn) => "collision-lab-inelastic-head-on",
        Screen::Inelastic(InelasticPreset::CrissCross) => "collision-lab-inelastic-criss-cross",
        Screen::Inelastic(InelasticPreset::Glancing) => "collision-lab-inelastic-glancing",
    };
    Scene {
        name: Some(name.to_owned()),
        world: World {
            restitution,
            inelastic: options.inelastic,
            border: options.reflecting_border.then(|| BorderSpec {
                border: play_area(screen),
                restitution: 1.0,
                periodic: false,
            }),
            ..World::default()
        },
        balls,
        boxes: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_from_mass_is_a_sphere_at_35_kg_per_cubic_metre() {
        let r = radius_for_mass(1.0, false);
        let volume = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        assert!((1.0 / volume - DENSITY).abs() < 1e-12);
        assert_eq!(radius_for_mass(3.0, true), CONSTANT_RADIUS);
    }

    #[test]
    fn every_screen_and_option_gives_a_valid_scene() {
        for screen in Screen::ALL {
            for constant_size in [false, true] {
                for reflecting_border in [false, true] {
                    let opts = Options {
                        reflecting_border,
                        constant_size,
                        ..Options::default()
                    };
                    let s = scene(screen, &opts);
                    s.validate()
                        .unwrap_or_else(|e| panic!("{screen:?} {opts:?}: {e}"));
                    assert_eq!(s.balls.len(), preset_balls(screen).len());
                }
            }
        }
    }

    #[test]
    fn options_select_balls_and_elasticity() {
        let s = scene(
            Screen::Explore1d,
            &Options {
                balls: Some(3),
                elasticity_percent: Some(40.0),
                ..Options::default()
            },
        );
        assert_eq!(s.balls.len(), 3);
        assert!((s.world.restitution - 0.4).abs() < 1e-15);
        let s = scene(
            Screen::Inelastic(InelasticPreset::Glancing),
            &Options::default(),
        );
        assert_eq!(
            s.world.restitution, 0.0,
            "the Inelastic screen starts at 0 %"
        );
        let bad = scene(
            Screen::Intro,
            &Options {
                elasticity_percent: Some(150.0),
                ..Options::default()
            },
        );
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("world.restitution")
        );
    }
}
