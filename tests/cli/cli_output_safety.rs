//! Never lose an input, never lose output, exit codes that tell the truth (issue 13).
//!
//! Probes of `rheometer` with outputs that are (links to) inputs, output directories that are
//! files or data directories, standard streams that fail or close, SIGINT during long runs,
//! and very many experiments. Every probe checksums the inputs before and after.
#![cfg(unix)]

use crate::probe;
use rheometer::data::input::LoadOptions;

use probe::{checksums_below, rheometer, run_with, s, shipped_copy, Probe};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(120);

/// Names of files in `dir` that are leftovers of atomic writes.
fn temporaries(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.contains(".tmp-"))
                .collect()
        })
        .unwrap_or_default()
}

/// Writes `copies` copies of every experiment of the data set's TOML (names suffixed `_cK`,
/// same measurement files) into `data/name` and returns its path.
fn many_experiments(data: &Path, name: &str, copies: usize) -> PathBuf {
    let text = fs::read_to_string(data.join("experiments.toml")).unwrap();
    let (head, rest) = text.split_once("[[experiment]]").unwrap();
    let blocks: Vec<&str> = rest.split("[[experiment]]").collect();
    let mut out = head.to_string();
    for c in 0..copies {
        for b in &blocks {
            let renamed: String = b
                .lines()
                .map(|l| match l.strip_prefix("name = \"") {
                    Some(n) => format!("name = \"{}_c{c}\"", n.trim_end_matches('"')),
                    None => l.to_string(),
                })
                .collect::<Vec<_>>()
                .join("\n");
            out.push_str("[[experiment]]");
            out.push_str(&renamed);
            out.push('\n');
        }
    }
    let path = data.join(name);
    fs::write(&path, out).unwrap();
    path
}

fn profile_files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with("_profile.csv") && !n.starts_with('.'))
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------------------------------------
// Outputs that are inputs

#[test]
fn json_hard_link_to_a_measurement_csv_is_refused() {
    let (dir, toml, data) = shipped_copy("hard_link_json");
    let hard = dir.join("hard.json");
    fs::hard_link(data.join("v0p27_p1.csv"), &hard).unwrap();
    let p = rheometer(&["fit", s(&toml), "--json", s(&hard)], &[&data], LIMIT);
    p.assert_clean_failure(&[
        "refusing to write",
        "hard.json",
        "it is an input file (the same file as the input",
        "v0p27_p1.csv, through a link",
    ]);
    assert!(
        p.elapsed < Duration::from_secs(5),
        "refused after the fit: {:?}",
        p.elapsed
    );
}

#[test]
fn json_symlink_to_the_toml_is_refused() {
    let (dir, toml, data) = shipped_copy("symlink_json");
    let sym = dir.join("sym.json");
    std::os::unix::fs::symlink(&toml, &sym).unwrap();
    let p = rheometer(&["fit", s(&toml), "--json", s(&sym)], &[&data], LIMIT);
    p.assert_clean_failure(&[
        "refusing to write",
        "sym.json",
        "it is an input file (the same file as the input",
        "experiments.toml, through a link",
    ]);
}

#[test]
fn simulate_out_equal_to_an_input_csv_is_refused() {
    let (_dir, toml, data) = shipped_copy("out_is_csv_simulate");
    let csv = data.join("v0p27_p1.csv");
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&csv),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&[
        "refusing to use",
        "v0p27_p1.csv",
        "output directory",
        "input file",
    ]);
    assert!(!p.stderr.contains("os error 17"), "{}", p.stderr);
}

#[test]
fn landscape_out_equal_to_an_input_csv_is_refused_before_the_work() {
    let (_dir, toml, data) = shipped_copy("out_is_csv_landscape");
    let csv = data.join("v0p53_p2.csv");
    let p = rheometer(&["landscape", s(&toml), "--out", s(&csv)], &[&data], LIMIT);
    p.assert_clean_failure(&["refusing to use", "v0p53_p2.csv", "input file"]);
    // the default 41x41 grid takes tens of seconds: refused before it starts
    assert!(p.elapsed < Duration::from_secs(5), "{:?}", p.elapsed);
}

