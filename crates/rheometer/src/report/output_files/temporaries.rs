//! Temporaries of atomic writes: short names (`.tmp-diffbvp-PID-N`, at most 43 bytes, so that
//! any legal target name works), a registry of the ones being written (removed by a program
//! that ends on a signal) and the removal of the ones a killed run left behind.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Prefix of every temporary file name.
pub const TEMPORARY_PREFIX: &str = ".tmp-diffbvp-";

/// A fresh temporary name for a file in `dir`: `dir/.tmp-diffbvp-PID-N`. The name does not
/// depend on the target's name, so a target name of up to NAME_MAX bytes has a temporary too.
pub fn temporary_in(dir: &Path) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    dir.join(format!("{TEMPORARY_PREFIX}{}-{n}", std::process::id()))
}

/// The process id in a temporary's file name: `.tmp-diffbvp-PID-N` (this module's names) or
/// `.NAME.tmp-PID-N[.EXT]` (the longer names of earlier versions, whose `EXT` repeats the
/// extension of `NAME`). `None` for any other name.
pub fn temporary_owner(name: &str) -> Option<u32> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if let Some(rest) = name.strip_prefix(TEMPORARY_PREFIX) {
        let (pid, n) = rest.split_once('-')?;
        return (digits(pid) && digits(n)).then(|| pid.parse().ok())?;
    }
    // legacy: ".NAME.tmp-PID-N" + extension of NAME
    let inner = name.strip_prefix('.')?;
    let at = inner.rfind(".tmp-")?;
    let (target, rest) = (&inner[..at], &inner[at + 5..]);
    let (pid, tail) = rest.split_once('-')?;
    let ext = Path::new(target)
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let n = tail.strip_suffix(ext.as_str())?;
    (!target.is_empty() && digits(pid) && digits(n)).then(|| pid.parse().ok())?
}

/// Whether the process `pid` is alive (`kill(pid, 0)`; a process of another user counts as
/// alive). Without a way to ask (not Unix), every process counts as alive.
fn alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(p) = libc::pid_t::try_from(pid) else {
            return true;
        };
        if p <= 0 {
            return true;
        }
        // SAFETY: kill with signal 0 sends nothing; it only checks the process exists
        let r = unsafe { libc::kill(p, 0) };
        r == 0 || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Removes from `dir` the temporaries (see [`temporary_owner`]) of processes that no longer
/// run: what a run ended by `kill -9` or a power cut left behind. Only regular files are
/// removed; a temporary of a live process (another run writing into the same directory) is
/// kept. Returns the removed paths. A missing or unreadable `dir` removes nothing.
pub fn remove_stale_temporaries(dir: &Path) -> Vec<PathBuf> {
    let me = std::process::id();
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(temporary_owner) else {
            continue;
        };
        let regular = e.file_type().is_ok_and(|t| t.is_file());
        if !regular || pid == me || alive(pid) {
            continue;
        }
        let path = e.path();
        if fs::remove_file(&path).is_ok() {
            removed.push(path);
        }
    }
    removed
}

/// Temporaries being written now (registered when created, unregistered when the writer is
/// done with them), so that a program ended by a signal can remove them.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A temporary file created in a directory and registered as pending while the guard lives;
/// dropping the guard unregisters it (it never deletes a file: the writer renames or removes
/// it).
pub(super) struct PendingTemporary {
    path: PathBuf,
}

impl PendingTemporary {
    /// Creates a fresh temporary in `dir` (see [`temporary_in`]) with `create`, registered in
    /// the same step: a signal handler's [`remove_pending_temporaries`] either sees it or
    /// keeps the registry locked until the process ends, so none escapes.
    pub(super) fn create(
        dir: &Path,
        create: impl FnOnce(&Path) -> io::Result<fs::File>,
    ) -> io::Result<(Self, fs::File)> {
        let path = temporary_in(dir);
        let mut pending = match PENDING.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        let file = create(&path)?;
        pending.push(path.clone());
        Ok((PendingTemporary { path }, file))
    }

    /// The temporary's path.
    pub(super) fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for PendingTemporary {
    fn drop(&mut self) {
        let mut pending = match PENDING.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        if let Some(i) = pending.iter().position(|p| *p == self.path) {
            pending.swap_remove(i);
        }
    }
}

/// Removes the temporaries of writes still in progress, for a program about to end because
/// of a signal: no half-written temporary is left beside the outputs. Returns how many files
/// were removed. The registry stays locked afterwards, so a write starting now waits (the
/// caller is expected to end the process).
pub fn remove_pending_temporaries() -> usize {
    let guard = match PENDING.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    };
    let removed = guard.iter().filter(|p| fs::remove_file(p).is_ok()).count();
    // keep the lock until the process ends: no new temporary is created after the removal
    std::mem::forget(guard);
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_short_and_recognised() {
        let t = temporary_in(Path::new("d"));
        let name = t.file_name().unwrap().to_str().unwrap();
        assert!(name.len() <= 43, "{name}");
        assert_eq!(temporary_owner(name), Some(std::process::id()));
        assert_eq!(temporary_owner(".tmp-diffbvp-12-3"), Some(12));
        assert_eq!(temporary_owner(".fit.json.tmp-77-0.json"), Some(77));
        assert_eq!(temporary_owner(".a_profile.csv.tmp-5-12.csv"), Some(5));
        for other in [
            "fit.json",
            ".tmp-diffbvp-x-1",
            ".tmp-diffbvp-12",
            ".fit.json.tmp-77-0.png",
            ".tmp-77-0",
            "tmp-diffbvp-1-2",
        ] {
            assert_eq!(temporary_owner(other), None, "{other}");
        }
    }
}
