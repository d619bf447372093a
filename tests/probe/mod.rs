//! A harness for probing the `rheometer` program and the library with bad or extreme inputs.
//!
//! Every probe runs in its own scratch copy of a data set, checksums every input file before
//! and after, and reports what happened: exit code, whether the program panicked, stdout and
//! stderr. Tests assert on these; [`Probe::assert_clean_failure`] bundles the usual checks
//! (failed with exit code 1 or 2, no panic, message names what it must, inputs unchanged).
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The repository root (where `data/` lives).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh scratch directory under the target directory, unique per test name.
pub fn scratch(name: &str) -> PathBuf {
    let dir = repo()
        .join("target")
        .join("probes")
        .join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// Copies a shipped data set (`data/<set>`) into `dir/<set>` and returns the TOML's path.
pub fn copy_data_set(set: &str, dir: &Path) -> PathBuf {
    let from = repo().join("data").join(set);
    let to = dir.join(set);
    copy_tree(&from, &to);
    to.join("experiments.toml")
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create dir");
    for entry in std::fs::read_dir(from).expect("read dir") {
        let entry = entry.expect("dir entry");
        let p = entry.path();
        let q = to.join(entry.file_name());
        if p.is_dir() {
            copy_tree(&p, &q);
        } else {
            std::fs::copy(&p, &q).expect("copy file");
        }
    }
}

/// A scratch copy of the shipped `pmma7n_synthetic` data set for test `name`: (scratch dir,
/// TOML path, data dir).
pub fn shipped_copy(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = scratch(name);
    let toml = copy_data_set("pmma7n_synthetic", &dir);
    let data = dir.join("pmma7n_synthetic");
    (dir, toml, data)
}

/// A path as `&str` (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// A variant of `toml` with the first `from` replaced by `to`, written next to it as `file`
/// (the line structure unchanged); returns its path.
pub fn variant(toml: &Path, file: &str, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(toml).expect("read TOML");
    assert!(text.contains(from), "{from:?} not in {}", toml.display());
    let out = toml.with_file_name(file);
    std::fs::write(&out, text.replacen(from, to, 1)).expect("write variant");
    out
}

/// The 1-based number of the first line of `path` for which `matches` holds.
pub fn line_where(path: &Path, matches: impl Fn(&str) -> bool) -> usize {
    let text = std::fs::read_to_string(path).expect("read file");
    text.lines()
        .position(matches)
        .unwrap_or_else(|| panic!("no such line in {}", path.display()))
        + 1
}

/// A 64-bit checksum of a file's bytes (None if it cannot be read).
pub fn checksum(path: &Path) -> Option<u64> {
    let bytes = std::fs::read(path).ok()?;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    bytes.hash(&mut h);
    bytes.len().hash(&mut h);
    Some(h.finish())
}

/// Checksums of every regular file below `dir` (recursively), by path.
pub fn checksums_below(dir: &Path) -> BTreeMap<PathBuf, Option<u64>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            let Ok(meta) = std::fs::symlink_metadata(&p) else {
                continue;
            };
            if meta.is_dir() {
                stack.push(p);
            } else if meta.is_file() {
                out.insert(p.clone(), checksum(&p));
            }
        }
    }
    out
}

/// What one run of the program did.
#[derive(Debug)]
pub struct Probe {
    /// The arguments (for messages).
    pub args: Vec<String>,
    /// Exit code (None if killed by a signal).
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
    /// Wall time.
    pub elapsed: Duration,
    /// Files (watched inputs) whose content changed or that disappeared.
    pub changed_inputs: Vec<PathBuf>,
}

impl Probe {
    /// Whether the program panicked (Rust's panic message on stderr, or exit code 101).
    pub fn panicked(&self) -> bool {
        self.code == Some(101) || self.stderr.contains("panicked at")
    }

