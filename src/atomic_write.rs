//! Temporary file names for atomic writes: a file is written to a temporary sibling of its
//! target and renamed into place when complete, so that a failed or interrupted write never
//! leaves a half-written file. Shared by the figures ([`plot`](crate::plot)) and the rheometer's
//! outputs.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

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

/// Temporaries being written now (registered before the file is created, unregistered when the
/// writer is done with them), so that a program ended early can remove them.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A temporary sibling registered as pending while it is alive: the writer creates, fills and
/// renames (or removes) it; dropping the guard unregisters it (it never deletes a file).
pub(crate) struct PendingTemporary {
    path: PathBuf,
}

impl PendingTemporary {
    /// Registers a fresh temporary sibling of `target` (see [`temporary_sibling`]).
    pub(crate) fn new(target: &Path) -> Self {
        let path = temporary_sibling(target);
        if let Ok(mut pending) = PENDING.lock() {
            pending.push(path.clone());
        }
        PendingTemporary { path }
    }

    /// The temporary's path.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for PendingTemporary {
    fn drop(&mut self) {
        if let Ok(mut pending) = PENDING.lock() {
            if let Some(i) = pending.iter().position(|p| *p == self.path) {
                pending.swap_remove(i);
            }
        }
    }
}

/// Removes the temporaries of writes still in progress (for a program that is about to end
/// because of a signal: no half-written temporary is left beside the outputs). Returns how many
/// files were removed. The registry stays locked afterwards, so a write starting now waits
/// (the caller is expected to end the process).
pub fn remove_pending_temporaries() -> usize {
    let guard = match PENDING.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    };
    let removed = guard
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count();
    // keep the lock until the process ends: no new temporary is registered (and created) after
    // the removal
    std::mem::forget(guard);
    removed
}
