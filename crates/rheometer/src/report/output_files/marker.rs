//! [`PartialMarker`]: a manifest file that marks an output directory as incomplete while its
//! files are written, so that a run that fails, is interrupted or killed leaves a visible
//! mark and the list of what is missing.

use super::error::OutputError;
use super::write::{ensure_not_input, write_bytes};
use std::fs;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Name of the manifest of an incomplete output directory.
pub const PARTIAL_NAME: &str = "PARTIAL.txt";

/// The manifest `DIR/PARTIAL.txt` of an output directory being written:
///
/// ```text
/// # TITLE: INCOMPLETE output (still running, interrupted or failed).
/// # This file is removed once every file is written.
/// # 1 of 3 WHAT written
/// complete LABEL FILE
/// missing LABEL FILE
/// ```
///
/// Written by [`PartialMarker::begin`] before the first file, rewritten by
/// [`PartialMarker::done`] after each, removed by [`PartialMarker::finish`] after the last:
/// a run ended at any point (also by `kill -9`) leaves the directory marked.
#[derive(Debug, Clone)]
pub struct PartialMarker {
    path: PathBuf,
    title: String,
    what: String,
    entries: Vec<(String, String, bool)>,
    inputs: Vec<PathBuf>,
}

impl PartialMarker {
    /// A manifest for `dir` listing `entries` `(label, file name)` as missing; `title` names
    /// the program, `what` the kind of files (`"profiles"`, `"files"`). Nothing is written
    /// yet.
    pub fn new(
        dir: &Path,
        title: &str,
        what: &str,
        entries: impl IntoIterator<Item = (String, String)>,
        inputs: &[PathBuf],
    ) -> Self {
        PartialMarker {
            path: dir.join(PARTIAL_NAME),
            title: title.to_string(),
            what: what.to_string(),
            entries: entries.into_iter().map(|(l, f)| (l, f, false)).collect(),
            inputs: inputs.to_vec(),
        }
    }

    /// The manifest's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The manifest's text.
    pub fn text(&self) -> String {
        let done = self.entries.iter().filter(|e| e.2).count();
        let mut t = format!(
            "# {}: INCOMPLETE output (still running, interrupted or failed).\n\
             # This file is removed once every file is written.\n\
             # {done} of {} {} written\n",
            self.title,
            self.entries.len(),
            self.what
        );
        for (label, file, ok) in &self.entries {
            let state = if *ok { "complete" } else { "missing" };
            t.push_str(&format!("{state} {label} {file}\n"));
        }
        t
    }

    /// Writes the manifest (every entry missing, unless marked done).
    pub fn begin(&self) -> Result<(), OutputError> {
        write_bytes(&self.path, &self.inputs, self.text().as_bytes())
    }

    /// Marks the entry of file `file` as written and rewrites the manifest.
    pub fn done(&mut self, file: &str) -> Result<(), OutputError> {
        for e in self.entries.iter_mut().filter(|e| e.1 == file) {
            e.2 = true;
        }
        self.begin()
    }

    /// Marks done every entry whose file exists and was modified at or after `since` (the
    /// start of the writing): brings the manifest up to date after a failed write.
    pub fn mark_written_since(&mut self, since: SystemTime) {
        let dir = self.path.parent().unwrap_or(Path::new(".")).to_path_buf();
        for e in self.entries.iter_mut().filter(|e| !e.2) {
            let modified = fs::metadata(dir.join(&e.1)).and_then(|m| m.modified());
            e.2 = modified.is_ok_and(|t| t >= since);
        }
    }

    /// Removes the manifest (every file is written). A missing manifest is fine.
    pub fn finish(&self) -> Result<(), OutputError> {
        ensure_not_input(&self.path, &self.inputs)?;
        match fs::remove_file(&self.path) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
            Err(e) => Err(OutputError::io(&self.path, e)),
        }
    }
}
