//! Runs the report's accuracy sections (work-precision and stability) on their own and
//! prints their rows and elapsed times; writes the work-precision plots into the
//! directory given as the first argument (default `target/accuracy-sections`).
//!
//! `cargo run --release -p carom-report --example accuracy_sections [DIR] [--full]`

use std::path::PathBuf;
use std::time::Instant;

use carom_report::model::Mode;
use carom_report::{stability, work_precision};

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = if args.iter().any(|a| a == "--full") {
        Mode::Full
    } else {
        Mode::Quick
    };
    let dir = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map_or_else(|| PathBuf::from("target/accuracy-sections"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;
    let start = Instant::now();
    let progress = |what: &str| eprintln!("[{:6.1} s] {what}", start.elapsed().as_secs_f64());
    let rows = work_precision::run(mode, &progress);
    let wp = start.elapsed().as_secs_f64();
    for r in &rows {
        println!(
            "{:16} {:34} dt {:>10} error {:9.2e} seconds {:9.2e}",
            r.problem,
            r.method,
            r.dt.map_or_else(|| "-".to_owned(), |d| format!("{d:.2e}")),
            r.error,
            r.seconds
        );
    }
    for format in [work_precision::Format::Svg, work_precision::Format::Png] {
        for path in work_precision::plot_as(&rows, &dir, format)? {
            println!("wrote {}", path.display());
        }
    }
    let stability_start = Instant::now();
    let table = stability::run(mode, &progress);
    let st = stability_start.elapsed().as_secs_f64();
    for r in &table {
        println!(
            "{} | {} | {}",
            if r.pass { "pass" } else { "FAIL" },
            r.case,
            r.figure
        );
    }
    println!(
        "work-precision {wp:.1} s, stability {st:.1} s, total {:.1} s",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
