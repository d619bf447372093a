//! Writing one output: [`write_file`] classifies the path ([`classify`]) and writes it the
//! way its kind requires.

use super::error::OutputError;
use super::target::{check_replaceable, classify, parent_dir, Target};
use super::temporaries::PendingTemporary;
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How long a write into a FIFO waits for a reader to open it, unless the environment
/// variable [`FIFO_WAIT_VARIABLE`] says otherwise ([`fifo_reader_wait`]).
pub const FIFO_READER_WAIT: Duration = Duration::from_secs(10);

/// The environment variable that sets the FIFO reader wait in seconds (a number in
/// `[0.1, 3600]`, e.g. `DIFFBVP_FIFO_WAIT_S=60` for a reader that starts late; the
/// program refuses anything else at its start, and the library keeps the default
/// [`FIFO_READER_WAIT`]).
pub const FIFO_WAIT_VARIABLE: &str = "DIFFBVP_FIFO_WAIT_S";

/// The accepted values of [`FIFO_WAIT_VARIABLE`], inclusive \[s\]: the one range the
/// program's check of its environment and the library's reading share.
pub(crate) const FIFO_WAIT_RANGE: [f64; 2] = [0.1, 3600.0];

/// How long a write into a FIFO waits for a reader: [`FIFO_WAIT_VARIABLE`] if it holds a number
/// of seconds in `[0.1, 3600]`, else [`FIFO_READER_WAIT`].
pub fn fifo_reader_wait() -> Duration {
    fifo_wait_from(std::env::var(FIFO_WAIT_VARIABLE).ok().as_deref())
}

/// The wait a value of [`FIFO_WAIT_VARIABLE`] gives (`None`: unset).
fn fifo_wait_from(value: Option<&str>) -> Duration {
    value
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| (FIFO_WAIT_RANGE[0]..=FIFO_WAIT_RANGE[1]).contains(s))
        .map_or(FIFO_READER_WAIT, Duration::from_secs_f64)
}

/// Whether `a` and `b` are the same file: same device and inode on Unix (hard and symbolic
/// links included), same canonical path elsewhere. False if either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (fs::canonicalize(a), fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// Fails if `path` exists and is one of `inputs` (the same file, see [`same_file`]).
pub fn ensure_not_input(path: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    if fs::symlink_metadata(path).is_err() {
        return Ok(());
    }
    match inputs.iter().find(|i| same_file(path, i)) {
        Some(input) => Err(OutputError::WouldOverwriteInput {
            path: path.to_path_buf(),
            input: input.clone(),
        }),
        None => Ok(()),
    }
}

/// Writes the output `path` with `write`, never over one of `inputs`:
///
/// * `-` and names of standard output: written to standard output;
/// * `/dev/fd/N` and the like: through that descriptor, in place;
/// * character devices and FIFOs: opened and written in place, never renamed over (a FIFO
///   without a reader is waited for up to `FIFO_READER_WAIT`);
/// * regular files (new or existing, links resolved): written to a temporary in the same
///   directory (short name, see `temporary_in`) and renamed over the
///   file when complete; a write-protected file is refused, an existing file's permissions
///   are kept; missing directories are created. On failure the temporary is removed and the
///   file is untouched.
pub fn write_file(
    path: &Path,
    inputs: &[PathBuf],
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    let target = classify(path)?;
    write_target(&target, path, inputs, write)
}

/// [`write_file`] of `bytes`.
pub fn write_bytes(path: &Path, inputs: &[PathBuf], bytes: &[u8]) -> Result<(), OutputError> {
    write_file(path, inputs, |w| w.write_all(bytes))
}

