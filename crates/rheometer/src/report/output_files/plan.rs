//! [`OutputPlan`]: every output of a run, checked before any work against the inputs, against
//! each other and against the file system; [`CheckedOutputs`] writes them.

use super::error::OutputError;
use super::file::OutputFile;
use super::target::{blocking_file, check_directory, check_replaceable, classify, Target};
use super::temporaries::remove_stale_temporaries;
use super::write::{ensure_not_input, same_file, write_target};
use std::fs;
use std::io::{self, Write};
use std::path::{Component, Path, PathBuf};

/// One planned output file.
#[derive(Debug, Clone)]
struct Planned {
    /// The path as the run writes it.
    path: PathBuf,
    /// Who asks for it, for messages: `--json fit.json`, `--out res (its fit.json)`.
    label: String,
}

/// One planned output directory.
#[derive(Debug, Clone)]
struct PlannedDir {
    path: PathBuf,
    label: String,
}

/// Every output of a run, collected before the work starts: the files (`--json`), the
/// output directories (`--out`) with the names of the files written into them, and the
/// inputs they must never replace. [`OutputPlan::check`] validates all of it at once and
/// creates nothing (it only removes the temporaries of ended runs in the output
/// directories).
///
/// ```
/// use rheometer::report::output_files::OutputPlan;
/// let dir = std::path::Path::new("target").join(format!("diffbvp-plan-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let input = dir.join("data.csv");
/// std::fs::write(&input, "1,2\n")?;
/// let mut plan = OutputPlan::new();
/// plan.input(&input);
/// plan.file(dir.join("result.json"), "--json");
/// plan.dir(dir.join("out"), "--out", ["report.txt", "table.csv"]);
/// let outputs = plan.check()?;
/// outputs.write_text(&dir.join("out").join("report.txt"), "done\n")?;
/// // an output that is an input is refused before anything is written
/// let mut bad = OutputPlan::new();
/// bad.input(&input);
/// bad.file(&input, "--json");
/// assert!(bad.check().is_err());
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct OutputPlan {
    inputs: Vec<PathBuf>,
    files: Vec<Planned>,
    dirs: Vec<PlannedDir>,
}

impl OutputPlan {
    /// An empty plan.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an input file: no output may be it (by device and inode, so also not through a
    /// hard or symbolic link).
    pub fn input(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.inputs.push(path.as_ref().to_path_buf());
        self
    }

    /// Adds input files (see [`OutputPlan::input`]).
    pub fn inputs<P: AsRef<Path>>(&mut self, paths: impl IntoIterator<Item = P>) -> &mut Self {
        for p in paths {
            self.input(p);
        }
        self
    }

    /// Adds an output file asked for by `flag` (e.g. `--json`; named in messages with the
    /// path).
    pub fn file(&mut self, path: impl AsRef<Path>, flag: &str) -> &mut Self {
        let path = path.as_ref().to_path_buf();
        let label = format!("{flag} {}", path.display());
        self.files.push(Planned { path, label });
        self
    }

    /// Adds the output directory `dir` asked for by `flag` (e.g. `--out`) with the names of
    /// the files written into it.
    pub fn dir<S: AsRef<str>>(
        &mut self,
        dir: impl AsRef<Path>,
        flag: &str,
        names: impl IntoIterator<Item = S>,
    ) -> &mut Self {
        let dir = dir.as_ref().to_path_buf();
        let label = format!("{flag} {}", dir.display());
        for n in names {
            let n = n.as_ref();
            self.files.push(Planned {
                path: dir.join(n),
                label: format!("{label} (its {n})"),
            });
        }
        self.dirs.push(PlannedDir { path: dir, label });
        self
    }

    /// Adds more file names to the already planned directory `dir` (see [`OutputPlan::dir`]).
    pub fn dir_files<S: AsRef<str>>(
        &mut self,
        dir: impl AsRef<Path>,
        names: impl IntoIterator<Item = S>,
    ) -> &mut Self {
        let dir = dir.as_ref();
        let label = self
            .dirs
            .iter()
            .find(|d| d.path == dir)
            .map_or_else(|| dir.display().to_string(), |d| d.label.clone());
        for n in names {
            let n = n.as_ref();
            self.files.push(Planned {
                path: dir.join(n),
                label: format!("{label} (its {n})"),
            });
        }
        self
    }

