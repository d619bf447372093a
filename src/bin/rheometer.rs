//! `rheometer`: simulate fiber spinning and identify the Carreau-type elongational viscosity
//! from your own TOML + CSV measurements.

use clap::{Parser, Subcommand, ValueEnum};
use diffbvp::fiber::diagnostics::candidates::{
    physics_with, Effect, EffectSetting, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA,
};
use diffbvp::fiber::diagnostics::compare::{
    compare, simulate_experiments, CompareOptions, FigureFormat, FitParameters, MissingTakeUp,
    ModelSetup,
};
use diffbvp::fiber::diagnostics::diagnose::{diagnose, DiagnoseOptions, ResidualProfiles};
use diffbvp::fiber::diagnostics::report::save_residual_figure;
use diffbvp::fiber::figures::{self, ExperimentView, ModelCurves, View};
use diffbvp::fiber::input::{load_experiments_with, LoadedExperiments};
use diffbvp::fiber::output::{create_dir, ensure_not_input, profiles_csv, write_text};
use diffbvp::fiber::rheometer::{Estimator, FitReport, IdentifyOptions, Rheometer};
use diffbvp::fiber::setup::TakeUp;
use diffbvp::fiber::smoothing::smooth;
use diffbvp::fiber::{simulate, CarreauLike, FiberModel, FiberSolution, Physics, SimulateOptions};
use indicatif::{ProgressBar, ProgressStyle};
use std::error::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `println!` that ignores a closed stdout (e.g. `rheometer ... | head`) instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "rheometer",
    version,
    about = "Simulation-based elongational rheometer for Carreau-type polymer melts",
    long_about = "Simulates stationary melt spinning and identifies the Carreau-type elongational \
viscosity (n, kappa = ln K) from fiber diameters measured along the spin line.",
    after_help = "Examples:\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --json target/fit.json\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --take-up-from-data --out target/sim\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 21x21 --out target/landscape\n\n\
Input format, outputs and error messages: see the book (mdbook build book)."
)]
struct Cli {
    /// Print nothing but results and errors.
    #[arg(long, global = true)]
    quiet: bool,
    /// Print more detail (solver statistics, iterations).
    #[arg(long, short, global = true)]
    verbose: bool,
    /// Figure format.
    #[arg(long, value_enum, global = true, default_value_t = FormatArg::Png)]
    format: FormatArg,
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum EstimatorArg {
    /// Relative least squares against the raw data, take-up diameters fitted (default).
    Principled,
    /// The paper's strain-rate-weighted cost against the smoothed data.
    Paper,
}

#[derive(Clone, Copy, ValueEnum)]
enum FormatArg {
    /// Bitmap figures.
    Png,
    /// Vector figures.
    Svg,
}

impl FormatArg {
    fn ext(self) -> &'static str {
        match self {
            FormatArg::Png => "png",
            FormatArg::Svg => "svg",
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Simulate every experiment and write profiles (CSV) and figures into DIR.
    #[command(after_help = "Examples:\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --n 0.8 --kappa 11.71 \
--take-up-from-data --out target/sim\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --newtonian --take-up-diameter 1e-4 \
--out target/sim_newtonian\n\n\
Writes DIR/<experiment>_profile.csv with the columns listed in the book's CLI reference, \
DIR/profiles.png (diameter and temperature of all experiments) and, where measurements exist, \
DIR/diameters_vs_data.png.")]
    Simulate {
        /// The experiments file (TOML; see the book for the format).
        experiments: PathBuf,
        /// Power index n of the Carreau-type law.
        #[arg(long, default_value_t = 0.8)]
        n: f64,
        /// kappa = ln(K / 1 Pa) of the Carreau-type law.
        #[arg(long, default_value_t = 11.71)]
        kappa: f64,
        /// Use the Newtonian law (n = 1).
        #[arg(long)]
        newtonian: bool,
        /// Take-up diameter (m) for experiments without one in the TOML.
        #[arg(long)]
        take_up_diameter: Option<f64>,
        /// Take the take-up diameter d_fit(L) from the smoothed measurements where the TOML has none.
        #[arg(long)]
        take_up_from_data: bool,
        /// Number of uniform output positions.
        #[arg(long, default_value_t = 101)]
        points: usize,
        /// Output directory (created; input files are never overwritten).
        #[arg(long)]
        out: PathBuf,
    },
    /// Identify (n, kappa) from the measurements and print an uncertainty report.
    #[command(after_help = "Examples:\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --json target/fit.json\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --estimator paper --start 0.5,11.51\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --out target/fit\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --newtonian")]
    Fit {
        /// The experiments file (TOML).
        experiments: PathBuf,
        /// Start point "N,KAPPA" (default: the paper's start heuristic).
        #[arg(long, value_parser = parse_pair)]
        start: Option<(f64, f64)>,
        /// The estimator.
        #[arg(long, value_enum, default_value_t = EstimatorArg::Principled)]
        estimator: EstimatorArg,
        /// Evaluate the Newtonian model (n = 1) instead of fitting.
        #[arg(long)]
        newtonian: bool,
        /// The viscosity law of the model: carreau (n, kappa fitted) or newtonian.
        #[arg(long, default_value = "carreau")]
        model: LawChoice,
        /// Add an effect, its strength fitted ("radiation") or fixed ("radiation=0.9");
        /// repeatable. Effects: strain_thinning, radiation, air_coflow,
        /// air_temperature_profile, inlet_velocity, nusselt_scale.
        #[arg(long = "with", value_name = "EFFECT[=VALUE]")]
        with: Vec<EffectSetting>,
        /// Write the result as JSON to FILE.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write the report, the fitted profiles and figures (paper Fig. 2, 3, 5; with --with also
        /// a before/after residual figure) into DIR.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Which physical effect is missing from the model? Ranks the candidate effects by how
    /// much of the misfit each explains (linearised scores, refits, delta BIC).
    ///
    /// Example: rheometer diagnose data/pmma7n_synthetic/experiments.toml --json
    /// target/diagnose.json --out target/diagnose
    Diagnose {
        /// The experiments file (TOML).
        experiments: PathBuf,
        /// The viscosity law of your model: carreau or newtonian.
        #[arg(long, default_value = "carreau")]
        model: LawChoice,
        /// Effects already in your model (fitted or "=VALUE" fixed); repeatable.
        #[arg(long = "with", value_name = "EFFECT[=VALUE]")]
        with: Vec<EffectSetting>,
        /// How many of the best linearised candidates are refitted.
        #[arg(long, default_value_t = 3)]
        refit_top: usize,
        /// Write the diagnosis as JSON to FILE.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Output directory (report and before/after residual figure).
        #[arg(long)]
        out: PathBuf,
    },
    /// Compute the cost landscape J(n, kappa) on a grid; write it as CSV and heat map.
    #[command(after_help = "Examples:\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 41x41 --out target/landscape\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 11x11 --n-range 0.6,1 \
--kappa-range 10,14 --estimator principled --out target/landscape_zoom\n\n\
Writes DIR/landscape.csv with the columns n,kappa,cost and the heat map DIR/landscape.png.")]
    Landscape {
        /// The experiments file (TOML).
        experiments: PathBuf,
        /// Grid size "NxM" (n values x kappa values).
        #[arg(long, default_value = "41x41", value_parser = parse_grid)]
        grid: (usize, usize),
        /// Range of n "MIN,MAX".
        #[arg(long, default_value = "0,1", value_parser = parse_pair)]
        n_range: (f64, f64),
        /// Range of kappa "MIN,MAX".
        #[arg(long, default_value = "9,16", value_parser = parse_pair)]
        kappa_range: (f64, f64),
        /// The estimator whose cost is mapped.
        #[arg(long, value_enum, default_value_t = EstimatorArg::Paper)]
        estimator: EstimatorArg,
        /// BVP tolerance of the landscape solves (a picture; fits use 1e-6).
        #[arg(long, default_value_t = 1e-4)]
        tol: f64,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Compare the model with the measurements: residuals along the spin line, noise level,
    /// chi2/dof, whiteness and where the misfit is systematic; text, JSON, CSV and figures.
    ///
    /// Example: rheometer compare data/pmma7n_synthetic/experiments.toml --fit target/fit.json
    /// --out target/compare
    Compare {
        /// The experiments file (TOML).
        experiments: PathBuf,
        /// Parameters (n, kappa and take-up factors) from the JSON written by `rheometer fit --json`.
        #[arg(long, conflicts_with_all = ["n", "kappa", "newtonian"])]
        fit: Option<PathBuf>,
        /// Power index n of the Carreau-type law (without --fit).
        #[arg(long)]
        n: Option<f64>,
        /// kappa = ln(K / 1 Pa) of the Carreau-type law (without --fit).
        #[arg(long)]
        kappa: Option<f64>,
        /// Use the Newtonian law (n = 1).
        #[arg(long)]
        newtonian: bool,
        /// Take the take-up diameter d_fit(L) from the smoothed measurements where the TOML has
        /// none (implied by --fit, which was fitted that way).
        #[arg(long)]
        take_up_from_data: bool,
        /// An effect in the model with its strength, "EFFECT=VALUE" (repeatable; "EFFECT" alone
        /// takes the strength from --fit): radiation, air_coflow, air_temperature_profile,
        /// inlet_velocity, nusselt_scale. Effects in the fit file are included automatically.
        #[arg(long = "with", value_name = "EFFECT[=VALUE]")]
        with: Vec<EffectSetting>,
        /// Relative measurement uncertainty (overrides the TOML's relative_uncertainty; default:
        /// the TOML's, else estimated from the data).
        #[arg(long)]
        relative_uncertainty: Option<f64>,
        /// Output directory (created; input files are never overwritten).
        #[arg(long)]
        out: PathBuf,
    },
}

fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 2 {
        return Err(format!("expected two numbers \"A,B\", got \"{s}\""));
    }
    let a: f64 = parts[0]
        .trim()
        .parse()
        .map_err(|_| format!("\"{}\" is not a number", parts[0]))?;
    let b: f64 = parts[1]
        .trim()
        .parse()
        .map_err(|_| format!("\"{}\" is not a number", parts[1]))?;
    if !a.is_finite() || !b.is_finite() {
        return Err(format!("\"{s}\" contains a non-finite number"));
    }
    Ok((a, b))
}

fn parse_grid(s: &str) -> Result<(usize, usize), String> {
    let parts: Vec<&str> = s.split(['x', 'X']).collect();
    if parts.len() != 2 {
        return Err(format!("expected \"NxM\", got \"{s}\""));
    }
    let a: usize = parts[0]
        .trim()
        .parse()
        .map_err(|_| format!("\"{}\" is not a count", parts[0]))?;
    let b: usize = parts[1]
        .trim()
        .parse()
        .map_err(|_| format!("\"{}\" is not a count", parts[1]))?;
    if a < 2 || b < 2 {
        return Err("the grid needs at least 2 points per direction".into());
    }
    Ok((a, b))
}

fn inputs_of(path: &Path, loaded: &LoadedExperiments) -> Vec<PathBuf> {
    let mut v = vec![path.to_path_buf()];
    v.extend(loaded.details.iter().filter_map(|d| d.data.clone()));
    v
}

fn estimator(e: EstimatorArg) -> Estimator {
    match e {
        EstimatorArg::Principled => Estimator::Principled,
        EstimatorArg::Paper => Estimator::Paper,
    }
}

fn write_json(path: &Path, text: &str, inputs: &[PathBuf]) -> Result<(), Box<dyn Error>> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            create_dir(parent)?;
        }
    }
    write_text(path, text, inputs)?;
    Ok(())
}

