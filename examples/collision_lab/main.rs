//! PhET's Collision Lab on carom's exact event-driven engine: the four screens (Intro,
//! Explore 1D, Explore 2D, Inelastic) with the sim's default initial states, play areas,
//! radius-from-mass and options, headless.
//!
//! It prints the balls, a table of every collision with the momenta of the bodies just
//! before and just after, the total momentum, kinetic energy, centre of mass and angular
//! momentum over time, and which of them are conserved, with the numbers that show it.
//! With `--out DIR` it draws the play area to scale (paths, velocity and momentum
//! arrows, the centre of mass, the collisions, a stuck cluster's rotation) and the
//! quantities over time as PNG pictures; `--frames N` adds an animated GIF.
//!
//! ```sh
//! cargo run --release --example collision_lab -- --screen explore2d --until 5 --out pictures
//! cargo run --release --example collision_lab -- --screen inelastic --preset glancing --inelastic stick --out pictures
//! cargo run --release --example collision_lab -- --screen explore1d --elasticity 50 --reverse
//! cargo run --release --example collision_lab -- --case spinning-cluster-wall --until 2 --out pictures
//! ```
//!
//! `--case spinning-cluster-wall` shows a known gap of PhET's engine handled correctly:
//! a stuck cluster that only spins, next to a wall, bounces off it instead of passing
//! through. See docs/examples.md for sample output and the pictures.

#[path = "../common/cli.rs"]
mod cli;
mod draw;
pub(crate) mod lab;
#[path = "../common/picture.rs"]
mod picture;
mod report;

use std::error::Error;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use carom::sim::scene::Inelastic;
use carom::sim::scenes::collision_lab::{InelasticPreset, Options, Screen};
use clap::{Parser, ValueEnum};

use self::lab::{Case, Record, Setup, simulate};

/// The screens of Collision Lab.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum ScreenArg {
    /// Two balls on a line.
    Intro,
    /// Up to five balls on a line.
    Explore1d,
    /// Up to four balls in the plane.
    Explore2d,
    /// Two balls at elasticity 0 %, with a preset.
    Inelastic,
}

/// The presets of the Inelastic screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum PresetArg {
    /// Equal balls meeting head-on.
    HeadOn,
    /// Equal balls on crossing paths.
    CrissCross,
    /// A light ball glancing off a heavy one at rest.
    Glancing,
}

/// Cases beyond the sim's screens.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum CaseArg {
    /// A stuck cluster that only spins, next to the wall (a gap of PhET's engine).
    SpinningClusterWall,
}

/// On or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Switch {
    /// On.
    On,
    /// Off.
    Off,
}

/// What elasticity 0 % means.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum InelasticArg {
    /// The balls fuse into a rigid cluster.
    Stick,
    /// The balls lose their approach velocity and slide on.
    Slide,
}

/// PhET's Collision Lab, headless, on carom's exact event-driven engine.
#[derive(Parser, Debug)]
#[command(name = "collision_lab", about, long_about = None)]
pub(crate) struct Args {
    /// The screen.
    #[arg(long, value_enum, default_value = "explore2d")]
    pub(crate) screen: ScreenArg,
    /// The preset of the Inelastic screen.
    #[arg(long, value_enum, default_value = "head-on")]
    pub(crate) preset: PresetArg,
    /// Run a case beyond the sim's screens instead of a screen.
    #[arg(long, value_enum, conflicts_with_all = ["screen", "preset", "balls"])]
    pub(crate) case: Option<CaseArg>,
    /// Elasticity in percent, 0 to 100 (default: 100, or 0 on the Inelastic screen).
    #[arg(long)]
    pub(crate) elasticity: Option<f64>,
    /// The reflecting border of the play area.
    #[arg(long, value_enum, default_value = "on")]
    pub(crate) border: Switch,
    /// What elasticity 0 % means: stick (clusters) or slide.
    #[arg(long, value_enum, default_value = "slide")]
    pub(crate) inelastic: InelasticArg,
    /// How many of the screen's balls take part (default: all of them).
    #[arg(long)]
    pub(crate) balls: Option<usize>,
    /// Every ball 0.15 m in radius instead of the radius from its mass.
    #[arg(long)]
    pub(crate) constant_size: bool,
    /// Run backwards in time from the initial state (the sim's step-back button).
    #[arg(long)]
    pub(crate) reverse: bool,
    /// How long to run (s); a negative time runs backwards like --reverse.
    #[arg(long, default_value_t = 5.0, allow_negative_numbers = true)]
    pub(crate) until: f64,
    /// The spacing of the rows of the quantities table (s).
    #[arg(long, default_value_t = 0.5)]
    pub(crate) every: f64,
    /// Write pictures (PNG, and a GIF with --frames) into this directory.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Frames of an animated GIF of the run (needs --out).
    #[arg(long, requires = "out")]
    pub(crate) frames: Option<usize>,
}