    /// Checks every output before any work:
    ///
    /// * each directory: not an input, not a file or below one, writable (a temporary is
    ///   created and removed), every name within NAME_MAX; the temporaries that ended runs
    ///   left in it are removed;
    /// * each file (`classify`): not a directory, block device, socket, standard input or
    ///   dangling link; a regular file not an input, not write-protected, its directory
    ///   writable; a FIFO not an input;
    /// * no two outputs the same file (by device and inode, or by path for new files), and
    ///   at most one on standard output.
    ///
    /// Errors name the flag (`OutputError::Planned`).
    pub fn check(&self) -> Result<CheckedOutputs, OutputError> {
        let mut removed = Vec::new();
        for d in &self.dirs {
            check_dir(&d.path, &self.inputs).map_err(|e| planned(&d.label, e))?;
            removed.extend(remove_stale_temporaries(&d.path));
        }
        // a file that is (a parent of) an output directory: named as such before the file's
        // own check would call it "an existing directory"
        check_files_against_dirs(&self.files, &self.dirs)?;
        let mut targets = Vec::with_capacity(self.files.len());
        for f in &self.files {
            let t = check_file(&f.path, &self.inputs).map_err(|e| planned(&f.label, e))?;
            if let Target::Regular { path, .. } = &t {
                let dir = super::target::parent_dir(path);
                if !self.dirs.iter().any(|d| d.path == dir) {
                    removed.extend(remove_stale_temporaries(dir));
                }
            }
            targets.push((f.clone(), t));
        }
        check_distinct(&targets)?;
        Ok(CheckedOutputs {
            inputs: self.inputs.clone(),
            targets,
            dirs: self.dirs.iter().map(|d| d.path.clone()).collect(),
            removed,
        })
    }
}

fn planned(label: &str, e: OutputError) -> OutputError {
    OutputError::Planned {
        origin: label.to_string(),
        source: Box::new(e),
    }
}

/// Checks an output directory (see [`OutputPlan::check`]).
fn check_dir(dir: &Path, inputs: &[PathBuf]) -> Result<(), OutputError> {
    if dir.as_os_str() == super::target::STDOUT_PATH {
        return Err(OutputError::Unwritable {
            path: dir.to_path_buf(),
            what: "standard output cannot hold a directory of files; name a directory".into(),
        });
    }
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
    // a file that would be created in the directory: its directory (or the first existing
    // ancestor) must accept new files
    check_directory(&dir.join(".probe")).map_err(|e| match e {
        OutputError::DirectoryNotWritable { dir: d, source, .. } => {
            OutputError::DirectoryNotWritable {
                dir: d,
                path: dir.to_path_buf(),
                source,
            }
        }
        e => e,
    })
}

/// Checks one output file (see [`OutputPlan::check`]).
fn check_file(path: &Path, inputs: &[PathBuf]) -> Result<Target, OutputError> {
    let t = classify(path)?;
    match &t {
        Target::Regular { path: real, exists } => {
            // the path as given: a link to an input is named as such
            ensure_not_input(path, inputs)?;
            if *exists {
                check_replaceable(real)?;
            }
            check_directory(real)?;
        }
        Target::Special {
            path: p,
            fifo: true,
        } => ensure_not_input(p, inputs)?,
        Target::Special {
            path: p,
            fifo: false,
        } => probe_device(p)?,
        _ => {}
    }
    Ok(t)
}

/// Whether the character device `path` takes writes, known before the work: it is opened for
/// writing (never created) and given a zero-length write, which writes nothing anywhere but
/// reports the device's refusal (`/dev/full`: "No space left on device"; a device without
/// write permission: "Permission denied"). A device that fails only on real data (a full
/// disk behind a block of a longer write, a terminal hung up later) is still reported when
/// the output is written, after the work.
fn probe_device(path: &Path) -> Result<(), OutputError> {
    let io = |e| OutputError::io(path, e);
    let mut f = fs::OpenOptions::new().write(true).open(path).map_err(io)?;
    // `write`, not `write_all`: a zero-length `write_all` makes no system call
    f.write(&[]).map(|_| ()).map_err(io)
}

/// What makes two outputs the same file.
#[derive(Debug, PartialEq, Eq)]
enum Identity {
    Stdout,
    Descriptor(i32),
    Node(u64, u64),
    Path(PathBuf),
    /// A character device: writing it twice harms nothing.
    Shareable,
}

