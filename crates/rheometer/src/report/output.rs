//! Writing results without ever overwriting an input, and without ever leaving a half-written
//! file: the rheometer's use of the generic output layer [`crate::report::output_files`].
//!
//! * An output is refused if it *is* an input: the same file by device and inode on Unix (so
//!   hard links and symbolic links to an input are recognised), by canonical path elsewhere.
//! * A regular file is written to a temporary in its directory and renamed into place when
//!   complete: a failed or interrupted write leaves either the old file or nothing, never a
//!   truncated one. Character devices, FIFOs, `/dev/fd/N` and `-` (standard output) are
//!   written in place.
//! * An output directory may be the data directory itself: new files are written next to the
//!   inputs, and only a name that collides with an input is refused.
//!
//! A command collects its outputs in an [`OutputPlan`] and checks them all before any work.

use crate::model::simulate::Profiles;
pub use crate::report::output_files::{
    blocking_file, remove_pending_temporaries, same_file, CheckedOutputs, OutputError, OutputPlan,
    PartialMarker, PARTIAL_NAME,
};
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Fails if `path` exists and is one of `inputs` (the same file, see [`same_file`]), or if it
/// is an existing directory.
pub(crate) fn ensure_not_input(path: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    crate::report::output_files::ensure_not_input(path, inputs)?;
    if path.is_dir() {
        return Err(OutputError::IsADirectory {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// Creates `dir` (and parents). A `dir` that is, or lies below, an existing file gives
/// [`OutputError::NotADirectory`] naming that file.
pub(crate) fn create_dir(dir: &Path) -> Result<(), OutputError> {
    if let Some(file) = blocking_file(dir) {
        return Err(OutputError::NotADirectory {
            path: dir.to_path_buf(),
            file,
        });
    }
    fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))
}

/// Checks an output directory: refuses a `dir` that is one of `inputs`
/// ([`OutputError::DirectoryIsInput`]) or an existing file, and refuses every file of `names`
/// (written into `dir`) that is an input. Creates nothing. (A command checks all its outputs
/// at once with an [`OutputPlan`].)
pub(crate) fn check_output_dir(
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
pub(crate) fn create_output_dir(dir: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    check_output_dir(dir, &[], inputs)?;
    create_dir(dir)
}

/// Writes the output `path` with `write`, never over one of `inputs` (see
/// [`output_files::write_file`](crate::report::output_files::write_file): regular files atomically,
/// special files in place).
pub(crate) fn write_atomically(
    path: &Path,
    inputs: &[PathBuf],
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    crate::report::output_files::write_file(path, inputs, write)
}

/// Writes text to `path` unless it is an input (see `write_atomically`).
pub fn write_text(path: &Path, text: &str, inputs: &[PathBuf]) -> Result<(), OutputError> {
    write_atomically(path, inputs, |w| w.write_all(text.as_bytes()))
}

/// CSV header of simulated profiles.
pub(crate) const PROFILE_HEADER: &str =
    "position_m,velocity_m_s,force_N,temperature_K,strain_rate_1_s,diameter_m";

/// The column [`write_profiles_csv`] adds after [`PROFILE_HEADER`]'s for a model with gauge
/// effects: what the gauge reads ([`Profiles::gauge_reading`]).
pub(crate) const GAUGE_READING_COLUMN: &str = "gauge_reading_m";

/// Writes profiles as CSV with `PROFILE_HEADER` to `w`, row by row (no string of the whole
/// table is built); with gauge effects a last column `GAUGE_READING_COLUMN`.
pub fn write_profiles_csv(w: &mut dyn Write, p: &Profiles) -> std::io::Result<()> {
    match &p.gauge_reading {
        Some(_) => writeln!(w, "{PROFILE_HEADER},{GAUGE_READING_COLUMN}")?,
        None => writeln!(w, "{PROFILE_HEADER}")?,
    }
    for i in 0..p.position.len() {
        write!(
            w,
            "{:.6e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
            p.position[i],
            p.velocity[i],
            p.force[i],
            p.temperature[i],
            p.strain_rate[i],
            p.diameter[i]
        )?;
        match &p.gauge_reading {
            Some(g) => writeln!(w, ",{:.10e}", g[i])?,
            None => writeln!(w)?,
        }
    }
    Ok(())
}

/// Writes profiles as CSV (`PROFILE_HEADER`) to `path`, streamed and atomically, unless
/// `path` is an input.
pub fn write_profiles(path: &Path, p: &Profiles, inputs: &[PathBuf]) -> Result<(), OutputError> {
    write_atomically(path, inputs, |w| write_profiles_csv(w, p))
}

/// Profiles as CSV text with `PROFILE_HEADER` (for large tables prefer [`write_profiles`],
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
        let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("target")
            .join("unit-scratch")
            .join(format!("fiber-output-{name}-{}", std::process::id()));
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
