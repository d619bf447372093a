//! `rheometer fit --from FILE`: a fit that continues from a previous result (a fit report or a
//! diagnosis). The model takes the file's effects (fitted strengths and shapes free again) and
//! starts from its law and strengths; bad combinations are refused naming the flags and the
//! file; the file itself is an input no output may overwrite.

use crate::probe;

use probe::{s, Probe};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

const LIMIT: Duration = Duration::from_secs(120);

fn run(args: &[&str], data_dir: &Path) -> Probe {
    probe::rheometer(args, &[data_dir], LIMIT)
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("read JSON")).expect("JSON")
}

fn strength(fit: &Value, effect: &str) -> f64 {
    fit["effects"]
        .as_array()
        .and_then(|a| a.iter().find(|e| e["effect"] == effect))
        .and_then(|e| e["strength"]["value"].as_f64())
        .unwrap_or(f64::NAN)
}

/// A scratch copy of `data/hidden_radiation` for test `name`, fitted with radiation: (scratch
/// dir, TOML, data dir, the fit's JSON `fit.json` in the data dir).
fn radiation_fit(name: &str) -> (PathBuf, PathBuf, PathBuf, PathBuf) {
    let dir = probe::scratch(name);
    let toml = probe::copy_data_set("hidden_radiation", &dir);
    let dd = dir.join("hidden_radiation");
    let fit = dd.join("fit.json");
    run(
        &["fit", s(&toml), "--with", "radiation", "--json", s(&fit)],
        &dd,
    )
    .assert_success();
    (dir, toml, dd, fit)
}

/// The hidden-radiation data fitted with radiation, then again from that fit: the second fit
/// has radiation in its model without `--with`, fitted, at the same optimum; a third adds a
/// die temperature offset to it and ends no worse.
#[test]
fn a_fit_continues_from_a_previous_fit_with_its_effects() {
    let (dir, toml, dd, first) = radiation_fit("fit_from_fit");
    let second = dir.join("second.json");
    let p = run(
        &["fit", s(&toml), "--from", s(&first), "--json", s(&second)],
        &dd,
    );
    p.assert_success();
    let (a, b) = (read(&first), read(&second));
    assert!(
        b["fitted"]
            .as_array()
            .is_some_and(|f| f.iter().any(|x| x == "radiation")),
        "{}",
        b["fitted"]
    );
    let (ja, jb) = (a["cost"].as_f64().unwrap(), b["cost"].as_f64().unwrap());
    assert!(jb <= ja * (1.0 + 1e-6), "J {jb} after {ja}");
    let (ea, eb) = (strength(&a, "radiation"), strength(&b, "radiation"));
    let se = a["effects"][0]["strength"]["stderr"].as_f64().unwrap();
    assert!((ea - eb).abs() <= 0.01 * se, "ε {eb} after {ea} ± {se}");
    // one more effect on top of the file's: both in the model, J no higher
    let third = dir.join("third.json");
    run(
        &[
            "fit",
            s(&toml),
            "--from",
            s(&second),
            "--with",
            "die_temperature_offset",
            "--json",
            s(&third),
        ],
        &dd,
    )
    .assert_success();
    let c = read(&third);
    assert!(strength(&c, "radiation").is_finite());
    assert!(strength(&c, "die_temperature_offset").is_finite());
    assert!(c["cost"].as_f64().unwrap() <= jb * (1.0 + 1e-6));
}

/// Refused: an effect given twice, a start besides the file's, a file of another data set,
/// a missing file, and an output over the file itself; every message names the flag and the
/// file, and no input changes.
#[test]
fn bad_uses_of_from_are_refused_by_name() {
    let (_, toml, dd, fit) = radiation_fit("fit_from_bad");
    run(
        &[
            "fit",
            s(&toml),
            "--from",
            s(&fit),
            "--with",
            "radiation=0.5",
        ],
        &dd,
    )
    .assert_clean_failure(&["--with radiation", "--from", "fit.json"]);
    run(
        &["fit", s(&toml), "--from", s(&fit), "--start", "0.5,12"],
        &dd,
    )
    .assert_clean_failure(&["--from", "--start"]);
    let missing = dd.join("nowhere.json");
    run(&["fit", s(&toml), "--from", s(&missing)], &dd)
        .assert_clean_failure(&["--from", "nowhere.json"]);
    // the file is an input: an output over it is refused before the fit
    run(
        &["fit", s(&toml), "--from", s(&fit), "--json", s(&fit)],
        &dd,
    )
    .assert_clean_failure(&["--json", "fit.json"]);
    // a fit of another data set (other experiment names)
    let other_dir = probe::scratch("fit_from_other");
    let other = probe::copy_data_set("pmma7n_synthetic", &other_dir);
    let odd = other_dir.join("pmma7n_synthetic");
    let text = std::fs::read_to_string(&fit).unwrap();
    let renamed = text.replacen("\"v0p27", "\"other", 1);
    assert_ne!(text, renamed, "the fit names its experiments");
    let foreign = odd.join("foreign.json");
    std::fs::write(&foreign, renamed).unwrap();
    run(&["fit", s(&other), "--from", s(&foreign)], &odd)
        .assert_clean_failure(&["foreign.json", "experiments"]);
}

/// `diagnose --from` a fit with radiation: radiation is in the user's model (fitted, started
/// from the file's value), no longer a candidate, and the user's fit is the file's optimum.
#[test]
fn a_diagnosis_continues_from_a_fit_with_its_effects() {
    let (dir, toml, dd, fit) = radiation_fit("diagnose_from_fit");
    let diag = dir.join("diagnosis.json");
    let p = run(
        &[
            "diagnose",
            "--quiet",
            s(&toml),
            "--from",
            s(&fit),
            "--refit-top",
            "2",
            "--json",
            s(&diag),
        ],
        &dd,
    );
    p.assert_success();
    // the report says what the user's model holds
    assert!(
        p.stdout.contains("Effects in your model: radiation"),
        "{}",
        p.stdout
    );
    let (f, d) = (read(&fit), read(&diag));
    let base = &d["base_fit"];
    assert!(
        base["fitted"]
            .as_array()
            .is_some_and(|a| a.iter().any(|x| x == "radiation")),
        "{}",
        base["fitted"]
    );
    assert!(d["candidates"]
        .as_array()
        .is_some_and(|a| a.iter().all(|c| c["effect"] != "radiation")));
    let (jf, jd) = (f["cost"].as_f64().unwrap(), base["cost"].as_f64().unwrap());
    assert!(
        (jd / jf - 1.0).abs() < 1e-3,
        "the diagnosis' fit J {jd}, the file's {jf}"
    );
    // the file is an input: --json over it is refused
    run(
        &["diagnose", s(&toml), "--from", s(&fit), "--json", s(&fit)],
        &dd,
    )
    .assert_clean_failure(&["--json", "fit.json"]);
}