#[test]
fn compare_out_equal_to_the_toml_is_refused() {
    let (_dir, toml, data) = shipped_copy("out_is_toml_compare");
    let p = rheometer(
        &[
            "compare",
            s(&toml),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            s(&toml),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["refusing to use", "experiments.toml", "input file"]);
}

#[test]
fn out_below_an_input_file_names_the_file() {
    let (_dir, toml, data) = shipped_copy("out_below_file");
    let below = data.join("v0p27_p1.csv").join("sim");
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&below),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["v0p27_p1.csv", "is a file, not a directory"]);
}

#[test]
fn out_equal_to_an_existing_other_file_is_refused() {
    let (dir, toml, data) = shipped_copy("out_is_other_file");
    let file = dir.join("notes.txt");
    fs::write(&file, "my notes").unwrap();
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&file),
        ],
        &[&data, &file],
        LIMIT,
    );
    p.assert_clean_failure(&["notes.txt", "is a file, not a directory"]);
}

#[test]
fn out_equal_to_the_data_directory_writes_next_to_unchanged_inputs() {
    let (_dir, toml, data) = shipped_copy("out_is_data_dir");
    let before = checksums_below(&data);
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&data),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert_eq!(profile_files(&data).len(), 9);
    assert!(data.join("profiles.png").is_file());
    assert!(
        !data.join("PARTIAL.txt").exists(),
        "complete run left PARTIAL.txt"
    );
    assert!(temporaries(&data).is_empty(), "{:?}", temporaries(&data));
    let after = checksums_below(&data);
    for (path, sum) in &before {
        assert_eq!(after.get(path), Some(sum), "{} changed", path.display());
    }
}

#[test]
fn output_name_colliding_with_an_input_is_refused_before_any_file_is_written() {
    let (_dir, toml, data) = shipped_copy("name_collision");
    // the last experiment's measurements live in a file named like the first profile
    fs::copy(data.join("v1p06_p3.csv"), data.join("v0p27_p1_profile.csv")).unwrap();
    let text = fs::read_to_string(&toml)
        .unwrap()
        .replace("data = \"v1p06_p3.csv\"", "data = \"v0p27_p1_profile.csv\"");
    fs::write(&toml, text).unwrap();
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&data),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["refusing to write", "v0p27_p1_profile.csv", "input file"]);
    // nothing else was written: refused before the first experiment
    assert_eq!(
        profile_files(&data),
        vec!["v0p27_p1_profile.csv".to_string()]
    );
}

#[test]
fn existing_profile_hard_linked_to_an_input_is_refused() {
    let (dir, toml, data) = shipped_copy("profile_hard_link");
    let out = dir.join("sim");
    fs::create_dir_all(&out).unwrap();
    fs::hard_link(data.join("v0p53_p1.csv"), out.join("v0p53_p1_profile.csv")).unwrap();
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["refusing to write", "v0p53_p1_profile.csv", "input file"]);
    assert_eq!(
        profile_files(&out).len(),
        1,
        "work started before the refusal"
    );
}

#[test]
fn compare_json_hard_linked_to_an_input_is_refused_and_the_input_kept() {
    let (dir, toml, data) = shipped_copy("compare_hard_link");
    let out = dir.join("cmp");
    fs::create_dir_all(&out).unwrap();
    fs::hard_link(data.join("v1p06_p2.csv"), out.join("compare.json")).unwrap();
    let p = rheometer(
        &[
            "compare",
            s(&toml),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["refusing to write", "compare.json", "input file"]);
}

#[test]
fn fit_out_with_report_symlinked_to_an_input_is_refused() {
    let (dir, toml, data) = shipped_copy("fit_out_symlink");
    let out = dir.join("fit");
    fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(data.join("v0p27_p3.csv"), out.join("fit_report.txt")).unwrap();
    let p = rheometer(&["fit", s(&toml), "--out", s(&out)], &[&data], LIMIT);
    p.assert_clean_failure(&["refusing to write", "fit_report.txt", "input file"]);
}

#[test]
fn landscape_figure_symlinked_to_the_toml_is_refused_before_the_work() {
    let (dir, toml, data) = shipped_copy("landscape_symlink");
    let out = dir.join("land");
    fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(&toml, out.join("landscape.png")).unwrap();
    let p = rheometer(&["landscape", s(&toml), "--out", s(&out)], &[&data], LIMIT);
    p.assert_clean_failure(&["refusing to write", "landscape.png", "input file"]);
    assert!(p.elapsed < Duration::from_secs(5), "{:?}", p.elapsed);
}

#[test]
fn existing_output_hard_linked_to_another_file_is_replaced_not_truncated() {
    // atomic writes replace the directory entry: a hard link elsewhere keeps its content
    let (dir, toml, data) = shipped_copy("replace_not_truncate");
    let out = dir.join("sim");
    fs::create_dir_all(&out).unwrap();
    let keep = dir.join("backup.csv");
    fs::write(&keep, "my old profile\n").unwrap();
    fs::hard_link(&keep, out.join("v0p27_p1_profile.csv")).unwrap();
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data, &keep],
        LIMIT,
    );
    p.assert_success();
    let written = fs::read_to_string(out.join("v0p27_p1_profile.csv")).unwrap();
    assert!(written.starts_with("position_m,"), "{written}");
    assert_eq!(fs::read_to_string(&keep).unwrap(), "my old profile\n");
}

