//! Property test of the TOML and CSV readers: arbitrary text and structured mutations of the
//! shipped data set (lines deleted, duplicated, swapped; numbers replaced by extreme values;
//! garbage inserted; truncation; keys changed). The readers must never panic, and every error
//! must be non-empty and start with the file it is about.
//!
//! The runs are deterministic (a fixed seed, no failure persistence) and bounded (a fixed
//! number of cases per property) so that CI is reproducible and fast (a few seconds in release).

use rheometer::data::input::LoadOptions;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use rheometer::data::input::{load_experiments_with, parse_experiments, parse_measurements};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/pmma7n_synthetic");

fn shipped_toml() -> String {
    std::fs::read_to_string(format!("{DATA}/experiments.toml")).unwrap()
}

fn shipped_csv() -> String {
    std::fs::read_to_string(format!("{DATA}/v0p53_p2.csv")).unwrap()
}

/// A deterministic runner with `cases` cases.
fn runner(cases: u32) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 2000,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

/// Values that readers get wrong: non-finite, overflowing, subnormal, signed zero, huge
/// integers, other TOML types, empty.
const EXTREMES: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "+nan",
    "1e308",
    "1e309",
    "-1e308",
    "4.9e-324",
    "1e-320",
    "-0",
    "-0.0",
    "0",
    "0.0",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999999",
    "0x7fffffffffffffff",
    "0o777",
    "0b101",
    "1_000",
    "1__0",
    "+1",
    "1.",
    ".5",
    "1e",
    "",
    "\"0.001\"",
    "true",
    "[1, 2]",
    "{}",
    "1979-05-27",
    "NaN",
    "1e-9",
    "-1",
    "273.151",
];

/// One edit of a text, with indices reduced modulo the text's size when applied.
#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    /// Replace the `k`-th number-like token by an extreme value.
    ReplaceNumber(usize, usize),
    InsertGarbage(usize, Vec<u8>),
    Truncate(usize),
    /// Change one character of the key (or first cell) on a line.
    ChangeKey(usize, usize, char),
    /// Replace a character by one of the format's special characters.
    Punctuate(usize, char),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let any_idx = any::<usize>();
    prop_oneof![
        any_idx.prop_map(Mutation::DeleteLine),
        any_idx.prop_map(Mutation::DuplicateLine),
        (any_idx, any_idx).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (any_idx, 0..EXTREMES.len()).prop_map(|(a, b)| Mutation::ReplaceNumber(a, b)),
        (any_idx, proptest::collection::vec(any::<u8>(), 1..12))
            .prop_map(|(a, g)| Mutation::InsertGarbage(a, g)),
        any_idx.prop_map(Mutation::Truncate),
        (any_idx, any_idx, any::<char>()).prop_map(|(a, b, c)| Mutation::ChangeKey(a, b, c)),
        (
            any_idx,
            prop::sample::select(vec![
                '=', '[', ']', '"', '\'', '#', ',', '\n', '\r', '\t', '\\', '{', '}', '.',
                '\u{feff}', '\0', 'é'
            ])
        )
            .prop_map(|(a, c)| Mutation::Punctuate(a, c)),
    ]
}