fn profiles_of(rh: &Rheometer, sols: &[diffbvp::Solution]) -> ResidualProfiles {
    sols.iter()
        .enumerate()
        .map(|(k, s)| {
            (
                rh.experiments[k].name.clone(),
                rh.measurements[k]
                    .positions
                    .iter()
                    .copied()
                    .zip(rh.relative_residuals(k, s))
                    .collect(),
            )
        })
        .collect()
}

fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    diffbvp::mesh::linspace(a, b, m)
}

/// The effects of a compared model: those of the fit file, overridden or extended by `--with`.
fn compare_effects(
    fit: Option<&FitParameters>,
    with: &[EffectSetting],
) -> Result<Vec<(Effect, f64)>, Box<dyn Error>> {
    let mut out: Vec<(Effect, f64)> = Vec::new();
    if let Some(f) = fit {
        for e in &f.effects {
            let effect: Effect = e.effect.parse()?;
            out.push((effect, e.strength));
        }
    }
    for w in with {
        let name = w.effect.name();
        let value = match (w.value, out.iter().find(|(e, _)| e.name() == name)) {
            (Some(v), _) => v,
            (None, Some((_, v))) => *v,
            (None, None) => {
                return Err(format!(
                "--with {name}: give its strength as --with {name}=VALUE (the fit file has none)"
            )
                .into())
            }
        };
        out.retain(|(e, _)| e.name() != name);
        out.push((w.effect.clone(), value));
    }
    Ok(out)
}

