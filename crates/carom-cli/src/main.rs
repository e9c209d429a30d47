//! The `carom` command.
//!
//! * `carom run SCENE.toml --until T [...]` simulates a scene file and prints JSON Lines
//!   (samples, optional collision events, one summary), following docs/scene-format.md.
//!
//! Exit status: 0 on success, 2 on a bad scene or bad flags (one line on stderr naming
//! the problem), 1 if the simulation itself fails.

mod json;
mod run;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// carom: exact and time-stepped simulation of balls, boxes and borders.
#[derive(Parser, Debug)]
#[command(name = "carom", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a scene file and print JSON Lines.
    Run(run::RunArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(args) => run::main(&args),
    }
}
