//! `rheometer simulate`.

use crate::*;
use diffbvp::fiber::input::Location;
use diffbvp::fiber::simulate;
use diffbvp::fiber::take_up::{resolve_take_up, TakeUpError};

/// Arguments of `rheometer simulate`.
#[derive(clap::Args)]
pub struct SimulateArgs {
    /// The experiments file (TOML; see the book for the format).
    pub experiments: PathBuf,
    /// Power index n of the Carreau-type law (n >= 0; 1 is Newtonian).
    #[arg(long, default_value_t = 0.8, allow_hyphen_values = true, value_parser = checks::parse_n)]
    pub n: f64,
    /// kappa = ln(K / 1 Pa) of the Carreau-type law (|kappa| <= 700).
    #[arg(long, default_value_t = 11.71, allow_hyphen_values = true, value_parser = checks::parse_kappa)]
    pub kappa: f64,
    /// Use the Newtonian law (n = 1).
    #[arg(long)]
    pub newtonian: bool,
    /// Take-up diameter (m, 1e-7 to 0.02) for experiments without one in the TOML.
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_take_up_diameter)]
    pub take_up_diameter: Option<f64>,
    /// Take the take-up diameter d_fit(L) from the smoothed measurements where the TOML has none.
    #[arg(long)]
    pub take_up_from_data: bool,
    /// Number of uniform output positions (2 to 100000).
    #[arg(long, default_value_t = 101, value_parser = checks::parse_points)]
    pub points: usize,
    /// Output directory (created; input files are never overwritten).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rheometer simulate`.
