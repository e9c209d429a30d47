//! Ping pong on carom's time-stepped engine: a tilted 3D table (an OBB at any rotation),
//! a net, side walls, a paddle that is a kinematic box swung along a scripted arc, and
//! three balls under gravity and air drag that hit the table, the net, the paddle and
//! each other. The same rally runs with each integrator, and the example prints the
//! rally events and each integrator's energy error against an accurate reference.
//!
//! ```sh
//! cargo run --release --example ping_pong -- --until 3 --out pictures
//! cargo run --release --example ping_pong -- --integrator semi-implicit-euler --dt 0.01
//! ```
//!
//! The scene's numbers and their sources are in `rally.rs`. See docs/examples.md.

#[path = "../common/cli.rs"]
mod cli;
mod draw;
#[allow(
    dead_code,
    reason = "the shared picture module has helpers only collision_lab uses"
)]
#[path = "../common/picture.rs"]
mod picture;
pub(crate) mod rally;

use std::error::Error;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use carom::integrate::Integrator;
use carom::sim::Collision;
use clap::Parser;

use self::rally::{Frame, Part, Rally, along_table, energies, part, play, script};

/// The original project's scheme: semi-implicit Euler at its frame step.
pub(crate) const ORIGINAL_DT: f64 = 1.0 / 60.0;
/// The reference: the exact integrator (gravity and linear drag in closed form) at a
/// small step, so that only contact timing along chords differs from the true motion.
pub(crate) const REFERENCE_DT: f64 = 1.0 / 2000.0;

/// Ping pong on carom's time-stepped engine, compared across integrators.
#[derive(Parser, Debug)]
#[command(name = "ping_pong", about, long_about = None)]
pub(crate) struct Args {
    /// Integrators to compare (comma-separated names, or `all`): explicit-euler,
    /// semi-implicit-euler, verlet, rk4, exact.
    #[arg(long, default_value = "all")]
    pub(crate) integrator: String,
    /// The step of the compared integrators (s); the original project's is 1/60.
    #[arg(long, default_value_t = ORIGINAL_DT)]
    pub(crate) dt: f64,
    /// How long the rally lasts (s).
    #[arg(long, default_value_t = 3.0)]
    pub(crate) until: f64,
    /// Write pictures (PNG, and a GIF with --frames) into this directory.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Frames of an animated GIF of the reference rally (needs --out).
    #[arg(long, requires = "out")]
    pub(crate) frames: Option<usize>,
}

/// What a run produced.
#[allow(dead_code, reason = "read by tests/ping_pong.rs, not by main")]
pub(crate) struct Outcome {
    /// The table's frame.
    pub(crate) frame: Frame,
    /// The reference rally.
    pub(crate) reference: Rally,
    /// The compared rallies.
    pub(crate) rallies: Vec<Rally>,
    /// The pictures written.
    pub(crate) pictures: Vec<PathBuf>,
}

/// The integrators named by `--integrator`.
///
/// # Errors
/// An unknown name.
pub(crate) fn integrators(list: &str) -> Result<Vec<Integrator>, String> {
    if list == "all" {
        return Ok(Integrator::ALL.to_vec());
    }
    list.split(',')
        .map(|name| {
            name.trim()
                .parse::<Integrator>()
                .map_err(|e| format!("--integrator: {e}"))
        })
        .collect()
}

/// A collision in words: `ball 1 – paddle`.
pub(crate) fn describe(c: &Collision<f64>) -> String {
    match *c {
        Collision::BallBall { i, j, .. } => format!("ball {} – ball {}", i + 1, j + 1),
        Collision::BallBorder { i, .. } => format!("ball {} – floor or room", i + 1),
        Collision::BallBox { i, k, .. } => format!(
            "ball {} – {}",
            i + 1,
            match part(k) {
                Part::Table => "table",
                Part::Net => "net",
                Part::Wall => "side wall",
                Part::Paddle => "paddle",
            }
        ),
    }
}

fn print_events(frame: &Frame, r: &Rally, out: &mut dyn Write) -> std::io::Result<()> {
    for c in &r.events {
        let step = ((c.time() / r.dt).ceil() as usize).min(r.frames.len() - 1);
        let i = match *c {
            Collision::BallBall { i, .. }
            | Collision::BallBorder { i, .. }
            | Collision::BallBox { i, .. } => i,
        };
        let before = along_table(frame, r, step.saturating_sub(1), i);
        let after = along_table(frame, r, step, i);
        writeln!(
            out,
            "    {:>7.4}  {:<22}  v along the table {before:+.2} → {after:+.2} m/s",
            c.time(),
            describe(c)
        )?;
    }
    Ok(())
}

