//! Writing results without ever overwriting an input.

use super::simulate::Profiles;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Writing an output failed.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The output path is one of the inputs.
    #[error("refusing to write {path}: it is an input file; choose another output directory")]
    WouldOverwriteInput {
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

fn same_file(a: &Path, b: &Path) -> bool {
    match (fs::canonicalize(a), fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Fails if `path` exists and is one of `inputs`.
pub fn ensure_not_input(path: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    if path.exists() && inputs.iter().any(|i| same_file(path, i)) {
        return Err(OutputError::WouldOverwriteInput {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// Creates `dir` (and parents).
pub fn create_dir(dir: &Path) -> Result<(), OutputError> {
    fs::create_dir_all(dir).map_err(|source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Writes text to `path` unless it is an input.
pub fn write_text(path: &Path, text: &str, inputs: &[PathBuf]) -> Result<(), OutputError> {
    ensure_not_input(path, inputs)?;
    let mut f = fs::File::create(path).map_err(|source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    f.write_all(text.as_bytes())
        .map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        })
}

/// CSV header of simulated profiles.
pub const PROFILE_HEADER: &str =
    "position_m,velocity_m_s,force_N,temperature_K,strain_rate_1_s,diameter_m";

/// Profiles as CSV text with [`PROFILE_HEADER`].
pub fn profiles_csv(p: &Profiles) -> String {
    let mut s = String::with_capacity(80 * (p.position.len() + 1));
    s.push_str(PROFILE_HEADER);
    s.push('\n');
    for i in 0..p.position.len() {
        s.push_str(&format!(
            "{:.6e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}\n",
            p.position[i],
            p.velocity[i],
            p.force[i],
            p.temperature[i],
            p.strain_rate[i],
            p.diameter[i]
        ));
    }
    s
}
