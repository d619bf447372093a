//! The findings of the second bad-input round (`bad-input-findings-t4.md`), classes A (the
//! JSON inputs `fit --from`, `diagnose --from`, `compare --fit`), C (outputs and signals) and
//! E (the environment): each finding as a test over its whole family (every door that reads
//! a report, every long subcommand, every variable the program reads). Test names carry the
//! finding's class and a short name.

use crate::probe;

use probe::{s, Probe};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(180);

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_rheometer")
}

/// The reports every test reads: a fit of the shipped data set, a diagnosis of
/// `hidden_radiation` (same experiment names), a comparison and a flow curve, made once.
struct Fixtures {
    /// The scratch directory.
    dir: PathBuf,
    /// The shipped data set's copy.
    toml: PathBuf,
    /// `fit TOML --json` (plus `--out`'s flow_curve.json in `fit_out`).
    fit: PathBuf,
    fit_out: PathBuf,
    /// `diagnose hidden_radiation --json`.
    diag: PathBuf,
    /// `compare TOML --fit fit.json --out cmp`'s JSON.
    comparison: PathBuf,
}

fn fixtures() -> &'static Fixtures {
    static F: OnceLock<Fixtures> = OnceLock::new();
    F.get_or_init(|| {
        let dir = probe::scratch("t4_fixtures");
        let toml = probe::copy_data_set("pmma7n_synthetic", &dir);
        let hr = probe::copy_data_set("hidden_radiation", &dir);
        let fit = dir.join("fit.json");
        let fit_out = dir.join("fit_out");
        let diag = dir.join("diag.json");
        probe::rheometer(
            &["fit", s(&toml), "--json", s(&fit), "--out", s(&fit_out)],
            &[],
            LIMIT,
        )
        .assert_success();
        probe::rheometer(&["diagnose", s(&hr), "--json", s(&diag)], &[], LIMIT).assert_success();
        let cmp = dir.join("cmp");
        probe::rheometer(
            &["compare", s(&toml), "--fit", s(&fit), "--out", s(&cmp)],
            &[],
            LIMIT,
        )
        .assert_success();
        let comparison = fs::read_dir(&cmp)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .find(|p| p.extension().is_some_and(|e| e == "json"))
            .expect("compare --out writes a JSON");
        Fixtures {
            dir,
            toml,
            fit,
            fit_out,
            diag,
            comparison,
        }
    })
}

/// Every door that reads a report, with `file` as the report: `fit --from`,
/// `diagnose --from`, `compare --fit` (its outputs in a fresh directory).
fn doors(file: &str) -> Vec<Vec<String>> {
    let f = fixtures();
    let toml = s(&f.toml).to_string();
    let out = f.dir.join(format!(
        "out-{}",
        COUNTER.fetch_add(1, std::sync::atomic::Ordering::SeqCst)
    ));
    vec![
        vec!["fit".into(), toml.clone(), "--from".into(), file.into()],
        vec![
            "diagnose".into(),
            toml.clone(),
            "--from".into(),
            file.into(),
        ],
        vec![
            "compare".into(),
            toml,
            "--fit".into(),
            file.into(),
            "--out".into(),
            s(&out).into(),
        ],
    ]
}

static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn run(args: &[String], watch: &[&Path]) -> Probe {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    probe::rheometer(&a, watch, LIMIT)
}

/// Every door refuses `file` quickly (before any work), naming every needle.
fn refused_everywhere(file: &Path, needles: &[&str]) {
    // only regular files are watched: the probe reads what it watches, and a FIFO or a
    // device would block it or never end
    let watch: Vec<&Path> = if file.is_file() { vec![file] } else { vec![] };
    for args in doors(s(file)) {
        let p = run(&args, &watch);
        p.assert_clean_failure(needles);
        assert!(
            p.elapsed < Duration::from_secs(10),
            "{args:?}: {:?}",
            p.elapsed
        );
    }
}

/// The fit report as JSON text, edited by `edit` (on its value), written to `name`.
fn edited(name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let f = fixtures();
    let mut v: Value = serde_json::from_str(&fs::read_to_string(&f.fit).unwrap()).unwrap();
    edit(&mut v);
    let p = f.dir.join(name);
    fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    p
}

