//! Running a long library call with the GIL released and Ctrl-C honoured.
//!
//! The call runs on a scoped worker thread while the calling thread waits with the GIL
//! released, waking every [`POLL`] to let Python run its signal handlers
//! ([`Python::check_signals`]). On `KeyboardInterrupt` (or any exception a handler raises) the
//! cancellation flag is set; the library stops at its next check (between fit iterations, grid
//! points or experiments) and the exception is raised once the worker has returned. In a thread
//! other than the main one (e.g. a Dask worker's task thread) Python runs no signal handlers, and
//! the call simply runs to its end.
//!
//! Every call runs on the Rust thread pool chosen with [`set_threads`] (the library's parallel
//! loops — experiments of a fit, rows of a landscape, candidates of a diagnosis — and the
//! sparse linear algebra use it), by default rayon's global pool (`RAYON_NUM_THREADS`, else
//! one thread per core).

use crate::errors::input_error;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The pool of [`set_threads`], if one was chosen.
static POOL: Mutex<Option<Arc<rayon::ThreadPool>>> = Mutex::new(None);

/// Largest thread count accepted by [`set_threads`].
const MAX_THREADS: usize = 4096;

fn pool() -> Option<Arc<rayon::ThreadPool>> {
    POOL.lock().ok().and_then(|p| p.clone())
}

/// Sets the number of Rust threads every later call of this process uses (`None`: rayon's
/// global pool again, sized by `RAYON_NUM_THREADS` or the number of cores). On a Dask worker
/// process that shares the machine's cores with others, 1 thread per worker keeps the cores
/// from being oversubscribed.
#[pyfunction]
#[pyo3(signature = (n=None))]
pub fn set_threads(n: Option<usize>) -> PyResult<()> {
    let new = match n {
        None => None,
        Some(n) if (1..=MAX_THREADS).contains(&n) => {
            if let Some(p) = pool().filter(|p| p.current_num_threads() == n) {
                Some(p)
            } else {
                let p = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .thread_name(|i| format!("diffbvp-{i}"))
                    .build()
                    .map_err(|e| input_error(format!("set_threads({n}): {e}")))?;
                Some(Arc::new(p))
            }
        }
        Some(n) => {
            return Err(input_error(format!(
                "set_threads: give 1 to {MAX_THREADS} threads, or None for the default (got {n})"
            )))
        }
    };
    match POOL.lock() {
        Ok(mut p) => *p = new,
        Err(poisoned) => *poisoned.into_inner() = new,
    }
    Ok(())
}

/// The number of Rust threads a call uses now (see [`set_threads`]).
#[pyfunction]
pub fn threads() -> usize {
    pool().map_or_else(rayon::current_num_threads, |p| p.current_num_threads())
}

/// How often the waiting thread looks for signals.
const POLL: Duration = Duration::from_millis(50);

/// Runs `f` (given a fresh cancellation flag) on a worker thread with the GIL released; a
/// signal handler's exception (Ctrl-C: `KeyboardInterrupt`) sets the flag and is raised after
/// `f` returns.
pub fn interruptible<T, F>(py: Python<'_>, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(Arc<AtomicBool>) -> T + Send,
{
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    let (tx, mut rx) = channel::<T>();
    let pool = pool();
    std::thread::scope(|s| {
        s.spawn(move || {
            let out = match pool {
                Some(p) => p.install(|| f(flag)),
                None => f(flag),
            };
            // the receiver is gone only if the caller stopped waiting; nothing to report then
            let _ = tx.send(out);
        });
        loop {
            let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Ok(v) => return Ok(v),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    // the worker panicked: the scope re-raises its panic on exit
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "the computation stopped unexpectedly (a panic in the library)",
                    ));
                }
            }
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::SeqCst);
                // wait (GIL released) for the library to notice the flag
                py.detach(move || drop(rx.recv()));
                return Err(e);
            }
        }
    })
}