    /// Asserts: a failure with exit code 1 or 2 (clap's usage errors), no panic, every needle
    /// (case-insensitive) in stderr, no input changed.
    pub fn assert_clean_failure(&self, needles: &[&str]) {
        assert!(
            !self.panicked(),
            "{:?} panicked:\n{}",
            self.args,
            self.stderr
        );
        assert!(
            matches!(self.code, Some(1) | Some(2)),
            "{:?}: expected exit code 1 or 2, got {:?}\nstderr:\n{}",
            self.args,
            self.code,
            self.stderr
        );
        let low = self.stderr.to_lowercase();
        for n in needles {
            assert!(
                low.contains(&n.to_lowercase()),
                "{:?}: stderr does not mention {n:?}:\n{}",
                self.args,
                self.stderr
            );
        }
        self.assert_inputs_unchanged();
    }

    /// Asserts success (exit 0), no panic, inputs unchanged.
    pub fn assert_success(&self) {
        assert!(
            !self.panicked(),
            "{:?} panicked:\n{}",
            self.args,
            self.stderr
        );
        assert_eq!(
            self.code,
            Some(0),
            "{:?} failed:\nstdout:\n{}\nstderr:\n{}",
            self.args,
            self.stdout,
            self.stderr
        );
        self.assert_inputs_unchanged();
    }

    /// Asserts that no watched input changed.
    pub fn assert_inputs_unchanged(&self) {
        assert!(
            self.changed_inputs.is_empty(),
            "{:?} modified inputs {:?}",
            self.args,
            self.changed_inputs
        );
    }
}

/// Runs `rheometer ARGS` with `watch` (files or directories whose files must stay unchanged),
/// standard input closed, and a time limit after which the child is killed and the probe fails.
pub fn rheometer(args: &[&str], watch: &[&Path], limit: Duration) -> Probe {
    run_with(args, watch, limit, |c| c)
}

/// Like [`rheometer`], with the command adjusted by `f` before it starts (e.g. stdout to
/// `/dev/full`).
pub fn run_with(
    args: &[&str],
    watch: &[&Path],
    limit: Duration,
    f: impl FnOnce(&mut Command) -> &mut Command,
) -> Probe {
    let before = watched(watch);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rheometer"));
    cmd.args(args)
        .current_dir(repo())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    f(&mut cmd);
    let t0 = Instant::now();
    let child = cmd.spawn().expect("start rheometer");
    let out = wait_with_limit(child, limit, args);
    let elapsed = t0.elapsed();
    let after = watched(watch);
    let changed_inputs = before
        .iter()
        .filter(|(p, c)| after.get(*p) != Some(c))
        .map(|(p, _)| p.clone())
        .collect();
    Probe {
        args: args.iter().map(|s| s.to_string()).collect(),
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        elapsed,
        changed_inputs,
    }
}

fn watched(watch: &[&Path]) -> BTreeMap<PathBuf, Option<u64>> {
    let mut all = BTreeMap::new();
    for w in watch {
        if w.is_dir() {
            all.extend(checksums_below(w));
        } else {
            all.insert(w.to_path_buf(), checksum(w));
        }
    }
    all
}

fn wait_with_limit(mut child: std::process::Child, limit: Duration, args: &[&str]) -> Output {
    // drain the pipes on threads so a chatty child cannot block on a full pipe
    let mut so = child.stdout.take();
    let mut se = child.stderr.take();
    let t_out = std::thread::spawn(move || {
        let mut v = Vec::new();
        if let Some(s) = so.as_mut() {
            let _ = std::io::Read::read_to_end(s, &mut v);
        }
        v
    });
    let t_err = std::thread::spawn(move || {
        let mut v = Vec::new();
        if let Some(s) = se.as_mut() {
            let _ = std::io::Read::read_to_end(s, &mut v);
        }
        v
    });
    let t0 = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("wait") {
            break st;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still running after {limit:?}: killed");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Output {
        status,
        stdout: t_out.join().unwrap_or_default(),
        stderr: t_err.join().unwrap_or_default(),
    }
}
