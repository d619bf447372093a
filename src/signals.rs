//! SIGINT, SIGTERM and SIGHUP, as a terminal or a batch system sends them (Ctrl-C; `kill`,
//! `timeout`, a scheduler at the end of a job's time; a closed terminal) are one rule: the
//! first of them stops `simulate` and `landscape` cleanly (between experiments or grid
//! points, keeping and marking what they finished) and ends every other command at once;
//! the exit code is 128 + the signal (130, 143, 129). No temporary of a write in progress is
//! left behind: a watchdog thread removes them before the program ends (a second signal, or
//! `kill -9`, may leave one, which the next run into the same directory removes). SIGXFSZ
//! (a file-size limit, `ulimit -f`) is ignored, so that a write beyond the limit fails with
//! an error the output layer reports and cleans up, instead of killing the program.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::Duration;

/// Set by the first SIGINT, SIGTERM or SIGHUP: `simulate` and `landscape` stop between
/// experiments or grid points, keep and mark what they finished, and exit with code 128 +
/// the signal; the other commands end at once (same code, no temporary left). A second
/// signal ends the program at once.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The first of SIGINT, SIGTERM, SIGHUP received (0: none).
static FIRST_SIGNAL: AtomicI32 = AtomicI32::new(0);

/// Exit code after SIGINT (128 + 2, the shell's convention); SIGTERM gives 143 and SIGHUP
/// 129 ([`exit_code`]).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Grace period after the first signal before `simulate` and `landscape` are ended
/// regardless (a single solve that does not check the flag); outputs are written atomically
/// and `simulate` keeps its `PARTIAL.txt` manifest up to date, so ending here loses no
/// finished file.
pub const INTERRUPT_GRACE: Duration = Duration::from_millis(1500);

/// The exit code after the first signal: 128 + its number ([`EXIT_INTERRUPTED`] if none was
/// recorded).
pub fn exit_code() -> u8 {
    let sig = FIRST_SIGNAL.load(Ordering::SeqCst);
    u8::try_from(128 + sig)
        .ok()
        .filter(|_| sig > 0)
        .unwrap_or(EXIT_INTERRUPTED)
}

/// How the program says it was stopped: `interrupted` (SIGINT, Ctrl-C) or `terminated by
/// SIGTERM` / `terminated by SIGHUP (the terminal was closed)`.
pub fn stopped_by() -> String {
    let sig = FIRST_SIGNAL.load(Ordering::SeqCst);
    #[cfg(unix)]
    {
        if sig == libc::SIGINT || sig == 0 {
            return "interrupted".into();
        }
    }
    format!("terminated by {}", signal_name(sig))
}

/// Whether SIGINT, SIGTERM or SIGHUP was received (see [`INTERRUPTED`]).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(unix)]
extern "C" fn on_signal(sig: libc::c_int) {
    // async-signal-safe only: atomic operations, and _exit on a second signal
    let _ = FIRST_SIGNAL.compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst);
    if INTERRUPTED.swap(true, Ordering::SeqCst) {
        let first = FIRST_SIGNAL.load(Ordering::SeqCst);
        // SAFETY: _exit is async-signal-safe and takes no pointers
        unsafe { libc::_exit(128 + first) };
    }
}

/// Installs the handlers (SIGXFSZ ignored) and starts the watchdog that ends the program
/// `grace` after the first signal (at once for a zero grace), after removing the temporaries
/// of writes in progress.
pub fn install(grace: Duration) {
    #[cfg(unix)]
    {
        let handler: extern "C" fn(libc::c_int) = on_signal;
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            // SAFETY: the handler only touches atomics and calls _exit, both
            // async-signal-safe
            unsafe {
                libc::signal(sig, handler as libc::sighandler_t);
            }
        }
        // SAFETY: ignoring a signal installs no code; a write past `ulimit -f` then fails
        // with EFBIG, which the output layer reports and cleans up after
        unsafe {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
        }
    }
    std::thread::spawn(move || watchdog(grace));
}

fn watchdog(grace: Duration) {
    let tick = Duration::from_millis(25);
    let mut since_interrupt = Duration::ZERO;
    loop {
        std::thread::sleep(tick);
        if interrupted() {
            if since_interrupt >= grace {
                let message = if grace.is_zero() {
                    "stopped at once; finished files are kept, no temporary is left"
                } else {
                    "stopped before the current step finished; finished files are kept"
                };
                end(
                    i32::from(exit_code()),
                    &format!("{}: {message}", stopped_by()),
                );
            }
            since_interrupt += tick;
        }
    }
}

fn end(code: i32, message: &str) -> ! {
    rheometer::report::output_files::remove_pending_temporaries();
    crate::err_line(message);
    std::process::exit(code);
}

fn signal_name(sig: i32) -> String {
    #[cfg(unix)]
    {
        match sig {
            libc::SIGTERM => return "SIGTERM".into(),
            libc::SIGHUP => return "SIGHUP (the terminal was closed)".into(),
            _ => {}
        }
    }
    format!("signal {sig}")
}
