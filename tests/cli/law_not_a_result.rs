//! A law that is not a result (issue 26, item 3) is said so wherever `rheometer fit` shows
//! it: the text report, the HTML page's verdict, the flow curve's JSON, CSV and its figure's
//! legend; a plausible law is shown as the identified law in all of them.

use std::fs;
use std::path::Path;
use std::time::Duration;

use crate::probe::{rheometer, s, shipped_copy};

const LIMIT: Duration = Duration::from_secs(240);

/// `rheometer fit TOML ARGS... --out OUT` on a scratch copy of the shipped data: (the text
/// report `fit_report.txt`, whose result section stdout prints too, the HTML page,
/// `flow_curve.json` parsed, the `law_is_a_result` column of `flow_curve.csv`).
fn fit_out(name: &str, args: &[&str]) -> (String, String, serde_json::Value, Vec<String>) {
    let (dir, toml, data) = shipped_copy(name);
    let out = dir.join("out");
    let mut all = vec!["fit", s(&toml)];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", s(&out)]);
    let p = rheometer(&all, &[&data], LIMIT);
    p.assert_success();
    let read = |f: &str| fs::read_to_string(Path::new(&out).join(f)).expect(f);
    let curve: serde_json::Value = serde_json::from_str(&read("flow_curve.json")).expect("json");
    let report = read("fit_report.txt");
    let result_line = |t: &str| {
        t.lines()
            .find(|l| l.contains("NOT A RESULT:"))
            .map(str::to_owned)
    };
    assert_eq!(
        result_line(&report),
        result_line(&p.stdout),
        "stdout and the report"
    );
    let page = read("fit_report.html");
    let csv = read("flow_curve.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "law_is_a_result")
        .unwrap_or_else(|| panic!("no law_is_a_result column: {header:?}"));
    let flags = lines
        .map(|l| l.split(',').nth(col).unwrap_or("").to_string())
        .collect();
    let _ = fs::remove_dir_all(&dir);
    (report, page, curve, flags)
}

#[test]
fn a_law_at_its_bound_is_not_a_result_in_the_text_the_page_and_the_flow_curve() {
    // 300 K of warm air fixed where there is none: the law runs to n = 1, kappa undetermined
    let (text, page, curve, flags) = fit_out(
        "law_not_a_result_warm_air",
        &["--with", "air_temperature_profile=300"],
    );
    let line = text
        .lines()
        .find(|l| l.contains("NOT A RESULT:"))
        .unwrap_or_else(|| panic!("no NOT A RESULT line:\n{text}"));
    assert!(line.contains("is at its"), "{line}");
    assert!(page.contains("class=\"verdict bad\"") && page.contains("NOT A RESULT"));
    let why = curve["not_a_result"]
        .as_str()
        .expect("flow_curve.json: not_a_result");
    assert!(
        !flags.is_empty() && flags.iter().all(|f| f == "0"),
        "{flags:?}"
    );
    assert!(
        line.contains(why.split(" (").next().unwrap_or(why)),
        "{why} / {line}"
    );

    // the control: the shipped data with the paper's model, a plausible law
    let (text, page, curve, flags) = fit_out("law_not_a_result_control", &[]);
    assert!(
        !flags.is_empty() && flags.iter().all(|f| f == "1"),
        "{flags:?}"
    );
    assert!(!text.contains("NOT A RESULT"), "{text}");
    assert!(!page.contains("class=\"verdict bad\""));
    assert!(curve.get("not_a_result").is_none(), "{curve}");
}