/// Writes the classified `target` of `path` (see [`write_file`]).
pub fn write_target(
    target: &Target,
    path: &Path,
    inputs: &[PathBuf],
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    let io_err = |e| OutputError::io(path, e);
    match target {
        Target::Stdout => {
            let mut out = io::stdout().lock();
            match write(&mut out).and_then(|()| out.flush()) {
                // a reader that closed the pipe (`| head`) wanted no more: success, as for the
                // report on stdout
                Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
                r => r.map_err(io_err),
            }
        }
        Target::Descriptor(fd) => {
            let file = duplicate(*fd).map_err(io_err)?;
            let mut w = BufWriter::new(file);
            write(&mut w).and_then(|()| w.flush()).map_err(io_err)
        }
        Target::Special { path: p, fifo } => {
            if *fifo {
                ensure_not_input(p, inputs)?;
            }
            let file = open_special(p, *fifo)?;
            let mut w = BufWriter::new(file);
            write(&mut w).and_then(|()| w.flush()).map_err(io_err)
        }
        Target::Regular { path: real, .. } => {
            // the path as given (a link to an input is named as such), then the file itself
            ensure_not_input(path, inputs)?;
            ensure_not_input(real, inputs)?;
            replace_regular(real, write)
        }
    }
}

/// The temporary-then-rename write of the regular file `path`.
fn replace_regular(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    let existing = match fs::metadata(path) {
        Ok(m) if m.is_dir() => {
            return Err(OutputError::IsADirectory {
                path: path.to_path_buf(),
            })
        }
        Ok(m) => {
            check_replaceable(path)?;
            Some(m.permissions())
        }
        Err(_) => None,
    };
    let dir = parent_dir(path);
    fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))?;
    let (pending, file) = PendingTemporary::create(dir, |tmp| {
        fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(tmp)
    })
    .map_err(|source| OutputError::DirectoryNotWritable {
        dir: dir.to_path_buf(),
        path: path.to_path_buf(),
        source,
    })?;
    let tmp = pending.path();
    let result = (|| {
        if let Some(perm) = existing {
            file.set_permissions(perm)?;
        }
        let mut w = BufWriter::with_capacity(1 << 16, file);
        write(&mut w)?;
        // flush errors (a full disk) surface here, before the rename
        w.into_inner().map_err(|e| e.into_error())?;
        fs::rename(tmp, path)
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(tmp);
        return Err(OutputError::io(path, e));
    }
    Ok(())
}

/// A duplicate of this process's descriptor `fd` as a file.
#[cfg(unix)]
fn duplicate(fd: i32) -> io::Result<fs::File> {
    use std::os::fd::FromRawFd;
    // SAFETY: F_DUPFD_CLOEXEC returns a new descriptor (or -1), which the File then owns
    let new = unsafe { libc::fcntl(fd, libc::F_DUPFD_CLOEXEC, 3) };
    if new < 0 {
        return Err(io::Error::last_os_error());
    }
    // SAFETY: `new` is a fresh descriptor owned by nobody else
    Ok(unsafe { fs::File::from_raw_fd(new) })
}

#[cfg(not(unix))]
fn duplicate(_fd: i32) -> io::Result<fs::File> {
    Err(io::Error::other("descriptor paths are not supported"))
}

