//! [`OutputError`]: why an output cannot be written. Every variant names the path, and the
//! checks of an [`OutputPlan`](super::OutputPlan) also the flag or role that asked for it.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why an output cannot be written.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The output path is one of the inputs (also through a hard or symbolic link).
    #[error(
        "refusing to write {path}: it is an input file{}; choose another output name or \
         directory",
        alias_note(path, input)
    )]
    WouldOverwriteInput {
        /// The path.
        path: PathBuf,
        /// The input it is (the same file, perhaps under another name).
        input: PathBuf,
    },
    /// The output directory is one of the inputs (e.g. `--out` names a measurement CSV).
    #[error(
        "refusing to use {path} as the output directory: it is an input file; choose another \
         output directory"
    )]
    DirectoryIsInput {
        /// The path.
        path: PathBuf,
    },
    /// The output directory, or one of its parents, exists and is not a directory.
    #[error(
        "cannot create the output directory {path}: {file} exists and is {}, not a directory",
        kind_of(file)
    )]
    NotADirectory {
        /// The requested directory.
        path: PathBuf,
        /// The existing file in its way (the directory itself or a parent).
        file: PathBuf,
    },
    /// An output file path is an existing directory.
    #[error("cannot write {path}: it is an existing directory; name a file")]
    IsADirectory {
        /// The path.
        path: PathBuf,
    },
    /// The existing file is write-protected (no write permission bit, or none for this user):
    /// it is not replaced.
    #[error(
        "refusing to replace {path}: the file is write-protected (mode {mode:o}){}; remove \
         the protection (chmod u+w) or choose another name",
        if *others { ", and you do not own it" } else { "" }
    )]
    WriteProtected {
        /// The path.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
        /// Whether another user owns it.
        others: bool,
    },
    /// The existing file is immutable or append-only (`chattr +i`, `+a`): not even root may
    /// replace it, so it is refused before the work.
    #[error(
        "refusing to replace {path}: the file is immutable or append-only (chattr +i or +a: \
         {source}); remove the attribute (`chattr -i {path}` as root) or choose another name"
    )]
    Immutable {
        /// The path.
        path: PathBuf,
        /// The error of opening it for writing.
        source: std::io::Error,
    },
    /// The existing file belongs to another user in a directory with the sticky bit (as
    /// `/tmp`): it cannot be replaced.
    #[error(
        "refusing to replace {path}: it belongs to another user in {dir}, a directory with the \
         sticky bit (as /tmp), where only its owner may replace it; choose another name"
    )]
    OwnedByAnother {
        /// The path.
        path: PathBuf,
        /// The sticky directory.
        dir: PathBuf,
    },
    /// No file can be created in the directory (permissions, read-only file system, ...).
    #[error(
        "cannot write into {dir} (for {path}): {source}; choose a directory you can write to, \
         or change its permissions"
    )]
    DirectoryNotWritable {
        /// The directory.
        dir: PathBuf,
        /// The output that was to be written there.
        path: PathBuf,
        /// Why creating a file failed.
        source: std::io::Error,
    },
    /// A file name longer than the file system allows.
    #[error(
        "cannot write {path}: the name {name:?} is {len} bytes long, but the file system \
         allows at most {max}; choose a shorter name"
    )]
    NameTooLong {
        /// The path.
        path: PathBuf,
        /// The name (one component).
        name: String,
        /// Its length in bytes.
        len: usize,
        /// The file system's limit (NAME_MAX).
        max: usize,
    },
    /// A kind of file that is never written to: a block device, a socket, standard input.
    #[error("refusing to write {path}: {what}")]
    Unwritable {
        /// The path.
        path: PathBuf,
        /// What it is and why it is not written ("it is a block device (a disk) ...").
        what: String,
    },
    /// A symbolic link to nothing: it is neither followed nor replaced.
    #[error(
        "refusing to write {path}: it is a symbolic link to {target}, which does not exist; \
         remove the link or name the file itself"
    )]
    DanglingLink {
        /// The link.
        path: PathBuf,
        /// What it points to.
        target: PathBuf,
    },
    /// `/dev/fd/N` (or `/proc/self/fd/N`) names a descriptor that is not open for writing.
    #[error(
        "cannot write {path}: descriptor {fd} is {state} (a process substitution >(...) or a \
         redirection N> FILE opens it for writing)"
    )]
    Descriptor {
        /// The path.
        path: PathBuf,
        /// The descriptor number.
        fd: i32,
        /// "not open" or "open for reading only".
        state: &'static str,
    },
    /// The file is where standard output is redirected to (`> FILE` and `--json FILE`).
    #[error(
        "refusing to write {path}: standard output is redirected to it, so the report and \
         this output would destroy each other; choose another name, or - to write it to \
         standard output"
    )]
    IsStandardOutput {
        /// The path.
        path: PathBuf,
    },
    /// Nobody opened the FIFO for reading.
    #[error(
        "cannot write {path}: no process opened this FIFO for reading within {waited_s} s; \
         start the reader first (e.g. cat {path} &), or let the writer wait longer \
         (DIFFBVP_FIFO_WAIT_S=60)"
    )]
    FifoWithoutReader {
        /// The FIFO.
        path: PathBuf,
        /// How long the writer waited \[s\].
        waited_s: f64,
    },
    /// Two outputs of one run are the same file: one would replace the other.
    #[error(
        "{first} and {second} name the same file{}: one would replace the other; choose \
         another name for one of them",
        same_path_note(path)
    )]
    SameOutput {
        /// The shared path (as the first names it).
        path: PathBuf,
        /// The first output (flag and path).
        first: String,
        /// The second output (flag and path).
        second: String,
    },
    /// A path the run did not plan (a program error).
    #[error("internal error: {path} was not among the outputs checked before the run")]
    NotPlanned {
        /// The path.
        path: PathBuf,
    },
    /// A check of a planned output failed: `origin` names the flag or role.
    #[error("{origin}: {source}")]
    Planned {
        /// The flag or role (`--json`, `--out DIR (fit.json)`).
        origin: String,
        /// The failed check.
        #[source]
        source: Box<OutputError>,
    },
    /// I/O failure while writing (the temporary of the write removed).
    #[error("cannot write {path}: {source}{}", io_hint(source))]
    Io {
        /// The path.
        path: PathBuf,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
}

