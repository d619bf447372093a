//! `rheometer simulate`.

use crate::*;
use diffbvp::fiber::simulate::Profiles;
use diffbvp::fiber::workflow::{SimulateError, SimulateRequest};
use std::ops::ControlFlow;

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
    let request = SimulateRequest {
        law,
        missing_take_up: if let Some(d) = take_up_diameter {
            MissingTakeUp::Diameter(d)
        } else if take_up_from_data {
            MissingTakeUp::FromData
        } else {
            MissingTakeUp::Error
        },
        points,
        simulate: SimulateOptions {
            max_nodes: g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES),
            ..SimulateOptions::default()
        },
        source: experiments.clone(),
        ..SimulateRequest::new(law, PathBuf::new())
    };
    // each profile written (and the manifest updated) as soon as it is finished
    let mut write_error: Option<Box<dyn Error>> = None;
    let result = workflow::simulate_experiments(&loaded, &request, |k, p| {
        let path = out.join(format!("{}_profile.csv", p.name));
        let written = write_profiles(&path, &p.profiles, &inputs)
            .map_err(Box::<dyn Error>::from)
            .and_then(|()| {
                complete.push(names[k]);
                write_partial(&out, &names, &complete, &inputs)
            });
        if let Err(e) = written {
            write_error = Some(e);
            return ControlFlow::Break(());
        }
        if g.verbose {
            let pr = &p.profiles;
            g.say(format!(
                "{}: {} nodes, T(L) = {:.2} K, d(L) = {:.3} µm -> {}",
                p.name,
                p.nodes,
                pr.temperature.last().copied().unwrap_or(f64::NAN),
                1e6 * pr.diameter.last().copied().unwrap_or(f64::NAN),
                path.display()
            ));
        }
        if interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    if let Some(e) = write_error {
        return Err(e);
    }
    let all_profiles: Vec<Profiles> = match result {
        Ok(v) => v.into_iter().map(|p| p.profiles).collect(),
        Err(SimulateError::Stopped { done }) => {
            return Err(Interrupted(format!(
                "simulated {done} of {} experiments; {} lists the profiles written and the \
                 missing ones",
                names.len(),
                out.join(PARTIAL).display()
            ))
            .into())
        }
        Err(SimulateError::Experiment(f)) => return Err(f),
        Err(e) => return Err(e.to_string().into()),
    };
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