/// Opens a character device or FIFO for writing, in place (no creation, no truncation). A
/// FIFO is opened without blocking, retried until a reader opens it (up to
/// [`fifo_reader_wait`]), and then switched back to blocking writes.
fn open_special(path: &Path, fifo: bool) -> Result<fs::File, OutputError> {
    let mut opts = fs::OpenOptions::new();
    opts.write(true);
    if !fifo {
        return opts.open(path).map_err(|e| OutputError::io(path, e));
    }
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK);
        let t0 = Instant::now();
        let wait = fifo_reader_wait();
        loop {
            match opts.open(path) {
                Ok(f) => {
                    // SAFETY: F_GETFL/F_SETFL on a descriptor this File owns
                    unsafe {
                        let fl = libc::fcntl(f.as_raw_fd(), libc::F_GETFL);
                        if fl >= 0 {
                            libc::fcntl(f.as_raw_fd(), libc::F_SETFL, fl & !libc::O_NONBLOCK);
                        }
                    }
                    return Ok(f);
                }
                Err(e) if e.raw_os_error() == Some(libc::ENXIO) => {
                    if t0.elapsed() >= wait {
                        return Err(OutputError::FifoWithoutReader {
                            path: path.to_path_buf(),
                            waited_s: wait.as_secs_f64(),
                        });
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => return Err(OutputError::io(path, e)),
            }
        }
    }
    #[cfg(not(unix))]
    {
        let _ = Instant::now();
        opts.open(path).map_err(|e| OutputError::io(path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::super::scratch;

    #[test]
    fn the_fifo_wait_is_ten_seconds_unless_the_variable_gives_a_sane_one() {
        assert_eq!(fifo_wait_from(None), Duration::from_secs(10));
        assert_eq!(fifo_wait_from(Some("60")), Duration::from_secs(60));
        assert_eq!(fifo_wait_from(Some(" 0.5 ")), Duration::from_millis(500));
        // not a number, not finite, too short to be meant, longer than an hour: the default
        for v in ["", "ten", "NaN", "inf", "-1", "0", "0.05", "3601"] {
            assert_eq!(fifo_wait_from(Some(v)), FIFO_READER_WAIT, "{v:?}");
        }
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_name_of_255_bytes_is_written() {
        let d = scratch("long");
        let p = d.join(format!("{}.json", "j".repeat(250)));
        write_bytes(&p, &[], b"{}").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"{}");
        assert_eq!(names(&d).len(), 1);
        let _ = fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn write_protected_files_are_kept_and_modes_preserved() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("modes");
        let p = d.join("r.json");
        fs::write(&p, b"precious").unwrap();
        fs::set_permissions(&p, fs::Permissions::from_mode(0o444)).unwrap();
        let e = write_bytes(&p, &[], b"new").unwrap_err();
        assert!(matches!(e, OutputError::WriteProtected { .. }), "{e}");
        assert_eq!(fs::read(&p).unwrap(), b"precious");
        let q = d.join("g.txt");
        fs::write(&q, b"old").unwrap();
        fs::set_permissions(&q, fs::Permissions::from_mode(0o640)).unwrap();
        write_bytes(&q, &[], b"new").unwrap();
        assert_eq!(
            fs::metadata(&q).unwrap().permissions().mode() & 0o777,
            0o640
        );
        assert_eq!(names(&d), ["g.txt", "r.json"]);
        let _ = fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_stays_a_link_and_its_target_is_replaced() {
        let d = scratch("link");
        let real = d.join("real.txt");
        fs::write(&real, b"old").unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_bytes(&link, &[], b"new").unwrap();
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        let dangling = d.join("dangling.txt");
        std::os::unix::fs::symlink(d.join("nowhere"), &dangling).unwrap();
        let e = write_bytes(&dangling, &[], b"x").unwrap_err();
        assert!(matches!(e, OutputError::DanglingLink { .. }), "{e}");
        let _ = fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn dev_null_and_dev_full_are_written_in_place() {
        write_bytes(Path::new("/dev/null"), &[], b"x").unwrap();
        let e = write_bytes(Path::new("/dev/full"), &[], b"x").unwrap_err();
        assert!(e.to_string().contains("/dev/full"), "{e}");
        use std::os::unix::fs::FileTypeExt;
        for dev in ["/dev/null", "/dev/full"] {
            assert!(fs::metadata(dev).unwrap().file_type().is_char_device());
        }
    }

    #[test]
    fn failed_writes_leave_the_old_file_and_no_temporary() {
        let d = scratch("failed");
        let p = d.join("out.txt");
        write_bytes(&p, &[], b"first").unwrap();
        let failed = write_file(&p, &[], |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk on fire"))
        });
        assert!(failed.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"first");
        assert_eq!(names(&d), ["out.txt"]);
        let _ = fs::remove_dir_all(&d);
    }
}
