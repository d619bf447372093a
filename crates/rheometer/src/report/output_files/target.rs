//! What an output path names, and whether it may be written: [`Target`] and [`classify`],
//! the checks of an existing file before it is replaced ([`check_replaceable`]) and of the
//! directory that receives the temporary ([`check_directory`]).

use super::error::OutputError;
use super::temporaries::temporary_in;
use std::fs;
use std::io;
use std::path::{Component, Path, PathBuf};

/// The path that means standard output.
pub const STDOUT_PATH: &str = "-";

/// Where an output goes, and how it is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// Standard output: `-`, `/dev/stdout`, `/dev/fd/1`, `/proc/self/fd/1`, or a FIFO that is
    /// standard output. Written through the program's standard output, in order with
    /// everything else printed there.
    Stdout,
    /// Another open descriptor of this process named by `/dev/fd/N`, `/proc/self/fd/N` or
    /// `/dev/stderr`: written through a duplicate of it, in place (the shell's redirection,
    /// offset and append mode kept).
    Descriptor(i32),
    /// A character device (`/dev/null`, `/dev/full`, a terminal) or a FIFO: opened for writing
    /// and written in place; never created, renamed over or replaced by a regular file.
    Special {
        /// The path (as given; symbolic links are followed by the open).
        path: PathBuf,
        /// A FIFO (whose reader may have to be waited for) rather than a character device.
        fifo: bool,
    },
    /// A regular file, existing or new: written to a temporary in its directory that is then
    /// renamed over it. `path` is the file itself (symbolic links resolved, so a link stays a
    /// link and its target is replaced).
    Regular {
        /// The file (links resolved).
        path: PathBuf,
        /// Whether it exists now.
        exists: bool,
    },
}

/// The descriptor a `/dev/fd/N`-like path names: `/dev/stdin|stdout|stderr`, `/dev/fd/N`,
/// `/proc/self/fd/N`, `/proc/thread-self/fd/N` and `/proc/PID/fd/N` of this process.
fn descriptor_of(path: &Path) -> Option<i32> {
    let s = path.to_str()?;
    match s {
        "/dev/stdin" => return Some(0),
        "/dev/stdout" => return Some(1),
        "/dev/stderr" => return Some(2),
        _ => {}
    }
    for prefix in ["/dev/fd/", "/proc/self/fd/", "/proc/thread-self/fd/"] {
        if let Some(n) = s.strip_prefix(prefix) {
            return n.parse().ok();
        }
    }
    let rest = s.strip_prefix("/proc/")?;
    let (pid, rest) = rest.split_once('/')?;
    if pid != std::process::id().to_string() {
        return None;
    }
    rest.strip_prefix("fd/")?.parse().ok()
}

/// Device and inode of what descriptor `fd` refers to, with whether it is a regular file or
/// a FIFO (`None` if it is not open).
#[cfg(unix)]
fn descriptor_node(fd: i32) -> Option<(u64, u64, bool, bool)> {
    // SAFETY: fstat writes into the zeroed struct; an invalid fd gives -1
    let mut st: libc::stat = unsafe { std::mem::zeroed() };
    if unsafe { libc::fstat(fd, &mut st) } != 0 {
        return None;
    }
    let fmt = st.st_mode & libc::S_IFMT;
    #[allow(clippy::unnecessary_cast)]
    Some((
        st.st_dev as u64,
        st.st_ino as u64,
        fmt == libc::S_IFREG,
        fmt == libc::S_IFIFO,
    ))
}

/// Classifies `path` (see [`Target`]) and refuses what is never written: a directory, a block
/// device, a socket, standard input, a dangling symbolic link, a descriptor not open for
/// writing, the regular file standard output is redirected to.
pub fn classify(path: &Path) -> Result<Target, OutputError> {
    if path.as_os_str() == STDOUT_PATH {
        return Ok(Target::Stdout);
    }
    if path.as_os_str().is_empty() {
        return Err(OutputError::Unwritable {
            path: path.to_path_buf(),
            what: "the file name is empty; name a file".into(),
        });
    }
    if path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(OutputError::Unwritable {
            path: path.to_path_buf(),
            what: "a name ending with / names a directory; name a file".into(),
        });
    }
    if let Some(fd) = descriptor_of(path) {
        return classify_descriptor(path, fd);
    }
    let link = match fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Ok(Target::Regular {
                path: path.to_path_buf(),
                exists: false,
            })
        }
        Err(e) => return Err(lookup_error(path, e)),
    };
    let meta = if link.file_type().is_symlink() {
        match fs::metadata(path) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(OutputError::DanglingLink {
                    path: path.to_path_buf(),
                    target: fs::read_link(path).unwrap_or_default(),
                })
            }
            Err(e) => return Err(lookup_error(path, e)),
        }
    } else {
        link
    };
    classify_existing(path, &meta)
}

