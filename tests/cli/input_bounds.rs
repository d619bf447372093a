//! Bounded inputs (issue 28 items 2 and 6): special files are refused before they are opened,
//! every file, line, row count and the number of experiments has a cap checked while reading
//! (never after a whole unbounded stream was read), encodings are named with the byte offset,
//! and long cells and huge numbers are cut in messages. Finding ids of
//! `bad-input-findings.md` in brackets.
//!
//! Scratch files live under `target/probes` (never in /tmp) and are removed at the end.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rheometer::data::input::{
    estimated_fit_memory_bytes, load_experiments, load_experiments_with, InputError, Limit,
    LoadOptions,
};

/// A scratch copy of the shipped data set: (scratch dir, TOML, data dir).
fn copy(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    crate::probe::shipped_copy(name)
}

/// Points experiment `v0p27_p1` at `data`.
fn set_data(toml: &Path, data: &str) {
    let text = std::fs::read_to_string(toml).unwrap();
    let from = "data = \"v0p27_p1.csv\"";
    assert!(text.contains(from));
    std::fs::write(toml, text.replacen(from, &format!("data = {data:?}"), 1)).unwrap();
}

/// `file:line:` of the first line of `toml` containing `needle`.
fn key_line(toml: &Path, needle: &str) -> String {
    let line = crate::probe::line_where(toml, |l| l.contains(needle));
    format!("{}:{line}:", toml.display())
}

/// Loads `toml`, expecting an error within `limit`; returns the message.
fn refused(toml: &Path, limit: Duration) -> String {
    let t0 = Instant::now();
    let e = load_experiments(toml).expect_err("the input must be refused");
    let elapsed = t0.elapsed();
    assert!(elapsed < limit, "refused only after {elapsed:?}: {e}");
    e.to_string()
}

fn assert_contains(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "`{part}` missing in: {message}");
    }
}

/// Runs `rheometer ARGS` and returns (exit code, stderr, wall time, peak resident memory kB of
/// the child, from `wait4`).
#[cfg(unix)]
fn run_measured(args: &[&str], scratch: &Path) -> (Option<i32>, String, Duration, i64) {
    use std::os::unix::process::ExitStatusExt;
    let err_path = scratch.join("stderr.txt");
    let err = std::fs::File::create(&err_path).unwrap();
    let t0 = Instant::now();
    let child = Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err)
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: an all-zero rusage is valid; wait4 fills it for our own child, which std does
    // not wait for (the `Child` is dropped without `wait`).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(r, pid, "wait4 failed");
    let elapsed = t0.elapsed();
    drop(child);
    let code = std::process::ExitStatus::from_raw(status).code();
    let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
    (code, stderr, elapsed, usage.ru_maxrss)
}

