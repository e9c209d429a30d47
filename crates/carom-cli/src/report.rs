//! `carom report [--quick | --full] [--out DIR]`: measure carom against its peers and
//! write REPORT.md, report.json and plots into DIR; print the summary table.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use carom_report::{Mode, Progress};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

/// The folder a report goes to by default.
pub(crate) const DEFAULT_OUT: &str = "carom-report";

/// `carom report [--quick | --full] [--out DIR]`.
#[derive(Args, Debug)]
pub(crate) struct ReportArgs {
    /// Small and medium sizes, under 3 minutes on 2 cores (the default).
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// The large sizes: engines to 1e5 balls, broad phases to 1e6 (much longer).
    #[arg(long)]
    full: bool,
    /// The folder for REPORT.md, report.json and the plots.
    #[arg(long, default_value = DEFAULT_OUT)]
    out: PathBuf,
}

impl ReportArgs {
    /// The quick report into the default folder (what `carom` alone runs).
    pub(crate) fn quick_default() -> Self {
        Self {
            quick: true,
            full: false,
            out: PathBuf::from(DEFAULT_OUT),
        }
    }

    fn mode(&self) -> Mode {
        if self.full { Mode::Full } else { Mode::Quick }
    }
}

pub(crate) fn main(args: &ReportArgs) -> ExitCode {
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new(1);
        bar.set_style(
            ProgressStyle::with_template("[{bar:30}] {pos}/{len} {elapsed:>4} {wide_msg}")
                .expect("a valid template")
                .progress_chars("=> "),
        );
        bar
    });
    let show = |p: Progress<'_>| {
        if let Some(bar) = &bar {
            bar.set_length(p.total as u64);
            bar.set_position(p.done as u64);
            bar.set_message(p.message.to_owned());
        }
    };
    let start = Instant::now();
    let result = carom_report::run(args.mode(), &args.out, &show);
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    match result {
        Ok(report) => {
            println!("{}", carom_report::summary_table(&report));
            println!(
                "Report written to {} (REPORT.md, report.json, plots) in {:.0} s.",
                args.out.display(),
                start.elapsed().as_secs_f64()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("carom: report: {e}");
            ExitCode::from(1)
        }
    }
}