fn read_fit(path: &Path) -> Result<FitParameters, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the fit file {}: {e}", path.display()))?;
    Ok(FitParameters::from_json(
        &text,
        &path.display().to_string(),
    )?)
}

fn run(cli: Cli) -> Result<(), Box<dyn Error>> {
    let say = |s: String| {
        if !cli.quiet {
            eprintln!("{s}");
        }
    };
    match cli.command {
        Command::Simulate {
            experiments,
            n,
            kappa,
            newtonian,
            take_up_diameter,
            take_up_from_data,
            points,
            out,
        } => {
            let loaded = load_experiments_with(&experiments, 4)?;
            let inputs = inputs_of(&experiments, &loaded);
            let set = &loaded.set;
            create_dir(&out)?;
            let law = if newtonian { [1.0, kappa] } else { [n, kappa] };
            let mut all_profiles = Vec::with_capacity(set.experiments.len());
            for (k, e) in set.experiments.iter().enumerate() {
                let mut e = e.clone();
                if e.take_up.is_none() {
                    if let Some(d) = take_up_diameter {
                        e.take_up = Some(TakeUp::Diameter(d));
                    } else if take_up_from_data {
                        let m = set.measurements[k].as_ref().ok_or_else(|| {
                            format!(
                                "experiment {}: --take-up-from-data needs measurements",
                                e.name
                            )
                        })?;
                        let f = smooth(&m.positions, &m.diameters)?;
                        e.take_up = Some(TakeUp::Diameter(f.diameter(e.spinline_length)));
                    } else {
                        return Err(format!(
                            "experiment {} has no take-up condition: give take_up_diameter_m or take_up_velocity_m_s \
                             in {}, or use --take-up-diameter M or --take-up-from-data",
                            e.name,
                            experiments.display()
                        )
                        .into());
                    }
                }
                let model = FiberModel::new(
                    &set.material,
                    &set.air,
                    &e,
                    CarreauLike::new(),
                    Physics::paper(),
                )?;
                let sol = simulate(&model, &law, &SimulateOptions::default())?;
                let prof = sol.uniform_profiles(&model, points.max(2));
                let path = out.join(format!("{}_profile.csv", e.name));
                write_text(&path, &profiles_csv(&prof), &inputs)?;
                if cli.verbose {
                    say(format!(
                        "{}: {} nodes, T(L) = {:.2} K, d(L) = {:.3} µm -> {}",
                        e.name,
                        sol.nodes(),
                        prof.temperature[prof.temperature.len() - 1],
                        1e6 * prof.diameter[prof.diameter.len() - 1],
                        path.display()
                    ));
                }
                all_profiles.push(prof);
            }
            let names: Vec<&str> = set.experiments.iter().map(|e| e.name.as_str()).collect();
            let fig = out.join(format!("profiles.{}", cli.format.ext()));
            figures::profile_overview(&fig, &names, &all_profiles, &inputs)?;
            let with_data: Vec<usize> = (0..set.experiments.len())
                .filter(|&k| set.measurements[k].is_some())
                .collect();
            if !with_data.is_empty() {
                let views: Vec<ExperimentView> = with_data
                    .iter()
                    .filter_map(|&k| {
                        let m = set.measurements[k].as_ref()?;
                        Some(ExperimentView {
                            name: &set.experiments[k].name,
                            length: set.experiments[k].spinline_length,
                            positions: &m.positions,
                            diameters: &m.diameters,
                            smooth: None,
                        })
                    })
                    .collect();
                let profs: Vec<_> = with_data.iter().map(|&k| all_profiles[k].clone()).collect();
                let label = if newtonian {
                    "Newtonian (n = 1)".to_string()
                } else {
                    format!("n = {n}, κ = {kappa}")
                };
                let curves = [ModelCurves {
                    label: &label,
                    profiles: &profs,
                    dashed: false,
                }];
                let fig = out.join(format!("diameters_vs_data.{}", cli.format.ext()));
                figures::experiment_panels(&fig, &views, &curves, View::Diameter, &inputs)?;
            }
            say(format!(
                "wrote {} profiles and figures to {}",
                set.experiments.len(),
                out.display()
            ));
        }
        Command::Fit {
            experiments,
            start,
            estimator: est,
            newtonian,
            model,
            with,
            json,
            out,
        } => {
            let loaded = load_experiments_with(&experiments, 4)?;
            let inputs = inputs_of(&experiments, &loaded);
            // refuse an output that is an input before spending time on the fit
            if let Some(path) = &json {
                ensure_not_input(path, &inputs)?;
            }
            if let Some(dir) = &out {
                for name in ["fit.json", "fit_report.txt"] {
                    ensure_not_input(&dir.join(name), &inputs)?;
                }
            }
            let spec = ModelSpec {
                law: model,
                effects: with.clone(),
                candidates: Vec::new(),
            };
            let rh = Rheometer::with_spec(&loaded.set, spec)?;
            let opts = IdentifyOptions::with_estimator(estimator(est));
            let law_fitted = model == LawChoice::Carreau
                || with
                    .iter()
                    .any(|w| w.effect.name() == "strain_thinning" && w.value.is_none());
            if newtonian {
                let mut obj = rh.objective([1.0, 20.0], &opts)?;
                let j = obj.cost_at(1.0, 20.0)?;
                outln!(
                    "Newtonian model (n = 1): cost J = {j:.6e} ({} estimator)",
                    opts.estimator.name()
                );
                return Ok(());
            }
            let start = match start {
                Some((n, k)) => [n, k],
                None if !law_fitted => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
                None => {
                    let sp = rh.start_heuristic(&opts)?;
                    say(format!(
                        "start heuristic: (n, kappa) = ({}, {})",
                        sp.start[0], sp.start[1]
                    ));
                    sp.start
                }
            };
            let id = rh.identify(start, &opts)?;
            let rep = FitReport::new(&id);
            outln!("{}", rep.to_text());
            let text = serde_json::to_string_pretty(&rep)?;
            if let Some(path) = json {
                write_json(&path, &text, &inputs)?;
                say(format!("wrote {}", path.display()));
            }
            if let Some(dir) = out {
                create_dir(&dir)?;
                if !with.is_empty() {
                    // the same fit without the effects, for the before/after comparison
                    let rh0 = Rheometer::with_spec(&loaded.set, ModelSpec::new(model))?;
                    let s0 = if model == LawChoice::Carreau {
                        [id.n, id.kappa]
                    } else {
                        [1.0, STRAIN_THINNING_REFERENCE_KAPPA]
                    };
                    let id0 = rh0.identify(s0, &opts)?;
                    let names: Vec<String> =
                        with.iter().map(|w| w.effect.name().to_string()).collect();
                    let label = names.join(" + ");
                    let before = profiles_of(&rh0, &id0.solutions);
                    let after = profiles_of(&rh, &id.solutions);
                    let fig = dir.join("residuals_before_after.png");
                    save_residual_figure(&fig, &before, Some((&label, &after)))?;
                    outln!(
                        "RMS relative residual: {:.4} % without {label}, {:.4} % with it ({})",
                        100.0 * id0.rms_relative_residual,
                        100.0 * id.rms_relative_residual,
                        fig.display()
                    );
                }
                write_text(&dir.join("fit_report.txt"), &rep.to_text(), &inputs)?;
                write_text(&dir.join("fit.json"), &text, &inputs)?;
                for (k, sol) in id.solutions.iter().enumerate() {
                    let model = &rh.models[k];
                    let fs = FiberSolution {
                        solution: sol.clone(),
                    };
                    let prof = fs.uniform_profiles(model, 101);
                    write_text(
                        &dir.join(format!("{}_fitted_profile.csv", rh.experiments[k].name)),
                        &profiles_csv(&prof),
                        &inputs,
                    )?;
                }
                let written = figures::identification_figures(
                    &rh,
                    &id,
                    &opts,
                    &dir,
                    cli.format.ext(),
                    &inputs,
                )?;
                for w in written {
                    say(format!("wrote {}", w.display()));
                }
                say(format!(
                    "wrote the report and fitted profiles to {}",
                    dir.display()
                ));
            }
        }
        Command::Diagnose {
            experiments,
            model,
            with,
            refit_top,
            json,
            out,
        } => {
            let loaded = load_experiments_with(&experiments, 4)?;
            let inputs = inputs_of(&experiments, &loaded);
            let spec = ModelSpec {
                law: model,
                effects: with,
                candidates: Vec::new(),
            };
            spec.validate()?;
            let opts = DiagnoseOptions {
                refit_top,
                ..DiagnoseOptions::default()
            };
            // a spinner on a terminal (indicatif draws nothing when stderr is not a terminal)
            let spinner = if cli.quiet {
                ProgressBar::hidden()
            } else {
                let b = ProgressBar::new_spinner();
                b.set_message("fitting your model and scoring the candidate effects");
                b.enable_steady_tick(std::time::Duration::from_millis(120));
                b
            };
            let run = diagnose(&loaded.set, &spec, &opts);
            spinner.finish_and_clear();
            let run = run?;
            let text = run.diagnosis.to_text();
            outln!("{text}");
            create_dir(&out)?;
            write_text(&out.join("diagnosis.txt"), &text, &inputs)?;
            let js = serde_json::to_string_pretty(&run.diagnosis)?;
            write_text(&out.join("diagnosis.json"), &js, &inputs)?;
            if let Some(path) = json {
                write_json(&path, &js, &inputs)?;
                say(format!("wrote {}", path.display()));
            }
            let fig = out.join(format!("residuals_before_after.{}", cli.format.ext()));
            ensure_not_input(&fig, &inputs)?;
            run.save_figure(&fig)?;
            say(format!(
                "wrote the report and {} to {}",
                fig.display(),
                out.display()
            ));
        }
        Command::Landscape {
            experiments,
            grid,
            n_range,
            kappa_range,
            estimator: est,
            tol,
            out,
        } => {
            let loaded = load_experiments_with(&experiments, 4)?;
            let inputs = inputs_of(&experiments, &loaded);
            let rh = Rheometer::new(&loaded.set)?;
            let mut opts = IdentifyOptions::with_estimator(estimator(est));
            if !(tol > 0.0 && tol < 1.0) {
                return Err(format!("--tol must lie in (0, 1), got {tol}").into());
            }
            opts.simulate.tol = tol;
            let ns = linspace(n_range.0, n_range.1, grid.0);
            let ks = linspace(kappa_range.0, kappa_range.1, grid.1);
            let bar = if cli.quiet {
                ProgressBar::hidden()
            } else {
                let b = ProgressBar::new((grid.0 * grid.1) as u64);
                b.set_style(
                    ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta} left)")
                        .unwrap_or_else(|_| ProgressStyle::default_bar()),
                );
                b.set_message("landscape");
                b
            };
            let t0 = std::time::Instant::now();
            let l = rh.landscape(&ns, &ks, &opts, |d| bar.set_position(d as u64))?;
            bar.finish_and_clear();
            create_dir(&out)?;
            let mut csv = String::from("n,kappa,cost\n");
            for (j, k) in ks.iter().enumerate() {
                for (i, n) in ns.iter().enumerate() {
                    csv.push_str(&format!("{n},{k},{:e}\n", l.cost[j * ns.len() + i]));
                }
            }
            let path = out.join("landscape.csv");
            write_text(&path, &csv, &inputs)?;
            let mut markers = Vec::new();
            if let Some((n, k, c)) = l.minimum() {
                outln!("grid minimum: n = {n:.4}, kappa = {k:.4}, J = {c:.6e}");
                markers.push((n, k, "grid minimum".to_string()));
            }
            let fig = out.join(format!("landscape.{}", cli.format.ext()));
            let title = format!("J(n, κ), {} estimator", opts.estimator.name());
            figures::landscape_map(&fig, &l, &title, &markers, &inputs)?;
            say(format!(
                "{} points in {:.1} s; wrote {}",
                grid.0 * grid.1,
                t0.elapsed().as_secs_f64(),
                path.display()
            ));
        }
        Command::Compare {
            experiments,
            fit,
            n,
            kappa,
            newtonian,
            take_up_from_data,
            relative_uncertainty,
            with,
            out,
        } => {
            let loaded = load_experiments_with(&experiments, 4)?;
            let inputs = inputs_of(&experiments, &loaded);
            let set = &loaded.set;
            let fit_params = fit.as_ref().map(|p| read_fit(p)).transpose()?;
            let effects = compare_effects(fit_params.as_ref(), &with)?;
            // validated once here; the closure rebuilds the same physics per experiment
            physics_with(&effects)?;
            let physics = || physics_with(&effects).unwrap_or_else(|_| Physics::paper());
            for (e, v) in &effects {
                say(format!("model includes {} = {v} {}", e.name(), e.unit()));
            }
            let mut setup = ModelSetup::carreau([0.8, 11.71], &physics);
            let mut fitted = 0;
            if let (Some(path), Some(rep)) = (&fit, fit_params) {
                rep.apply(
                    &mut setup,
                    set.experiments.len(),
                    &path.display().to_string(),
                )?;
                fitted = rep.fitted_parameters();
                say(format!(
                    "model from {}: n = {}, kappa = {} ({} estimator)",
                    path.display(),
                    rep.n,
                    rep.kappa,
                    rep.estimator.name()
                ));
            } else {
                let kappa = kappa.ok_or(
                    "give the parameters: --fit FIT.json (from `rheometer fit --json`) or --kappa K \
                     with --n N or --newtonian",
                )?;
                let n = if newtonian {
                    1.0
                } else {
                    n.ok_or("give --n N (or --newtonian) together with --kappa")?
                };
                setup.law_params = [n, kappa];
                if take_up_from_data {
                    setup.missing_take_up = MissingTakeUp::FromData;
                }
            }
            let options = CompareOptions {
                relative_uncertainty,
                fitted_parameters: fitted,
                ..Default::default()
            };
            let t0 = std::time::Instant::now();
            let runs = simulate_experiments(set, &setup)?;
            let cmp = compare(&runs, set.relative_uncertainty, &options)?;
            let fmt = match cli.format {
                FormatArg::Png => FigureFormat::Png,
                FormatArg::Svg => FigureFormat::Svg,
            };
            let written = cmp.write(&out, fmt, &inputs)?;
            outln!("{}", cmp.to_text());
            say(format!(
                "compared {} experiments in {:.1} s; wrote {} files to {}",
                set.experiments.len(),
                t0.elapsed().as_secs_f64(),
                written.len(),
                out.display()
            ));
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let mut printed = e.to_string();
            eprintln!("error: {printed}");
            let mut src = e.source();
            while let Some(s) = src {
                // messages that already quote their cause are not repeated
                let text = s.to_string();
                if !printed.contains(&text) {
                    eprintln!("  caused by: {text}");
                }
                printed = text;
                src = s.source();
            }
            ExitCode::FAILURE
        }
    }
}
