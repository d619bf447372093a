//! Temporary file names for atomic writes: a file is written to a temporary sibling of its
//! target and renamed into place when complete, so that a failed or interrupted write never
//! leaves a half-written file. Shared by the figures ([`plot`](crate::plot)) and the rheometer's
//! outputs.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh temporary path next to `path`: `.NAME.tmp-PID-N` followed by `path`'s extension
/// (so that writers choosing the format by extension still work).
pub fn temporary_sibling(path: &Path) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}-{n}{ext}", std::process::id()))
}
