//! The HTML report of `rheometer fit` (issue 31): user text (experiment names, data file
//! names, the experiments file's path) shown escaped, nothing loaded from the network, the
//! estimates those of the JSON and of the text report, and its output paths checked before
//! the fit like every other output.
#![cfg(unix)]

use crate::probe::{copy_data_set, rheometer, s, scratch, shipped_copy};
use rheometer::report::format::{fmt_at, fmt_pm};
use std::fs;
use std::path::Path;
use std::time::Duration;

const LIMIT: Duration = Duration::from_secs(300);

/// The user text planted in the data set: an experiment name (no `/`: names are file stems),
/// a data file name and the directory of the experiments file.
const NAME: &str = "<script>alert(1)<script> & co 'x'";
const FILE: &str = "<img src=x onerror=alert(1)> & co.csv";
const DIR: [&str; 2] = ["<script>alert(1)<", "script> & co"];

/// Every value of a `src=` or `href=` attribute in `html` (lower-cased).
fn link_targets(html: &str) -> Vec<String> {
    let low = html.to_lowercase();
    let mut out = Vec::new();
    for attr in ["src=", "href="] {
        for (i, _) in low.match_indices(attr) {
            let rest = low[i + attr.len()..].trim_start_matches(['"', '\'', ' ']);
            out.push(rest.chars().take_while(|c| !"\"' >".contains(*c)).collect());
        }
    }
    out
}

#[test]
fn fit_html_escapes_user_text_loads_nothing_and_prints_the_estimates_of_the_json() {
    let dir = scratch("fit_html_escaping");
    let evil = dir.join(DIR[0]).join(DIR[1]);
    let toml = copy_data_set("pmma7n_synthetic", &evil);
    let data = toml.parent().unwrap().to_path_buf();
    fs::rename(data.join("v0p27_p1.csv"), data.join(FILE)).unwrap();
    let text = fs::read_to_string(&toml)
        .unwrap()
        .replacen("name = \"v0p27_p1\"", &format!("name = \"{NAME}\""), 1)
        .replacen("\"v0p27_p1.csv\"", &format!("\"{FILE}\""), 1);
    assert!(text.contains(NAME) && text.contains(FILE));
    fs::write(&toml, text).unwrap();
    let (json, html) = (dir.join("fit.json"), dir.join("report.html"));
    let p = rheometer(
        &["fit", s(&toml), "--json", s(&json), "--html", s(&html)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    let page = fs::read_to_string(&html).unwrap();

    // user text shows as text: name (in the table and in the residual figure's panel
    // title), data file, the experiments file's directory
    let name = "&lt;script&gt;alert(1)&lt;script&gt; &amp; co &#39;x&#39;";
    assert!(
        page.contains(&format!("<td>{name}</td>")),
        "name not in a cell"
    );
    assert!(page.contains("&lt;img src=x onerror=alert(1)&gt; &amp; co.csv"));
    assert!(page.contains("&lt;script&gt;alert(1)&lt;/script&gt; &amp; co"));
    assert!(
        page.matches("<svg").count() >= 2,
        "flow curve and residuals"
    );
    assert!(page.contains("&lt;script&gt;alert(1)&lt;script&gt; &amp; co"));
    // no markup from user text: the page has no script and no image element at all
    let low = page.to_lowercase();
    assert!(!low.contains("<script"), "a <script> element in the page");
    assert!(!low.contains("<img"), "an <img> element in the page");
    // (the handler's text is there, escaped, as part of the file name)
    assert!(
        !page.contains(FILE) && !page.contains(NAME),
        "user text unescaped"
    );
    // the CSP forbids every load; no link or source names the network
    assert!(
        page.contains("<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none';")
    );
    let targets = link_targets(&page);
    assert!(
        !targets.is_empty(),
        "the contents list links to its sections"
    );
    for t in &targets {
        assert!(
            !(t.starts_with("http:") || t.starts_with("https:") || t.starts_with("//")),
            "network reference {t:?}"
        );
    }

    // the estimates: the JSON's numbers, printed as the text report prints them
    let js: serde_json::Value = serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
    for (key, text_label) in [("n", "n:    "), ("kappa", "kappa:")] {
        let e = &js[key];
        let (v, se) = (e["value"].as_f64().unwrap(), e["stderr"].as_f64().unwrap());
        let ci = [
            e["ci95"][0].as_f64().unwrap(),
            e["ci95"][1].as_f64().unwrap(),
        ];
        let pm = fmt_pm(v, se);
        let interval = format!("[{}, {}]", fmt_at(ci[0], se), fmt_at(ci[1], se));
        assert!(
            page.contains(&format!("<td class=\"num\">{pm}</td><td>{interval}</td>")),
            "{key}: {pm} {interval} not in the law table"
        );
        assert!(
            p.stdout
                .contains(&format!("{text_label} {pm}  95% CI {interval}")),
            "{key}: the text report prints other numbers than {pm} {interval}:\n{}",
            p.stdout
        );
    }
    // the one noise level of the summary, as the text report gives it
    let noise = js["noise"]["level"].as_f64().unwrap();
    let level = format!("the noise level {:.3} %", 100.0 * noise);
    assert!(p.stdout.contains(&level), "{level}");
    assert!(page.contains(&level), "{level}");
    // one row per experiment with its points
    let csv = fs::read_to_string(data.join("v0p53_p2.csv")).unwrap();
    let points = csv.lines().skip(1).filter(|l| !l.trim().is_empty()).count();
    assert!(
        page.contains(&format!(
            "<td>v0p53_p2</td><td>v0p53_p2.csv</td><td class=\"num\">{points}</td>"
        )),
        "v0p53_p2 row with {points} points"
    );
    assert!(page.contains(&format!("diffbvp {}", env!("CARGO_PKG_VERSION"))));
}

/// A `fit` that must be refused before the fit, naming `needles`.
fn refused(args: &[&str], data: &Path, needles: &[&str]) {
    let p = rheometer(args, &[data], LIMIT);
    p.assert_clean_failure(needles);
    assert!(p.elapsed < Duration::from_secs(5), "{:?}", p.elapsed);
    assert!(!p.stdout.contains("[[Result"), "fitted first");
}

#[test]
fn fit_html_paths_are_checked_before_the_fit() {
    let (dir, toml, data) = shipped_copy("fit_html_paths");
    let out = dir.join("out");
    let csv = data.join("v0p27_p1.csv");
    // an input file
    refused(
        &["fit", s(&toml), "--html", s(&csv)],
        &data,
        &["--html", "it is an input file"],
    );
    refused(
        &["fit", s(&toml), "--html", s(&toml)],
        &data,
        &["--html", "it is an input file"],
    );
    // another output of the same run
    let json = dir.join("fit.json");
    refused(
        &["fit", s(&toml), "--json", s(&json), "--html", s(&json)],
        &data,
        &["--json", "--html", "name the same file"],
    );
    refused(
        &[
            "fit",
            s(&toml),
            "--html",
            s(&out.join("fit_report.html")),
            "--out",
            s(&out),
        ],
        &data,
        &["--html", "--out", "name the same file"],
    );
    assert!(!out.exists(), "written before the refusal");
    // an existing directory
    refused(&["fit", s(&toml), "--html", s(&dir)], &data, &["--html"]);
    // the page of --out linked to an input
    fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(data.join("v0p27_p3.csv"), out.join("fit_report.html")).unwrap();
    refused(
        &["fit", s(&toml), "--out", s(&out)],
        &data,
        &["refusing to write", "fit_report.html", "input file"],
    );
}
