//! The output layer (issue 28): every output planned and checked before the work, against the
//! inputs and against each other; special files (character devices, FIFOs, `/dev/fd/N`, `-`)
//! written in place; long names; write-protected files; signals and the temporaries they
//! leave; standard streams that fail. Each test names the rows of
//! `../shared/probes/bad-input-findings.md` it reproduces; every probe checksums the inputs.
#![cfg(unix)]

use crate::probe::{checksums_below, rheometer, run_with, s, shipped_copy, Probe};
use std::fs;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(120);

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_rheometer")
}

/// Names of the leftovers of atomic writes in `dir` (old and new temporary names).
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

/// What `path` is, without following a final symbolic link.
fn kind(path: &Path) -> &'static str {
    match fs::symlink_metadata(path) {
        Err(_) => "missing",
        Ok(m) => {
            let t = m.file_type();
            if t.is_symlink() {
                "symlink"
            } else if t.is_char_device() {
                "char device"
            } else if t.is_fifo() {
                "fifo"
            } else if t.is_dir() {
                "directory"
            } else {
                "regular"
            }
        }
    }
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// Runs `bash -c script` with `$BIN` the rheometer, in `dir`, and checksums `watch`.
fn bash(script: &str, dir: &Path, watch: &[&Path], limit: Duration) -> Probe {
    bash_with(script, dir, watch, limit, |c| c)
}

fn bash_with(
    script: &str,
    dir: &Path,
    watch: &[&Path],
    limit: Duration,
    f: impl FnOnce(&mut Command) -> &mut Command,
) -> Probe {
    let before: Vec<_> = watch.iter().map(|w| checksums_below(w)).collect();
    let mut cmd = Command::new("bash");
    cmd.args(["-c", script])
        .env("BIN", bin())
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    f(&mut cmd);
    let t0 = Instant::now();
    let mut child = cmd.spawn().expect("start bash");
    let out = loop {
        if child.try_wait().expect("wait").is_some() {
            break child.wait_with_output().expect("output");
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{script}: still running after {limit:?}: killed");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let changed_inputs = watch
        .iter()
        .zip(&before)
        .flat_map(|(w, b)| {
            let after = checksums_below(w);
            b.iter()
                .filter(|(p, c)| after.get(*p) != Some(*c))
                .map(|(p, _)| p.clone())
                .collect::<Vec<_>>()
        })
        .collect();
    Probe {
        args: vec![script.to_string()],
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        elapsed: t0.elapsed(),
        changed_inputs,
    }
}

/// Runs `script` as root in a private mount namespace whose `/dev` is a tmpfs copy of
/// `null`, `full` and the `stdout`/`fd` links (so that a program replacing `/dev/null`
/// damages only the copy). `None` when not root or namespaces are not available.
fn in_private_dev(script: &str, dir: &Path, watch: &[&Path]) -> Option<Probe> {
    if !is_root() {
        eprintln!("not root: the private /dev probe is skipped (the FIFO and link probes run)");
        return None;
    }
    let devcopy = dir.join("devcopy");
    fs::create_dir_all(&devcopy).unwrap();
    let full = format!(
        "set -u\n\
         mount -t tmpfs -o size=1m tmpfs {d} || exit 77\n\
         cp -a /dev/null /dev/full {d}/ || exit 77\n\
         ln -s /proc/self/fd {d}/fd; ln -s /proc/self/fd/0 {d}/stdin\n\
         ln -s /proc/self/fd/1 {d}/stdout; ln -s /proc/self/fd/2 {d}/stderr\n\
         mount --bind {d} /dev || exit 77\n\
         {script}",
        d = devcopy.display()
    );
    let p = bash(
        &format!(
            "exec unshare -m --propagation private bash -c {}",
            shell_quote(&full)
        ),
        dir,
        watch,
        LIMIT,
    );
    if p.code == Some(77) || p.stderr.contains("unshare failed") {
        eprintln!("no private mount namespace here: skipped\n{}", p.stderr);
        return None;
    }
    // the real /dev is untouched in any case
    assert_eq!(kind(Path::new("/dev/null")), "char device");
    assert_eq!(kind(Path::new("/dev/full")), "char device");
    Some(p)
}

fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// Lines `KEY=VALUE` printed by a probe script.
fn value<'a>(p: &'a Probe, key: &str) -> &'a str {
    p.stdout
        .lines()
        .find_map(|l| l.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key}= in stdout:\n{}\nstderr:\n{}", p.stdout, p.stderr))
}

fn assert_json(text: &str) {
    let v: serde_json::Value = serde_json::from_str(text.trim())
        .unwrap_or_else(|e| panic!("not JSON ({e}):\n{}", &text[..text.len().min(400)]));
    assert!(v.get("n").is_some() || v.get("candidates").is_some(), "{v}");
}

// ---------------------------------------------------------------------------------------------
// Special files: written in place, never replaced

