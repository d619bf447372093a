//! SIGINT, SIGTERM and SIGHUP: `simulate` and `landscape` stop cleanly after SIGINT (between
//! experiments or grid points, keeping and marking what they finished); every other case
//! ends the program at once. No temporary of a write in progress is left behind: a watchdog
//! thread removes them before the program ends (a second SIGINT, or `kill -9`, may leave
//! one, which the next run into the same directory removes).

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::Duration;

/// Set by the first SIGINT: `simulate` and `landscape` stop between experiments or grid
/// points, keep and mark what they finished, and exit with code 130; the other commands end
/// at once (code 130, no temporary left). A second SIGINT ends the program at once.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The first SIGTERM or SIGHUP received (0: none): the program ends at once, exit code
/// 128 + signal.
static TERMINATED: AtomicI32 = AtomicI32::new(0);

/// Exit code after SIGINT (128 + 2, the shell's convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Grace period after SIGINT before `simulate` and `landscape` are ended regardless (a single
/// solve that does not check the flag); outputs are written atomically and `simulate` keeps
/// its `PARTIAL.txt` manifest up to date, so ending here loses no finished file.
pub const INTERRUPT_GRACE: Duration = Duration::from_millis(1500);

/// Whether SIGINT was received (see [`INTERRUPTED`]).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(unix)]
extern "C" fn on_signal(sig: libc::c_int) {
    // async-signal-safe only: atomic operations, and _exit on a second SIGINT
    if sig == libc::SIGINT {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            // SAFETY: _exit is async-signal-safe and takes no pointers
            unsafe { libc::_exit(i32::from(EXIT_INTERRUPTED)) };
        }
    } else {
        let _ = TERMINATED.compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst);
    }
}

/// Installs the handlers and starts the watchdog that ends the program `grace` after SIGINT
/// (at once for a zero grace) and at once after SIGTERM or SIGHUP, after removing the
/// temporaries of writes in progress.
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
    }
    std::thread::spawn(move || watchdog(grace));
}

fn watchdog(grace: Duration) {
    let tick = Duration::from_millis(25);
    let mut since_interrupt = Duration::ZERO;
    loop {
        std::thread::sleep(tick);
        let sig = TERMINATED.load(Ordering::SeqCst);
        if sig != 0 {
            end(
                128 + sig,
                &format!(
                    "terminated by {}: stopped at once; finished files are kept, no temporary \
                     is left",
                    signal_name(sig)
                ),
            );
        }
        if interrupted() {
            if since_interrupt >= grace {
                end(
                    i32::from(EXIT_INTERRUPTED),
                    "interrupted: stopped before the current step finished; finished files \
                     are kept",
                );
            }
            since_interrupt += tick;
        }
    }
}

fn end(code: i32, message: &str) -> ! {
    rheometer::output_files::remove_pending_temporaries();
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
