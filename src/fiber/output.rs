//! Writing results without ever overwriting an input, and without ever leaving a half-written
//! file.
//!
//! * An output is refused if it *is* an input: the same file by device and inode on Unix (so
//!   hard links and symbolic links to an input are recognised), by canonical path elsewhere.
//! * Every file is written to a temporary sibling (`.NAME.tmp-PID-N` in the target directory)
//!   and renamed into place when complete: a failed or interrupted write leaves either the old
//!   file or nothing, never a truncated one, and the temporary is removed on failure.
//! * An output directory may be the data directory itself: new files are written next to the
//!   inputs, and only a name that collides with an input is refused.

use super::simulate::Profiles;
use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Writing an output failed.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The output path is one of the inputs (also through a hard or symbolic link).
    #[error(
        "refusing to write {path}: it is an input file{}; choose another output directory",
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
        "refusing to use {path} as the output directory: it is an input file; \
         choose another output directory"
    )]
    DirectoryIsInput {
        /// The path.
        path: PathBuf,
    },
    /// The output directory, or one of its parents, exists and is not a directory.
    #[error(
        "cannot create the output directory {path}: {file} exists and is a file, not a directory"
    )]
    NotADirectory {
        /// The requested directory.
        path: PathBuf,
        /// The existing file in its way (the directory itself or a parent).
        file: PathBuf,
    },
    /// An output file path is an existing directory.
    #[error("cannot write {path}: it is an existing directory")]
    IsADirectory {
        /// The path.
        path: PathBuf,
    },
    /// I/O failure.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
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