/// Runs the example with command-line `args` (without the program name), printing to
/// `out`: all of `main` but the exit status.
///
/// # Errors
/// Bad arguments (naming the flag), an engine failure, or pictures that cannot be written.
pub(crate) fn run(args: &[&str], out: &mut dyn Write) -> Result<Outcome, Box<dyn Error>> {
    let args = Args::try_parse_from(std::iter::once("ping_pong").chain(args.iter().copied()))?;
    let list = integrators(&args.integrator)?;
    if !(args.until.is_finite() && args.until > 0.0 && args.until <= 60.0) {
        return Err(format!("--until: between 0 and 60 s, got {}", args.until).into());
    }
    if !(args.dt.is_finite() && args.dt > 0.0 && args.dt <= 0.1) {
        return Err(format!("--dt: between 0 and 0.1 s, got {}", args.dt).into());
    }
    let frame = Frame::tilted();
    let script = script(&frame)?;
    writeln!(
        out,
        "Ping pong: 3 balls (40 mm, 2.7 g) on a 2.74 m × 1.525 m table turned 25° and rolled 3°, net 15.25 cm, gravity, linear drag b = {:.2e} kg/s",
        rally::DRAG
    )?;
    writeln!(
        out,
        "The paddle (a kinematic box) swings along an arc and meets ball 1 at t = {:.4} s at 3 m/s towards the net.",
        script.t_hit
    )?;
    let reference = play(
        &frame,
        Integrator::Exact,
        REFERENCE_DT,
        args.until,
        Some(script),
    )?;
    let mut rallies = Vec::new();
    for &integrator in &list {
        rallies.push(play(&frame, integrator, args.dt, args.until, Some(script))?);
    }
    writeln!(
        out,
        "\nRally events of the reference (exact integrator, step {REFERENCE_DT} s):"
    )?;
    print_events(&frame, &reference, out)?;
    for r in &rallies {
        writeln!(
            out,
            "\nRally events with {} at step {:.4} s:",
            r.integrator, r.dt
        )?;
        print_events(&frame, r, out)?;
    }
    print_energy(&reference, &rallies, out)?;
    let mut pictures = Vec::new();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| format!("--out {}: {e}", dir.display()))?;
        pictures.push(draw::trajectories(&frame, &reference, dir)?);
        pictures.push(draw::energy_chart(&reference, &rallies, dir)?);
        if let Some(n) = args.frames {
            if !(2..=2000).contains(&n) {
                return Err("--frames: between 2 and 2000".into());
            }
            pictures.push(draw::animation(&frame, &reference, dir, n)?);
        }
        writeln!(out, "\nPictures")?;
        for p in &pictures {
            writeln!(out, "  {}", p.display())?;
        }
    }
    Ok(Outcome {
        frame,
        reference,
        rallies,
        pictures,
    })
}

fn print_energy(reference: &Rally, rallies: &[Rally], out: &mut dyn Write) -> std::io::Result<()> {
    let e_ref = energies(reference);
    let e0 = e_ref[0].1;
    writeln!(
        out,
        "\nEnergy of the balls (kinetic + potential), E(0) = {e0:.6} J. Drag removes energy and the paddle adds some,"
    )?;
    writeln!(
        out,
        "so E is not conserved: each integrator is compared with the reference at the same times. 'drift' is"
    )?;
    writeln!(
        out,
        "E − E_ref at the end, 'worst' the largest |E − E_ref| on the way, both relative to E(0)."
    )?;
    writeln!(
        out,
        "  {:<22} {:>8}  {:>7}  {:>12}  {:>10}  {:>10}",
        "integrator", "step (s)", "events", "E(end) (J)", "drift", "worst"
    )?;
    writeln!(
        out,
        "  {:<22} {:>8.4}  {:>7}  {:>12.6}  {:>10}  {:>10}",
        "exact (reference)",
        reference.dt,
        reference.events.len(),
        e_ref[e_ref.len() - 1].1,
        "-",
        "-"
    )?;
    for r in rallies {
        let e = energies(r);
        let at = |t: f64| {
            let k = ((t / reference.dt).round() as usize).min(e_ref.len() - 1);
            e_ref[k].1
        };
        let worst = e
            .iter()
            .map(|&(t, x)| (x - at(t)).abs())
            .fold(0.0, f64::max);
        let (t_end, e_end) = e[e.len() - 1];
        writeln!(
            out,
            "  {:<22} {:>8.4}  {:>7}  {:>12.6}  {:>+10.2e}  {:>10.2e}",
            r.integrator.to_string(),
            r.dt,
            r.events.len(),
            e_end,
            (e_end - at(t_end)) / e0,
            worst / e0
        )?;
    }
    writeln!(
        out,
        "Explicit Euler gains energy in flight (it moves with the old velocity); semi-implicit Euler, the original\n\
         project's scheme, errs by O(dt) in position, so contacts come at slightly wrong heights and speeds; Verlet and\n\
         RK4 are second and fourth order in flight; the exact integrator solves gravity plus linear drag in closed form.\n\
         Once a contact differs, the rallies part ways, so late differences also measure how chaotic the rally is."
    )
}

fn main() -> ExitCode {
    cli::main("ping_pong", run)
}