#[cfg(unix)]
#[test]
fn dev_zero_and_dev_urandom_are_refused_within_a_second_in_little_memory() {
    // [C21, S04, C24] the CLI used to read /dev/zero at 3 GB/s and /dev/urandom forever
    let (dir, toml, _) = copy("bounds_devices");
    for device in ["/dev/zero", "/dev/urandom"] {
        let text = std::fs::read_to_string(
            crate::probe::repo().join("data/pmma7n_synthetic/experiments.toml"),
        )
        .unwrap();
        std::fs::write(&toml, text).unwrap();
        set_data(&toml, device);
        let line = crate::probe::line_where(&toml, |l| l.contains(device));
        let message = refused(&toml, Duration::from_secs(1));
        assert_contains(
            &message,
            &[
                &format!("{}:{line}:", toml.display()),
                "\"v0p27_p1\"",
                device,
                "a character device, not a regular file",
            ],
        );
        let (code, stderr, elapsed, kb) = run_measured(&["fit", crate::probe::s(&toml)], &dir);
        // a child spawned by vfork carries this test process's own memory peak into its
        // ru_maxrss (Linux records the old address space's high-water mark at exec): the
        // program's own memory is what it uses above a run that does nothing
        let (_, _, _, idle) = run_measured(&["--version"], &dir);
        assert_eq!(code, Some(1), "{stderr}");
        assert!(stderr.contains("character device"), "{stderr}");
        assert!(elapsed < Duration::from_secs(1), "{device}: {elapsed:?}");
        assert!(
            kb - idle < 100_000,
            "{device}: {kb} kB ({idle} kB for --version)"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success());
}

#[cfg(unix)]
#[test]
fn fifos_are_refused_before_they_are_opened() {
    // [C22] a FIFO as data file blocked forever; [C23] as the TOML too
    let (dir, toml, data) = copy("bounds_fifo");
    mkfifo(&data.join("pipe.csv"));
    set_data(&toml, "pipe.csv");
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &[
            &key_line(&toml, "pipe.csv"),
            "pipe.csv",
            "a FIFO (named pipe), not a regular file",
            "save the data to a file",
        ],
    );
    let fifo_toml = data.join("pipe.toml");
    mkfifo(&fifo_toml);
    let message = refused(&fifo_toml, Duration::from_secs(1));
    assert_contains(&message, &["pipe.toml", "a FIFO (named pipe)"]);
    let p = crate::probe::rheometer(
        &["fit", crate::probe::s(&fifo_toml)],
        &[],
        Duration::from_secs(20),
    );
    p.assert_clean_failure(&["pipe.toml", "FIFO"]);
    assert!(p.elapsed < Duration::from_secs(1), "{:?}", p.elapsed);
    // a directory as data
    let text = std::fs::read_to_string(&toml).unwrap();
    std::fs::write(&toml, text.replace("data = \"pipe.csv\"", "data = \".\"")).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(&message, &["a directory, not a regular file"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn experiments_from_standard_input_need_absolute_data_paths() {
    // [C26] relative data paths were resolved against /dev ("/dev/v0p27_p1.csv")
    let (dir, toml, data) = copy("bounds_stdin");
    let toml_file = std::fs::File::open(&toml).unwrap();
    let p = crate::probe::run_with(
        &["fit", "/dev/stdin"],
        &[&data],
        Duration::from_secs(30),
        |c| c.stdin(toml_file),
    );
    p.assert_clean_failure(&[
        "/dev/stdin:",
        "`data` = \"v0p27_p1.csv\" is a relative path",
        "read from /dev/stdin",
        "absolute paths",
    ]);
    assert!(!p.stderr.contains("/dev/v0p27_p1.csv"), "{}", p.stderr);
    // with absolute data paths, the experiments can come from a pipe
    let text = std::fs::read_to_string(&toml).unwrap();
    let abs = text.replace("data = \"", &format!("data = \"{}/", data.display()));
    let piped = dir.join("absolute.toml");
    std::fs::write(&piped, abs).unwrap();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "cat '{}' | '{}' --quiet fit /dev/stdin",
            piped.display(),
            env!("CARGO_BIN_EXE_rheometer")
        ))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn encodings_are_named_with_the_byte_and_utf8_is_suggested() {
    let (dir, toml, data) = copy("bounds_encodings");
    let original = std::fs::read_to_string(&toml).unwrap();
    // [E18] a UTF-16 CSV (with byte-order mark, as iconv and Excel write it)
    let csv = data.join("v0p27_p1.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut utf16 = vec![0xFF, 0xFE];
    utf16.extend(text.encode_utf16().flat_map(u16::to_le_bytes));
    std::fs::write(&csv, &utf16).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &[
            &key_line(&toml, "data = \"v0p27_p1.csv\""),
            "v0p27_p1.csv:1",
            "UTF-16",
            "FF FE",
            "re-save it as UTF-8",
        ],
    );
    // [c27] random bytes in a CSV
    let random: Vec<u8> = (0..3000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    std::fs::write(&csv, &random).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(&message, &["v0p27_p1.csv:1", "byte ", "binary data"]);
    std::fs::write(&csv, &text).unwrap();
    // [F55] a UTF-16 TOML
    let mut utf16 = vec![0xFF, 0xFE];
    utf16.extend(original.encode_utf16().flat_map(u16::to_le_bytes));
    std::fs::write(&toml, &utf16).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &["experiments.toml:1", "UTF-16", "re-save it as UTF-8"],
    );
    // [F56] a Latin-1 byte in a name; [t29] in a comment
    let latin1 = original.replacen("name = \"v0p27_p1\"", "name = \"Versuch \u{e4}\"", 1);
    let mut bytes = latin1.into_bytes();
    let i = bytes
        .windows(2)
        .position(|w| w == "\u{e4}".as_bytes())
        .unwrap();
    bytes.splice(i..i + 2, [0xE4]);
    std::fs::write(&toml, &bytes).unwrap();
    let line = bytes[..i].iter().filter(|&&b| b == b'\n').count() + 1;
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &[
            &format!("experiments.toml:{line}:17: byte {i} (0xE4)"),
            "Latin-1",
            "'\u{e4}'",
            "re-save it as UTF-8",
        ],
    );
    let comment = original.replacen("[material]", "# temp\u{e9}rature\n[material]", 1);
    let mut bytes = comment.into_bytes();
    let i = bytes
        .windows(2)
        .position(|w| w == "\u{e9}".as_bytes())
        .unwrap();
    bytes.splice(i..i + 2, [0xE9]);
    std::fs::write(&toml, &bytes).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(&message, &[&format!("byte {i} (0xE9)"), "'\u{e9}'"]);
    // [t03] random bytes as the TOML
    std::fs::write(&toml, &random).unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(&message, &["experiments.toml:1", "binary data"]);
    // an Excel workbook as data
    std::fs::write(&toml, &original).unwrap();
    std::fs::write(&csv, b"PK\x03\x04\x14\x00\x06\x00").unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(&message, &[".xlsx", "CSV UTF-8"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn long_cells_and_huge_numbers_are_cut_in_messages() {
    let (dir, toml, data) = copy("bounds_cells");
    let csv = data.join("v0p27_p1.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    // [E16] a 1 MB cell: the line is longer than the line cap, and only its start is echoed
    lines[3] = format!("0.04,{}", "1".repeat(1_000_000));
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert!(message.len() < 600, "{} bytes: {message}", message.len());
    assert_contains(
        &message,
        &["v0p27_p1.csv:4", "longer than", "max_line_bytes"],
    );
    // a 1000-character cell: cut to 80 characters with its length
    lines[3] = format!("0.04,x{}", "1".repeat(1000));
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert!(message.len() < 600, "{} bytes: {message}", message.len());
    assert_contains(
        &message,
        &["v0p27_p1.csv:4", "non-numeric cell", "(1001 characters)"],
    );
    // [E09] a position of 1e308 is printed as written, not as 309 digits
    lines[3] = "1e308,9e-05".into();
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &["position 1e308 m lies beyond the spin-line length 0.51 m"],
    );
    assert!(!message.contains("0000000000"), "{message}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes a data set of `n` experiments that all read `v0p27_p1.csv`, into `dir`.
fn many_experiments(toml: &Path, n: usize) {
    let text = std::fs::read_to_string(toml).unwrap();
    let head = &text[..text.find("[[experiment]]").unwrap()];
    let mut out = head.to_string();
    for k in 0..n {
        out.push_str(&format!(
            "[[experiment]]\nname = \"e{k:05}\"\nmass_flow_kg_s = 1.5690566037735852e-05\n\
             inlet_diameter_m = 0.001134\ndata = \"v0p27_p1.csv\"\n\n"
        ));
    }
    std::fs::write(toml, out).unwrap();
}

#[test]
fn the_number_of_experiments_is_capped_before_any_data_is_read() {
    // [F49, F50] 2000 and 20000 experiments printed nothing for 10 minutes
    let (dir, toml, _) = copy("bounds_experiments");
    for n in [2000, 20_000] {
        many_experiments(&toml, n);
        let message = refused(&toml, Duration::from_secs(5));
        assert_contains(
            &message,
            &[
                "experiments.toml:",
                &format!(
                    "{} [[experiment]] tables",
                    if n == 2000 { "2,000" } else { "20,000" }
                ),
                &format!(
                    "more than the limit of {}",
                    LoadOptions::default().max_experiments
                )
                .replace("1000", "1,000"),
                "max_experiments",
            ],
        );
        let p = crate::probe::rheometer(
            &["--quiet", "fit", crate::probe::s(&toml)],
            &[],
            Duration::from_secs(30),
        );
        p.assert_clean_failure(&["max_experiments", "--allow-large-inputs"]);
        // 0.05 s and 0.4 s alone; generous for a loaded machine
        assert!(
            p.elapsed < Duration::from_secs(5),
            "{n} experiments: {:?}",
            p.elapsed
        );
    }
    // raised, the cap lets them through (parsing only: no fit)
    many_experiments(&toml, 2000);
    let options = LoadOptions {
        max_experiments: 5000,
        ..LoadOptions::default()
    };
    // then the estimated memory of their fit (2000 x 26 rows, 2002 parameters: 8 GB) stops them
    let e = load_experiments_with(&toml, &options)
        .unwrap_err()
        .to_string();
    assert_contains(
        &e,
        &["v0p27_p1.csv:", "2000 experiments", "max_fit_memory_bytes"],
    );
    let options = LoadOptions {
        max_fit_memory_bytes: 16 << 30,
        ..options
    };
    let loaded = load_experiments_with(&toml, &options).unwrap();
    assert_eq!(loaded.set.experiments.len(), 2000);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rows_are_capped_per_file_and_by_the_fit_memory_while_reading() {
    let (dir, toml, data) = copy("bounds_rows");
    let limited = |options: &LoadOptions| {
        let e = load_experiments_with(&toml, options).unwrap_err();
        match &e {
            InputError::Data { cause, .. } => match &**cause {
                InputError::Limit { limit, .. } => (*limit, e.to_string()),
                other => panic!("not a limit: {other}"),
            },
            other => panic!("not a data error: {other}"),
        }
    };
    let (limit, message) = limited(&LoadOptions {
        max_rows_per_file: 10,
        ..LoadOptions::default()
    });
    assert_eq!(limit, Limit::RowsPerFile);
    assert_contains(
        &message,
        &[
            "v0p27_p1.csv:12:",
            "more than 10 measurement rows",
            "max_rows_per_file",
            "thin the data",
        ],
    );
    // 9 x 27 = 243 rows fit in 9 experiments only if the cap allows them
    let max = estimated_fit_memory_bytes(100, 9);
    let (limit, message) = limited(&LoadOptions {
        max_fit_memory_bytes: max,
        ..LoadOptions::default()
    });
    assert_eq!(limit, Limit::FitMemory);
    assert_contains(
        &message,
        &["v0p53_p1.csv:", "reach 101 rows", "max_fit_memory_bytes"],
    );
    // [E43, S24] 9 x 1e6 rows: refused while reading, long before the fit's 5.3 GB
    // [S23] the same input under a memory cap: refused here, so there is no allocation to abort
    let mut big = String::from("position_m,diameter_m\n");
    for i in 0..1_000_000u32 {
        let s = 0.5 * f64::from(i) / 999_999.0;
        let d = 1.1e-3 * (-s / 0.05).exp() + 1.0e-4;
        big.push_str(&format!("{s:.9},{d:.6e}\n"));
    }
    std::fs::write(data.join("big.csv"), big).unwrap();
    let text = std::fs::read_to_string(&toml).unwrap();
    let text = text
        .lines()
        .map(|l| {
            if l.starts_with("data = ") {
                "data = \"big.csv\""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&toml, text).unwrap();
    let t0 = Instant::now();
    let e = load_experiments(&toml).unwrap_err().to_string();
    assert!(t0.elapsed() < Duration::from_secs(20), "{:?}", t0.elapsed());
    assert_contains(
        &e,
        &[
            "big.csv:",
            "max_fit_memory_bytes",
            "the most that a fit of 9",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn oversized_files_are_refused_from_their_size() {
    let (dir, toml, data) = copy("bounds_sizes");
    // sparse files: no disk space, but a size beyond the caps
    let f = std::fs::File::create(data.join("huge.csv")).unwrap();
    f.set_len(200 << 20).unwrap();
    set_data(&toml, "huge.csv");
    let message = refused(&toml, Duration::from_secs(1));
    assert_contains(
        &message,
        &[
            "huge.csv",
            "larger than the limit of 134 MB",
            "max_csv_bytes",
        ],
    );
    let huge_toml = data.join("huge.toml");
    std::fs::File::create(&huge_toml)
        .unwrap()
        .set_len(17 << 20)
        .unwrap();
    let message = refused(&huge_toml, Duration::from_secs(1));
    assert_contains(&message, &["huge.toml", "max_toml_bytes"]);
    let options = LoadOptions {
        max_toml_bytes: 100,
        ..LoadOptions::default()
    };
    let e = load_experiments_with(&toml, &options).unwrap_err();
    assert!(
        matches!(
            e,
            InputError::Limit {
                limit: Limit::TomlBytes,
                ..
            }
        ),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