#[test]
fn c01_c02_c03_as_root_json_to_dev_null_stdout_and_full_keeps_the_devices() {
    let (dir, toml, data) = shipped_copy("private_dev");
    let script = format!(
        "\"$BIN\" --quiet fit {t} --json /dev/null > /dev/null; echo rc_null=$?\n\
         echo kind_null=$(stat -c %F /dev/null)\n\
         \"$BIN\" --quiet fit {t} --json /dev/stdout > stdout.json 2> report.txt; \
         echo rc_stdout=$?\n\
         echo kind_stdout=$(stat -c %F /dev/stdout)\n\
         \"$BIN\" --quiet fit {t} --json /dev/full > /dev/null 2> full.err; echo rc_full=$?\n\
         echo kind_full=$(stat -c %F /dev/full)\n\
         echo tmp_in_dev=$(ls -A /dev | grep -c tmp)",
        t = s(&toml)
    );
    let Some(p) = in_private_dev(&script, &dir, &[&data]) else {
        return;
    };
    assert!(!p.panicked(), "{}", p.stderr);
    p.assert_inputs_unchanged();
    assert_eq!(value(&p, "rc_null"), "0", "{}", p.stderr);
    assert_eq!(value(&p, "kind_null"), "character special file");
    // the JSON reached standard output, the report went to stderr, the link stayed a link
    assert_eq!(value(&p, "rc_stdout"), "0", "{}", p.stderr);
    assert_eq!(value(&p, "kind_stdout"), "symbolic link");
    assert_json(&fs::read_to_string(dir.join("stdout.json")).unwrap());
    let report = fs::read_to_string(dir.join("report.txt")).unwrap();
    assert!(report.contains("[[Variables]]"), "{report}");
    // /dev/full: written in place, the error said, the device kept
    assert_eq!(value(&p, "rc_full"), "1");
    let err = fs::read_to_string(dir.join("full.err")).unwrap();
    assert!(
        err.contains("/dev/full") && err.contains("No space left"),
        "{err}"
    );
    assert_eq!(value(&p, "kind_full"), "character special file");
    assert_eq!(value(&p, "tmp_in_dev"), "0");
}

#[test]
fn c04_as_root_diagnose_json_to_dev_null_keeps_the_device() {
    let (dir, toml, data) = shipped_copy("private_dev_diagnose");
    let script = format!(
        "\"$BIN\" --quiet diagnose {t} --refit-top 1 --json /dev/null --out out > /dev/null; \
         echo rc=$?\necho kind=$(stat -c %F /dev/null)",
        t = s(&toml)
    );
    let Some(p) = in_private_dev(&script, &dir, &[&data]) else {
        return;
    };
    assert_eq!(value(&p, "rc"), "0", "{}", p.stderr);
    assert_eq!(value(&p, "kind"), "character special file");
    p.assert_inputs_unchanged();
    assert!(dir.join("out").join("diagnosis.json").is_file());
}