impl OutputError {
    /// The error without the [`OutputError::Planned`] wrappers.
    pub fn innermost(&self) -> &OutputError {
        match self {
            OutputError::Planned { source, .. } => source.innermost(),
            e => e,
        }
    }

    /// The [`OutputError::Io`] of writing `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        OutputError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// `" (the same file as the input X, through a link)"` when the output path names the input
/// under another name; empty when it is the input's own path.
fn alias_note(path: &Path, input: &Path) -> String {
    let same_name = match (std::fs::canonicalize(path), std::fs::canonicalize(input)) {
        (Ok(a), Ok(b)) => a == b && std::fs::symlink_metadata(path).is_ok_and(|m| !m.is_symlink()),
        _ => false,
    };
    if same_name || path == input {
        String::new()
    } else {
        format!(
            " (the same file as the input {}, through a link)",
            input.display()
        )
    }
}

/// What to do after a failed write: for a file beyond the size limit (`ulimit -f`) or a full
/// disk or quota, what limits it; nothing otherwise.
fn io_hint(e: &std::io::Error) -> &'static str {
    #[cfg(unix)]
    {
        match e.raw_os_error() {
            Some(libc::EFBIG) => {
                return "; the file would exceed the file-size limit of this process (`ulimit \
                        -f`, a batch system's limit): raise the limit, or write where larger \
                        files are allowed; nothing was left behind"
            }
            Some(libc::ENOSPC) | Some(libc::EDQUOT) => {
                return "; the disk or your quota is full: free space, or write elsewhere; \
                        nothing was left behind"
            }
            _ => {}
        }
    }
    let _ = e;
    ""
}

/// What the existing `file` is, for messages: `a file`, `a character device`, `a FIFO (named
/// pipe)`, `a socket`, `a block device`.
fn kind_of(file: &Path) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if let Ok(m) = std::fs::metadata(file) {
            let t = m.file_type();
            if t.is_char_device() {
                return "a character device";
            }
            if t.is_block_device() {
                return "a block device";
            }
            if t.is_fifo() {
                return "a FIFO (named pipe)";
            }
            if t.is_socket() {
                return "a socket";
            }
        }
    }
    let _ = file;
    "a file"
}

fn same_path_note(path: &Path) -> String {
    format!(" ({})", path.display())
}