/// The fit report's text with `from` replaced by `to` (once), written to `name`.
fn text_edited(name: &str, from: &str, to: &str) -> PathBuf {
    let f = fixtures();
    let text = fs::read_to_string(&f.fit).unwrap();
    assert!(text.contains(from), "{from}");
    let p = f.dir.join(name);
    fs::write(&p, text.replacen(from, to, 1)).unwrap();
    p
}

/// `n`'s value replaced by the literal `lit` in a file `name`.
fn n_value(name: &str, lit: &str) -> PathBuf {
    let p = edited(name, |v| v["n"]["value"] = "@@N@@".into());
    let text = fs::read_to_string(&p).unwrap().replace("\"@@N@@\"", lit);
    fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_devices_fifos_and_directories_are_refused_before_opening() {
    let f = fixtures();
    refused_everywhere(Path::new("/dev/zero"), &["/dev/zero", "a character device"]);
    let fifo = f.dir.join("fit.fifo");
    let _ = fs::remove_file(&fifo);
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    refused_everywhere(&fifo, &["a FIFO (named pipe)", "not a regular file"]);
    // a directory of its own: the probe checksums what it is given
    let empty = f.dir.join("a_directory");
    fs::create_dir_all(&empty).unwrap();
    refused_everywhere(&empty, &["a directory"]);
    // standard input that never ends: refused at its first bytes, not read to the end
    for args in doors("/dev/stdin").into_iter().chain(doors("-")) {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let p = probe::run_with(&a, &[], LIMIT, |c| {
            c.stdin(fs::File::open("/dev/zero").unwrap())
        });
        p.assert_clean_failure(&["binary data (NUL bytes)"]);
        assert!(p.elapsed < Duration::from_secs(10), "{:?}", p.elapsed);
    }
}

#[test]
fn a_large_files_are_refused_by_the_cap_before_reading() {
    let f = fixtures();
    // a 1 GB sparse file (NUL bytes): refused from its size, at once
    let big = f.dir.join("big.json");
    let file = fs::File::create(&big).unwrap();
    file.set_len(1 << 30).unwrap();
    refused_everywhere(&big, &["larger than the limit", "--allow-large-inputs"]);
    // a valid report followed by NUL bytes: binary data, named
    let mut bytes = fs::read(&f.fit).unwrap();
    bytes.extend(std::iter::repeat_n(0u8, 4096));
    let nul = f.dir.join("nul.json");
    fs::write(&nul, &bytes).unwrap();
    refused_everywhere(&nul, &["binary data (NUL bytes)"]);
    // a 70 MB string field, and 6 million extra keys (90 MB): over the cap
    let long = edited("long.json", |v| v["note"] = "x".repeat(70 << 20).into());
    refused_everywhere(&long, &["larger than the limit of 67 MB"]);
    let text = fs::read_to_string(&f.fit).unwrap();
    let mut keys = String::with_capacity(100 << 20);
    keys.push('{');
    for i in 0..6_000_000 {
        keys.push_str(&format!("\"k{i}\": 1, "));
    }
    keys.push_str(&text[1..]);
    let many = f.dir.join("many.json");
    fs::write(&many, keys).unwrap();
    refused_everywhere(&many, &["larger than the limit"]);
    let _ = fs::remove_file(&big);
    let _ = fs::remove_file(&long);
    let _ = fs::remove_file(&many);
}

#[test]
fn a_truncated_empty_and_blank_files_say_so() {
    let f = fixtures();
    let text = fs::read_to_string(&f.fit).unwrap();
    let half = f.dir.join("half.json");
    fs::write(&half, &text[..text.len() / 2]).unwrap();
    refused_everywhere(&half, &["ends early (truncated?)", "rheometer fit --json"]);
    let empty = f.dir.join("empty.json");
    fs::write(&empty, "").unwrap();
    refused_everywhere(&empty, &["the file is empty", "re-create it"]);
    let blank = f.dir.join("blank.json");
    fs::write(&blank, " \n\t\n").unwrap();
    refused_everywhere(&blank, &["empty (whitespace only)"]);
}

#[test]
fn a_nan_infinity_and_out_of_range_numbers_name_the_field() {
    for lit in ["NaN", "Infinity", "-Infinity"] {
        let p = n_value(&format!("n_{lit}.json"), lit);
        refused_everywhere(
            &p,
            &[&format!("`n.value` = {lit}"), "JSON has no NaN or Infinity"],
        );
    }
    let p = n_value("n_1e400.json", "1e400");
    refused_everywhere(
        &p,
        &["`n.value` = 1e400", "out of the range of a 64-bit float"],
    );
}

#[test]
fn a_wrong_types_and_missing_fields_name_the_field() {
    let p = edited("n_string.json", |v| v["n"]["value"] = "0.8".into());
    refused_everywhere(
        &p,
        &["field `n.value` is a string (\"0.8\"); it should be a number"],
    );
    let p = edited("exp_string.json", |v| v["experiments"] = "v0p27_p1".into());
    refused_everywhere(&p, &["field `experiments`", "v0p27_p1", "sequence"]);
    let p = edited("exp_item.json", |v| v["experiments"][2] = 7.into());
    refused_everywhere(&p, &["field `experiments[2]`"]);
    let p = edited("no_experiments.json", |v| {
        v.as_object_mut().unwrap().remove("experiments");
    });
    refused_everywhere(
        &p,
        &["field `experiments`: missing", "ties the fit to its data"],
    );
}

#[test]
fn a_duplicate_keys_are_refused() {
    let p = text_edited("dupkey.json", "{", "{\n  \"n\": {\"value\": 0.1},");
    refused_everywhere(&p, &["the key \"n\" appears twice", "keep one"]);
    let p = text_edited(
        "dupkey_inner.json",
        "\"value\":",
        "\"value\": 0.5, \"value\":",
    );
    refused_everywhere(&p, &["appears twice"]);
}

#[test]
fn a_encodings_are_named_and_a_bom_is_skipped() {
    let f = fixtures();
    let text = fs::read_to_string(&f.fit).unwrap();
    let utf16 = f.dir.join("utf16.json");
    let mut bytes = vec![0xFF, 0xFE];
    bytes.extend(text.encode_utf16().flat_map(u16::to_le_bytes));
    fs::write(&utf16, bytes).unwrap();
    refused_everywhere(&utf16, &["UTF-16"]);
    let latin1 = f.dir.join("latin1.json");
    let bytes: Vec<u8> = text
        .replacen(
            "\"written_by\": \"rheometer",
            "\"written_by\": \"rh\u{e9}ometer",
            1,
        )
        .chars()
        .map(|c| c as u32 as u8)
        .collect();
    fs::write(&latin1, bytes).unwrap();
    refused_everywhere(&latin1, &["Latin-1"]);
    // a UTF-8 byte-order mark is skipped: the report reads
    let bom = f.dir.join("bom.json");
    fs::write(&bom, format!("\u{feff}{text}")).unwrap();
    let out = f.dir.join("cmp_bom");
    let p = probe::rheometer(
        &["compare", s(&f.toml), "--fit", s(&bom), "--out", s(&out)],
        &[&bom],
        LIMIT,
    );
    p.assert_success();
}

#[test]
fn a_reports_of_another_kind_are_named() {
    let f = fixtures();
    let flow = f.fit_out.join("flow_curve.json");
    refused_everywhere(
        &f.comparison,
        &["this is a `compare --json` report", "wants a fit report"],
    );
    refused_everywhere(&flow, &["this is a `fit --out (flow_curve.json)` report"]);
    // a design report as this program writes it, and one without a stamp
    let design = f.dir.join("design.json");
    fs::write(
        &design,
        serde_json::json!({"schema_version": 1, "report": "design", "written_by": "rheometer 0.1.0",
            "criterion": "d", "candidates": []})
        .to_string(),
    )
    .unwrap();
    refused_everywhere(
        &design,
        &["this is a `design --json` report", "--", "diagnosis"],
    );
    let unstamped = f.dir.join("design_unstamped.json");
    fs::write(
        &unstamped,
        serde_json::json!({"criterion": "d", "candidates": [], "estimator": null}).to_string(),
    )
    .unwrap();
    refused_everywhere(&unstamped, &["this is a `design --json` report"]);
    let array = f.dir.join("array.json");
    fs::write(&array, "[1, 2]").unwrap();
    refused_everywhere(&array, &["the JSON is an array, not a report"]);
}

#[test]
fn a_schema_versions_other_than_this_one_are_refused_with_the_writer() {
    let f = fixtures();
    let v: Value = serde_json::from_str(&fs::read_to_string(&f.fit).unwrap()).unwrap();
    assert_eq!(v["schema_version"], 1);
    assert_eq!(v["report"], "fit");
    assert!(v["written_by"].as_str().unwrap().starts_with("rheometer "));
    assert!(
        v["data_digest"].as_str().is_some_and(|d| d.len() == 16),
        "{}",
        v["data_digest"]
    );
    for path in [&f.diag, &f.comparison, &f.fit_out.join("flow_curve.json")] {
        let w: Value = serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap();
        assert_eq!(w["schema_version"], 1, "{}", path.display());
        assert!(w["written_by"].is_string(), "{}", path.display());
    }
    let p = edited("v2.json", |v| {
        v["schema_version"] = 2.into();
        v["written_by"] = "rheometer 9.0.0".into();
    });
    refused_everywhere(
        &p,
        &[
            "schema_version 2 (written by rheometer 9.0.0)",
            "re-create it with this version",
        ],
    );
    let p = edited("v0.json", |v| {
        let o = v.as_object_mut().unwrap();
        o.remove("schema_version");
        o.remove("report");
        o.remove("written_by");
    });
    refused_everywhere(
        &p,
        &["a fit report without \"schema_version\"", "re-create it"],
    );
}

#[test]
fn a_compare_takes_a_diagnosis_and_every_door_reads_standard_input() {
    let f = fixtures();
    // compare --fit diag.json: the diagnosis' final fit (hidden_radiation's names agree)
    let out = f.dir.join("cmp_diag");
    let p = probe::rheometer(
        &["compare", s(&f.toml), "--fit", s(&f.diag), "--out", s(&out)],
        &[&f.diag],
        LIMIT,
    );
    p.assert_success();
    // `-` is standard input, for --fit and --from
    let out = f.dir.join("cmp_stdin");
    let p = probe::run_with(
        &["compare", s(&f.toml), "--fit", "-", "--out", s(&out)],
        &[&f.fit],
        LIMIT,
        |c| c.stdin(fs::File::open(&f.fit).unwrap()),
    );
    p.assert_success();
    assert!(p.stderr.contains("model from -"), "{}", p.stderr);
    let p = probe::run_with(
        &["fit", s(&f.toml), "--from", "-", "--quiet"],
        &[&f.fit],
        LIMIT,
        |c| c.stdin(fs::File::open(&f.fit).unwrap()),
    );
    p.assert_success();
}

#[test]
fn a_a_fit_of_other_data_with_the_same_names_is_warned_about() {
    let f = fixtures();
    // the same data: no warning
    let out = f.dir.join("cmp_same");
    let p = probe::rheometer(
        &["compare", s(&f.toml), "--fit", s(&f.fit), "--out", s(&out)],
        &[],
        LIMIT,
    );
    p.assert_success();
    assert!(!p.stderr.contains("other data"), "{}", p.stderr);
    // one measured diameter changed: same names, other data
    let dir = probe::scratch("t4_other_data");
    let toml = probe::copy_data_set("pmma7n_synthetic", &dir);
    let csv = toml.with_file_name("v0p27_p1.csv");
    let text = fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let i = lines.len() - 1;
    let (a, b) = lines[i].split_once(',').unwrap();
    let d: f64 = b.trim().parse().unwrap();
    lines[i] = format!("{a},{}", d * 1.01);
    fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let out = dir.join("cmp");
    let p = probe::rheometer(
        &["compare", s(&toml), "--fit", s(&f.fit), "--out", s(&out)],
        &[],
        LIMIT,
    );
    p.assert_success();
    assert!(
        p.stderr.contains("was fitted on other data than these")
            && p.stderr.contains("data digest"),
        "{}",
        p.stderr
    );
    // a diagnosis of another data set (hidden_radiation) with the same names
    let out = dir.join("cmp_diag");
    let p = probe::rheometer(
        &["compare", s(&toml), "--fit", s(&f.diag), "--out", s(&out)],
        &[],
        LIMIT,
    );
    p.assert_success();
    assert!(p.stderr.contains("other data"), "{}", p.stderr);
}

/// Temporaries of the output layer in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.contains(".tmp-diffbvp"))
                .collect()
        })
        .unwrap_or_default()
}