pub fn run(args: SimulateArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let SimulateArgs {
        experiments,
        n,
        kappa,
        newtonian,
        take_up_diameter,
        take_up_from_data,
        points,
        out,
    } = args;
    let loaded = load_input(
        g,
        &experiments,
        take_up_from_data && take_up_diameter.is_none(),
        false,
    )?;
    let inputs = inputs_of(&experiments, &loaded);
    let set = &loaded.set;
    // every output name is checked against the inputs before any work starts
    let names: Vec<&str> = set.experiments.iter().map(|e| e.name.as_str()).collect();
    let ext = g.format.ext();
    let mut outputs: Vec<String> = names.iter().map(|n| format!("{n}_profile.csv")).collect();
    outputs.extend([
        PARTIAL.to_string(),
        format!("profiles.{ext}"),
        format!("diameters_vs_data.{ext}"),
    ]);
    check_output_dir(&out, &outputs, &inputs)?;
    create_dir(&out)?;
    // the manifest stays until every profile is written: an interrupted or failed run (or
    // one still running) is always marked, with the finished experiments listed
    let mut complete: Vec<&str> = Vec::with_capacity(names.len());
    write_partial(&out, &names, &complete, &inputs)?;
    let law = if newtonian { [1.0, kappa] } else { [n, kappa] };
    let options = SimulateOptions {
        max_nodes: g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES),
        ..SimulateOptions::default()
    };
    let mut all_profiles = Vec::with_capacity(set.experiments.len());
    for (k, e) in set.experiments.iter().enumerate() {
        if interrupted() {
            return Err(Interrupted(format!(
                "simulated {} of {} experiments; {} lists the profiles written and the missing ones",
                complete.len(),
                names.len(),
                out.join(PARTIAL).display()
            ))
            .into());
        }
        let mut e = e.clone();
        let rule = if let Some(d) = take_up_diameter {
            MissingTakeUp::Diameter(d)
        } else if take_up_from_data {
            MissingTakeUp::FromData
        } else {
            MissingTakeUp::Error
        };
        let resolved = resolve_take_up(&e, set.measurements[k].as_ref(), rule, None).map_err(
            |err| -> Box<dyn std::error::Error> {
                match err {
                    TakeUpError::NoMeasurements => format!(
                        "experiment {}: --take-up-from-data needs measurements",
                        e.name
                    ),
                    TakeUpError::Smoothing(err) => format!(
                        "experiment {} ({}): --take-up-from-data: smoothing the measurements \
                         failed: {err}",
                        e.name,
                        Location {
                            path: experiments.clone(),
                            line: loaded.details[k].line,
                        }
                    ),
                    TakeUpError::Missing => format!(
                        "experiment {} has no take-up condition: give take_up_diameter_m or take_up_velocity_m_s \
                         in {}, or use --take-up-diameter M or --take-up-from-data",
                        e.name,
                        experiments.display()
                    ),
                }
                .into()
            },
        )?;
        let from_data = resolved.from_data;
        e.take_up = Some(resolved.take_up);
        // a failure names the experiment, its TOML line and likely causes
        let failed = |source: diffbvp::fiber::FiberError| {
            let mut f = ExperimentFailure::new(
                &e,
                &set.material,
                Location {
                    path: experiments.clone(),
                    line: loaded.details[k].line,
                },
                Some(law),
                Box::new(source),
            );
            if let Some(d) = from_data {
                f.hints.push(format!(
                    "the take-up diameter {d:.4e} m is d_fit(L) of the smoothed measurements \
                     (--take-up-from-data)"
                ));
            }
            f
        };
        let model = FiberModel::new(
            &set.material,
            &set.air,
            &e,
            CarreauLike::new(),
            Physics::paper(),
        )
        .map_err(failed)?;
        let sol = simulate(&model, &law, &options).map_err(failed)?;
        let prof = sol.uniform_profiles(&model, points);
        let path = out.join(format!("{}_profile.csv", e.name));
        write_profiles(&path, &prof, &inputs)?;
        complete.push(names[k]);
        write_partial(&out, &names, &complete, &inputs)?;
        if g.verbose {
            g.say(format!(
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
    // every profile is written: the figures cannot lose data any more
    remove_partial(&out, &inputs)?;
    let fig = out.join(format!("profiles.{ext}"));
    figures::profile_overview(&fig, &names, &all_profiles, &inputs).map_err(|e| {
        format!(
            "the {} profiles were written to {}, but the figure failed: {e}",
            names.len(),
            out.display()
        )
    })?;
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
        let fig = out.join(format!("diameters_vs_data.{ext}"));
        let pages = figures::experiment_panel_pages(&fig, &views, &curves, View::Diameter, &inputs)
            .map_err(|e| {
                format!(
                    "the {} profiles were written to {}, but the figure failed: {e}",
                    names.len(),
                    out.display()
                )
            })?;
        if pages.len() > 1 {
            g.say(format!(
                "{} experiments with measurements: the diameter figure is split into {} files \
                 ({}_1.{ext} …) of at most {} panels",
                views.len(),
                pages.len(),
                out.join("diameters_vs_data").display(),
                figures::MAX_PANELS_PER_FIGURE
            ));
        }
    }
    g.say(format!(
        "wrote {} profiles and figures to {}",
        set.experiments.len(),
        out.display()
    ));
    Ok(())
}

/// Name of the manifest that marks an incomplete `simulate` output directory.
pub const PARTIAL: &str = "PARTIAL.txt";

/// Writes `DIR/PARTIAL.txt`: which experiments have their profile written and which are missing.
fn write_partial(
    out: &Path,
    names: &[&str],
    complete: &[&str],
    inputs: &[PathBuf],
) -> Result<(), Box<dyn Error>> {
    let mut text = String::from(
        "# rheometer simulate: INCOMPLETE output (still running, interrupted or failed).\n\
         # This file is removed once every profile is written.\n",
    );
    text.push_str(&format!(
        "# {} of {} profiles written\n",
        complete.len(),
        names.len()
    ));
    for n in names {
        let state = if complete.contains(n) {
            "complete"
        } else {
            "missing"
        };
        text.push_str(&format!("{state} {n} {n}_profile.csv\n"));
    }
    write_text(&out.join(PARTIAL), &text, inputs)?;
    Ok(())
}

/// Removes `DIR/PARTIAL.txt` (after [`write_partial`]; never an input).
fn remove_partial(out: &Path, inputs: &[PathBuf]) -> Result<(), Box<dyn Error>> {
    let path = out.join(PARTIAL);
    ensure_not_input(&path, inputs)?;
    match std::fs::remove_file(&path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("cannot remove {}: {e}", path.display()).into()),
    }
}