/// The error of looking `path` up: a file in the way of a directory, a name too long, or
/// the OS error.
fn lookup_error(path: &Path, e: io::Error) -> OutputError {
    if e.kind() == io::ErrorKind::NotADirectory {
        if let Some(file) = blocking_file(path.parent().unwrap_or(Path::new(""))) {
            return OutputError::NotADirectory {
                path: path.parent().unwrap_or(path).to_path_buf(),
                file,
            };
        }
    }
    if let Some(long) = long_component(path) {
        return long;
    }
    OutputError::io(path, e)
}

#[cfg(unix)]
fn classify_existing(path: &Path, meta: &fs::Metadata) -> Result<Target, OutputError> {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let t = meta.file_type();
    let unwritable = |what: &str| OutputError::Unwritable {
        path: path.to_path_buf(),
        what: what.to_string(),
    };
    if t.is_dir() {
        return Err(OutputError::IsADirectory {
            path: path.to_path_buf(),
        });
    }
    if t.is_block_device() {
        return Err(unwritable(
            "it is a block device (a disk); it is never written to",
        ));
    }
    if t.is_socket() {
        return Err(unwritable(
            "it is a socket, which cannot be opened as a file",
        ));
    }
    let stdout = descriptor_node(1);
    let is_stdout = stdout.is_some_and(|(d, i, _, _)| d == meta.dev() && i == meta.ino());
    if t.is_fifo() {
        if is_stdout {
            return Ok(Target::Stdout);
        }
        return Ok(Target::Special {
            path: path.to_path_buf(),
            fifo: true,
        });
    }
    if t.is_char_device() {
        return Ok(Target::Special {
            path: path.to_path_buf(),
            fifo: false,
        });
    }
    if is_stdout {
        return Err(OutputError::IsStandardOutput {
            path: path.to_path_buf(),
        });
    }
    let real = fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    Ok(Target::Regular {
        path: real,
        exists: true,
    })
}

#[cfg(not(unix))]
fn classify_existing(path: &Path, meta: &fs::Metadata) -> Result<Target, OutputError> {
    if meta.is_dir() {
        return Err(OutputError::IsADirectory {
            path: path.to_path_buf(),
        });
    }
    let real = fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    Ok(Target::Regular {
        path: real,
        exists: true,
    })
}

#[cfg(unix)]
fn classify_descriptor(path: &Path, fd: i32) -> Result<Target, OutputError> {
    let err = |state| OutputError::Descriptor {
        path: path.to_path_buf(),
        fd,
        state,
    };
    if fd == 0 {
        return Err(OutputError::Unwritable {
            path: path.to_path_buf(),
            what: "it is standard input".into(),
        });
    }
    // SAFETY: F_GETFL only reads the descriptor's flags; an invalid fd gives -1
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    if flags < 0 {
        return Err(err("not open"));
    }
    if flags & libc::O_ACCMODE == libc::O_RDONLY {
        return Err(err("open for reading only"));
    }
    if fd == 1 {
        return Ok(Target::Stdout);
    }
    Ok(Target::Descriptor(fd))
}

#[cfg(not(unix))]
fn classify_descriptor(path: &Path, fd: i32) -> Result<Target, OutputError> {
    if fd == 1 {
        return Ok(Target::Stdout);
    }
    Err(OutputError::Unwritable {
        path: path.to_path_buf(),
        what: "descriptor paths are not supported on this system".into(),
    })
}

/// The effective user id (0 elsewhere than on Unix, where nothing depends on it).
pub(super) fn effective_uid() -> u32 {
    #[cfg(unix)]
    {
        // SAFETY: geteuid cannot fail
        unsafe { libc::geteuid() }
    }
    #[cfg(not(unix))]
    {
        0
    }
}

/// Refuses to replace the existing regular file `path` (links resolved) when its owner could
/// not write it: no write permission bit at all (`chmod 444`; checked from the mode bits, so
/// also for root), no write permission for this user, or another user's file in a directory
/// with the sticky bit.
pub fn check_replaceable(path: &Path) -> Result<(), OutputError> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        let meta = fs::metadata(path).map_err(|e| OutputError::io(path, e))?;
        let mode = meta.permissions().mode() & 0o7777;
        let euid = effective_uid();
        let others = meta.uid() != euid;
        let protected = || OutputError::WriteProtected {
            path: path.to_path_buf(),
            mode,
            others,
        };
        if mode & 0o222 == 0 {
            return Err(protected());
        }
        // an immutable or append-only file refuses writing with EPERM (EACCES is the mode),
        // for root too; opening for writing without truncation changes nothing
        if meta.is_file() {
            if let Err(e) = fs::OpenOptions::new().write(true).open(path) {
                if e.raw_os_error() == Some(libc::EPERM) {
                    return Err(OutputError::Immutable {
                        path: path.to_path_buf(),
                        source: e,
                    });
                }
            }
        }
        if euid != 0 {
            // another user's file in a sticky directory first: the rename would fail whatever
            // the file's mode
            let dir = parent_dir(path);
            if let Ok(d) = fs::metadata(dir) {
                let sticky = d.permissions().mode() & 0o1000 != 0;
                if sticky && others && d.uid() != euid {
                    return Err(OutputError::OwnedByAnother {
                        path: path.to_path_buf(),
                        dir: dir.to_path_buf(),
                    });
                }
            }
            // the kernel's own answer for this user (groups and ACLs included); opening for
            // writing without truncation changes nothing
            if let Err(e) = fs::OpenOptions::new().write(true).open(path) {
                if e.kind() == io::ErrorKind::PermissionDenied {
                    return Err(protected());
                }
            }
        }
    }
    #[cfg(not(unix))]
    {
        let meta = fs::metadata(path).map_err(|e| OutputError::io(path, e))?;
        if meta.permissions().readonly() {
            return Err(OutputError::WriteProtected {
                path: path.to_path_buf(),
                mode: 0o444,
                others: false,
            });
        }
    }
    Ok(())
}

