//! `rheometer design`.

use crate::*;
use rheometer::design::{
    CandidateGrid, Criterion, Design, DesignRequest, Discrimination, DiscriminationRequest,
    TakeUpAxis,
};
use rheometer::effects::Effect;
use rheometer::setup::TakeUp;
use rheometer::take_up::{resolve_take_up, MissingTakeUp};

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
    #[arg(long, value_parser = checks::parse_pair, conflicts_with = "stencil_velocity")]
    pub mass_flow: Option<(f64, f64)>,
    /// Stencil-velocity range "MIN,MAX" in mm/s (mass flow proportional to it, scaled by the
    /// template's stencil_velocity_mm_s).
    #[arg(long, value_parser = checks::parse_pair)]
    pub stencil_velocity: Option<(f64, f64)>,
    /// Take-up-diameter range "MIN,MAX" in m (default: from 0.6 times the smallest to 1.3 times
    /// the largest take-up diameter of the data).
    #[arg(long, value_parser = checks::parse_pair, conflicts_with = "take_up_velocity")]
    pub take_up_diameter: Option<(f64, f64)>,
    /// Take-up-speed range "MIN,MAX" in m/s (instead of diameters).
    #[arg(long, value_parser = checks::parse_pair)]
    pub take_up_velocity: Option<(f64, f64)>,
    /// Candidate grid "NxM" (mass flows x take-up values).
    #[arg(long, default_value = "9x9", value_parser = checks::parse_grid)]
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
    #[arg(long, value_parser = parse_noise)]
    pub noise: Option<f64>,
    /// BVP tolerance of the candidates' solves (1e-12 to 0.1).
    #[arg(long, default_value_t = 1e-6, value_parser = checks::parse_tol)]
    pub tol: f64,
    /// Write the design as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write design.txt, design.json and design.csv (every candidate) into DIR.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--noise`: a relative noise level in (0, 0.5).
fn parse_noise(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("\"{s}\" is not a number"))?;
    if !(v > 0.0 && v < 0.5) {
        return Err(format!(
            "the noise is a relative level in (0, 0.5) (got {v}; 0.015 is 1.5 %)"
        ));
    }
    Ok(v)
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
    if effects.len() < 2 {
        return Err(format!(
            "give at least two rival effects, comma-separated (e.g. \
             mass_flow_scale,nusselt_scale); the effects are {}",
            rheometer::effects::ALL_NAMES.join(", ")
        ));
    }
    for (i, e) in effects.iter().enumerate() {
        if effects[..i].iter().any(|o| o.name() == e.name()) {
            return Err(format!("effect {} given twice", e.name()));
        }
    }
    Ok(Rivals(effects))
}

fn range(flag: &str, (lo, hi): (f64, f64), m: usize) -> Result<Vec<f64>, String> {
    if !(lo > 0.0 && lo < hi) {
        return Err(format!("{flag} {lo},{hi}: give MIN,MAX with 0 < MIN < MAX"));
    }
    Ok(linspace(lo, hi, m))
}

