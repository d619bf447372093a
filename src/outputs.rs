//! The outputs of a command: planned before the work (every file, with the inputs they must
//! not replace), checked at once, written through the checked plan; an output directory is
//! marked incomplete (`DIR/PARTIAL.txt`) from its first file to its last.

use crate::*;
use rheometer::report::output_files::{
    CheckedOutputs, OutputFile, OutputPlan, PartialMarker, PARTIAL_NAME,
};
use std::time::SystemTime;

/// A plan whose inputs are the experiments file `toml` and its data files.
pub fn plan_for(toml: &Path, loaded: &LoadedExperiments) -> OutputPlan {
    let mut plan = OutputPlan::new();
    plan.input(toml);
    plan.inputs(loaded.details.iter().filter_map(|d| d.data.as_ref()));
    plan
}

/// Checks `plan` before the work: on success the report moves to stderr when an output
/// takes stdout (`--json -`), and the removed temporaries of ended runs are mentioned.
pub fn check(plan: &OutputPlan, g: &Global) -> Result<CheckedOutputs, Box<dyn Error>> {
    let checked = plan.check()?;
    if checked.uses_stdout() {
        if streams::stdout_was_closed() {
            return Err(
                "an output goes to standard output (- or /dev/stdout), but standard \
                        output is closed (>&-); name a file instead"
                    .into(),
            );
        }
        streams::report_to_stderr();
    }
    for p in checked.removed_temporaries() {
        g.say(format!(
            "removed {}, a temporary left behind by an ended run",
            p.display()
        ));
    }
    Ok(checked)
}

/// An output directory being written: its files are marked done in `DIR/PARTIAL.txt` one by
/// one; the manifest is removed after the last (see [`DirWriter::finish`]).
pub struct DirWriter<'a> {
    outputs: &'a CheckedOutputs,
    dir: PathBuf,
    marker: PartialMarker,
    started: SystemTime,
}

impl<'a> DirWriter<'a> {
    /// Creates `dir` and writes its manifest listing `entries` `(label, file name)` as missing
    /// (`title` names the command, e.g. `rheometer fit`).
    pub fn begin(
        outputs: &'a CheckedOutputs,
        dir: &Path,
        title: &str,
        what: &str,
        entries: Vec<(String, String)>,
    ) -> Result<Self, Box<dyn Error>> {
        outputs.create_dirs()?;
        let marker = PartialMarker::new(dir, title, what, entries, outputs.inputs());
        marker.begin()?;
        Ok(DirWriter {
            outputs,
            dir: dir.to_path_buf(),
            marker,
            started: SystemTime::now(),
        })
    }

    /// The path of file `name` in the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes the file `name` with `write` and marks it done.
    pub fn write(
        &mut self,
        name: &str,
        write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Result<(), Box<dyn Error>> {
        let r = self.outputs.write(&self.dir.join(name), write);
        self.after(name, r.map_err(Into::into))
    }

    /// Writes `text` to the file `name` and marks it done.
    pub fn text(&mut self, name: &str, text: &str) -> Result<(), Box<dyn Error>> {
        self.write(name, |w| w.write_all(text.as_bytes()))
    }

    /// Runs `f`, which renders files of the directory in memory (figures, a comparison's
    /// set), then writes each through the checked outputs and marks it done; returns their
    /// paths.
    pub fn rendered<E: Into<Box<dyn Error>>>(
        &mut self,
        f: impl FnOnce(&Path) -> Result<Vec<OutputFile>, E>,
    ) -> Result<Vec<PathBuf>, Box<dyn Error>> {
        let files = match f(&self.dir) {
            Ok(files) => files,
            Err(e) => return Err(self.failed(e.into())),
        };
        let mut paths = Vec::with_capacity(files.len());
        for file in &files {
            let r = self.outputs.write_output(file);
            let name = file
                .path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned());
            self.after(&name.unwrap_or_default(), r.map_err(Into::into))?;
            paths.push(file.path.clone());
        }
        Ok(paths)
    }

    fn after(&mut self, name: &str, r: Result<(), Box<dyn Error>>) -> Result<(), Box<dyn Error>> {
        match r {
            Ok(()) => {
                self.marker.done(name)?;
                Ok(())
            }
            Err(e) => Err(self.failed(e)),
        }
    }

    /// The error `e` of a write, after the manifest was brought up to date (files written
    /// since the start marked done) and with a note naming it.
    pub fn failed(&mut self, e: Box<dyn Error>) -> Box<dyn Error> {
        let since = self.started;
        self.marker.mark_written_since(since);
        let note = match self.marker.begin() {
            Ok(()) => format!(
                "the output set in {} is incomplete: {} lists the files written and the \
                 missing ones",
                self.dir.display(),
                self.dir.join(PARTIAL_NAME).display()
            ),
            Err(_) => format!("the output set in {} is incomplete", self.dir.display()),
        };
        format!("{e}\n  note: {note}").into()
    }

    /// Removes the manifest: every file is written.
    pub fn finish(self) -> Result<(), Box<dyn Error>> {
        self.marker.finish()?;
        Ok(())
    }
}