fn identity(t: &Target) -> Identity {
    match t {
        Target::Stdout => Identity::Stdout,
        Target::Descriptor(fd) => Identity::Descriptor(*fd),
        Target::Special { fifo: false, .. } => Identity::Shareable,
        Target::Special { path, .. } | Target::Regular { path, .. } => node(path)
            .map(|(d, i)| Identity::Node(d, i))
            .unwrap_or_else(|| Identity::Path(normalized(path))),
    }
}

#[cfg(unix)]
fn node(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn node(_path: &Path) -> Option<(u64, u64)> {
    None
}

/// `path` made absolute: the longest existing prefix canonicalised, the rest with `.` and
/// `..` resolved by name.
pub(super) fn normalized(path: &Path) -> PathBuf {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(path)
    };
    let mut base = abs.clone();
    let mut rest = Vec::new();
    loop {
        if let Ok(c) = fs::canonicalize(&base) {
            base = c;
            break;
        }
        // the last component, also `..` (which `file_name` does not return: `out/../out/x`
        // with `out` still missing must name the same file as `out/x`)
        let last = base
            .components()
            .next_back()
            .map(|c| c.as_os_str().to_os_string());
        match (last, base.parent()) {
            (Some(n), Some(p)) => {
                rest.push(n);
                base = p.to_path_buf();
            }
            _ => break,
        }
    }
    let mut out = base;
    for n in rest.iter().rev() {
        for c in Path::new(n).components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::CurDir => {}
                other => out.push(other),
            }
        }
    }
    out
}

/// Refuses two outputs that are the same file.
fn check_distinct(targets: &[(Planned, Target)]) -> Result<(), OutputError> {
    let ids: Vec<Identity> = targets.iter().map(|(_, t)| identity(t)).collect();
    let paths: Vec<PathBuf> = targets.iter().map(|(p, _)| normalized(&p.path)).collect();
    for i in 0..targets.len() {
        for j in 0..i {
            let same_node = ids[i] == ids[j] && ids[i] != Identity::Shareable;
            let shareable = ids[i] == Identity::Shareable || ids[j] == Identity::Shareable;
            if same_node || (!shareable && paths[i] == paths[j]) {
                return Err(OutputError::SameOutput {
                    path: targets[j].0.path.clone(),
                    first: targets[j].0.label.clone(),
                    second: targets[i].0.label.clone(),
                });
            }
        }
    }
    Ok(())
}

/// Refuses a planned file that is an output directory or one of its parents.
fn check_files_against_dirs(files: &[Planned], dirs: &[PlannedDir]) -> Result<(), OutputError> {
    let dir_paths: Vec<PathBuf> = dirs.iter().map(|d| normalized(&d.path)).collect();
    for f in files {
        let path = normalized(&f.path);
        if let Some((d, _)) = dirs
            .iter()
            .zip(&dir_paths)
            .find(|(_, dp)| dp.starts_with(&path))
        {
            return Err(OutputError::SameOutput {
                path: d.path.clone(),
                first: f.label.clone(),
                second: d.label.clone(),
            });
        }
    }
    Ok(())
}

/// The outputs of a run after [`OutputPlan::check`]: writes them (each write classifies its
/// path again, so a file system changed during the work is still written safely).
#[derive(Debug)]
pub struct CheckedOutputs {
    inputs: Vec<PathBuf>,
    targets: Vec<(Planned, Target)>,
    dirs: Vec<PathBuf>,
    removed: Vec<PathBuf>,
}

impl CheckedOutputs {
    /// The inputs no output may replace.
    pub fn inputs(&self) -> &[PathBuf] {
        &self.inputs
    }

    /// Whether one of the outputs goes to standard output (`-`, `/dev/stdout`, ...): a
    /// program then prints its report elsewhere (e.g. on standard error).
    pub fn uses_stdout(&self) -> bool {
        self.targets.iter().any(|(_, t)| *t == Target::Stdout)
    }

    /// How each planned file was classified, in the order planned.
    pub fn targets(&self) -> impl Iterator<Item = (&Path, &Target)> {
        self.targets.iter().map(|(p, t)| (p.path.as_path(), t))
    }

    /// The temporaries of ended runs removed from the output directories by the check.
    pub fn removed_temporaries(&self) -> &[PathBuf] {
        &self.removed
    }

    /// Creates the planned output directories (and their parents).
    pub fn create_dirs(&self) -> Result<(), OutputError> {
        for d in &self.dirs {
            if let Some(file) = blocking_file(d) {
                return Err(OutputError::NotADirectory {
                    path: d.clone(),
                    file,
                });
            }
            fs::create_dir_all(d).map_err(|e| OutputError::io(d, e))?;
        }
        Ok(())
    }