/// The directory of `path` (`.` for a bare name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The first of `dir` and its ancestors that exists and is not a directory.
pub fn blocking_file(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .find(|a| a.exists() && !a.is_dir())
        .map(Path::to_path_buf)
}

/// The longest name a file in `dir` may have (NAME_MAX; 255 where it cannot be asked).
pub fn name_max(dir: &Path) -> usize {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) else {
            return 255;
        };
        // SAFETY: a valid NUL-terminated path; pathconf only reads it
        let v = unsafe { libc::pathconf(c.as_ptr(), libc::_PC_NAME_MAX) };
        usize::try_from(v).ok().filter(|&v| v > 0).unwrap_or(255)
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        255
    }
}

/// [`OutputError::NameTooLong`] for the first component of `path` longer than NAME_MAX of the
/// file system it would be created on.
fn long_component(path: &Path) -> Option<OutputError> {
    let (existing, _) = existing_ancestor(path);
    let max = name_max(&existing);
    path.components().find_map(|c| match c {
        Component::Normal(n) if n.len() > max => Some(OutputError::NameTooLong {
            path: path.to_path_buf(),
            name: n.to_string_lossy().into_owned(),
            len: n.len(),
            max,
        }),
        _ => None,
    })
}

/// The longest existing ancestor of `path` (`.` for a relative path with none) and whether it
/// is a directory.
fn existing_ancestor(path: &Path) -> (PathBuf, bool) {
    for a in path.ancestors().skip(1) {
        let a = if a.as_os_str().is_empty() {
            Path::new(".")
        } else {
            a
        };
        if let Ok(m) = fs::metadata(a) {
            return (a.to_path_buf(), m.is_dir());
        }
    }
    (PathBuf::from("."), true)
}

/// Checks, creating nothing that stays, that a file can be written at the regular path
/// `path`: every name within NAME_MAX, the directory (or the first existing ancestor that
/// would hold the missing ones) a directory in which a temporary can be created (one is
/// created and removed at once). `path` itself is not looked at.
pub fn check_directory(path: &Path) -> Result<(), OutputError> {
    if let Some(long) = long_component(path) {
        return Err(long);
    }
    let (existing, is_dir) = existing_ancestor(path);
    if !is_dir {
        return Err(OutputError::NotADirectory {
            path: parent_dir(path).to_path_buf(),
            file: existing,
        });
    }
    let probe = temporary_in(&existing);
    match fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = fs::remove_file(&probe);
            Ok(())
        }
        Err(source) => Err(OutputError::DirectoryNotWritable {
            dir: existing,
            path: path.to_path_buf(),
            source,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descriptor_paths_are_recognised() {
        assert_eq!(descriptor_of(Path::new("/dev/stdout")), Some(1));
        assert_eq!(descriptor_of(Path::new("/dev/fd/63")), Some(63));
        assert_eq!(descriptor_of(Path::new("/proc/self/fd/2")), Some(2));
        let own = format!("/proc/{}/fd/5", std::process::id());
        assert_eq!(descriptor_of(Path::new(&own)), Some(5));
        assert_eq!(descriptor_of(Path::new("/proc/1/fd/5")), None);
        assert_eq!(descriptor_of(Path::new("/dev/null")), None);
        assert_eq!(classify(Path::new("-")).unwrap(), Target::Stdout);
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_special_and_descriptors_checked() {
        assert_eq!(
            classify(Path::new("/dev/null")).unwrap(),
            Target::Special {
                path: "/dev/null".into(),
                fifo: false
            }
        );
        let e = classify(Path::new("/dev/fd/987")).unwrap_err();
        assert!(e.to_string().contains("descriptor 987 is not open"), "{e}");
        let e = classify(Path::new("/dev/stdin")).unwrap_err();
        assert!(e.to_string().contains("standard input"), "{e}");
        assert!(matches!(
            classify(Path::new("/dev")),
            Err(OutputError::IsADirectory { .. })
        ));
        let e = classify(Path::new("/")).unwrap_err();
        assert!(e.to_string().contains("names a directory"), "{e}");
    }
}