// ---------------------------------------------------------------------------------------------
// Outputs that cannot be written

#[test]
fn json_into_a_missing_directory_creates_it() {
    let (dir, toml, data) = shipped_copy("json_missing_dir");
    let json = dir.join("new").join("deeper").join("fit.json");
    let p = rheometer(&["fit", s(&toml), "--json", s(&json)], &[&data], LIMIT);
    p.assert_success();
    let text = fs::read_to_string(&json).unwrap();
    assert!(text.trim_start().starts_with('{'), "{text}");
    assert!(temporaries(json.parent().unwrap()).is_empty());
}

#[test]
fn json_into_a_read_only_location_fails_naming_it() {
    // /proc accepts no new files, even for root (chmod 555 would not stop root)
    let (_dir, toml, data) = shipped_copy("json_read_only");
    let p = rheometer(
        &["fit", s(&toml), "--json", "/proc/fit.json"],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["cannot write", "/proc/fit.json"]);
}

#[test]
fn stdout_to_dev_full_exits_non_zero_with_a_message() {
    let (_dir, toml, data) = shipped_copy("stdout_full");
    let p = run_with(&["fit", s(&toml)], &[&data], LIMIT, |c| {
        c.stdout(
            fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap(),
        )
    });
    p.assert_clean_failure(&["cannot write to standard output", "no space left"]);
}