fn sh(script: &str, env: &[(&str, &str)]) -> (Option<i32>, String, Duration) {
    let t0 = Instant::now();
    let mut c = Command::new("bash");
    c.arg("-c")
        .arg(script)
        .env("R", bin())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code(), text, t0.elapsed())
}

#[test]
fn c_a_file_size_limit_is_an_error_and_leaves_no_temporary() {
    let f = fixtures();
    let dir = probe::scratch("t4_ulimit_f");
    let json = dir.join("o.json");
    // bash counts ulimit -f in blocks of 1024 bytes: 10 kB, less than a fit report
    let (code, text, _) = sh(
        &format!(
            "ulimit -f 10; \"$R\" fit {} --json {}; echo \"exit=$?\"",
            s(&f.toml),
            s(&json)
        ),
        &[],
    );
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("exit=1"), "{text}");
    assert!(text.contains("file-size limit"), "{text}");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
    assert!(!json.exists());
    // a long subcommand's directory: simulate --out
    let out = dir.join("sim");
    let (_, text, _) = sh(
        &format!(
            "ulimit -f 10; \"$R\" simulate {} --take-up-from-data --points 2000 --out {}; \
             echo \"exit=$?\"",
            s(&f.toml),
            s(&out)
        ),
        &[],
    );
    assert!(
        text.contains("exit=1") && text.contains("file-size limit"),
        "{text}"
    );
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

