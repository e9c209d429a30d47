//! The `carom` command.
//!
//! * `carom run SCENE.toml --until T [...]` simulates a scene file and prints JSON Lines
//!   (samples, optional collision events, one summary), following docs/scene-format.md.
//! * `carom report [--quick | --full] [--out DIR]` measures carom against its peers and
//!   writes REPORT.md, report.json and plots into DIR (default `carom-report`).
//! * `carom` alone runs the quick report into `carom-report/` and prints its summary.
//!
//! Exit status: 0 on success, 2 on a bad scene or bad flags (one line on stderr naming
//! the problem), 1 if the simulation itself fails.

mod json;
mod report;
mod run;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// carom: exact and time-stepped simulation of balls, boxes and borders.
#[derive(Parser, Debug)]
#[command(name = "carom", version, about, long_about = None)]
struct Cli {
    /// With no command: the quick report into `carom-report/`.
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a scene file and print JSON Lines.
    Run(run::RunArgs),
    /// Measure carom against its peers: REPORT.md, report.json and plots.
    Report(report::ReportArgs),
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
        Some(Command::Run(args)) => run::main(&args),
        Some(Command::Report(args)) => report::main(&args),
        None => report::main(&report::ReportArgs::quick_default()),
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
