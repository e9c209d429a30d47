//! What the examples' `main` functions share: run with the command line's arguments,
//! and turn the outcome into the process's exit status the way `carom` does.
//!
//! Each example's `run(args, out)` parses its own arguments (clap) and writes its report
//! to `out`, so that the tests call it directly; `main` only hands it the real ones.

use std::error::Error;
use std::io::Write;
use std::process::ExitCode;

/// Runs `run` on the process's arguments (without the program name) and standard
/// output. Exit status 0 on success; clap's own errors, `--help` and `--version` exit as
/// clap has them; any other error is printed as `name: error` on stderr with status 2
/// (bad input, as `carom run` uses it).
pub(crate) fn main<T>(
    name: &str,
    run: impl FnOnce(&[&str], &mut dyn Write) -> Result<T, Box<dyn Error>>,
) -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match run(&args, &mut std::io::stdout().lock()) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(clap_error) = e.downcast_ref::<clap::Error>() {
                clap_error.exit();
            }
            eprintln!("{name}: {e}");
            ExitCode::from(2)
        }
    }
}
