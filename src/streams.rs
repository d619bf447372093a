//! Standard output and standard error that never panic: a write error on stdout (other than
//! a closed pipe) is remembered and makes the program exit 1 with a message; a closed stdout
//! (`>&-`) loses the report, which is said on stderr (exit 1); the report moves to stderr
//! when an output file goes to stdout (`--json -`).

use std::io::Write as _;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// The first error writing to stdout other than a closed pipe.
static STDOUT_ERROR: OnceLock<String> = OnceLock::new();

/// Whether the report goes to stderr (an output file takes stdout).
static REPORT_TO_STDERR: AtomicBool = AtomicBool::new(false);

/// Whether stdout was closed when the program started (see [`stdout_was_closed`]).
static STDOUT_CLOSED: OnceLock<bool> = OnceLock::new();

/// Whether descriptor 1 was closed when the process started, recorded by
/// [`RECORD_STDOUT`] before the Rust runtime reopens closed standard descriptors.
#[cfg(target_os = "linux")]
static STDOUT_CLOSED_AT_START: AtomicBool = AtomicBool::new(false);

/// A constructor (`.init_array`) that runs before the Rust runtime's start-up, which opens
/// `/dev/null` on closed standard descriptors: it records whether descriptor 1 was open.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static RECORD_STDOUT: extern "C" fn() = {
    extern "C" fn record() {
        // SAFETY: F_GETFD only reads descriptor 1's flags (-1 when it is not open)
        if unsafe { libc::fcntl(1, libc::F_GETFD) } == -1 {
            STDOUT_CLOSED_AT_START.store(true, Ordering::SeqCst);
        }
    }
    record
};

/// Whether standard output was closed when the program started (`rheometer ... >&-`). On
/// Linux a constructor records it before the Rust runtime opens `/dev/null` read-write on a
/// closed standard descriptor, so a caller's own `/dev/null` opened read-write (Python's
/// `subprocess.DEVNULL`, systemd's `StandardOutput=null`) is not mistaken for a closed stdout.
/// Elsewhere a closed stdout is guessed as `/dev/null` open for reading and writing (a shell's
/// `> /dev/null` opens it write-only).
pub fn stdout_was_closed() -> bool {
    *STDOUT_CLOSED.get_or_init(|| {
        #[cfg(target_os = "linux")]
        {
            STDOUT_CLOSED_AT_START.load(Ordering::SeqCst)
        }
        #[cfg(all(unix, not(target_os = "linux")))]
        {
            // SAFETY: fstat and fcntl only read descriptor 1's state
            let mut st: libc::stat = unsafe { std::mem::zeroed() };
            if unsafe { libc::fstat(1, &mut st) } != 0 {
                return true;
            }
            let flags = unsafe { libc::fcntl(1, libc::F_GETFL) };
            let null = std::fs::metadata("/dev/null").ok();
            let is_null = null.is_some_and(|m| {
                use std::os::unix::fs::MetadataExt;
                #[allow(clippy::unnecessary_cast)]
                let rdev = st.st_rdev as u64;
                (st.st_mode & libc::S_IFMT) == libc::S_IFCHR && rdev == m.rdev()
            });
            is_null && flags >= 0 && flags & libc::O_ACCMODE == libc::O_RDWR
        }
        #[cfg(not(unix))]
        {
            false
        }
    })
}

/// Sends the report (what [`out_line`] prints) to stderr from now on.
pub fn report_to_stderr() {
    REPORT_TO_STDERR.store(true, Ordering::SeqCst);
}

/// Writes one line of the report: to stdout (or stderr, see [`report_to_stderr`]); remembers
/// the first stdout failure other than a closed pipe, and a report lost to a closed stdout.
pub fn out_line(args: std::fmt::Arguments<'_>) {
    if REPORT_TO_STDERR.load(Ordering::SeqCst) {
        let mut e = std::io::stderr().lock();
        let _ = e.write_fmt(args).and_then(|()| e.write_all(b"\n"));
        return;
    }
    if stdout_was_closed() {
        let _ = STDOUT_ERROR.set(
            "standard output is closed (>&-), so the report was lost; redirect it to a file \
             or to /dev/null instead"
                .into(),
        );
        return;
    }
    let mut o = std::io::stdout().lock();
    if let Err(e) = o.write_fmt(args).and_then(|()| o.write_all(b"\n")) {
        note_stdout_error(&e);
    }
}

/// Remembers a stdout write error (a closed pipe, `| head`, is not one).
pub fn note_stdout_error(e: &std::io::Error) {
    if e.kind() != std::io::ErrorKind::BrokenPipe {
        let _ = STDOUT_ERROR.set(format!("cannot write to standard output: {e}"));
    }
}

/// Writes one line to stderr, ignoring failures (`2>/dev/full` must not panic).
pub fn err_line(s: &str) {
    let mut e = std::io::stderr().lock();
    let _ = e.write_all(s.as_bytes()).and_then(|()| e.write_all(b"\n"));
}

/// Flushes stdout; reports (on stderr) the first stdout failure other than a closed pipe.
pub fn finish_stdout() -> Result<(), ()> {
    if let Err(e) = std::io::stdout().flush() {
        note_stdout_error(&e);
    }
    match STDOUT_ERROR.get() {
        Some(e) => {
            err_line(&format!("error: {e}"));
            Err(())
        }
        None => Ok(()),
    }
}
