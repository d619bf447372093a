//! Output files that never harm: not the inputs, not each other, not special files.
//!
//! Generic (no solver or fiber types): used by [`plot`](crate::report::plot) for figures and by the
//! rheometer for every file it writes.
//!
//! * [`OutputPlan`] collects every output of a run — files, output directories with the
//!   names written into them — and the inputs; [`OutputPlan::check`] validates all of them
//!   **before any work**: no output is an input (same device and inode, so hard and symbolic
//!   links count), no two outputs are the same file, directories exist or can be created and
//!   accept new files, names fit NAME_MAX, write-protected files are refused.
//! * [`OutputFile`] is an output rendered in memory (a figure, a text), written through the
//!   checked outputs or saved by itself.
//! * `write_file` writes one output the way its kind requires ([`Target`]): regular files
//!   through a temporary with a short name in the same directory, renamed over the file when
//!   complete (never half-written; permissions kept; a file without write permission is
//!   refused); character devices (`/dev/null`), FIFOs, `/dev/fd/N` and `-` (standard output)
//!   in place, never renamed over or replaced by a regular file.
//! * Temporaries are registered while written: [`remove_pending_temporaries`] (for a program
//!   ending on a signal) removes them; `remove_stale_temporaries` removes those of ended
//!   runs (`kill -9`), which [`OutputPlan::check`] does in every output directory.
//! * [`PartialMarker`] marks an output directory as incomplete while it is written.

mod error;
mod file;
mod marker;
mod plan;
mod target;
mod temporaries;
mod write;

pub use error::OutputError;
pub use file::OutputFile;
pub use marker::{PartialMarker, PARTIAL_NAME};
pub use plan::{CheckedOutputs, OutputPlan};
pub use target::Target;
pub use temporaries::remove_pending_temporaries;
pub(crate) use write::write_bytes;
pub(crate) use write::FIFO_WAIT_RANGE;
pub(crate) use write::FIFO_WAIT_VARIABLE;

/// A fresh scratch directory `target/unit-scratch/output-files-NAME-PID` (under the crate) for
/// the layer's unit tests.
#[cfg(test)]
pub(crate) fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("target")
        .join("unit-scratch")
        .join(format!("output-files-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