impl Args {
    /// The run these arguments ask for.
    ///
    /// # Errors
    /// A value out of range, naming the flag.
    pub(crate) fn setup(&self) -> Result<Setup, String> {
        let case = match self.case {
            Some(CaseArg::SpinningClusterWall) => Case::SpinningClusterWall,
            None => Case::Screen(match self.screen {
                ScreenArg::Intro => Screen::Intro,
                ScreenArg::Explore1d => Screen::Explore1d,
                ScreenArg::Explore2d => Screen::Explore2d,
                ScreenArg::Inelastic => Screen::Inelastic(match self.preset {
                    PresetArg::HeadOn => InelasticPreset::HeadOn,
                    PresetArg::CrissCross => InelasticPreset::CrissCross,
                    PresetArg::Glancing => InelasticPreset::Glancing,
                }),
            }),
        };
        if let Some(e) = self.elasticity
            && !(0.0..=100.0).contains(&e)
        {
            return Err(format!(
                "--elasticity: must be between 0 and 100 %, got {e}"
            ));
        }
        if self.balls == Some(0) {
            return Err("--balls: at least one ball".to_owned());
        }
        if !(self.until.is_finite() && self.until != 0.0) {
            return Err(format!(
                "--until: must be a finite non-zero time, got {}",
                self.until
            ));
        }
        if !(self.every.is_finite() && self.every > 0.0) {
            return Err(format!("--every: must be > 0, got {}", self.every));
        }
        if self.frames.is_some_and(|n| !(2..=2000).contains(&n)) {
            return Err("--frames: between 2 and 2000".to_owned());
        }
        let span = self.until.abs();
        let until = if self.reverse || self.until < 0.0 {
            -span
        } else {
            span
        };
        Ok(Setup {
            case,
            options: Options {
                elasticity_percent: self.elasticity,
                reflecting_border: self.border == Switch::On,
                inelastic: match self.inelastic {
                    InelasticArg::Stick => Inelastic::Stick,
                    InelasticArg::Slide => Inelastic::Slide,
                },
                balls: self.balls,
                constant_size: self.constant_size,
            },
            until,
            // Fine enough that a spinning cluster's paths look round.
            sample_step: (span / 2000.0).clamp(1e-4, 0.005),
        })
    }
}

/// What a run produced (the tests look at it; `main` only needs the printed report).
#[allow(dead_code, reason = "read by tests/collision_lab.rs, not by main")]
pub(crate) struct Outcome {
    /// The recorded run.
    pub(crate) record: Record,
    /// For `--case spinning-cluster-wall`: the same cluster with the border off.
    pub(crate) without_wall: Option<Record>,
    /// The pictures written.
    pub(crate) pictures: Vec<PathBuf>,
}

/// Runs the example with command-line `args` (without the program name), printing to
/// `out`. This is all of `main` but the exit status, so tests run exactly this.
///
/// # Errors
/// Bad arguments (the message names the flag), a failed run, or pictures that cannot be
/// written.
pub(crate) fn run(args: &[&str], out: &mut dyn Write) -> Result<Outcome, Box<dyn Error>> {
    let args = Args::try_parse_from(std::iter::once("collision_lab").chain(args.iter().copied()))?;
    let setup = args.setup()?;
    let record = simulate(&setup)?;
    report::print(&record, args.every, out)?;
    let without_wall = if setup.case == Case::SpinningClusterWall {
        let free = simulate(&Setup {
            options: Options {
                reflecting_border: false,
                ..setup.options
            },
            ..setup
        })?;
        report::print_gap(&record, &free, out)?;
        Some(free)
    } else {
        None
    };
    let mut pictures = Vec::new();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| format!("--out {}: {e}", dir.display()))?;
        pictures.push(draw::picture(&record, dir)?);
        pictures.push(draw::quantities_chart(&record, dir)?);
        if let Some(frames) = args.frames {
            pictures.push(draw::animation(&record, dir, frames)?);
        }
        writeln!(out, "Pictures")?;
        for p in &pictures {
            writeln!(out, "  {}", p.display())?;
        }
    }
    Ok(Outcome {
        record,
        without_wall,
        pictures,
    })
}

fn main() -> ExitCode {
    cli::main("collision_lab", run)
}
