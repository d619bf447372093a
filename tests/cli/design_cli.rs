//! `rheometer design` on the shipped data: it runs, its report names the top experiment (the
//! same as its JSON's rank 1), `--discriminate` ranks by telling rivals apart, and bad flag
//! values are refused before any work with the flag and the valid values named.

use std::path::PathBuf;
use std::process::{Command, Output};

const DATA: &str = "data/pmma7n_synthetic/experiments.toml";

fn design(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("design")
        .arg(DATA)
        .args(args)
        .output()
        .expect("the rheometer binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The name of the rank-1 candidate in a design's JSON.
fn top_of(json: &std::path::Path) -> String {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let i = v["ranking"][0].as_u64().expect("a ranked candidate") as usize;
    v["candidates"][i]["name"].as_str().unwrap().to_string()
}

#[test]
fn design_runs_on_the_shipped_data_and_names_the_top_experiment() {
    let dir = out_dir("design_cli_estimation");
    let out = design(&["--grid", "3x3", "--out", dir.to_str().unwrap()]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let top = top_of(&dir.join("design.json"));
    assert!(
        stdout.contains(&format!("Recommended: {top} ")),
        "top {top} not named:\n{stdout}"
    );
    assert!(stdout.contains("ranked by the D-criterion"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("design.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 9, "{csv}");
    // a melt that thins: its (n, kappa) are estimates, no Newtonian note
    assert!(
        !stdout.contains("the data show no strain thinning"),
        "{stdout}"
    );
}

/// On a Newtonian melt (`data/newtonian_melt`, by the independent test model) the design says
/// that the `(n, kappa)` it ranks by are the fit's point in the Newtonian corner, not
/// estimates, in the text and the JSON's notes.
#[test]
fn design_on_a_newtonian_melt_says_n_and_kappa_are_not_estimates() {
    let dir = out_dir("design_cli_newtonian");
    let out = Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "design",
            "data/newtonian_melt/experiments.toml",
            "--grid",
            "3x3",
        ])
        .args(["--out", dir.to_str().unwrap()])
        .output()
        .expect("the rheometer binary runs");
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("the data show no strain thinning") && stdout.contains("not estimates"),
        "{stdout}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("design.json")).unwrap()).unwrap();
    let first = v["notes"][0].as_str().unwrap_or_default();
    assert!(first.starts_with("the data show no strain thinning"), "{v}");
}

#[test]
fn design_discriminate_names_the_experiment_that_tells_the_rivals_apart() {
    let dir = out_dir("design_cli_discriminate");
    let out = design(&[
        "--grid",
        "3x3",
        "--discriminate",
        "mass_flow_scale,nusselt_scale",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let top = top_of(&dir.join("design.json"));
    assert!(
        stdout.contains("Telling rivals apart: mass_flow_scale vs nusselt_scale")
            && stdout.contains(&format!("Recommended: {top} ")),
        "top {top} not named:\n{stdout}"
    );
    let csv = std::fs::read_to_string(dir.join("design.csv")).unwrap();
    assert!(
        csv.starts_with("i,j,mass_flow_kg_s,take_up,lambda_mass_flow_scale_vs_nusselt_scale,"),
        "{csv}"
    );
}

#[test]
fn bad_design_flags_are_refused_with_the_flag_and_the_valid_values() {
    for (args, words) in [
        (
            vec!["--discriminate", "mass_flow_scale"],
            vec!["--discriminate", "at least two", "nusselt_scale"],
        ),
        (
            vec!["--discriminate", "mass_flow_scale,bogus"],
            vec!["--discriminate", "bogus", "nusselt_scale", "gauge_offset"],
        ),
        (
            vec!["--discriminate", "radiation,radiation"],
            vec!["--discriminate", "radiation given twice"],
        ),
        (
            vec![
                "--discriminate",
                "radiation,gauge_scale",
                "--criterion",
                "a",
            ],
            vec!["--discriminate", "--criterion"],
        ),
        (
            vec!["--criterion", "x"],
            vec!["--criterion", "unknown design criterion"],
        ),
        (
            vec![
                "--discriminate",
                "strain_thinning,radiation",
                "--grid",
                "2x2",
            ],
            vec!["strain_thinning", "already part of the Carreau model"],
        ),
    ] {
        let out = design(&args);
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "{args:?} accepted");
        assert!(out.stdout.is_empty(), "{args:?}: {}", text(&out.stdout));
        for w in words {
            assert!(stderr.contains(w), "{args:?}: no \"{w}\" in {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}