#[test]
fn landscape_stdout_to_dev_full_exits_non_zero() {
    let (dir, toml, data) = shipped_copy("landscape_stdout_full");
    let out = dir.join("land");
    let p = run_with(
        &[
            "landscape",
            s(&toml),
            "--grid",
            "2x2",
            "--n-range",
            "0.7,0.9",
            "--kappa-range",
            "11,12",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
        |c| {
            c.stdout(
                fs::OpenOptions::new()
                    .write(true)
                    .open("/dev/full")
                    .unwrap(),
            )
        },
    );
    p.assert_clean_failure(&["cannot write to standard output"]);
    // the files were written all the same
    assert!(out.join("landscape.csv").is_file());
}

#[test]
fn help_to_dev_full_exits_non_zero() {
    let p = run_with(&["--help"], &[], LIMIT, |c| {
        c.stdout(
            fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap(),
        )
    });
    p.assert_clean_failure(&["cannot write to standard output"]);
}

#[test]
fn stderr_to_dev_full_never_panics() {
    let (dir, toml, data) = shipped_copy("stderr_full");
    let full = || {
        fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    // a success with progress messages on stderr
    let ok = run_with(&["fit", s(&toml)], &[&data], LIMIT, |c| c.stderr(full()));
    assert_eq!(ok.code, Some(0), "{ok:?}");
    assert!(ok.stdout.contains("kappa"), "{}", ok.stdout);
    ok.assert_inputs_unchanged();
    // a failure whose message cannot be written: exit 1, not a panic (101)
    let hard = dir.join("hard.json");
    fs::hard_link(data.join("v0p27_p1.csv"), &hard).unwrap();
    let bad = run_with(
        &["fit", s(&toml), "--json", s(&hard)],
        &[&data],
        LIMIT,
        |c| c.stderr(full()),
    );
    assert_eq!(bad.code, Some(1), "{bad:?}");
    bad.assert_inputs_unchanged();
    // a usage error (clap) with stderr full
    let usage = run_with(&["simulate", "--points", "x"], &[], LIMIT, |c| {
        c.stderr(full())
    });
    assert_eq!(usage.code, Some(2), "{usage:?}");
}

#[test]
fn closed_stdout_pipe_exits_zero_silently() {
    let (_dir, toml, data) = shipped_copy("closed_pipe");
    let before = checksums_below(&data);
    let mut child = Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .args(["fit", s(&toml)])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // close the read end before the fit prints anything (`rheometer fit | head -0`)
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        !stderr.contains("error") && !stderr.contains("panicked"),
        "{stderr}"
    );
    assert_eq!(checksums_below(&data), before);
}

// ---------------------------------------------------------------------------------------------
// Interrupts

/// Starts `rheometer args`, waits until `ready()` (or 60 s), sends SIGINT, and returns the
/// probe and the time from SIGINT to exit.
fn interrupt(args: &[&str], watch: &[&Path], ready: impl Fn() -> bool) -> (Probe, Duration) {
    let before: Vec<_> = watch.iter().map(|w| checksums_below(w)).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !ready() && t0.elapsed() < Duration::from_secs(60) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before SIGINT"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "finished before SIGINT"
    );
    let sent = Instant::now();
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    // drain the pipes on threads; kill the child if it does not stop within 10 s
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = std::io::Read::read_to_end(&mut so, &mut v);
        v
    });
    let t_err = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = std::io::Read::read_to_end(&mut se, &mut v);
        v
    });
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if sent.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still running 10 s after SIGINT: killed");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stop = sent.elapsed();
    let out = std::process::Output {
        status,
        stdout: t_out.join().unwrap(),
        stderr: t_err.join().unwrap(),
    };
    let changed_inputs = watch
        .iter()
        .zip(&before)
        .flat_map(|(w, b)| {
            let after = checksums_below(w);
            b.iter()
                .filter(|(p, c)| after.get(*p) != Some(c))
                .map(|(p, _)| p.clone())
                .collect::<Vec<_>>()
        })
        .collect();
    let probe = Probe {
        args: args.iter().map(|a| a.to_string()).collect(),
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        elapsed: t0.elapsed(),
        changed_inputs,
    };
    (probe, stop)
}

