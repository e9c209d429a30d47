//! What can stop a report: a case that fails to build or run, or an output that cannot be
//! written.

use std::fmt::Display;
use std::io;
use std::path::PathBuf;

/// Why a report could not be produced.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A measured case could not be built or run (a bug: every case is a valid scene).
    #[error("{case}: {message}")]
    Case {
        /// The case, e.g. `stepped gas2d-phi0.1 N=1000`.
        case: String,
        /// What went wrong.
        message: String,
    },
    /// An output file or directory could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The system's reason.
        source: io::Error,
    },
    /// A plot could not be drawn.
    #[error("cannot draw {}: {message}", path.display())]
    Plot {
        /// The plot's file.
        path: PathBuf,
        /// plotters' reason.
        message: String,
    },
}

impl ReportError {
    /// A failure of `case`, for `map_err`.
    pub(crate) fn case<E: Display>(case: &str) -> impl FnOnce(E) -> Self + '_ {
        move |e| Self::Case {
            case: case.to_owned(),
            message: e.to_string(),
        }
    }

    /// A failure to write `path`, for `map_err`.
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { path, source }
    }
}