#[test]
fn c01_without_root_a_link_to_a_character_device_stays_a_link_to_it() {
    let (dir, toml, data) = shipped_copy("link_to_dev_null");
    let link = dir.join("null.json");
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    let p = rheometer(
        &["--quiet", "fit", s(&toml), "--json", s(&link)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert_eq!(kind(&link), "symlink");
    assert_eq!(fs::read_link(&link).unwrap(), Path::new("/dev/null"));
    assert_eq!(kind(Path::new("/dev/null")), "char device");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

#[test]
fn c03_json_to_dev_full_is_refused_before_the_fit() {
    // [C03, issue 28 item 2] a zero-length write tells /dev/full's refusal before the work:
    // the report of the fit never reaches stdout, and the error names the device
    let (dir, toml, data) = shipped_copy("dev_full_before");
    let link = dir.join("full.json");
    std::os::unix::fs::symlink("/dev/full", &link).unwrap();
    for target in [Path::new("/dev/full"), link.as_path()] {
        let p = rheometer(&["fit", s(&toml), "--json", s(target)], &[&data], LIMIT);
        p.assert_clean_failure(&["--json", "no space left on device"]);
        assert!(!p.stdout.contains("[[Result"), "the fit ran:\n{}", p.stdout);
        assert!(p.elapsed < Duration::from_secs(5), "{:?}", p.elapsed);
    }
    assert_eq!(kind(&link), "symlink");
    assert_eq!(kind(Path::new("/dev/full")), "char device");
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a24_a_fifo_is_written_in_place_and_its_reader_gets_the_json() {
    let (dir, toml, data) = shipped_copy("fifo_json");
    let fifo = dir.join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || fs::read_to_string(fifo).unwrap())
    };
    let p = rheometer(
        &["--quiet", "fit", s(&toml), "--json", s(&fifo)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert_json(&reader.join().unwrap());
    assert_eq!(kind(&fifo), "fifo");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

#[test]
fn a24_a_fifo_without_reader_is_an_error_after_a_wait_not_a_hang() {
    let (dir, toml, data) = shipped_copy("fifo_no_reader");
    let fifo = dir.join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    // the wait set by the environment (the default, 10 s, is the unit test's): the failure
    // comes after it, not before and not never
    let p = run_with(
        &["--quiet", "fit", s(&toml), "--json", s(&fifo)],
        &[&data],
        LIMIT,
        |c| c.env("DIFFBVP_FIFO_WAIT_S", "1.5"),
    );
    p.assert_clean_failure(&[
        "fifo",
        "no process opened this FIFO for reading within 1.5 s",
        "cat",
        "DIFFBVP_FIFO_WAIT_S",
    ]);
    assert_eq!(kind(&fifo), "fifo");
    assert!(p.elapsed >= Duration::from_millis(1500), "{:?}", p.elapsed);
    assert!(p.elapsed < Duration::from_secs(60), "{:?}", p.elapsed);
}

#[test]
fn c05_c06_as_another_user_dev_null_and_dev_stdout_work() {
    let (dir, toml, data) = shipped_copy("nobody_devices");
    // as root: run as nobody (the case of the findings); otherwise as this user, not root
    let run_as = if is_root()
        && Command::new("setpriv")
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
    {
        "setpriv --reuid=65534 --regid=65534 --clear-groups "
    } else {
        ""
    };
    let _ = Command::new("chmod")
        .args(["-R", "a+rwX", s(&dir)])
        .status();
    let script = format!(
        "{run_as}\"$BIN\" fit {t} --json /dev/null > /dev/null 2> null.err; echo rc_null=$?\n\
         {run_as}\"$BIN\" --quiet fit {t} --json /dev/stdout 2> /dev/null | wc -c | tr -d ' ' \
         > count.txt; echo count=$(cat count.txt)",
        t = s(&toml)
    );
    let p = bash(&script, &dir, &[&data], LIMIT);
    assert_eq!(
        value(&p, "rc_null"),
        "0",
        "{}",
        fs::read_to_string(dir.join("null.err")).unwrap_or_default()
    );
    let bytes: usize = value(&p, "count").parse().unwrap();
    assert!(bytes > 1000, "only {bytes} bytes of JSON on stdout");
    p.assert_inputs_unchanged();
    assert_eq!(kind(Path::new("/dev/null")), "char device");
}

#[test]
fn a25_json_to_a_process_substitution_and_a_descriptor_is_written_in_place() {
    let (dir, toml, data) = shipped_copy("descriptors");
    let script = format!(
        "\"$BIN\" --quiet fit {t} --json >(cat > substituted.json) > /dev/null; echo rc_sub=$?\n\
         exec 3> fd3.json\n\
         \"$BIN\" --quiet fit {t} --json /dev/fd/3 > /dev/null; echo rc_fd=$?\n\
         exec 3>&-\n\
         \"$BIN\" --quiet fit {t} --json /dev/fd/7 > /dev/null 2> fd7.err; echo rc_closed=$?\n\
         sleep 0.3",
        t = s(&toml)
    );
    let p = bash(&script, &dir, &[&data], LIMIT);
    assert_eq!(value(&p, "rc_sub"), "0", "{}", p.stderr);
    assert_eq!(value(&p, "rc_fd"), "0", "{}", p.stderr);
    assert_json(&fs::read_to_string(dir.join("substituted.json")).unwrap());
    assert_json(&fs::read_to_string(dir.join("fd3.json")).unwrap());
    // a descriptor that is not open: refused before the fit, with what to do
    assert_eq!(value(&p, "rc_closed"), "1");
    let err = fs::read_to_string(dir.join("fd7.err")).unwrap();
    assert!(err.contains("descriptor 7 is not open"), "{err}");
    assert!(!err.contains("[[Variables]]"));
    p.assert_inputs_unchanged();
}

#[test]
fn x33_json_dash_goes_to_stdout_with_the_report_on_stderr() {
    let (dir, toml, data) = shipped_copy("json_dash");
    let p = run_with(&["fit", s(&toml), "--json", "-"], &[&data], LIMIT, |c| {
        c.current_dir(&dir)
    });
    p.assert_success();
    assert_json(&p.stdout);
    assert!(p.stderr.contains("[[Variables]]"), "{}", p.stderr);
    assert_eq!(
        kind(&dir.join("-")),
        "missing",
        "a file named - was created"
    );
}

#[test]
fn c13_a_closed_stdout_loses_the_report_with_a_message_and_exit_one() {
    let (dir, toml, data) = shipped_copy("closed_stdout");
    let p = bash(
        &format!("\"$BIN\" fit {} >&-", s(&toml)),
        &dir,
        &[&data],
        LIMIT,
    );
    assert_eq!(p.code, Some(1), "{}", p.stderr);
    assert!(!p.panicked());
    assert!(
        p.stderr.contains("standard output is closed") && p.stderr.contains("report was lost"),
        "{}",
        p.stderr
    );
    // and --json - with a closed stdout is refused before the fit
    let p = bash(
        &format!("\"$BIN\" fit {} --json - >&-", s(&toml)),
        &dir,
        &[&data],
        LIMIT,
    );
    assert_eq!(p.code, Some(1), "{}", p.stderr);
    assert!(
        p.stderr.contains("standard output is closed"),
        "{}",
        p.stderr
    );
    assert!(p.elapsed < Duration::from_secs(5));
    // a stdout the caller opened read-write on /dev/null (bash `1<>`, Python's
    // subprocess.DEVNULL) is open, not closed: the report goes there, exit 0
    let p = bash(
        &format!("\"$BIN\" --quiet fit {} 1<> /dev/null", s(&toml)),
        &dir,
        &[&data],
        LIMIT,
    );
    assert_eq!(p.code, Some(0), "{}", p.stderr);
    assert!(!p.stderr.contains("closed"), "{}", p.stderr);
}

#[test]
fn s09_a_json_path_through_a_missing_directory_and_dotdot_is_the_same_file() {
    // [S09] `out/../out/fit.json` with `out` not yet made names out/fit.json of --out out
    let (dir, toml, data) = shipped_copy("dotdot_same_file");
    let p = bash(
        &format!(
            "\"$BIN\" --quiet fit {} --json out/../out/fit.json --out out > /dev/null",
            s(&toml)
        ),
        &dir,
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["--json", "--out", "name the same file"]);
    assert!(!dir.join("out").join("fit.json").exists());
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn c11_c12_hints_on_a_full_stderr_never_panic() {
    let (dir, toml, data) = shipped_copy("hints_full_stderr");
    let full = || {
        fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let out = dir.join("out");
    // C11: a failure with hint lines, stderr full
    let p = run_with(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--n",
            "0",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
        |c| c.stderr(full()),
    );
    assert_eq!(p.code, Some(1), "{p:?}");
    // the same failure prints its hints when stderr works
    let q = rheometer(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--n",
            "0",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    q.assert_clean_failure(&["hint:"]);
    // C12: a failing fit (mass flow 1000 times too large) with hints
    let bad = crate::probe::variant(
        &toml,
        "mass_flow.toml",
        "1.5690566037735852e-05",
        "1.5690566037735852e-02",
    );
    let p = run_with(&["fit", s(&bad)], &[&data], LIMIT, |c| c.stderr(full()));
    assert_eq!(p.code, Some(1), "{p:?}");
    p.assert_inputs_unchanged();
}

// ---------------------------------------------------------------------------------------------
// Outputs that are inputs, or each other: refused before the work

#[test]
fn a08_a09_a10_fit_outputs_named_like_inputs_are_refused_before_the_fit() {
    for (csv, name, extra) in [
        (
            "v0p27_p1.csv",
            "residuals_before_after.png",
            vec!["--with", "radiation"],
        ),
        ("v0p27_p1.csv", "fig2_smoothing.png", vec![]),
        ("v0p27_p2.csv", "v0p27_p2_fitted_profile.csv", vec![]),
    ] {
        let (_dir, toml, data) = shipped_copy(&format!("fit_name_{name}"));
        fs::rename(data.join(csv), data.join(name)).unwrap();
        let text = fs::read_to_string(&toml)
            .unwrap()
            .replace(&format!("\"{csv}\""), &format!("\"{name}\""));
        fs::write(&toml, text).unwrap();
        let before: Vec<_> = fs::read_dir(&data).unwrap().flatten().collect();
        let mut args = vec!["fit", s(&toml), "--out", s(&data)];
        args.extend(extra);
        let p = rheometer(&args, &[&data], LIMIT);
        p.assert_clean_failure(&["--out", name, "it is an input file"]);
        assert_eq!(
            fs::read_dir(&data).unwrap().count(),
            before.len(),
            "files written before the refusal"
        );
        assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
        assert!(!p.stdout.contains("[[Variables]]"), "fitted first");
    }
}

#[test]
fn a14_a15_compare_never_replaces_its_fit_file() {
    let (dir, toml, data) = shipped_copy("compare_fit_file");
    let fit = data.join("compare.json");
    rheometer(&["--quiet", "fit", s(&toml), "--json", s(&fit)], &[], LIMIT).assert_success();
    let res = dir.join("res");
    fs::create_dir_all(&res).unwrap();
    let fit2 = res.join("compare_summary.txt");
    fs::copy(&fit, &fit2).unwrap();
    for (f, out) in [(&fit, &data), (&fit2, &res)] {
        let p = rheometer(
            &["compare", s(&toml), "--fit", s(f), "--out", s(out)],
            &[&data, &res],
            LIMIT,
        );
        p.assert_clean_failure(&["refusing to write", "it is an input file", "--out"]);
        assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
    }
}

#[test]
fn s09_s10_two_outputs_of_one_fit_with_the_same_path_are_refused_naming_both_flags() {
    let (dir, toml, data) = shipped_copy("same_output");
    let out = dir.join("out");
    for name in ["fit_report.txt", "v0p27_p1_fitted_profile.csv", "fit.json"] {
        let json = out.join(name);
        let p = rheometer(
            &["fit", s(&toml), "--json", s(&json), "--out", s(&out)],
            &[&data],
            LIMIT,
        );
        p.assert_clean_failure(&["--json", "--out", name, "name the same file"]);
        assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
        assert!(!out.exists(), "written before the refusal");
    }
    // the same through another spelling of the path and through a link
    fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(out.join("fit.json"), dir.join("alias.json")).unwrap();
    fs::write(out.join("fit.json"), "old").unwrap();
    for json in [
        format!("{}/../out/./fit_report.txt", out.display()),
        dir.join("alias.json").display().to_string(),
    ] {
        let p = rheometer(
            &["fit", s(&toml), "--json", &json, "--out", s(&out)],
            &[&data],
            LIMIT,
        );
        p.assert_clean_failure(&["name the same file"]);
    }
    // --json naming the output directory itself
    let p = rheometer(
        &["fit", s(&toml), "--json", s(&out), "--out", s(&out)],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["--json", "--out"]);
}

#[test]
fn s11_a11_a12_a13_diagnose_checks_every_output_before_the_work() {
    let (dir, toml, data) = shipped_copy("diagnose_outputs");
    let out = dir.join("out");
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["--json".into(), s(&out.join("diagnosis.txt")).into()],
            vec!["--json", "--out", "name the same file"],
        ),
        (
            vec!["--json".into(), s(&toml).into()],
            vec!["--json", "it is an input file"],
        ),
        (
            vec![],
            vec!["refusing to use", "v0p27_p1.csv", "output directory"],
        ),
    ];
    for (k, (extra, needles)) in cases.into_iter().enumerate() {
        let target = if k == 2 {
            data.join("v0p27_p1.csv")
        } else {
            out.clone()
        };
        let mut args = vec!["diagnose".to_string(), s(&toml).into()];
        args.extend(extra);
        args.extend(["--out".into(), s(&target).into()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let p = rheometer(&args, &[&data], LIMIT);
        p.assert_clean_failure(&needles);
        // diagnose takes seconds: refused before it started
        assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
        assert!(!out.exists(), "written before the refusal");
    }
    // A13: a data file named like one of the outputs, --out the data directory
    fs::rename(data.join("v0p27_p1.csv"), data.join("diagnosis.json")).unwrap();
    let text = fs::read_to_string(&toml)
        .unwrap()
        .replace("\"v0p27_p1.csv\"", "\"diagnosis.json\"");
    fs::write(&toml, text).unwrap();
    let p = rheometer(&["diagnose", s(&toml), "--out", s(&data)], &[&data], LIMIT);
    p.assert_clean_failure(&["diagnosis.json", "it is an input file"]);
    assert!(!data.join("diagnosis.txt").exists());
    assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
}

#[test]
fn s14_s15_s16_x24_a28_x11b_bad_output_paths_are_refused_before_the_work() {
    let (dir, toml, data) = shipped_copy("bad_paths");
    let blocked = dir.join("blocked");
    fs::create_dir_all(blocked.join("fig2_smoothing.png")).unwrap();
    fs::create_dir_all(blocked.join("residuals_before_after.png")).unwrap();
    fs::create_dir_all(blocked.join("compare.json")).unwrap();
    let notes = dir.join("notes.txt");
    fs::write(&notes, "hi").unwrap();
    let csv = data.join("v0p27_p1.csv");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["fit".into(), "--out".into(), s(&blocked).into()],
            "it is an existing directory",
        ),
        (
            vec!["diagnose".into(), "--out".into(), s(&blocked).into()],
            "it is an existing directory",
        ),
        (
            vec![
                "compare".into(),
                "--n".into(),
                "0.8".into(),
                "--kappa".into(),
                "11.71".into(),
                "--take-up-from-data".into(),
                "--out".into(),
                s(&blocked).into(),
            ],
            "it is an existing directory",
        ),
        (
            vec!["fit".into(), "--out".into(), s(&notes).into()],
            "is a file, not a directory",
        ),
        (
            vec![
                "fit".into(),
                "--json".into(),
                format!("{}/fit.json", s(&csv)),
            ],
            "is a file, not a directory",
        ),
        (
            vec!["fit".into(), "--json".into(), "/proc/x.json".into()],
            "cannot write into /proc",
        ),
    ];
    for (args, needle) in cases {
        let mut all = vec![args[0].clone(), s(&toml).to_string()];
        all.extend(args[1..].iter().cloned());
        let all: Vec<&str> = all.iter().map(String::as_str).collect();
        let p = rheometer(&all, &[&data, &notes], LIMIT);
        p.assert_clean_failure(&[needle]);
        assert!(
            p.elapsed < Duration::from_secs(3),
            "{all:?}: {:?}",
            p.elapsed
        );
        assert!(!p.stdout.contains("[[Variables]]"), "{all:?} fitted first");
    }
    // nothing was written into the blocked directory
    let mut names: Vec<_> = fs::read_dir(&blocked)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    names.sort();
    assert_eq!(names.len(), 3, "{names:?}");
}

#[test]
fn d21_d23_a36_unwritable_places_are_refused_before_the_work_for_a_normal_user() {
    if !is_root()
        || !Command::new("setpriv")
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
    {
        eprintln!("needs root and setpriv to act as another user: skipped");
        return;
    }
    let (dir, toml, data) = shipped_copy("normal_user");
    let ro = dir.join("ro");
    fs::create_dir_all(&ro).unwrap();
    let sticky = dir.join("sticky");
    fs::create_dir_all(&sticky).unwrap();
    fs::write(sticky.join("res.json"), "theirs").unwrap();
    let _ = Command::new("chmod").args(["-R", "a+rX", s(&dir)]).status();
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o555)).unwrap();
    fs::set_permissions(&sticky, fs::Permissions::from_mode(0o1777)).unwrap();
    fs::set_permissions(sticky.join("res.json"), fs::Permissions::from_mode(0o666)).unwrap();
    let script = format!(
        "as=\"setpriv --reuid=65534 --regid=65534 --clear-groups\"\n\
         $as \"$BIN\" fit {t} --out {ro} > /dev/null 2> d21.err; echo rc_d21=$?\n\
         $as \"$BIN\" fit {t} --json {ro}/fit.json > /dev/null 2> d23.err; echo rc_d23=$?\n\
         $as \"$BIN\" fit {t} --json {st}/res.json > /dev/null 2> a36.err; echo rc_a36=$?",
        t = s(&toml),
        ro = s(&ro),
        st = s(&sticky)
    );
    let p = bash(&script, &dir, &[&data], LIMIT);
    for (id, needle) in [
        ("d21", "cannot write into"),
        ("d23", "cannot write into"),
        ("a36", "belongs to another user"),
    ] {
        assert_eq!(value(&p, &format!("rc_{id}")), "1", "{id}");
        let err = fs::read_to_string(dir.join(format!("{id}.err"))).unwrap();
        assert!(err.contains(needle), "{id}: {err}");
    }
    assert_eq!(
        fs::read_to_string(sticky.join("res.json")).unwrap(),
        "theirs"
    );
    assert!(p.elapsed < Duration::from_secs(10), "{:?}", p.elapsed);
    p.assert_inputs_unchanged();
}

// ---------------------------------------------------------------------------------------------
// Regular files: write-protected, long names

#[test]
fn d24_a_write_protected_results_file_is_refused_and_kept() {
    let (dir, toml, data) = shipped_copy("write_protected");
    let r = dir.join("r.json");
    fs::write(&r, "precious").unwrap();
    fs::set_permissions(&r, fs::Permissions::from_mode(0o444)).unwrap();
    let p = rheometer(&["fit", s(&toml), "--json", s(&r)], &[&data, &r], LIMIT);
    p.assert_clean_failure(&["refusing to replace", "r.json", "write-protected", "444"]);
    assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
    assert_eq!(fs::read_to_string(&r).unwrap(), "precious");
    assert_eq!(
        fs::metadata(&r).unwrap().permissions().mode() & 0o777,
        0o444
    );
}

#[test]
fn d05_d07_legal_names_up_to_255_bytes_are_written() {
    let (dir, toml, data) = shipped_copy("long_names");
    // D07: a 250-byte --json name (its temporary used to be longer than 255 bytes)
    let json = dir.join(format!("{}.json", "j".repeat(250)));
    let p = rheometer(
        &["--quiet", "fit", s(&toml), "--json", s(&json)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert_json(&fs::read_to_string(&json).unwrap());
    // D05: a 236-byte experiment name gives a 248-byte profile name
    let long = "e".repeat(236);
    let t = crate::probe::variant(
        &toml,
        "long.toml",
        "name = \"v0p27_p1\"",
        &format!("name = \"{long}\""),
    );
    let out = dir.join("sim");
    let p = rheometer(
        &["simulate", s(&t), "--take-up-from-data", "--out", s(&out)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    assert!(out.join(format!("{long}_profile.csv")).is_file());
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
    assert!(!out.join("PARTIAL.txt").exists());
}

#[test]
fn d06_a_name_longer_than_the_file_system_allows_is_refused_before_the_work() {
    let (dir, toml, data) = shipped_copy("too_long_names");
    let t = crate::probe::variant(
        &toml,
        "long.toml",
        "name = \"v0p27_p1\"",
        &format!("name = \"{}\"", "e".repeat(255)),
    );
    let out = dir.join("sim");
    let p = rheometer(
        &["simulate", s(&t), "--take-up-from-data", "--out", s(&out)],
        &[&data],
        LIMIT,
    );
    // refused by the reader already: output files are named after the experiment
    p.assert_clean_failure(&[
        "255 bytes long",
        "output files are named after the experiment",
    ]);
    assert!(!out.exists(), "written before the refusal");
    let json = dir.join(format!("{}.json", "j".repeat(300)));
    let p = rheometer(&["fit", s(&toml), "--json", s(&json)], &[&data], LIMIT);
    p.assert_clean_failure(&["--json", "305 bytes long"]);
    assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
}

// ---------------------------------------------------------------------------------------------
// Signals, kill -9 and the temporaries they leave

/// Starts `rheometer args`, waits until `ready()` (or 60 s), sends `signal`, waits for the
/// end and returns (exit code or None, stderr).
fn signal_during(args: &[&str], signal: &str, ready: impl Fn() -> bool) -> (Option<i32>, String) {
    let mut child = Command::new(bin())
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !ready() && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "finished before the signal"
    );
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let sent = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        assert!(
            sent.elapsed() < Duration::from_secs(10),
            "still running 10 s after {signal}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn b06_b13_x17b_sigterm_and_sighup_leave_no_temporary_and_a_marked_set() {
    for (signal, code, name) in [("-TERM", 143, "SIGTERM"), ("-HUP", 129, "SIGHUP")] {
        let (dir, toml, data) = shipped_copy(&format!("signal{signal}"));
        let out = dir.join("sim");
        // large profiles (about 9 MB each): the signal arrives while one is being written
        let ready = || {
            fs::read_dir(&out).is_ok_and(|rd| {
                rd.flatten()
                    .any(|e| e.file_name().to_string_lossy().ends_with("_profile.csv"))
            })
        };
        let (c, stderr) = signal_during(
            &[
                "simulate",
                s(&toml),
                "--take-up-from-data",
                "--points",
                "100000",
                "--out",
                s(&out),
            ],
            signal,
            ready,
        );
        assert_eq!(c, Some(code), "{stderr}");
        assert!(stderr.contains(name), "{stderr}");
        assert!(
            temporaries(&out).is_empty(),
            "{signal}: {:?}",
            temporaries(&out)
        );
        let manifest = fs::read_to_string(out.join("PARTIAL.txt")).unwrap();
        assert!(manifest.contains("missing "), "{manifest}");
        assert!(checksums_below(&data).values().all(Option::is_some));
    }
}

#[test]
fn b05_sigterm_during_fit_out_leaves_the_set_marked_and_no_temporary() {
    let (dir, toml, _data) = shipped_copy("sigterm_fit");
    let out = dir.join("fit");
    let ready = || out.join("fit_report.txt").exists();
    let (c, stderr) = signal_during(&["fit", s(&toml), "--out", s(&out)], "-TERM", ready);
    if c == Some(0) {
        // the figures were done before the signal arrived: a complete set, no manifest
        assert!(!out.join("PARTIAL.txt").exists());
    } else {
        assert_eq!(c, Some(143), "{stderr}");
        let manifest = fs::read_to_string(out.join("PARTIAL.txt")).unwrap();
        assert!(manifest.contains("missing figure "), "{manifest}");
    }
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

/// The id of a process that has ended (for temporaries left by a dead run).
fn dead_pid() -> u32 {
    let mut c = Command::new("true").spawn().unwrap();
    let pid = c.id();
    c.wait().unwrap();
    pid
}

#[test]
fn b04_b20_temporaries_of_killed_runs_are_removed_by_the_next_run() {
    // [B04, B04b] temporaries of runs killed at any moment (B04b: later in the run) carry the
    // dead process's id and are removed by the next run
    let (dir, toml, data) = shipped_copy("stale_temporaries");
    let out = dir.join("sim");
    fs::create_dir_all(&out).unwrap();
    let dead = dead_pid();
    let stale = [
        format!(".tmp-diffbvp-{dead}-0"),
        format!(".v0p27_p3_profile.csv.tmp-{dead}-3.csv"),
    ];
    for n in &stale {
        fs::write(out.join(n), "half a profile").unwrap();
    }
    // a temporary of a live process (this test) and a user's file that merely looks alike
    let live = format!(".tmp-diffbvp-{}-0", std::process::id());
    fs::write(out.join(&live), "being written").unwrap();
    fs::write(out.join("notes.tmp-1-2.txt"), "mine").unwrap();
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
    for n in &stale {
        assert!(!out.join(n).exists(), "{n} left");
    }
    assert!(
        out.join(&live).exists(),
        "a live run's temporary was removed"
    );
    assert!(out.join("notes.tmp-1-2.txt").exists());
    assert!(
        p.stderr.contains("a temporary left behind by an ended run"),
        "{}",
        p.stderr
    );
    // B20: runs killed at random moments leave at most one temporary each, removed by the
    // next run into the same directory
    for (k, delay) in [150u64, 300, 450].into_iter().enumerate() {
        let o = dir.join(format!("killed{k}"));
        let mut child = Command::new(bin())
            .args([
                "--quiet",
                "simulate",
                s(&toml),
                "--take-up-from-data",
                "--points",
                "100000",
                "--out",
                s(&o),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay));
        let _ = child.kill();
        let _ = child.wait();
        assert!(temporaries(&o).len() <= 1, "{:?}", temporaries(&o));
        let p = rheometer(
            &[
                "--quiet",
                "simulate",
                s(&toml),
                "--take-up-from-data",
                "--out",
                s(&o),
            ],
            &[&data],
            LIMIT,
        );
        p.assert_success();
        assert!(temporaries(&o).is_empty(), "{:?}", temporaries(&o));
        assert!(!o.join("PARTIAL.txt").exists());
    }
}

// ---------------------------------------------------------------------------------------------
// A figure that cannot be written

#[test]
fn c08_a_full_disk_gives_a_readable_message_and_a_marked_set() {
    let (dir, toml, data) = shipped_copy("full_disk");
    // as root: a 300 KiB tmpfs in a private mount namespace; the report, JSON and profiles
    // fit, the figures do not
    if !is_root() {
        eprintln!("needs root for a small tmpfs: skipped");
        return;
    }
    let fs_dir = dir.join("small");
    fs::create_dir_all(&fs_dir).unwrap();
    let script = format!(
        "mount -t tmpfs -o size=300k tmpfs {d} || exit 77\n\
         \"$BIN\" --quiet fit {t} --out {d}/out > /dev/null 2> err.txt; echo rc=$?\n\
         echo partial=$(test -e {d}/out/PARTIAL.txt && echo yes || echo no)\n\
         grep -c '^complete ' {d}/out/PARTIAL.txt | sed 's/^/complete=/'\n\
         echo temporaries=$(ls -A {d}/out | grep -c tmp-)",
        d = s(&fs_dir),
        t = s(&toml)
    );
    let p = bash(
        &format!("exec unshare -m bash -c {}", shell_quote(&script)),
        &dir,
        &[&data],
        LIMIT,
    );
    if p.code == Some(77) {
        eprintln!("no tmpfs mount here: skipped");
        return;
    }
    assert_eq!(value(&p, "rc"), "1", "{}", p.stderr);
    let err = fs::read_to_string(dir.join("err.txt")).unwrap();
    assert!(err.contains("No space left on device"), "{err}");
    assert!(
        !err.contains("ImageError") && !err.contains("Custom {"),
        "{err}"
    );
    assert!(err.contains("PARTIAL.txt"), "{err}");
    assert_eq!(value(&p, "partial"), "yes");
    // the report, the JSON and the profiles are listed as written
    let complete: usize = value(&p, "complete").parse().unwrap();
    assert!(complete >= 11, "{complete} files listed as complete");
    assert_eq!(value(&p, "temporaries"), "0");
    p.assert_inputs_unchanged();
}

// ---------------------------------------------------------------------------------------------
// Flags that contradict each other: refused, both flags named

#[test]
fn g40_g41_x20c_x21_contradicting_flags_are_refused_naming_both() {
    let (dir, toml, data) = shipped_copy("conflicts");
    let out = dir.join("out");
    let (t, o) = (s(&toml), s(&out));
    let cases: Vec<(Vec<&str>, [&str; 2])> = vec![
        (
            vec![
                "compare",
                t,
                "--newtonian",
                "--kappa",
                "11",
                "--n",
                "0.5",
                "--take-up-from-data",
                "--out",
                o,
            ],
            ["--newtonian", "--n"],
        ),
        (
            vec![
                "simulate",
                t,
                "--take-up-from-data",
                "--out",
                o,
                "--newtonian",
                "--n",
                "0.5",
            ],
            ["--newtonian", "--n"],
        ),
        (
            vec![
                "simulate",
                t,
                "--take-up-diameter",
                "1e-4",
                "--take-up-from-data",
                "--out",
                o,
            ],
            ["--take-up-diameter", "--take-up-from-data"],
        ),
        (
            vec!["fit", t, "--newtonian", "--model", "carreau"],
            ["--newtonian", "--model"],
        ),
        (
            vec!["fit", t, "--newtonian", "--start", "0.5,12"],
            ["--newtonian", "--start"],
        ),
    ];
    for (args, flags) in cases {
        let p = rheometer(&args, &[&data], LIMIT);
        p.assert_clean_failure(&flags);
        assert!(p.stderr.contains("cannot be used with"), "{}", p.stderr);
        assert!(!out.exists());
    }
}

#[test]
fn g25_g68_value_dependent_contradictions_are_refused_before_the_fit() {
    let (_dir, toml, data) = shipped_copy("value_conflicts");
    let t = s(&toml);
    for (args, needles) in [
        (
            vec!["fit", t, "--f-scale", "0.02"],
            vec!["--f-scale 0.02", "robust loss", "--loss soft_l1"],
        ),
        (
            vec!["fit", t, "--loss", "linear", "--f-scale", "0.02"],
            vec!["--f-scale", "linear"],
        ),
        (
            vec!["diagnose", t, "--f-scale", "0.02"],
            vec!["--f-scale 0.02", "robust loss", "--loss soft_l1"],
        ),
        (
            vec!["fit", t, "--model", "newtonian", "--start", "0.5,12"],
            vec!["--start", "--model newtonian", "no (n, kappa)"],
        ),
    ] {
        let p = rheometer(&args, &[&data], LIMIT);
        p.assert_clean_failure(&needles);
        assert!(p.elapsed < Duration::from_secs(3), "{:?}", p.elapsed);
    }
    // with a robust loss the margin is used
    let p = rheometer(
        &[
            "--quiet",
            "fit",
            t,
            "--loss",
            "soft_l1",
            "--f-scale",
            "0.02",
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
}

#[test]
fn g67_newtonian_with_an_effect_fits_the_effect() {
    let (_dir, toml, data) = shipped_copy("newtonian_with");
    let p = rheometer(
        &["fit", s(&toml), "--newtonian", "--with", "radiation"],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    // the effect is part of the fitted model, not ignored
    assert!(p.stdout.contains("radiation"), "{}", p.stdout);
    assert!(p.stdout.contains("Newtonian"), "{}", p.stdout);
}

// ---------------------------------------------------------------------------------------------
// Numbers in messages

#[test]
fn x03d_g50_g51_x08b_x02c_numbers_and_negative_values_in_messages() {
    let (dir, toml, data) = shipped_copy("numbers");
    let out = dir.join("out");
    let (t, o) = (s(&toml), s(&out));
    let sim = |extra: &[&str]| {
        let mut a = vec!["simulate", t, "--take-up-from-data", "--out", o];
        a.extend(extra);
        rheometer(&a, &[&data], LIMIT)
    };
    let p = sim(&["--kappa", "1e308"]);
    p.assert_clean_failure(&["--kappa", "got 1e308"]);
    assert!(!p.stderr.contains("00000000000"), "{}", p.stderr);
    let p = sim(&["--points", "-5"]);
    p.assert_clean_failure(&["--points", "give 2 to 100000", "got -5"]);
    assert!(!p.stderr.contains("unexpected argument"), "{}", p.stderr);
    let p = sim(&["--n", "--", "-0.1"]);
    p.assert_clean_failure(&["negative numbers need no \"--\"", "--n -0.1"]);
    let p = sim(&["--n", "-0.1"]);
    p.assert_clean_failure(&["--n", "must be >= 0", "-0.1"]);
    let p = sim(&["--max-nodes", "-3"]);
    p.assert_clean_failure(&["--max-nodes", "got -3"]);
    let p = sim(&["--take-up-diameter", "1e-300"]);
    p.assert_clean_failure(&["--take-up-diameter", "got 1e-300 m"]);
    let land = |extra: &[&str]| {
        let mut a = vec!["landscape", t, "--grid", "3x3", "--out", o];
        a.extend(extra);
        rheometer(&a, &[&data], LIMIT)
    };
    let p = land(&["--n-range", "0,0"]);
    p.assert_clean_failure(&["--n-range 0,0", "single value"]);
    assert!(!p.stderr.contains("did you mean"), "{}", p.stderr);
    let p = land(&["--n-range", "0.9,0.2"]);
    p.assert_clean_failure(&["did you mean 0.2,0.9?"]);
    let p = rheometer(
        &["landscape", t, "--grid", "-3x3", "--out", o],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["--grid", "-3x3", "at least 2 points per direction"]);
    // G51: a range of 1e-300 width: no 300-digit numbers in messages or in the CSV
    let p = land(&["--n-range", "0,1e-300"]);
    assert!(!p.panicked(), "{}", p.stderr);
    assert!(!p.stderr.contains("000000000000"), "{}", p.stderr);
    if let Ok(csv) = fs::read_to_string(out.join("landscape.csv")) {
        assert!(
            !csv.contains("000000000000"),
            "{}",
            &csv[..csv.len().min(300)]
        );
        assert!(csv.contains("1e-300"), "{}", &csv[..csv.len().min(300)]);
    }
}

#[test]
fn g42_format_svg_applies_to_every_figure_of_fit() {
    let (dir, toml, data) = shipped_copy("format_svg");
    let out = dir.join("out");
    let p = rheometer(
        &[
            "--format",
            "svg",
            "--quiet",
            "fit",
            s(&toml),
            "--with",
            "radiation",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    let names: Vec<String> = fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().any(|n| n == "residuals_before_after.svg"),
        "{names:?}"
    );
    assert!(!names.iter().any(|n| n.ends_with(".png")), "{names:?}");
    assert!(!names.iter().any(|n| n == "PARTIAL.txt"), "{names:?}");
}

/// The output set of a normal run has no manifest and no temporary left, and files of an
/// earlier run are replaced.
#[test]
fn a_rerun_into_the_same_directories_replaces_its_own_files() {
    let (dir, toml, data) = shipped_copy("rerun");
    let out = dir.join("out");
    for _ in 0..2 {
        let p = rheometer(
            &[
                "--quiet",
                "fit",
                s(&toml),
                "--json",
                s(&dir.join("fit.json")),
                "--out",
                s(&out),
            ],
            &[&data],
            LIMIT,
        );
        p.assert_success();
    }
    assert!(!out.join("PARTIAL.txt").exists());
    assert!(temporaries(&out).is_empty() && temporaries(&dir).is_empty());
    assert_json(&fs::read_to_string(dir.join("fit.json")).unwrap());
    let _: PathBuf = out;
}