#[test]
fn sigint_during_simulate_keeps_and_marks_the_finished_profiles() {
    let (dir, _toml, data) = shipped_copy("sigint_simulate");
    // 1080 experiments: more than the default cap of 1000, lifted by --allow-large-inputs
    let toml = many_experiments(&data, "many.toml", 120);
    let out = dir.join("sim");
    let ready = || out.is_dir() && profile_files(&out).len() >= 3;
    let (p, stop) = interrupt(
        &[
            "--allow-large-inputs",
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        ready,
    );
    assert!(!p.panicked(), "{}", p.stderr);
    assert_eq!(p.code, Some(130), "{}", p.stderr);
    assert!(stop < Duration::from_secs(2), "took {stop:?} to stop");
    assert!(p.stderr.contains("interrupted"), "{}", p.stderr);
    assert!(p.stderr.contains("PARTIAL.txt"), "{}", p.stderr);
    p.assert_inputs_unchanged();
    // the manifest lists exactly the profiles on disk as complete, every other one as missing
    let manifest = fs::read_to_string(out.join("PARTIAL.txt")).unwrap();
    let complete: Vec<String> = manifest
        .lines()
        .filter_map(|l| l.strip_prefix("complete "))
        .map(|l| l.split(' ').nth(1).unwrap().to_string())
        .collect();
    // the manifest lists the figures too (written after the last profile)
    let missing = manifest
        .lines()
        .filter(|l| l.starts_with("missing ") && l.ends_with("_profile.csv"))
        .count();
    let mut sorted = complete.clone();
    sorted.sort();
    assert_eq!(sorted, profile_files(&out));
    assert!(complete.len() >= 3 && missing > 0, "{manifest}");
    assert_eq!(complete.len() + missing, 1080);
    // every listed profile is whole (header + 101 rows)
    for name in &complete {
        let rows = fs::read_to_string(out.join(name)).unwrap().lines().count();
        assert_eq!(rows, 102, "{name}");
    }
    assert!(!out.join("profiles.png").exists());
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

#[test]
fn sigint_during_landscape_keeps_the_finished_points() {
    let (dir, toml, data) = shipped_copy("sigint_landscape");
    let out = dir.join("land");
    let t0 = Instant::now();
    // a 101x101 grid at tol 1e-6 runs for about 20 s (the default 41x41 at 1e-4: about 1 s)
    let ready = || t0.elapsed() > Duration::from_millis(1500);
    let args = [
        "landscape",
        s(&toml),
        "--grid",
        "101x101",
        "--tol",
        "1e-6",
        "--out",
        s(&out),
    ];
    let (p, stop) = interrupt(&args, &[&data], ready);
    assert!(!p.panicked(), "{}", p.stderr);
    assert_eq!(p.code, Some(130), "{}", p.stderr);
    assert!(stop < Duration::from_secs(2), "took {stop:?} to stop");
    assert!(p.stderr.contains("interrupted"), "{}", p.stderr);
    assert!(p.stderr.contains("not_computed"), "{}", p.stderr);
    p.assert_inputs_unchanged();
    let csv = fs::read_to_string(out.join("landscape.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("n,kappa,cost,status,tol"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 101 * 101);
    let (mut ok, mut not_computed) = (0, 0);
    for r in &rows {
        let cost: f64 = r[2].parse().unwrap();
        let tol: f64 = r[4].parse().unwrap();
        match r[3] {
            "ok" => {
                assert!(cost.is_finite() && cost >= 0.0, "{r:?}");
                // the landscape's tolerance, or ten times it far from the row's minimum
                assert!(tol == 1e-6 || tol == 1e-5, "{r:?}");
                ok += 1;
            }
            "failed" | "not_computed" => {
                assert!(cost.is_nan() && tol.is_nan(), "{r:?}");
                not_computed += usize::from(r[3] == "not_computed");
            }
            other => panic!("unknown status {other}"),
        }
    }
    assert!(ok > 0, "no finished point kept");
    assert!(not_computed > 0, "nothing marked as not computed");
    assert!(
        p.stderr
            .contains(&format!("{not_computed} points not computed")),
        "{}",
        p.stderr
    );
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

// ---------------------------------------------------------------------------------------------
// Size and failure accounting

#[test]
fn simulate_with_two_hundred_experiments_writes_everything() {
    let (dir, _toml, data) = shipped_copy("many_experiments");
    let toml = many_experiments(&data, "many.toml", 23); // 207 experiments
    let out = dir.join("sim");
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--points",
            "11",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert_eq!(profile_files(&out).len(), 207);
    assert!(out.join("profiles.png").is_file());
    // 207 panels: split into ceil(207 / 24) = 9 figures, none of them too large
    let pages: Vec<_> = (1..=9)
        .map(|k| out.join(format!("diameters_vs_data_{k}.png")))
        .collect();
    for page in &pages {
        assert!(page.is_file(), "{} missing", page.display());
    }
    assert!(!out.join("diameters_vs_data_10.png").exists());
    assert!(p.stderr.contains("split into 9 files"), "{}", p.stderr);
    assert!(!out.join("PARTIAL.txt").exists());
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

#[test]
fn simulate_failing_midway_leaves_a_manifest() {
    let (dir, toml, data) = shipped_copy("simulate_fails_midway");
    // the last experiment loses its measurements: --take-up-from-data fails there
    let text = fs::read_to_string(&toml)
        .unwrap()
        .replace("data = \"v1p06_p3.csv\"\n", "");
    fs::write(&toml, text).unwrap();
    let out = dir.join("sim");
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["v1p06_p3"]);
    let manifest = fs::read_to_string(out.join("PARTIAL.txt")).unwrap();
    // 9 profiles, profiles.png and diameters_vs_data.png: 8 profiles written
    assert!(manifest.contains("8 of 11 files written"), "{manifest}");
    assert!(
        manifest.contains("missing figure profiles.png"),
        "{manifest}"
    );
    assert!(manifest.contains("missing v1p06_p3 "), "{manifest}");
    assert_eq!(profile_files(&out).len(), 8);
}

#[test]
fn a_complete_rerun_removes_the_manifest() {
    let (dir, toml, data) = shipped_copy("rerun_removes_manifest");
    let out = dir.join("sim");
    fs::create_dir_all(&out).unwrap();
    fs::write(out.join("PARTIAL.txt"), "stale\n").unwrap();
    let p = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert!(!out.join("PARTIAL.txt").exists());
    assert_eq!(profile_files(&out).len(), 9);
}

#[test]
fn landscape_counts_failed_points_and_warns_when_most_fail() {
    let (dir, toml, data) = shipped_copy("landscape_failures");
    let out = dir.join("land");
    // strain thinning this strong (n near 0) has no solution for most of these points
    let p = rheometer(
        &[
            "landscape",
            s(&toml),
            "--grid",
            "2x2",
            "--n-range",
            "0,0.05",
            "--kappa-range",
            "9,16",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    let csv = fs::read_to_string(out.join("landscape.csv")).unwrap();
    let failed = csv.lines().filter(|l| l.contains(",failed,")).count();
    let ok = csv.lines().filter(|l| l.contains(",ok,")).count();
    assert_eq!(failed + ok, 4, "{csv}");
    assert!(failed > 2, "expected most points to fail:\n{csv}");
    assert!(
        p.stdout
            .contains(&format!("{failed} of 4 grid points failed")),
        "{}",
        p.stdout
    );
    assert!(
        p.stderr
            .contains(&format!("warning: most grid points failed ({failed} of 4)")),
        "{}",
        p.stderr
    );
    assert!(out.join("landscape.png").is_file());
}

#[test]
fn library_landscape_cancelled_up_front_reaches_no_point() {
    use rheometer::data::input::load_experiments_with;
    use rheometer::fit::{Estimator, IdentifyOptions, PointStatus, Rheometer};
    use std::sync::atomic::AtomicBool;
    let (_dir, toml, _data) = shipped_copy("library_cancel");
    let loaded = load_experiments_with(&toml, &LoadOptions::default()).unwrap();
    let rh = Rheometer::new(&loaded.set).unwrap();
    let mut opts = IdentifyOptions::with_estimator(Estimator::Paper);
    opts.simulate.tol = 1e-4;
    let cancel = AtomicBool::new(true);
    let run = rh
        .landscape_with(&[0.7, 0.9], &[11.0, 12.0], &opts, |_| {}, &cancel)
        .unwrap();
    assert!(run.cancelled);
    assert_eq!(run.not_reached(), 4);
    assert_eq!(run.failed(), 0);
    assert!(run.landscape.cost.iter().all(|c| c.is_nan()));
    // not cancelled: every point computed, same API as `landscape`
    let go = AtomicBool::new(false);
    let full = rh
        .landscape_with(&[0.7, 0.9], &[11.0, 12.0], &opts, |_| {}, &go)
        .unwrap();
    assert!(!full.cancelled);
    assert_eq!(full.count(PointStatus::Computed), 4);
    let plain = rh
        .landscape(&[0.7, 0.9], &[11.0, 12.0], &opts, |_| {})
        .unwrap();
    assert_eq!(plain.cost, full.landscape.cost);
}

#[test]
fn sigint_during_fit_and_compare_still_stops_at_once() {
    // commands without a clean stop keep the default: SIGINT ends them immediately, and their
    // outputs (written atomically, at the end) are never half-written
    let (dir, _toml, data) = shipped_copy("sigint_fit_compare");
    let toml = many_experiments(&data, "many.toml", 40); // 360 experiments
    let t0 = Instant::now();
    let json = dir.join("fit.json");
    let (p, stop) = interrupt(&["fit", s(&toml), "--json", s(&json)], &[&data], || {
        t0.elapsed() > Duration::from_millis(800)
    });
    assert!(!p.panicked(), "{}", p.stderr);
    assert_ne!(p.code, Some(0), "{p:?}");
    assert!(stop < Duration::from_secs(2), "fit took {stop:?} to stop");
    assert!(!json.exists());
    p.assert_inputs_unchanged();

    let out = dir.join("cmp");
    let t1 = Instant::now();
    let (p, stop) = interrupt(
        &[
            "compare",
            s(&toml),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        || t1.elapsed() > Duration::from_millis(800),
    );
    assert!(!p.panicked(), "{}", p.stderr);
    assert_ne!(p.code, Some(0), "{p:?}");
    assert!(
        stop < Duration::from_secs(2),
        "compare took {stop:?} to stop"
    );
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
    p.assert_inputs_unchanged();
}
