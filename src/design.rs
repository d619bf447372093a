//! `rheometer design`.

use crate::*;
use rheometer::design::{Criterion, DesignEstimate, DesignRequest, DiscriminationRequest};
use rheometer::model::Effect;
use rheometer::report::report_json::{to_report_json, ReportKind};
use rheometer::workflow::request::{self, DesignRanges, Door};

/// Arguments of `rheometer design`.
#[derive(clap::Args)]
pub struct DesignArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// The experiment the candidates copy (inlet, temperatures, spin line, measurement
    /// positions; default: the first).
    #[arg(long)]
    pub template: Option<String>,
    /// Mass-flow range "MIN,MAX" in kg/s (default: half the smallest to twice the largest of
    /// the data set).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true, conflicts_with = "stencil_velocity")]
    pub mass_flow: Option<(f64, f64)>,
    /// Stencil-velocity range "MIN,MAX" in mm/s (mass flow proportional to it, scaled by the
    /// template's stencil_velocity_mm_s).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub stencil_velocity: Option<(f64, f64)>,
    /// Take-up-diameter range "MIN,MAX" in m (default: from 0.6 times the smallest to 1.3 times
    /// the largest take-up diameter of the data).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true, conflicts_with = "take_up_velocity")]
    pub take_up_diameter: Option<(f64, f64)>,
    /// Take-up-speed range "MIN,MAX" in m/s (instead of diameters).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub take_up_velocity: Option<(f64, f64)>,
    /// Candidate grid "NxM" (mass flows x take-up values).
    #[arg(long, default_value = "9x9", allow_hyphen_values = true, value_parser = checks::parse_grid)]
    pub grid: (usize, usize),
    /// Ranking criterion: d (volume of the confidence region), a (mean variance), e (worst
    /// direction).
    #[arg(long, default_value = "d", value_parser = Criterion::parse)]
    pub criterion: Criterion,
    /// Rank the candidates by how well they tell rival explanations apart instead: "A,B" or "A,B,C",
    /// each the model plus one effect (e.g. mass_flow_scale,nusselt_scale, a tie `diagnose`
    /// reports).
    #[arg(long, value_name = "EFFECT,EFFECT", value_parser = parse_rivals, conflicts_with = "criterion")]
    pub discriminate: Option<Rivals>,
    /// Start point "N,KAPPA" of the fit (default: the paper's start heuristic).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub start: Option<(f64, f64)>,
    /// Relative noise of the measurements, e.g. 0.015 for 1.5 % (default: the data set's
    /// relative_uncertainty, else the fit's residual level; with --discriminate, the fit
    /// summary's noise level).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_noise)]
    pub noise: Option<f64>,
    /// BVP tolerance of the candidates' solves (1e-12 to 0.1).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: f64,
    /// Write the design as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write design.txt, design.json and design.csv (every candidate) into DIR.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--noise`: a relative noise level (see [`request::noise`]).
fn parse_noise(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("\"{s}\" is not a number"))?;
    request::noise(v).map_err(|r| r.reason(Door::Cli))
}

/// The rival effects of `--discriminate`.
#[derive(Clone)]
pub struct Rivals(pub Vec<Effect>);

/// `--discriminate`: two or more distinct effect names, comma-separated.
fn parse_rivals(s: &str) -> Result<Rivals, String> {
    let effects: Vec<Effect> = s
        .split(',')
        .map(|t| t.trim().parse::<Effect>())
        .collect::<Result<_, _>>()?;
    request::rivals(effects)
        .map(Rivals)
        .map_err(|r| r.reason(Door::Cli))
}

/// Runs `rheometer design`.
pub fn run(args: DesignArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let mut opts = IdentifyOptions::with_estimator(Estimator::Principled);
    opts.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    if let Some(s) = args.start {
        checks::check_start(s, &opts)?;
    }
    let loaded = load_input(g, &args.experiments, true, true)?;
    let ranges = DesignRanges {
        template: args.template.clone(),
        mass_flow: args.mass_flow,
        stencil_velocity: args.stencil_velocity,
        take_up_diameter: args.take_up_diameter,
        take_up_velocity: args.take_up_velocity,
        grid: args.grid,
    };
    let grid = request::design_grid(&ranges, &loaded)?;
    // every output is checked before the work starts, against the inputs and each other
    let names = vec![
        ("report".to_string(), "design.txt".to_string()),
        ("json".to_string(), "design.json".to_string()),
        ("table".to_string(), "design.csv".to_string()),
    ];
    let mut plan = outputs::plan_for(&args.experiments, &loaded);
    if let Some(path) = &args.json {
        plan.file(path, "--json");
    }
    if let Some(dir) = &args.out {
        plan.dir(dir, "--out", names.iter().map(|(_, n)| n));
        plan.dir_files(dir, [PARTIAL_NAME]);
    }
    let outputs = outputs::check(&plan, g)?;
    let mut fit_request = FitRequest::new(opts);
    fit_request.start = args.start.map(|(n, k)| [n, k]);
    let max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    let say_estimate = |e: &DesignEstimate| {
        if let Some(line) = checks::design_estimate(e) {
            g.say(line);
        }
    };
    let (text, json, csv) = match &args.discriminate {
        Some(Rivals(effects)) => {
            let mut request = DiscriminationRequest::new(grid);
            request.simulate.tol = args.tol;
            request.simulate.max_nodes = max_nodes;
            request.noise = args.noise;
            g.say(format!(
                "fitting {} rivals, then {} candidate experiments ...",
                effects.len(),
                request.grid.candidates().len()
            ));
            let run = workflow::discriminate_with_estimate(
                &loaded,
                &fit_request,
                effects,
                &request,
                &say_estimate,
            )?;
            let d = &run.design;
            (
                d.to_text(),
                to_report_json(ReportKind::Discrimination, d)?,
                d.to_csv(),
            )
        }
        None => {
            let mut request = DesignRequest::new(grid, args.criterion);
            request.simulate.tol = args.tol;
            request.noise = args.noise;
            request.simulate.max_nodes = max_nodes;
            g.say(format!(
                "fitting, then {} candidate experiments ...",
                request.grid.candidates().len()
            ));
            let run =
                workflow::design_with_estimate(&loaded, &fit_request, &request, &say_estimate)?;
            let d = &run.design;
            (
                d.to_text(),
                to_report_json(ReportKind::Design, d)?,
                d.to_csv(),
            )
        }
    };
    outln!("{text}");
    if let Some(j) = &args.json {
        outputs.write_text(j, &json)?;
        g.say(format!("wrote {}", j.display()));
    }
    if let Some(out) = &args.out {
        let mut dir = outputs::DirWriter::begin(&outputs, out, "rheometer design", "files", names)?;
        dir.text("design.txt", &text)?;
        dir.text("design.json", &json)?;
        dir.text("design.csv", &csv)?;
        dir.finish()?;
        g.say(format!("wrote {}", out.display()));
    }
    Ok(())
}