#[test]
fn c_sigterm_and_sighup_keep_the_finished_landscape_points() {
    let f = fixtures();
    for (signal, code, name) in [("-TERM", 143, "SIGTERM"), ("-HUP", 129, "SIGHUP")] {
        let dir = probe::scratch(&format!("t4_landscape{signal}"));
        let out = dir.join("l");
        let mut child = Command::new(bin())
            .args([
                "landscape",
                s(&f.toml),
                "--grid",
                "101x101",
                "--out",
                s(&out),
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(4000));
        assert!(Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap()
            .success());
        let t0 = Instant::now();
        while child.try_wait().unwrap().is_none() {
            assert!(t0.elapsed() < Duration::from_secs(15), "still running");
            std::thread::sleep(Duration::from_millis(20));
        }
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        if o.status.code() == Some(0) {
            // the machine finished the grid before the signal
            continue;
        }
        assert_eq!(o.status.code(), Some(code), "{stderr}");
        assert!(
            stderr.contains(&format!("terminated by {name}")),
            "{stderr}"
        );
        let csv = fs::read_to_string(out.join("landscape.csv")).unwrap();
        assert!(csv.contains(",ok,"), "no finished point kept");
        assert!(csv.contains("not_computed"), "{stderr}");
        assert!(out.join("PARTIAL.txt").exists() || stderr.contains("keeps them"));
        assert!(temporaries(&out).is_empty());
    }
}

#[test]
fn c_out_on_a_device_names_its_kind() {
    let f = fixtures();
    for cmd in [
        vec!["fit", s(&f.toml), "--out", "/dev/null"],
        vec![
            "simulate",
            s(&f.toml),
            "--take-up-from-data",
            "--out",
            "/dev/null",
        ],
        vec![
            "landscape",
            s(&f.toml),
            "--grid",
            "3x3",
            "--out",
            "/dev/null",
        ],
    ] {
        let p = probe::rheometer(&cmd, &[], LIMIT);
        p.assert_clean_failure(&["/dev/null exists and is a character device, not a directory"]);
    }
}

#[test]
fn c_a_closed_stdout_pipe_is_success_with_out_too() {
    let f = fixtures();
    let dir = probe::scratch("t4_pipe");
    let out = dir.join("o");
    let (code, text, _) = sh(
        &format!(
            "\"$R\" fit {} --json - --out {} | head -c 100 >/dev/null; \
             echo \"exit=${{PIPESTATUS[0]}}\"",
            s(&f.toml),
            s(&out)
        ),
        &[],
    );
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("exit=0"), "{text}");
    assert!(!text.contains("Broken pipe"), "{text}");
}

