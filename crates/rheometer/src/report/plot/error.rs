//! [`PlotError`]: why a figure could not be written.

use std::error::Error as StdError;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Why a figure could not be written. Every variant names the output path.
#[derive(Debug, Error)]
pub enum PlotError {
    /// The extension is neither `.png` nor `.svg`.
    #[error("cannot write plot {path}: unsupported file extension (use .png or .svg)")]
    UnsupportedFormat {
        /// The requested output path.
        path: PathBuf,
    },
    /// The figure description is unusable (sizes, grid shapes, column count, ...).
    #[error("cannot write plot {path}: {reason}")]
    InvalidInput {
        /// The requested output path.
        path: PathBuf,
        /// What is wrong with the input.
        reason: String,
    },
    /// Creating a parent directory or writing the file failed.
    #[error("cannot write plot {path}: {source}")]
    Io {
        /// The requested output path.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The output layer refused the path or writing failed (a full disk, a write-protected
    /// file, ...).
    #[error(transparent)]
    Output(#[from] crate::report::output_files::OutputError),
    /// The bundled font could not be registered.
    #[error("cannot write plot {path}: the bundled font could not be registered")]
    Font {
        /// The requested output path.
        path: PathBuf,
    },
    /// The drawing backend or the PNG encoder failed.
    #[error("cannot write plot {path}: drawing failed: {source}")]
    Draw {
        /// The requested output path.
        path: PathBuf,
        /// The backend's error.
        #[source]
        source: Box<dyn StdError + Send + Sync>,
    },
}

/// The [`PlotError::InvalidInput`] of an unusable figure description.
pub(super) fn invalid(path: &Path, reason: impl Into<String>) -> PlotError {
    PlotError::InvalidInput {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}
