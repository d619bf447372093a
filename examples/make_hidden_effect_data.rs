//! Generates the shipped data set `data/hidden_radiation/`: the nine PMMA7N-like experiments of
//! `data/pmma7n_synthetic/` simulated with an effect the paper's model does not have —
//! grey-body radiation with emissivity ε = 0.9 — plus measurement noise.
//!
//! ```text
//! cargo run --release --example make_hidden_effect_data            # refuses to overwrite
//! cargo run --release --example make_hidden_effect_data -- --force # regenerate in place
//! cargo run --release --example make_hidden_effect_data -- --out DIR
//! ```
//!
//! Truth: Carreau-type law (n, κ) = (0.8, 11.71), the paper's physics plus radiation
//! (`Physics::paper().with_radiation(0.9)`), the true take-up diameters of
//! `data/pmma7n_synthetic/TRUTH.md`, the same positions. Noise as in that data set:
//! `d_meas = d_true (1 + 0.015 ξ₁ + sd_extra(s) ξ₂)`, `sd_extra(s) = 0.04 ((s − 0.35)/0.16)²`
//! for `s > 0.35 m`, with the seeded generator of `rheometer::data::synthetic`.

use rheometer::data::input::load_experiments;
use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
use rheometer::model::Experiment;
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::Physics, model::SimulateOptions,
};
use std::error::Error;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

/// Seed of the noise.
const SEED: u64 = 20_250_611;
/// Emissivity of the hidden radiation term.
const EMISSIVITY: f64 = 0.9;
/// Truth of the law.
const TRUTH: [f64; 2] = [0.8, 11.71];
/// `v` in scientific notation with `digits` decimals and a two-digit exponent (`1.2345e-04`).
fn sci(v: f64, digits: usize) -> String {
    let t = format!("{v:.digits$e}");
    match t.split_once('e') {
        Some((m, e)) => {
            let (sign, num) = e.strip_prefix('-').map_or(("+", e), |n| ("-", n));
            let sign = if sign == "+" { "" } else { "-" };
            format!("{m}e{sign}{num:0>2}")
        }
        None => t,
    }
}

fn fmt_position(s: f64) -> String {
    if ((s * 100.0).round() / 100.0 - s).abs() < 1e-12 {
        format!("{s:.2}")
    } else {
        format!("{s}")
    }
}