    /// Writes the planned output `path` with `write` (see
    /// `write_file`); an unplanned path is refused
    /// (`OutputError::NotPlanned`).
    pub fn write(
        &self,
        path: &Path,
        write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        if !self.targets.iter().any(|(p, _)| p.path == path) {
            return Err(OutputError::NotPlanned {
                path: path.to_path_buf(),
            });
        }
        let now = classify(path)?;
        write_target(&now, path, &self.inputs, write)
    }

    /// Writes the planned output `file` (see [`CheckedOutputs::write`]).
    pub fn write_output(&self, file: &OutputFile) -> Result<(), OutputError> {
        self.write(&file.path, |w| w.write_all(&file.bytes))
    }

    /// Writes `text` to the planned output `path` (see [`CheckedOutputs::write`]).
    pub fn write_text(&self, path: &Path, text: &str) -> Result<(), OutputError> {
        self.write(path, |w| w.write_all(text.as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The refusal behind the planned output's label, after checking that the label names
    /// the flag `flag`.
    fn refusal(e: OutputError, flag: &str) -> OutputError {
        match e {
            OutputError::Planned { origin, source } => {
                assert!(origin.starts_with(flag), "{origin}");
                *source
            }
            e => panic!("not labelled with its flag: {e}"),
        }
    }

    use super::super::scratch;

    #[test]
    fn hard_and_symbolic_links_to_an_input_are_refused() {
        let d = scratch("plan-links");
        let input = d.join("data.csv");
        fs::write(&input, b"keep me").unwrap();
        let hard = d.join("hard.json");
        fs::hard_link(&input, &hard).unwrap();
        let mut links = vec![hard];
        #[cfg(unix)]
        {
            let sym = d.join("sym.json");
            std::os::unix::fs::symlink(&input, &sym).unwrap();
            links.push(sym);
        }
        for link in &links {
            let err = OutputPlan::new()
                .input(&input)
                .file(link, "--json")
                .check()
                .unwrap_err();
            let err = refusal(err, "--json");
            assert!(
                matches!(err, OutputError::WouldOverwriteInput { .. }),
                "{}: {err}",
                link.display()
            );
        }
        assert_eq!(fs::read(&input).unwrap(), b"keep me");
    }

    #[test]
    fn writes_replace_atomically_and_leave_no_temporary() {
        let d = scratch("plan-atomic");
        let p = d.join("out.txt");
        let outputs = OutputPlan::new().file(&p, "--out").check().unwrap();
        outputs.write_text(&p, "first").unwrap();
        outputs
            .write_output(&OutputFile::new(&p, "second"))
            .unwrap();
        assert_eq!(fs::read_to_string(&p).unwrap(), "second");
        let failed = outputs.write(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk on fire"))
        });
        assert!(failed.is_err());
        assert_eq!(fs::read_to_string(&p).unwrap(), "second");
        let names: Vec<_> = fs::read_dir(&d)
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        let unplanned = outputs.write_text(&d.join("other.txt"), "x").unwrap_err();
        assert!(
            matches!(unplanned, OutputError::NotPlanned { .. }),
            "{unplanned}"
        );
    }

    #[test]
    fn output_directory_checks_name_the_blocking_file() {
        let d = scratch("plan-dirs");
        let input = d.join("v.csv");
        fs::write(&input, b"1").unwrap();
        let no_names: [&str; 0] = [];
        let e = OutputPlan::new()
            .input(&input)
            .dir(&input, "--dir", no_names)
            .check()
            .unwrap_err();
        let e = refusal(e, "--dir");
        assert!(matches!(e, OutputError::DirectoryIsInput { .. }), "{e}");
        let e = OutputPlan::new()
            .dir(input.join("sub"), "--dir", no_names)
            .check()
            .unwrap_err();
        assert!(e.to_string().contains("v.csv"), "{e}");
        let e = OutputPlan::new()
            .input(&input)
            .dir(&d, "--dir", ["v.csv"])
            .check()
            .unwrap_err();
        let e = refusal(e, "--dir");
        assert!(matches!(e, OutputError::WouldOverwriteInput { .. }), "{e}");
        OutputPlan::new()
            .input(&input)
            .dir(&d, "--dir", ["new.csv"])
            .check()
            .unwrap();
    }
}
