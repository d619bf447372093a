//! `rheometer simulate`.

use crate::*;
use rheometer::model::ExperimentSet;
use rheometer::model::Profiles;
use rheometer::workflow::{SimulateError, SimulateRequest};
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
    /// Use the Newtonian law (n = 1; not with --n).
    #[arg(long, conflicts_with = "n")]
    pub newtonian: bool,
    /// Take-up diameter (m, 1e-7 to 0.02) for experiments without one in the TOML (not with
    /// --take-up-from-data).
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = checks::parse_take_up_diameter,
        conflicts_with = "take_up_from_data"
    )]
    pub take_up_diameter: Option<f64>,
    /// Take the take-up diameter d_fit(L) from the smoothed measurements where the TOML has none.
    #[arg(long)]
    pub take_up_from_data: bool,
    /// Number of uniform output positions (2 to 100000).
    #[arg(long, default_value_t = 101, allow_hyphen_values = true, value_parser = checks::parse_points)]
    pub points: usize,
    /// Output directory (created; input files are never overwritten).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rheometer simulate`.
pub fn run(args: SimulateArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let loaded = load_input(
        g,
        &args.experiments,
        args.take_up_from_data && args.take_up_diameter.is_none(),
        false,
    )?;
    let set = &loaded.set;
    let names: Vec<&str> = set.experiments.iter().map(|e| e.name.as_str()).collect();
    let ext = g.format.ext();
    // every output is checked before any work starts
    let entries = output_entries(&loaded, &names, ext);
    let mut plan = outputs::plan_for(&args.experiments, &loaded);
    plan.dir(&args.out, "--out", entries.iter().map(|(_, f)| f));
    plan.dir_files(&args.out, [PARTIAL_NAME]);
    let outputs = outputs::check(&plan, g)?;
    // the manifest stays until every file is written: an interrupted or failed run (or one
    // still running) is always marked, with the finished experiments listed
    let mut dir =
        outputs::DirWriter::begin(&outputs, &args.out, "rheometer simulate", "files", entries)?;
    let request = simulate_request(&args, g);
    let all_profiles = simulate_and_write(&loaded, &request, &mut dir, g, &args.out)?;
    // every profile is written; the figures are the last files of the set
    let fig = format!("profiles.{ext}");
    dir.rendered(|d| {
        figures::profile_overview(&d.join(&fig), &names, &all_profiles).map(|f| vec![f])
    })?;
    data_figure(&args, set, &all_profiles, &mut dir, g)?;
    dir.finish()?;
    g.say(format!(
        "wrote {} profiles and figures to {}",
        set.experiments.len(),
        args.out.display()
    ));
    Ok(())
}

/// The files `(label, name)` a run writes: one profile per experiment, the overview figure
/// and the pages of the figure against the data (for the experiments with measurements).
fn output_entries(loaded: &LoadedExperiments, names: &[&str], ext: &str) -> Vec<(String, String)> {
    let with_data = loaded
        .set
        .measurements
        .iter()
        .filter(|m| m.is_some())
        .count();
    let mut entries: Vec<(String, String)> = names
        .iter()
        .map(|n| (n.to_string(), format!("{n}_profile.csv")))
        .collect();
    entries.push(("figure".into(), format!("profiles.{ext}")));
    if with_data > 0 {
        for f in figures::panel_page_names("diameters_vs_data", ext, with_data) {
            entries.push(("figure".into(), f));
        }
    }
    entries
}

/// What to simulate: the law, the take-up diameter where the TOML has none, the output
/// points and the solver's node budget.
fn simulate_request(args: &SimulateArgs, g: &Global) -> SimulateRequest {
    let law = if args.newtonian {
        [1.0, args.kappa]
    } else {
        [args.n, args.kappa]
    };
    SimulateRequest {
        law,
        missing_take_up: if let Some(d) = args.take_up_diameter {
            MissingTakeUp::Diameter(d)
        } else if args.take_up_from_data {
            MissingTakeUp::FromData
        } else {
            MissingTakeUp::Error
        },
        points: args.points,
        simulate: SimulateOptions {
            max_nodes: g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES),
            ..SimulateOptions::default()
        },
        source: args.experiments.clone(),
        ..SimulateRequest::new(law, PathBuf::new())
    }
}

/// Simulates every experiment, each profile written (and the manifest updated) as soon as it
/// is finished; an interruption or a failed write stops the run with an error.
fn simulate_and_write(
    loaded: &LoadedExperiments,
    request: &SimulateRequest,
    dir: &mut outputs::DirWriter<'_>,
    g: &Global,
    out: &Path,
) -> Result<Vec<Profiles>, Box<dyn Error>> {
    let mut write_error: Option<Box<dyn Error>> = None;
    let result = workflow::simulate_experiments(loaded, request, |_, p| {
        let name = format!("{}_profile.csv", p.name);
        let path = dir.path(&name);
        let written = dir.write(&name, |w| write_profiles_csv(w, &p.profiles));
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
    match result {
        Ok(v) => Ok(v.into_iter().map(|p| p.profiles).collect()),
        Err(SimulateError::Stopped { done }) => Err(Interrupted(format!(
            "simulated {done} of {} experiments; {} lists the profiles written and the \
             missing ones",
            loaded.set.experiments.len(),
            out.join(PARTIAL_NAME).display()
        ))
        .into()),
        Err(SimulateError::Experiment(f)) => Err(f),
        Err(e) => Err(e.to_string().into()),
    }
}

/// The simulated diameters against the measurements, one panel per experiment with data
/// (nothing without any), split into pages of at most
/// [`MAX_PANELS_PER_FIGURE`](figures::MAX_PANELS_PER_FIGURE) panels.
fn data_figure(
    args: &SimulateArgs,
    set: &ExperimentSet,
    all_profiles: &[Profiles],
    dir: &mut outputs::DirWriter<'_>,
    g: &Global,
) -> Result<(), Box<dyn Error>> {
    let ext = g.format.ext();
    let with_data: Vec<usize> = (0..set.experiments.len())
        .filter(|&k| set.measurements[k].is_some())
        .collect();
    if with_data.is_empty() {
        return Ok(());
    }
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
    let label = if args.newtonian {
        "Newtonian (n = 1)".to_string()
    } else {
        format!(
            "n = {}, κ = {}",
            checks::show(args.n),
            checks::show(args.kappa)
        )
    };
    let curves = [ModelCurves {
        label: &label,
        profiles: &profs,
        dashed: false,
    }];
    let pages = dir.rendered(|d| {
        let fig = d.join(format!("diameters_vs_data.{ext}"));
        figures::experiment_panel_pages(&fig, &views, &curves, View::Diameter)
    })?;
    if pages.len() > 1 {
        g.say(format!(
            "{} experiments with measurements: the diameter figure is split into {} files \
             ({}_1.{ext} …) of at most {} panels",
            views.len(),
            pages.len(),
            args.out.join("diameters_vs_data").display(),
            figures::MAX_PANELS_PER_FIGURE
        ));
    }
    Ok(())
}