struct Run {
    name: String,
    positions: Vec<f64>,
    with: Vec<f64>,
    without: Vec<f64>,
    t_end: (f64, f64),
    nodes: usize,
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut force = false;
    let mut out = PathBuf::from("data/hidden_radiation");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--force" => force = true,
            "--out" => out = PathBuf::from(args.next().ok_or("--out needs a directory")?),
            other => {
                return Err(format!("unknown argument {other} (use --force, --out DIR)").into())
            }
        }
    }
    let source = Path::new("data/pmma7n_synthetic/experiments.toml");
    let set = load_experiments(source)?;
    // the true take-up diameters of data/pmma7n_synthetic/TRUTH.md
    let truth = Experiment::pmma7n_synthetic_truth();
    let options = SimulateOptions::with_tol(1e-8);
    let mut runs = Vec::new();
    for (k, e) in set.experiments.iter().enumerate() {
        let m = set.measurements[k]
            .as_ref()
            .ok_or_else(|| format!("{} has no measurements", e.name))?;
        let mut e = e.clone();
        e.take_up = truth
            .iter()
            .find(|t| t.name == e.name)
            .ok_or_else(|| format!("{}: no such experiment in the data set's truth", e.name))?
            .take_up;
        let hidden = Physics::paper().with_radiation(EMISSIVITY);
        let model = FiberModel::new(&set.material, &set.air, &e, CarreauLike::new(), hidden)?;
        let sol = simulate(&model, &TRUTH, &options)?;
        let with = sol.profiles(&model, &m.positions);
        let plain = FiberModel::new(
            &set.material,
            &set.air,
            &e,
            CarreauLike::new(),
            Physics::paper(),
        )?;
        let sol0 = simulate(&plain, &TRUTH, &options)?;
        let without = sol0.profiles(&plain, &m.positions);
        let l = [e.spinline_length];
        runs.push(Run {
            name: e.name.clone(),
            positions: m.positions.clone(),
            with: with.diameter,
            without: without.diameter,
            t_end: (
                sol.profiles(&model, &l).temperature[0],
                sol0.profiles(&plain, &l).temperature[0],
            ),
            nodes: sol.nodes(),
        });
        eprintln!("{}: simulated ({} nodes)", e.name, sol.nodes());
    }

    // noise: per experiment first all ξ₁, then all ξ₂
    let noise = SyntheticNoise::pmma7n_synthetic();
    let mut rng = SplitMix64::new(SEED);
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    for r in &runs {
        let measured = noise
            .apply(&r.positions, &r.with, &mut rng)
            .map_err(|e| format!("{}: {e}", r.name))?;
        let mut csv = String::from("position_m,diameter_m\n");
        for (s, d) in r.positions.iter().zip(&measured) {
            let _ = writeln!(csv, "{},{}", fmt_position(*s), sci(*d, 7));
        }
        files.push((out.join(format!("{}.csv", r.name)), csv));
    }
    let original = fs::read_to_string(source)?;
    let body = original
        .find("[material]")
        .map(|i| &original[i..])
        .ok_or("no [material] table in the source TOML")?;
    let toml = format!(
        "# Synthetic PMMA7N-like data set with a HIDDEN EFFECT (see TRUTH.md; try to find it first)\n\
         # Units are in the key suffixes (SI unless stated). Generated by\n\
         # `cargo run --release --example make_hidden_effect_data`.\n\n{body}"
    );
    files.push((out.join("experiments.toml"), toml));
    let mut truth_csv = String::from("position_m");
    for r in &runs {
        let _ = write!(truth_csv, ",{}", r.name);
    }
    truth_csv.push('\n');
    for i in 0..runs[0].positions.len() {
        truth_csv.push_str(&fmt_position(runs[0].positions[i]));
        for r in &runs {
            let _ = write!(truth_csv, ",{}", sci(r.with[i], 10));
        }
        truth_csv.push('\n');
    }
    files.push((out.join("truth/noise_free_diameters_m.csv"), truth_csv));
    files.push((out.join("TRUTH.md"), truth_md(&runs)));

    let existing: Vec<String> = files
        .iter()
        .filter(|(p, _)| p.exists())
        .map(|(p, _)| p.display().to_string())
        .collect();
    if !existing.is_empty() && !force {
        return Err(format!(
            "refusing to overwrite existing files ({}); pass --force to regenerate",
            existing.join(", ")
        )
        .into());
    }
    fs::create_dir_all(out.join("truth"))?;
    for (p, text) in &files {
        fs::write(p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

fn truth_md(runs: &[Run]) -> String {
    let mut s = String::new();
    s.push_str(
        "# TRUTH: PMMA7N-like data set with a hidden effect (spoiler: read only after looking)\n\n\
         Generated by `examples/make_hidden_effect_data.rs` with this crate's simulator:\n\n\
         ```text\ncargo run --release --example make_hidden_effect_data -- --force\n```\n\n\
         (without `--force` the generator refuses to overwrite existing files).\n\n\
         ## The hidden effect\n\
         **Grey-body radiation with emissivity ε = 0.9** is switched on in the energy balance\n\
         (`Physics::paper().with_radiation(0.9)`: heat loss π d ε σ_SB (T⁴ − T_air⁴) per unit\n\
         length, term `\"radiation\"`). Everything else is the paper's model exactly as in\n\
         `data/pmma7n_synthetic/TRUTH.md`: Carreau-type law **n = 0.8, κ = 11.71**, gravity, air\n\
         drag, convection (default Nusselt law of `docs/model-closure.md`), viscous heating, still\n\
         air at 293.15 K, the same material, mass flows, inlet diameter and spin-line length\n\
         (the `[material]` and `[[experiment]]` tables are copied from that data set).\n\n\
         Take-up condition: the true take-up diameters of `data/pmma7n_synthetic/TRUTH.md`\n\
         (110/70/55, 140/90/70, 180/120/95 µm); as there, they are **not** in the TOML (a real\n\
         data set does not know them either). BVP tolerance 1e-8.\n\n\
         ## Noise\n\
         Same model and positions as `data/pmma7n_synthetic`: s = 0, 0.02, …, 0.50 m;\n\
         `d_meas = d_true (1 + 0.015 ξ1 + sd_extra(s) ξ2)`, `sd_extra(s) = 0.04 ((s − 0.35)/0.16)²`\n\
         for s > 0.35 m (aspirator disturbance), else 0. ξ1, ξ2 standard normal from SplitMix64\n\
         (seed 20250611) with Box–Muller (one normal per pair of uniforms); per experiment, in\n\
         table order, first the 26 ξ1, then the 26 ξ2. Diameters written with 8 significant digits.\n\n\
         ## Size of the effect\n\
         Relative change of the noise-free diameters by the radiation term (same parameters and\n\
         take-up diameters, `d_with/d_without − 1`) and the temperature at the take-up:\n\n\
         | name | largest Δd/d [%] | at s [m] | mean Δd/d over s ≤ 0.50 m [%] | T(L) with radiation [K] | T(L) without [K] | nodes |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for r in runs {
        let rel: Vec<f64> = r
            .with
            .iter()
            .zip(&r.without)
            .map(|(a, b)| a / b - 1.0)
            .collect();
        let (imax, vmax) = rel.iter().enumerate().fold((0, 0.0f64), |(i, v), (j, x)| {
            if x.abs() > v.abs() {
                (j, *x)
            } else {
                (i, v)
            }
        });
        let mean = rel.iter().sum::<f64>() / rel.len() as f64;
        let _ = writeln!(
            s,
            "| {} | {:+.2} | {:.2} | {:+.2} | {:.2} | {:.2} | {} |",
            r.name,
            100.0 * vmax,
            r.positions[imax],
            100.0 * mean,
            r.t_end.0,
            r.t_end.1,
            r.nodes
        );
    }
    s.push_str(
        "\nThe noise-free diameters (with radiation) at the measurement positions are in\n\
         `truth/noise_free_diameters_m.csv` (one column per experiment).\n",
    );
    s
}