/// Fails if `path` exists and is one of `inputs` (the same file, see [`same_file`]), or if it
/// is an existing directory.
pub fn ensure_not_input(path: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    // symlink_metadata: a dangling symbolic link "exists" too (it would be followed on write)
    if fs::symlink_metadata(path).is_err() {
        return Ok(());
    }
    if let Some(input) = inputs.iter().find(|i| same_file(path, i)) {
        return Err(OutputError::WouldOverwriteInput {
            path: path.to_path_buf(),
            input: input.clone(),
        });
    }
    if path.is_dir() {
        return Err(OutputError::IsADirectory {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// `" (the same file as the input X, through a link)"` when the output path names the input
/// under another name; empty when it is the input's own path.
fn alias_note(path: &Path, input: &Path) -> String {
    let same_name = match (fs::canonicalize(path), fs::canonicalize(input)) {
        (Ok(a), Ok(b)) => a == b && fs::symlink_metadata(path).is_ok_and(|m| !m.is_symlink()),
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

/// The first of `dir` and its ancestors that exists and is not a directory.
fn blocking_file(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .find(|a| a.exists() && !a.is_dir())
        .map(Path::to_path_buf)
}

/// Creates `dir` (and parents). A `dir` that is, or lies below, an existing file gives
/// [`OutputError::NotADirectory`] naming that file.
pub fn create_dir(dir: &Path) -> Result<(), OutputError> {
    if let Some(file) = blocking_file(dir) {
        return Err(OutputError::NotADirectory {
            path: dir.to_path_buf(),
            file,
        });
    }
    fs::create_dir_all(dir).map_err(|source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Checks an output directory before any work starts: refuses a `dir` that is one of `inputs`
/// ([`OutputError::DirectoryIsInput`]) or an existing file, and refuses every file of `names`
/// (written into `dir`) that is an input. Creates nothing.
pub fn check_output_dir(
    dir: &Path,
    names: &[String],
    inputs: &[PathBuf],
) -> Result<(), OutputError> {
    if inputs.iter().any(|i| same_file(dir, i)) {
        return Err(OutputError::DirectoryIsInput {
            path: dir.to_path_buf(),
        });
    }
    if let Some(file) = blocking_file(dir) {
        return Err(OutputError::NotADirectory {
            path: dir.to_path_buf(),
            file,
        });
    }
    for name in names {
        ensure_not_input(&dir.join(name), inputs)?;
    }
    Ok(())
}

/// Creates the output directory `dir` after [`check_output_dir`]`(dir, &[], inputs)`.
pub fn create_output_dir(dir: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    check_output_dir(dir, &[], inputs)?;
    create_dir(dir)
}

pub use crate::atomic_write::{remove_pending_temporaries, temporary_sibling};

/// Writes `path` atomically: `write` fills a temporary sibling (see [`temporary_sibling`]),
/// which is then renamed over `path`. Refuses an input first ([`ensure_not_input`]). On any
/// failure the temporary is removed and `path` is untouched.
pub fn write_atomically(
    path: &Path,
    inputs: &[PathBuf],
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    ensure_not_input(path, inputs)?;
    let pending = crate::atomic_write::PendingTemporary::new(path);
    let tmp = pending.path();
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let result = (|| {
        let file = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(tmp)?;
        let mut w = BufWriter::with_capacity(1 << 16, file);
        write(&mut w)?;
        // flush errors (a full disk) surface here, before the rename
        w.into_inner().map_err(|e| e.into_error())?;
        fs::rename(tmp, path)
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(tmp);
        return Err(io(e));
    }
    Ok(())
}

/// Writes text to `path` unless it is an input, atomically (see [`write_atomically`]).
pub fn write_text(path: &Path, text: &str, inputs: &[PathBuf]) -> Result<(), OutputError> {
    write_atomically(path, inputs, |w| w.write_all(text.as_bytes()))
}

/// CSV header of simulated profiles.
pub const PROFILE_HEADER: &str =
    "position_m,velocity_m_s,force_N,temperature_K,strain_rate_1_s,diameter_m";

/// Writes profiles as CSV with [`PROFILE_HEADER`] to `w`, row by row (no string of the whole
/// table is built).
pub fn write_profiles_csv(w: &mut dyn Write, p: &Profiles) -> std::io::Result<()> {
    writeln!(w, "{PROFILE_HEADER}")?;
    for i in 0..p.position.len() {
        writeln!(
            w,
            "{:.6e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
            p.position[i],
            p.velocity[i],
            p.force[i],
            p.temperature[i],
            p.strain_rate[i],
            p.diameter[i]
        )?;
    }
    Ok(())
}

/// Writes profiles as CSV ([`PROFILE_HEADER`]) to `path`, streamed and atomically, unless
/// `path` is an input.
pub fn write_profiles(path: &Path, p: &Profiles, inputs: &[PathBuf]) -> Result<(), OutputError> {
    write_atomically(path, inputs, |w| write_profiles_csv(w, p))
}

/// Profiles as CSV text with [`PROFILE_HEADER`] (for large tables prefer [`write_profiles`],
/// which streams).
pub fn profiles_csv(p: &Profiles) -> String {
    let mut v = Vec::with_capacity(80 * (p.position.len() + 1));
    // writing into a Vec cannot fail
    let _ = write_profiles_csv(&mut v, p);
    String::from_utf8_lossy(&v).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("diffbvp-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn hard_and_symbolic_links_to_an_input_are_refused() {
        let d = scratch("links");
        let input = d.join("data.csv");
        fs::write(&input, b"keep me").unwrap();
        let hard = d.join("hard.json");
        fs::hard_link(&input, &hard).unwrap();
        let err = write_text(&hard, "x", std::slice::from_ref(&input)).unwrap_err();
        assert!(
            matches!(err, OutputError::WouldOverwriteInput { .. }),
            "{err}"
        );
        #[cfg(unix)]
        {
            let sym = d.join("sym.json");
            std::os::unix::fs::symlink(&input, &sym).unwrap();
            let err = write_text(&sym, "x", std::slice::from_ref(&input)).unwrap_err();
            assert!(
                matches!(err, OutputError::WouldOverwriteInput { .. }),
                "{err}"
            );
        }
        assert_eq!(fs::read(&input).unwrap(), b"keep me");
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let d = scratch("atomic");
        let p = d.join("out.txt");
        write_text(&p, "first", &[]).unwrap();
        write_text(&p, "second", &[]).unwrap();
        assert_eq!(fs::read_to_string(&p).unwrap(), "second");
        let failed = write_atomically(&p, &[], |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk on fire"))
        });
        assert!(failed.is_err());
        assert_eq!(fs::read_to_string(&p).unwrap(), "second");
        let names: Vec<_> = fs::read_dir(&d)
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }

    #[test]
    fn output_directory_checks_name_the_blocking_file() {
        let d = scratch("dirs");
        let input = d.join("v.csv");
        fs::write(&input, b"1").unwrap();
        let inputs = [input.clone()];
        let e = check_output_dir(&input, &[], &inputs).unwrap_err();
        assert!(matches!(e, OutputError::DirectoryIsInput { .. }), "{e}");
        let e = create_dir(&input.join("sub")).unwrap_err();
        assert!(e.to_string().contains("v.csv"), "{e}");
        let e = check_output_dir(&d, &["v.csv".into()], &inputs).unwrap_err();
        assert!(matches!(e, OutputError::WouldOverwriteInput { .. }), "{e}");
        check_output_dir(&d, &["new.csv".into()], &inputs).unwrap();
    }

    #[test]
    fn streamed_profiles_equal_the_string() {
        let p = Profiles {
            position: vec![0.0, 0.5, 1.0],
            velocity: vec![1.0, 2.0, 3.0],
            force: vec![0.1; 3],
            temperature: vec![500.0; 3],
            strain_rate: vec![0.0, 1.0, 2.0],
            diameter: vec![1e-3, 5e-4, 2e-4],
            ..Profiles::default()
        };
        let d = scratch("profiles");
        let path = d.join("p.csv");
        write_profiles(&path, &p, &[]).unwrap();
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text, profiles_csv(&p));
        assert_eq!(text.lines().count(), 4);
    }
}
