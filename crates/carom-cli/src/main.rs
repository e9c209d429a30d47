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
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version: print and exit 0
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("carom: {}", one_line(&e.to_string()));
            return ExitCode::from(2);
        }
    };
    match cli.command {
        Command::Run(args) => run::main(&args),
    }
}

/// A clap error as one line: its sentences without the usage and help hints.
fn one_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
        })
        .map(|l| l.trim_start_matches("error: "))
        .collect::<Vec<_>>()
        .join(" ")
}