/// The candidate grid of the arguments on the loaded data.
fn grid_of(a: &DesignArgs, loaded: &LoadedExperiments) -> Result<CandidateGrid, Box<dyn Error>> {
    let set = &loaded.set;
    let template = match &a.template {
        None => 0,
        Some(name) => set
            .experiments
            .iter()
            .position(|e| &e.name == name)
            .ok_or_else(|| {
                format!(
                    "--template {name}: no such experiment (the data set has {})",
                    set.experiments
                        .iter()
                        .map(|e| e.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?,
    };
    let flows: Vec<f64> = set.experiments.iter().map(|e| e.mass_flow).collect();
    let mass_flows = match (a.mass_flow, a.stencil_velocity) {
        (Some(r), _) => range("--mass-flow", r, a.grid.0)?,
        (None, Some(r)) => {
            let v0 = loaded.details[template]
                .stencil_velocity_mm_s
                .ok_or_else(|| {
                    format!(
                        "--stencil-velocity needs the template's stencil_velocity_mm_s, which \
                     experiment {} does not give; use --mass-flow",
                        set.experiments[template].name
                    )
                })?;
            let q0 = set.experiments[template].mass_flow;
            range("--stencil-velocity", r, a.grid.0)?
                .into_iter()
                .map(|v| q0 * v / v0)
                .collect()
        }
        (None, None) => {
            let lo = flows.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = flows.iter().copied().fold(0.0, f64::max);
            linspace(0.5 * lo, 2.0 * hi, a.grid.0)
        }
    };
    let take_up = match (a.take_up_diameter, a.take_up_velocity) {
        (Some(r), _) => TakeUpAxis::Diameter(range("--take-up-diameter", r, a.grid.1)?),
        (None, Some(r)) => TakeUpAxis::Velocity(range("--take-up-velocity", r, a.grid.1)?),
        (None, None) => {
            let mut d = Vec::new();
            for (e, m) in set.experiments.iter().zip(&set.measurements) {
                if let Ok(r) = resolve_take_up(e, m.as_ref(), MissingTakeUp::FromData, None) {
                    if let TakeUp::Diameter(v) = r.take_up {
                        d.push(v);
                    }
                }
            }
            if d.is_empty() {
                return Err(
                    "no take-up diameter in the data to take a default range from; give \
                            --take-up-diameter or --take-up-velocity"
                        .into(),
                );
            }
            let lo = d.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = d.iter().copied().fold(0.0, f64::max);
            TakeUpAxis::Diameter(linspace(0.6 * lo, 1.3 * hi, a.grid.1))
        }
    };
    Ok(CandidateGrid {
        template,
        mass_flows,
        take_up,
        positions: None,
    })
}

/// Every candidate as CSV: grid indices, conditions, predicted standard errors, correlation,
/// criteria, rank, and why it is infeasible.
fn design_csv(d: &Design) -> String {
    let mut s = String::from("i,j,mass_flow_kg_s,take_up,");
    for p in &d.parameters {
        s.push_str(&format!("se_{p},"));
    }
    s.push_str("corr_n_kappa,d_gain,a_ratio,e_ratio,gain,rank,infeasible\n");
    for c in &d.candidates {
        s.push_str(&format!(
            "{},{},{:e},{:e},",
            c.candidate.i, c.candidate.j, c.candidate.mass_flow, c.candidate.take_up
        ));
        match &c.prediction {
            Some(p) => {
                for v in &p.stderr {
                    s.push_str(&format!("{v:e},"));
                }
                s.push_str(&format!(
                    "{},{},{},{},{},{},\n",
                    p.correlation_n_kappa,
                    p.d_gain,
                    p.a_ratio,
                    p.e_ratio,
                    c.gain,
                    c.rank.map_or(String::new(), |r| r.to_string())
                ));
            }
            None => {
                s.push_str(&",".repeat(d.parameters.len() + 6));
                let why = c.infeasible.as_deref().unwrap_or("singular information");
                s.push_str(&format!("\"{}\"\n", why.replace('"', "'")));
            }
        }
    }
    s
}

/// Every candidate of a design for discrimination as CSV: grid indices, conditions, `λ` and
/// expected `ΔBIC` of every ordered pair of rivals, rank, and why it is infeasible.
fn discrimination_csv(d: &Discrimination) -> String {
    let mut s = String::from("i,j,mass_flow_kg_s,take_up,");
    for p in &d.current {
        s.push_str(&format!(
            "lambda_{t}_vs_{r},dbic_{t}_vs_{r},",
            t = p.truth,
            r = p.refitted
        ));
    }
    s.push_str("min_lambda,rank,infeasible\n");
    for c in &d.candidates {
        s.push_str(&format!(
            "{},{},{:e},{:e},",
            c.candidate.i, c.candidate.j, c.candidate.mass_flow, c.candidate.take_up
        ));
        if c.separations.is_empty() {
            s.push_str(&",".repeat(2 * d.current.len() + 2));
        } else {
            for p in &c.separations {
                s.push_str(&format!("{},{},", p.lambda, p.expected_delta_bic));
            }
            s.push_str(&format!(
                "{},{},",
                c.min_lambda,
                c.rank.map_or(String::new(), |r| r.to_string())
            ));
        }
        let why = c.infeasible.as_deref().unwrap_or("");
        if why.is_empty() {
            s.push('\n');
        } else {
            s.push_str(&format!("\"{}\"\n", why.replace('"', "'")));
        }
    }
    s
}

/// Runs `rheometer design`.
pub fn run(args: DesignArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let mut opts = IdentifyOptions::with_estimator(Estimator::Principled);
    opts.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    if let Some(s) = args.start {
        checks::check_start(s, &opts)?;
    }
    let loaded = load_input(g, &args.experiments, true, true)?;
    let grid = grid_of(&args, &loaded)?;
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
            let run = workflow::discriminate(&loaded, &fit_request, effects, &request)?;
            let d = &run.design;
            (
                d.to_text(),
                serde_json::to_string_pretty(d)?,
                discrimination_csv(d),
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
            let run = workflow::design(&loaded, &fit_request, &request)?;
            let d = &run.design;
            (d.to_text(), serde_json::to_string_pretty(d)?, design_csv(d))
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