/// Byte offset of the character boundary at or before `i`.
fn floor_boundary(s: &str, i: usize) -> usize {
    let mut i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Spans of number-like tokens (a digit, sign or dot and what follows up to a separator).
fn number_spans(s: &str) -> Vec<(usize, usize)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            || ((b[i] == b'-' || b[i] == b'+' || b[i] == b'.')
                && b.get(i + 1).is_some_and(|c| c.is_ascii_digit()));
        let after_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !after_word {
            let j = (i..b.len())
                .find(|&j| matches!(b[j], b',' | b'\n' | b'\r' | b' ' | b'#' | b']'))
                .unwrap_or(b.len());
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let n = lines.len().max(1);
    match m {
        Mutation::DeleteLine(i) => {
            if !lines.is_empty() {
                lines.remove(i % n);
            }
            lines.join("\n")
        }
        Mutation::DuplicateLine(i) => {
            if !lines.is_empty() {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            lines.join("\n")
        }
        Mutation::SwapLines(a, b) => {
            if !lines.is_empty() {
                lines.swap(a % n, b % n);
            }
            lines.join("\n")
        }
        Mutation::ReplaceNumber(k, v) => {
            let spans = number_spans(text);
            if spans.is_empty() {
                return text.to_string();
            }
            let (s, e) = spans[k % spans.len()];
            format!("{}{}{}", &text[..s], EXTREMES[*v], &text[e..])
        }
        Mutation::InsertGarbage(i, g) => {
            let at = floor_boundary(text, i % (text.len() + 1));
            let garbage = String::from_utf8_lossy(g);
            format!("{}{}{}", &text[..at], garbage, &text[at..])
        }
        Mutation::Truncate(i) => text[..floor_boundary(text, i % (text.len() + 1))].to_string(),
        Mutation::ChangeKey(i, j, c) => {
            if lines.is_empty() {
                return text.to_string();
            }
            let line = &mut lines[i % n];
            let key_len = line.find(['=', ',']).unwrap_or(line.len());
            if key_len > 0 {
                let at = floor_boundary(line, j % key_len);
                let end = at + line[at..].chars().next().map_or(0, char::len_utf8);
                line.replace_range(at..end, &c.to_string());
            }
            lines.join("\n")
        }
        Mutation::Punctuate(i, c) => {
            if text.is_empty() {
                return c.to_string();
            }
            let at = floor_boundary(text, i % text.len());
            let end = at + text[at..].chars().next().map_or(0, char::len_utf8);
            format!("{}{}{}", &text[..at], c, &text[end..])
        }
    }
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    proptest::collection::vec(mutation(), 1..5)
}

fn mutated(base: &str, ms: &[Mutation]) -> String {
    ms.iter().fold(base.to_string(), |t, m| apply(&t, m))
}

/// Parses `text` as the TOML experiment file `path`; fails the case on a panic or on an error
/// message that is empty or does not start with the file. Returns whether the text was
/// accepted.
fn check_toml(text: &str, path: &Path) -> Result<bool, TestCaseError> {
    let r = catch_unwind(AssertUnwindSafe(|| {
        parse_experiments(text, path).map_err(Box::new)
    }));
    match r {
        Err(_) => Err(TestCaseError::fail(format!(
            "parse_experiments panicked on {text:?}"
        ))),
        Ok(Ok(_)) => Ok(true),
        Ok(Err(e)) => {
            let msg = e.to_string();
            prop_assert!(
                msg.starts_with(&path.display().to_string())
                    && msg.len() > path.as_os_str().len() + 2,
                "error does not name the file or says nothing: {msg:?} for {text:?}"
            );
            Ok(false)
        }
    }
}

/// Like [`check_toml`] for the CSV text of a measurement file; what is accepted must satisfy
/// the documented checks. Returns whether the text was accepted.
fn check_csv(text: &str, path: &Path, length: f64) -> Result<bool, TestCaseError> {
    let r = catch_unwind(AssertUnwindSafe(|| {
        parse_measurements(text, path, length, 4).map_err(Box::new)
    }));
    match r {
        Err(_) => Err(TestCaseError::fail(format!(
            "parse_measurements panicked on {text:?}"
        ))),
        Ok(Ok(m)) => {
            // what was accepted satisfies the documented checks
            prop_assert!(m.positions.len() >= 4 && m.positions.len() == m.diameters.len());
            prop_assert!(m.positions.windows(2).all(|w| w[0] < w[1]));
            prop_assert!(m.positions.iter().all(|s| *s >= 0.0 && *s <= length));
            prop_assert!(m
                .diameters
                .iter()
                .all(|d| d.is_finite() && *d >= 1e-6 && *d <= 0.02));
            Ok(true)
        }
        Ok(Err(e)) => {
            let msg = e.to_string();
            prop_assert!(
                msg.starts_with(&path.display().to_string())
                    && msg.len() > path.as_os_str().len() + 2,
                "error does not name the file or says nothing: {msg:?} for {text:?}"
            );
            Ok(false)
        }
    }
}

/// Runs `test` on `cases` cases; returns how many inputs were accepted.
fn run<S: Strategy>(
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value) -> Result<bool, TestCaseError>,
) -> usize
where
    S::Value: std::fmt::Debug,
{
    let accepted = AtomicUsize::new(0);
    let mut r = runner(cases);
    let result = r.run(&strategy, |v| {
        if test(v)? {
            accepted.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    accepted.into_inner()
}

/// Asserts that a mutation run exercised both outcomes (some inputs accepted, most rejected is
/// fine): a run where everything is rejected would test only the first check.
fn assert_mixed(accepted: usize, cases: u32) {
    assert!(
        accepted > 0 && accepted < cases as usize,
        "{accepted} of {cases} mutated inputs accepted"
    );
}

#[test]
fn toml_reader_survives_arbitrary_text() {
    let path = PathBuf::from("fuzz/experiments.toml");
    run(1000, any::<String>(), |s| check_toml(&s, &path));
    run(500, proptest::collection::vec(any::<u8>(), 0..400), |b| {
        check_toml(&String::from_utf8_lossy(&b), &path)
    });
}

#[test]
fn toml_reader_survives_mutations_of_the_shipped_file() {
    let base = shipped_toml();
    let path = PathBuf::from("fuzz/experiments.toml");
    // the unmutated file parses
    assert!(parse_experiments(&base, &path).is_ok());
    let accepted = run(2000, mutations(), |ms| {
        check_toml(&mutated(&base, &ms), &path)
    });
    assert_mixed(accepted, 2000);
}

#[test]
fn csv_reader_survives_arbitrary_text() {
    let path = PathBuf::from("fuzz/data.csv");
    run(1000, any::<String>(), |s| check_csv(&s, &path, 0.51));
    run(500, proptest::collection::vec(any::<u8>(), 0..400), |b| {
        check_csv(&String::from_utf8_lossy(&b), &path, 0.51)
    });
    // the header followed by arbitrary text
    run(500, any::<String>(), |s| {
        check_csv(&format!("position_m,diameter_m\n{s}"), &path, 0.51)
    });
}

#[test]
fn csv_reader_survives_mutations_of_the_shipped_file() {
    let base = shipped_csv();
    let path = PathBuf::from("fuzz/data.csv");
    assert!(parse_measurements(&base, &path, 0.51, 4).is_ok());
    let accepted = run(2000, mutations(), |ms| {
        check_csv(&mutated(&base, &ms), &path, 0.51)
    });
    assert_mixed(accepted, 2000);
    // odd spin-line lengths passed by callers: refused, naming the file, unless +inf (no check)
    for l in [0.0, -1.0, f64::NAN, f64::NEG_INFINITY] {
        let msg = parse_measurements(&base, &path, l, 4)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("fuzz/data.csv: cannot check the positions against a spin-line length"),
            "{msg}"
        );
    }
    assert!(parse_measurements(&base, &path, f64::INFINITY, 4).is_ok());
    run(
        300,
        (
            mutations(),
            prop::sample::select(vec![0.0, -1.0, f64::NAN, f64::INFINITY, 1e-300]),
        ),
        |(ms, l)| check_csv(&mutated(&base, &ms), &path, l),
    );
}

/// The whole loader (TOML, then the CSV files it names) on mutated copies written to a scratch
/// directory: errors start with the TOML file, and errors in a CSV file also name that file.
#[test]
fn loader_survives_mutated_toml_and_csv_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("target")
        .join("test-scratch")
        .join(format!("reader_fuzz_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml_path = dir.join("experiments.toml");
    let base_toml = shipped_toml();
    let base_csv = shipped_csv();
    let names: Vec<String> = std::fs::read_dir(DATA)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".csv"))
        .collect();
    run(
        300,
        (
            proptest::collection::vec(mutation(), 0..3),
            mutations(),
            0..names.len(),
        ),
        |(tm, cm, which)| {
            for n in &names {
                std::fs::copy(Path::new(DATA).join(n), dir.join(n)).unwrap();
            }
            let csv_path = dir.join(&names[which]);
            std::fs::write(&csv_path, mutated(&base_csv, &cm)).unwrap();
            std::fs::write(&toml_path, mutated(&base_toml, &tm)).unwrap();
            let r = catch_unwind(AssertUnwindSafe(|| {
                load_experiments_with(&toml_path, &LoadOptions::default()).map_err(Box::new)
            }));
            match r {
                Err(_) => Err(TestCaseError::fail("load_experiments_with panicked")),
                Ok(Ok(_)) => Ok(true),
                Ok(Err(e)) => {
                    let msg = e.to_string();
                    prop_assert!(msg.starts_with(&toml_path.display().to_string()), "{msg:?}");
                    if let rheometer::data::input::InputError::Data { cause, .. } = &*e {
                        let cause = cause.to_string();
                        prop_assert!(cause.contains(".csv"), "{cause:?}");
                    }
                    Ok(false)
                }
            }
        },
    );
    let _ = std::fs::remove_dir_all(&dir);
}