#[test]
fn c_an_immutable_output_is_refused_before_the_work() {
    let f = fixtures();
    let dir = probe::scratch("t4_immutable");
    let json = dir.join("out.json");
    fs::write(&json, "old").unwrap();
    if !Command::new("chattr")
        .args(["+i", s(&json)])
        .status()
        .is_ok_and(|s| s.success())
    {
        eprintln!("chattr +i not possible here (not root, or the file system has no flags)");
        return;
    }
    let p = probe::rheometer(&["fit", s(&f.toml), "--json", s(&json)], &[&json], LIMIT);
    let _ = Command::new("chattr").args(["-i", s(&json)]).status();
    p.assert_clean_failure(&["immutable", "chattr -i"]);
    assert!(
        p.elapsed < Duration::from_secs(5),
        "refused after the work: {:?}",
        p.elapsed
    );
    assert_eq!(fs::read_to_string(&json).unwrap(), "old");
}

#[test]
fn e_rayon_num_threads_is_clamped_or_ignored_with_a_warning() {
    let f = fixtures();
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let max = 4 * cores;
    for value in ["100000", "5000"] {
        let (code, text, t) = sh(
            &format!("\"$R\" fit {} --quiet", s(&f.toml)),
            &[("RAYON_NUM_THREADS", value)],
        );
        assert_eq!(code, Some(0), "{text}");
        assert!(
            text.contains(&format!(
                "RAYON_NUM_THREADS={value} is more than 4 threads per core"
            )) && text.contains(&format!("using {max} threads")),
            "{text}"
        );
        assert!(t < Duration::from_secs(120), "{t:?}");
    }
    // under a memory limit a large count is clamped before any thread starts: no panic
    let (_, text, _) = sh(
        &format!("ulimit -v 8000000; \"$R\" fit {} --quiet", s(&f.toml)),
        &[("RAYON_NUM_THREADS", "5000")],
    );
    assert!(!text.contains("panicked"), "{text}");
    let (code, text, _) = sh(
        &format!("\"$R\" fit {} --quiet", s(&f.toml)),
        &[("RAYON_NUM_THREADS", "abc")],
    );
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("RAYON_NUM_THREADS=\"abc\" is not a whole number"),
        "{text}"
    );
}

