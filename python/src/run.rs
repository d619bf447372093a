//! Running a long library call with the GIL released and Ctrl-C honoured.
//!
//! The call runs on a scoped worker thread while the calling thread waits with the GIL
//! released, waking every [`POLL`] to let Python run its signal handlers
//! ([`Python::check_signals`]). On `KeyboardInterrupt` (or any exception a handler raises) the
//! cancellation flag is set; the library stops at its next check (between fit iterations, grid
//! points or experiments) and the exception is raised once the worker has returned. In a thread
//! other than the main one (e.g. a Dask worker's task thread) Python runs no signal handlers, and
//! the call simply runs to its end.

use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

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
    std::thread::scope(|s| {
        s.spawn(move || {
            // the receiver is gone only if the caller stopped waiting; nothing to report then
            let _ = tx.send(f(flag));
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
