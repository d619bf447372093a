//! Flags with one rule (issue 66, item 4; `../shared/probes/bad-input-findings-t4.md`, class
//! D): conflicting flags are refused by the parser, every malformed or out-of-range flag exits
//! with code 2 as the CLI reference states (also those only a check after parsing can judge),
//! and numbers are printed as written or in %g, never as a 309-digit decimal.

use crate::probe;

use probe::s;
use std::time::Duration;

/// Refusals of flags come before any work.
const QUICK: Duration = Duration::from_secs(5);
/// Time limit of a probe that fails a simulation.
const LIMIT: Duration = Duration::from_secs(120);

/// `rheometer ARGS` on a copy of the shipped data: exit code 2, no panic, every needle in
/// stderr, inputs unchanged, within [`QUICK`].
fn usage_error(args: &[&str], data: &std::path::Path, needles: &[&str]) {
    let p = probe::rheometer(args, &[data], LIMIT);
    p.assert_clean_failure(needles);
    assert_eq!(
        p.code,
        Some(2),
        "{args:?}: a flag error exits 2 (the CLI reference), got {:?}:\n{}",
        p.code,
        p.stderr
    );
    assert!(p.elapsed < QUICK, "{args:?} took {:?} to refuse", p.elapsed);
}

#[test]
fn d_conflicting_flags_are_refused_by_the_parser() {
    let (_dir, toml, data) = probe::shipped_copy("flags_conflict");
    usage_error(
        &["fit", s(&toml), "--quiet", "--verbose"],
        &data,
        &["--quiet", "--verbose", "cannot be used with"],
    );
    usage_error(
        &["--verbose", "fit", s(&toml), "--quiet"],
        &data,
        &["--quiet", "--verbose"],
    );
}

#[test]
fn d_every_flag_error_exits_two() {
    let (dir, toml, data) = probe::shipped_copy("flags_exit_two");
    let out = dir.join("never");
    let t = s(&toml);
    let o = s(&out);
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["fit", t, "--with", "radiation", "--with", "radiation"],
            vec!["radiation given twice"],
        ),
        (vec!["fit", t, "--start", "2,30"], vec!["--start 2,30"]),
        (
            vec!["fit", t, "--loss", "huber", "--estimator", "paper"],
            vec!["--loss huber", "principled"],
        ),
        (vec!["fit", t, "--f-scale", "0.02"], vec!["--f-scale 0.02"]),
        (
            vec!["fit", t, "--model", "newtonian", "--start", "0.8,11"],
            vec!["--start"],
        ),
        (
            vec![
                "diagnose",
                t,
                "--loss",
                "cauchy",
                "--f-scale",
                "0.02",
                "--tol",
                "1e-4",
                "--with",
                "radiation",
                "--with",
                "radiation",
            ],
            vec!["radiation given twice"],
        ),
        (
            vec!["design", t, "--mass-flow", "2,1"],
            vec!["--mass-flow 2,1"],
        ),
        (
            vec!["design", t, "--mass-flow", "-1,1"],
            vec!["--mass-flow -1,1"],
        ),
        (
            vec!["design", t, "--mass-flow", "1e-300,1e300"],
            vec!["--mass-flow 1e-300,1e300", "plausible"],
        ),
        (
            vec!["design", t, "--take-up-diameter", "0,1"],
            vec!["--take-up-diameter 0,1"],
        ),
        (
            vec!["design", t, "--template", "nonexistent"],
            vec!["--template nonexistent"],
        ),
        (vec!["design", t, "--start", "2,30"], vec!["--start 2,30"]),
        (
            vec!["landscape", t, "--n-range", "1,0", "--out", o],
            vec!["--n-range 1,0"],
        ),
        (
            vec!["landscape", t, "--kappa-range", "9,1e300", "--out", o],
            vec!["--kappa-range 9,1e300"],
        ),
        (
            vec!["landscape", t, "--max-nodes", "5000", "--out", o],
            vec!["--max-nodes 5000"],
        ),
        // the parser's own (clap's) usage errors, for comparison
        (vec!["fit", t, "--tol", "5"], vec!["--tol"]),
        (vec!["fit", t, "--max-nodes", "7"], vec!["--max-nodes"]),
    ];
    for (args, needles) in &cases {
        usage_error(args, &data, needles);
    }
    assert!(!out.exists(), "a refused landscape created {out:?}");
}

/// Whether `text` holds a run of `n` zeros (a number printed in full, not in %g).
fn long_zeros(text: &str, n: usize) -> bool {
    text.contains(&"0".repeat(n))
}

#[test]
fn d_numbers_are_printed_as_written_or_in_g() {
    let (dir, toml, data) = probe::shipped_copy("flags_numbers");
    let p = probe::rheometer(
        &["fit", s(&toml), "--with", "radiation=1e308"],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["radiation = 1e308"]);
    assert!(!long_zeros(&p.stderr, 20), "{}", p.stderr);
    let out = dir.join("sim");
    let p = probe::rheometer(
        &[
            "simulate",
            s(&toml),
            "--n",
            "1e-300",
            "--kappa",
            "11",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["(n, kappa) = (1e-300, 11)", "n = 1e-300 is strong"]);
    assert!(!long_zeros(&p.stderr, 20), "{}", p.stderr);
}

/// Finding D50: a landscape at a tolerance its mesh limit cannot reach fails at its first point;
/// the hint offers the tolerance as well as the node limit, which landscape caps.
#[test]
fn d_a_mesh_limit_failure_offers_a_looser_tolerance() {
    let (dir, toml, data) = probe::shipped_copy("flags_mesh_limit");
    let out = dir.join("l");
    let p = probe::rheometer(
        &[
            "landscape",
            s(&toml),
            "--grid",
            "3x3",
            "--tol",
            "1e-12",
            "--uniform-tol",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_clean_failure(&["--max-nodes", "loosen the tolerance (--tol", "1e-12"]);
}