#[test]
fn e_a_low_memory_limit_is_named() {
    let f = fixtures();
    let (code, text, _) = sh(
        &format!("ulimit -v 150000; \"$R\" fit {} --quiet", s(&f.toml)),
        &[],
    );
    assert!(
        text.contains("limited to 146 MB (ulimit -v)"),
        "{code:?} {text}"
    );
    assert!(!text.contains("panicked"), "{text}");
}

#[test]
fn e_diffbvp_variables_are_validated_by_name_and_range() {
    let f = fixtures();
    for value in ["abc", "0", "-1", "1e10", "nan", ""] {
        let (code, text, t) = sh(
            &format!("\"$R\" fit {} --quiet", s(&f.toml)),
            &[("DIFFBVP_FIFO_WAIT_S", value)],
        );
        assert_eq!(code, Some(1), "{value}: {text}");
        assert!(
            text.contains("DIFFBVP_FIFO_WAIT_S") && text.contains("[0.1, 3600]"),
            "{value}: {text}"
        );
        assert!(t < Duration::from_secs(5));
    }
    let (code, text, _) = sh(
        &format!("\"$R\" fit {} --quiet", s(&f.toml)),
        &[("DIFFBVP_FIFO_WAIT", "60")],
    );
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("DIFFBVP_FIFO_WAIT is not one this program reads"),
        "{text}"
    );
    let (code, text, _) = sh(
        &format!("\"$R\" fit {} --quiet", s(&f.toml)),
        &[("DIFFBVP_FIFO_WAIT_S", "60")],
    );
    assert_eq!(code, Some(0), "{text}");
}

#[test]
fn e_a_json_array_as_the_experiments_file_is_named_json() {
    let dir = probe::scratch("t4_json_array");
    for (name, text) in [("a.json", "[\n  {\"a\": 1}\n]\n"), ("b.json", "[1, 2]\n")] {
        let p = dir.join(name);
        fs::write(&p, text).unwrap();
        let probe = probe::rheometer(&["fit", s(&p)], &[&p], LIMIT);
        probe.assert_clean_failure(&["it is JSON"]);
    }
}
